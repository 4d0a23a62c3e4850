"""The parallel curve a_1 x a_2 = 0, enclosed in ball arithmetic (python-flint's arb).

With P_i the spring vectors and a_i = (P_i . dP_i/dgamma1, P_i . dP_i/dgamma2), grad V =
sum_i k_i (1 - L0_i/d_i) a_i: a critical point of V is relaxed (d_i = L0_i for both springs) or
lies on the parallel curve C = {f = 0}, f = a_1 x a_2 (docs/design.md). C does not depend on the
free lengths. This module covers C by boxes ("leaves") in each of which C is proved to be the
graph of a function of one angle: a quadtree over the torus drops every box where the enclosure
of f (or its mean value form about the box's midpoint) excludes 0 and keeps, as a leaf, every
box where that of df/dgamma2 (C a graph over gamma1) or of df/dgamma1 (over gamma2) excludes 0.
Every point of C lies in a leaf (or in one of the `undecided` boxes, where neither test
succeeded at the smallest size: near a singular point of C).

Boxes are index ranges on an increasing grid of angles per axis, so that a leaf's edges lie on
grid lines (the sampled lines of `fold_curves`, for the map's certificate).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from flint import arb

from ...params import Params

TWO_PI = 2 * math.pi


@dataclass(frozen=True)
class Springs:
    """The mechanism's constants as exact balls: L3 and, per spring, (bx, by, qx, qy, k, L0),
    b the anchor on the bottom body (frame B), q that on the top body (frame T); a coordinate
    that is exactly 0 is None (its products are skipped)."""

    L3: object
    springs: tuple
    free: tuple[bool, bool]  # whether each spring has a free length (V not smooth at d = 0)


def springs(params: Params) -> Springs:
    """The constants of `params` as balls (a float is an exact binary number)."""
    p = params

    def ball(v: float):
        return None if v == 0.0 else arb(v)

    rows = (
        (arb(p.p2x), None, arb(p.p6x), None, arb(p.k1), arb(p.L01)),
        (arb(p.p3x), ball(p.p3y), arb(p.p5x), ball(p.p5y), arb(p.k2), arb(p.L02)),
    )
    return Springs(arb(p.L3), rows, (p.L01 != 0.0, p.L02 != 0.0))


def spring_parts(sp: Springs, g1, g2, second: bool = False) -> list[tuple]:
    """Per spring over the angles g1, g2 (balls): (a1, a2, d^2) and, with `second`, the
    derivatives of a: (b11, b12, b22), b_jm = d a_j / d gamma_m.

    With u = (cos g1, sin g1), u' its derivative, R the rotation by g2, e = L3 u - b:
    P = e + R q, a1 = L3 (R q - b) . u', a2 = e . R'q (as u . u' = R q . R'q = 0), and
    b11 = -L3 (R q - b) . u, b12 = L3 u' . R'q, b22 = -e . R q.
    """
    s1, c1 = g1.sin_cos()
    s2, c2 = g2.sin_cos()
    l3c, l3s = sp.L3 * c1, sp.L3 * s1
    out = []
    for bx, by, qx, qy, _k, _l0 in sp.springs:
        rx, ry = c2 * qx, s2 * qx
        if qy is not None:
            rx, ry = rx - s2 * qy, ry + c2 * qy
        ex, hx = l3c - bx, rx - bx
        ey, hy = (l3s, ry) if by is None else (l3s - by, ry - by)
        a1 = hy * l3c - hx * l3s
        a2 = ey * rx - ex * ry
        dd = (ex + rx) ** 2 + (ey + ry) ** 2
        if second:
            out.append((a1, a2, dd, -(hx * l3c + hy * l3s), rx * l3c + ry * l3s,
                        -(ex * rx + ey * ry)))  # fmt: skip
        else:
            out.append((a1, a2, dd))
    return out


def cross_and_slopes(parts: list[tuple]) -> tuple:
    """f = a_1 x a_2 and its derivatives (df/dgamma1, df/dgamma2) from `spring_parts(...,
    second=True)`."""
    (u1, v1, _, p11, p12, p22), (u2, v2, _, q11, q12, q22) = parts
    f = u1 * v2 - v1 * u2
    fx = p11 * v2 + u1 * q12 - p12 * u2 - v1 * q11
    fy = p12 * v2 + u1 * q22 - p22 * u2 - v1 * q12
    return f, fx, fy


def cross(parts: list[tuple]):
    """f = a_1 x a_2 from `spring_parts`."""
    (u1, v1, *_), (u2, v2, *_) = parts
    return u1 * v2 - v1 * u2


def interval(lo: float, hi: float):
    """The ball holding [lo, hi]."""
    return arb(lo).union(arb(hi))


@dataclass
class Cover:
    """C enclosed: `leaves` (lo1, hi1, lo2, hi2, axis, slope) with C a graph over gamma1
    (axis 0: the enclosure `slope` of df/dgamma2 excludes 0) or over gamma2 (axis 1: that of
    df/dgamma1 does); `undecided` boxes at the smallest size where neither holds; `index`, the
    grid index ranges of the leaves (i0, i1, j0, j1)."""

    leaves: list[tuple] = field(default_factory=list)
    index: list[tuple] = field(default_factory=list)
    undecided: list[tuple] = field(default_factory=list)
    boxes: int = 0


def _start(n: int, parts: int) -> list[int]:
    return sorted({round(k * n / parts) for k in range(parts + 1)})


def curve_cover(
    sp: Springs, edges1, edges2, max_cells: int | None = None,
    start: int = 16,
) -> Cover:  # fmt: skip
    """The quadtree on the grid `edges1` x `edges2` (increasing angles, rad, spanning 2 pi):
    boxes where f excludes 0 (by its enclosure or its mean value form) dropped, leaves no wider
    than `max_cells` grid cells (if given), smallest box one cell."""
    cover = Cover()
    cuts1, cuts2 = _start(len(edges1) - 1, start), _start(len(edges2) - 1, start)
    stack = [(a, b, c, d) for a, b in zip(cuts1[:-1], cuts1[1:], strict=True)
             for c, d in zip(cuts2[:-1], cuts2[1:], strict=True)]  # fmt: skip
    cap = max_cells or max(len(edges1), len(edges2))
    while stack:
        i0, i1, j0, j1 = stack.pop()
        cover.boxes += 1
        q = (float(edges1[i0]), float(edges1[i1]), float(edges2[j0]), float(edges2[j1]))
        g1, g2 = interval(q[0], q[1]), interval(q[2], q[3])
        f, fx, fy = cross_and_slopes(spring_parts(sp, g1, g2, second=True))
        if f > 0 or f < 0 or _misses_curve(sp, q, g1, g2, fx, fy):
            continue
        small = i1 - i0 <= cap and j1 - j0 <= cap
        if small and (fy > 0 or fy < 0 or fx > 0 or fx < 0):
            axis = _axis(fx, fy)
            cover.leaves.append((*q, axis, fy if axis == 0 else fx))
            cover.index.append((i0, i1, j0, j1))
            continue
        if i1 - i0 <= 1 and j1 - j0 <= 1:
            cover.undecided.append(q)
            continue
        stack.extend(_halves((i0, i1, j0, j1)))
    return cover


def _misses_curve(sp: Springs, q: tuple, g1, g2, fx, fy) -> bool:
    """Whether the mean value form f(m) + f_x (g1 - m1) + f_y (g2 - m2) (m the box's midpoint)
    excludes 0: tighter than f's own enclosure where a_1 and a_2 are both small (f is then a
    difference of products of small quantities)."""
    m1, m2 = 0.5 * (q[0] + q[1]), 0.5 * (q[2] + q[3])
    value = cross(spring_parts(sp, arb(m1), arb(m2))) + fx * (g1 - m1) + fy * (g2 - m2)
    return value > 0 or value < 0


def _axis(fx, fy) -> int:
    """0 (C a graph over gamma1: df/dgamma2 excludes 0) or 1; where both do, the axis along
    which C is flatter (the larger lower bound of |df/d other|)."""
    ok_y, ok_x = fy > 0 or fy < 0, fx > 0 or fx < 0
    if ok_y and ok_x:
        return 0 if float(abs(fy).lower()) >= float(abs(fx).lower()) else 1
    return 0 if ok_y else 1


def _halves(b: tuple[int, int, int, int]) -> list[tuple[int, int, int, int]]:
    """Split the longer side (both if equal) at its middle index."""
    i0, i1, j0, j1 = b
    out = [b]
    if i1 - i0 >= j1 - j0 and i1 - i0 > 1:
        m = (i0 + i1) // 2
        out = [(i0, m, j0, j1), (m, i1, j0, j1)]
    if j1 - j0 >= i1 - i0 and j1 - j0 > 1:
        m = (j0 + j1) // 2
        out = [piece for a, b_, _, _ in out for piece in ((a, b_, j0, m), (a, b_, m, j1))]
    return out


class UniformEdges:
    """The edges -pi + 2 pi i / cells, i = 0 .. cells, computed on demand (a grid too fine to
    store); the same index always gives the same float."""

    def __init__(self, cells: int):
        self.cells = cells

    def __len__(self) -> int:
        return self.cells + 1

    def __getitem__(self, i: int) -> float:
        return math.pi if i == self.cells else -math.pi + TWO_PI * i / self.cells


def uniform_edges(cells: int) -> UniformEdges:
    """Grid edges -pi .. pi in `cells` cells."""
    return UniformEdges(cells)


@dataclass
class Crossings:
    """Where C crosses the edges of the cover's leaves, isolated: per axis of the grid lines
    (0: the lines gamma1 = edges1[i], 1: gamma2 = edges2[j]), (line index, lo, hi), the other
    angle's interval holding exactly one point of C on that line; `undecided` edge segments
    (line axis, line index, lo, hi) where isolation failed (C tangent to the line)."""

    lines: tuple[list, list] = field(default_factory=lambda: ([], []))
    undecided: list[tuple] = field(default_factory=list)
    segments: int = 0


def edge_crossings(
    sp: Springs, cover: Cover, edges1: np.ndarray, edges2: np.ndarray, min_width: float = 1e-12
) -> Crossings:
    """Every crossing of C with the edges of the cover's leaves (each edge segment once)."""
    out, seen, corners = Crossings(), set(), {}
    edges = (edges1, edges2)
    for i0, i1, j0, j1 in cover.index:
        for line_axis, lines, span in ((0, (i0, i1), (j0, j1)), (1, (j0, j1), (i0, i1))):
            for line in lines:
                key = (line_axis, line, *span)
                if key in seen:
                    continue
                seen.add(key)
                lo, hi = float(edges[1 - line_axis][span[0]]), float(edges[1 - line_axis][span[1]])
                fixed = float(edges[line_axis][line])
                _isolate(sp, out, corners, line_axis, line, fixed, (lo, hi), min_width)
    return out


def _isolate(sp, out: Crossings, corners: dict, axis: int, line: int, fixed: float,
             segment: tuple[float, float], min_width: float) -> None:  # fmt: skip
    """The points of C on one edge segment (the line of `axis` through `fixed`), by bisection:
    none where f excludes 0; where f's derivative along the line excludes 0, one exactly when
    f has opposite signs (or 0 may be its value) at the ends."""
    stack = [segment]
    point = arb(fixed)
    while stack:
        lo, hi = stack.pop()
        out.segments += 1
        run = interval(lo, hi)
        g = (point, run) if axis == 0 else (run, point)
        f, fx, fy = cross_and_slopes(spring_parts(sp, *g, second=True))
        if f > 0 or f < 0:
            continue
        along = fy if axis == 0 else fx
        if along > 0 or along < 0:
            ends = [_corner(sp, corners, axis, fixed, t) for t in (lo, hi)]
            if not (ends[0] > 0 and ends[1] > 0) and not (ends[0] < 0 and ends[1] < 0):
                out.lines[axis].append((line, lo, hi))
            continue
        if hi - lo <= min_width:
            out.undecided.append((axis, line, lo, hi))
            continue
        mid = 0.5 * (lo + hi)
        stack.extend([(lo, mid), (mid, hi)])


def _corner(sp: Springs, cache: dict, axis: int, fixed: float, t: float):
    """f at the point (fixed, t) of a line of `axis` (cached)."""
    key = (fixed, t) if axis == 0 else (t, fixed)
    if key not in cache:
        cache[key] = cross(spring_parts(sp, arb(key[0]), arb(key[1])))
    return cache[key]


LEAF_CELLS = 8  # the map's certificate: leaves at most this many sampling cells a side
SAME_ROOT = 1e-9  # rad: a sample this close to a crossing's interval is that crossing


def certify_samples(params: Params, samples: list, grid: np.ndarray,
                    max_cells: int = LEAF_CELLS) -> tuple[dict, list]:  # fmt: skip
    """Prove that samples of the parallel curve on the lines of `grid` (per axis: fixed angles
    on the grid, roots in the other angle, rad; `fold_curves.parallel_samples`) leave no part
    of C unsampled: the cover on the grid (leaves of at most `max_cells` cells whose edges are
    grid lines), every crossing of a leaf edge isolated, and each one found among the samples.
    Crossings the samples lack are added (bisected in double precision). Returns the run.json
    `certificate` record and the samples with any additions."""
    from ...versions import dist_version

    start = time.perf_counter()
    sp = springs(params)
    edges = np.append(grid, math.pi)
    cover = curve_cover(sp, edges, edges, max_cells)
    found = edge_crossings(sp, cover, edges, edges)
    samples, added = _add_missing(params, samples, grid, found)
    proved = not cover.undecided and not found.undecided
    crossings = len(found.lines[0]) + len(found.lines[1])
    size = math.degrees(max_cells * (grid[1] - grid[0]))
    cells = f"{max_cells} x {max_cells} sampling cells ({size:.2f} deg)"
    statement = (
        f"proved: the parallel curve lies in {len(cover.leaves)} boxes of at most {cells}, in "
        f"each the graph of a function of one angle; each of its {crossings} crossings of "
        "their edges is a sample, so every closed loop of the curve is sampled and between "
        "consecutive samples the curve stays in one box"
        if proved
        else f"not proved: {len(cover.undecided)} boxes and {len(found.undecided)} edges "
        "undecided (the curve may be singular or tangent to a sampling line there)"
    )
    record = {
        "status": "proved" if proved else "undecided",
        "statement": statement,
        "method": "quadtree on the sampling grid: boxes where the ball enclosure of "
        "a1 x a2 excludes 0 dropped, leaves where that of its derivative in one angle excludes "
        "0; crossings of leaf edges isolated by bisection on the edges",
        "library": f"python-flint {dist_version('python-flint', 'flint')} (arb)",
        "leaves": len(cover.leaves), "boxes_examined": cover.boxes, "edge_crossings": crossings,
        "samples_added": added, "undecided_boxes": [list(q) for q in cover.undecided],
        "undecided_edges": [list(e) for e in found.undecided],
        "seconds": time.perf_counter() - start,
    }  # fmt: skip
    return record, samples


def _add_missing(params: Params, samples: list, grid: np.ndarray, found: Crossings):
    """The samples with every crossing they lack added, and how many were added."""
    points, added, out = len(grid), 0, []
    for axis, (fixed, roots) in enumerate(samples):
        by_line: dict[float, np.ndarray] = {}
        order = np.lexsort((roots, fixed))
        for value, idx in zip(*np.unique(fixed[order], return_index=True), strict=True):
            stop = np.searchsorted(fixed[order], value, side="right")
            by_line[float(value)] = roots[order][idx:stop]
        extra_fixed, extra_roots = [], []
        for line, lo, hi in found.lines[axis]:
            x = float(grid[line % points])
            near = by_line.get(x, np.empty(0))
            shifted = (near - 0.5 * (lo + hi) + math.pi) % (2 * math.pi) - math.pi
            if (np.abs(shifted) <= 0.5 * (hi - lo) + SAME_ROOT).any():
                continue
            extra_fixed.append(x)
            extra_roots.append(_bisect(params, axis, x, lo, hi))
        added += len(extra_fixed)
        out.append((np.concatenate([fixed, extra_fixed]), np.concatenate([roots, extra_roots])))
    return out, added


def _bisect(params: Params, axis: int, x: float, lo: float, hi: float) -> float:
    """The root of a_1 x a_2 on the line of `axis` through x, in [lo, hi] (double precision)."""
    from ..design.free_lengths import parallel_cross

    def f(t: float) -> float:
        return float(parallel_cross(params, x, t) if axis == 0 else parallel_cross(params, t, x))

    f_lo = f(lo)
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        f_mid = f(mid)
        if f_mid == 0 or hi - lo <= 1e-15:
            return mid
        lo, hi, f_lo = (mid, hi, f_mid) if (f_mid > 0) == (f_lo > 0) else (lo, mid, f_lo)
    return 0.5 * (lo + hi)
