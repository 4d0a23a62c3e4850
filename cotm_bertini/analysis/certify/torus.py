"""Completeness, proved: every critical point of V on a torus of angles (a circle: one angle),
by branch and bound in ball arithmetic (python-flint's arb), outside small neighbourhoods of the
zero-length points.

V is given by a `Landscape`: enclosures of its gradient and Hessian over a box of angles, and of
the squared lengths of the springs with free lengths (the paper's mechanism: `paper_landscape`;
a framework whose poses form a torus: certify.framework_torus). Each box of angles is either
excluded (an interval enclosure of grad V misses 0), or shown by the Krawczyk operator to hold
exactly one critical point (K(Q) in the interior of Q) or none (K(Q) misses Q; the test is tried
on boxes no wider than KRAWCZYK_WIDTH only), or split along its two widest sides (`_split`). V is
not smooth where a spring with L0 > 0 has zero length: boxes where such a spring is certainly
shorter than `short` are set aside, and so are boxes where it may be, once split down to
`min_width`; the proof bounds the spring length over every box set aside, so the statement is:
every critical point with every spring length above that bound is found. A box with one critical
point is matched to the known equilibrium whose proved enclosure it contains; one with no known
equilibrium in it is a missing one. Boxes are flat tuples (lo1, hi1, lo2, hi2, ...) in radians.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np

from ...params import PARAM_NAMES, Params
from ...progress import Progress
from ..energy_terms import gradient_hessian

TWO_PI = 2 * math.pi
ROOT_MIN_WIDTH = 1e-10  # boxes holding a known equilibrium's enclosure are split down to this
KRAWCZYK_WIDTH = 0.1  # radians: wider boxes are split, not tested (the test rarely decides them)
MAX_CUTS = 2  # sides halved at a split (see _split)


@dataclass(frozen=True)
class Landscape:
    """V on the torus of `n` angles, as ball enclosures over a box (a tuple of n arb balls):
    `enclose(balls, hessian)` -> (grad V, its Hessian or None), `lengths(balls)` -> the squared
    lengths of the springs with free lengths (V is not smooth where one is 0); `length_unit`:
    the unit of those lengths (the smallest box worth splitting to scales with it)."""

    n: int
    enclose: Callable
    lengths: Callable
    length_unit: float


def arb_params(params: Params):
    """The parameters as exact balls (a float is an exact binary number)."""
    from flint import arb

    return SimpleNamespace(**{n: arb(getattr(params, n)) for n in PARAM_NAMES})


def box(*bounds: float) -> tuple:
    """Balls holding [lo1, hi1] x [lo2, hi2] x ... exactly."""
    from flint import arb

    return tuple(_interval(arb, lo, hi) for lo, hi in zip(bounds[::2], bounds[1::2], strict=True))


def _interval(arb, lo: float, hi: float):
    """A ball holding [lo, hi]: its float midpoint and a radius at least the distance to either
    end (a float difference is within half an ulp of the exact one: the next float up holds
    it)."""
    mid = 0.5 * (lo + hi)
    if lo == hi or not (math.isfinite(mid) and lo <= mid <= hi):
        return arb(lo).union(arb(hi))
    return arb(mid, math.nextafter(max(hi - mid, mid - lo), math.inf))


def enclosures(pa, g1, g2, hessian: bool = True):
    """Balls holding grad V (and its Hessian) over the box of angles g1 x g2."""
    from flint import arb

    angles = (g1.cos(), g1.sin(), g2.cos(), g2.sin())
    return gradient_hessian(pa, angles, lambda x: x.sqrt(), hessian, arb(0))


@dataclass
class TorusProof:
    """What the branch and bound established."""

    roots: dict[int, list]  # known equilibrium index -> boxes proved to hold it alone
    missing: list[tuple]  # boxes proved to hold a critical point no known equilibrium is in
    undecided: list[tuple]  # boxes no test decided (smaller than min_width)
    excluded: list[tuple]  # boxes where a spring may be shorter than `short`, set aside
    boxes: int = 0
    longest_excluded: float = 0.0  # the shortest spring is at most this long in every one
    # Every spring with a free length is at least this long over every box not set aside.
    shortest_length: float = math.inf
    notes: list[str] = field(default_factory=list)


def paper_landscape(params: Params, pa=None) -> Landscape:
    """The paper's mechanism: V(gamma1, gamma2) of its two springs."""
    pa = pa or arb_params(params)
    return Landscape(
        2,
        lambda balls, hessian=True: enclosures(pa, *balls, hessian=hessian),
        lambda balls: spring_length_squares(params, pa, *balls),
        params.L3,
    )


def krawczyk_2d(params: Params, pa, q: tuple[float, float, float, float]) -> tuple[str, tuple]:
    """`krawczyk_box` for the paper's mechanism."""
    return krawczyk_box(paper_landscape(params, pa), q)


def krawczyk_box(land: Landscape, q: tuple, balls: tuple | None = None) -> tuple[str, tuple]:
    """('one', K) (exactly one critical point in the box, and it lies in K), ('none', K), or
    ('unknown', K); K is the Krawczyk image of the box (arb balls); `balls`: box(*q), if made."""
    from flint import arb, arb_mat

    n = land.n
    m = [(q[2 * j] + q[2 * j + 1]) / 2 for j in range(n)]
    balls = balls or box(*q)
    _, hq = land.enclose(balls)  # first: the search has just enclosed grad V over this box
    if not all(h.is_finite() for row in hq for h in row):
        return "unknown", ()
    hm = arb_mat(hq)
    try:  # the preconditioner: the midpoint of the Hessian's inverse (any matrix is sound here)
        ym = hm.mid().inv().mid()
    except ZeroDivisionError:
        return "unknown", ()
    grad_m, _ = land.enclose(tuple(arb(v) for v in m), hessian=False)
    step = ym * arb_mat([[g] for g in grad_m])
    spread = (_eye(n) - ym * hm) * arb_mat([[balls[j] - m[j]] for j in range(n)])
    k = [arb(m[j]) - step[j, 0] + spread[j, 0] for j in range(n)]
    if not all(e.is_finite() for e in k):
        return "unknown", tuple(k)
    if all(balls[j].contains_interior(k[j]) for j in range(n)):
        return "one", tuple(k)
    if any(not balls[j].overlaps(k[j]) for j in range(n)):
        return "none", tuple(k)
    return "unknown", tuple(k)


_EYES: dict[int, object] = {}


def _eye(n: int):
    """The n x n identity as an arb_mat (made once)."""
    from flint import arb_mat

    if n not in _EYES:
        _EYES[n] = arb_mat([[int(i == j) for j in range(n)] for i in range(n)])
    return _EYES[n]


def _close(centres: np.ndarray, q: tuple, margin: float) -> bool:
    """Whether a known equilibrium lies within `margin` of the box (on the torus)."""
    if not len(centres):
        return False
    mid = np.array([(q[2 * j] + q[2 * j + 1]) / 2 for j in range(len(q) // 2)])
    half = np.array([(q[2 * j + 1] - q[2 * j]) / 2 for j in range(len(q) // 2)])
    gap = np.abs((centres - mid + math.pi) % TWO_PI - math.pi) - half
    return bool((gap.max(axis=1) <= margin).any())


def enclosure_bounds(known: dict[int, tuple], n: int = 2) -> tuple[list[int], np.ndarray]:
    """The known enclosures as float bounds, rounded outwards, with their copies one turn away
    in each angle: (indices, array (known, n, 3, 2) of (lo, hi) per angle and turn -1, 0, 1)."""
    keys = list(known)
    out = np.zeros((len(keys), n, 3, 2))
    for a, k in enumerate(keys):
        for j, e in enumerate(known[k]):
            lo = math.nextafter(float(e.lower()), -math.inf)
            hi = math.nextafter(float(e.upper()), math.inf)
            for b, s in enumerate((-1, 0, 1)):
                out[a, j, b] = (lo + s * TWO_PI, hi + s * TWO_PI)
    return keys, out


def _where(bounds: tuple[list[int], np.ndarray], q: tuple) -> tuple[list[int], list[int]]:
    """Known equilibria whose enclosure lies inside the box, and those it only touches (a copy
    of it turned by whole turns in any angles: angle by angle, as the turns in each angle are
    independent of the others').

    Float comparisons of outward-rounded bounds: a 'not inside' may be conservative (the box is
    then split), never an 'inside' that is not."""
    keys, b = bounds
    if not keys:
        return [], []
    lo, hi = np.array(q[0::2])[None, :, None], np.array(q[1::2])[None, :, None]
    inside = ((lo < b[..., 0]) & (b[..., 1] < hi)).any(axis=2).all(axis=1)
    touch = ((b[..., 0] <= hi) & (lo <= b[..., 1])).any(axis=2).all(axis=1)
    return [keys[a] for a in np.flatnonzero(inside)], [
        keys[a] for a in np.flatnonzero(touch & ~inside)]  # fmt: skip


def spring_length_squares(params: Params, pa, g1, g2) -> list:
    """Balls holding d_i^2 over the box, for each spring with L0 > 0 (where V is not smooth)."""
    from ...model.kinematics import spring_vectors

    vec = spring_vectors(pa, g1.cos(), g1.sin(), g2.cos(), g2.sin())
    free = {1: params.L01, 2: params.L02}
    return [vec[f"spring{i}"][0] ** 2 + vec[f"spring{i}"][1] ** 2 for i in (1, 2) if free[i]]


def _short(lengths: list, limit) -> str:
    """'all' if some spring is shorter than the limit on the whole box, 'some' if it may be
    somewhere in it, '' if every spring with L0 > 0 is longer everywhere (V smooth there)."""
    verdict = ""
    for dd in lengths:
        if dd < limit:
            return "all"
        if not dd > limit:
            verdict = "some"
    return verdict


def _split(q: tuple, balls: tuple | None = None) -> list:
    """A box halved along its MAX_CUTS widest sides (those at least half as wide as its widest;
    in one or two angles: every side). In four angles a box cut along every side makes 16 boxes
    where the first halvings would often have excluded half of them. With `balls` (box(*q)):
    each half as (bounds, its balls), the balls of the sides not cut kept."""
    from flint import arb

    n = len(q) // 2
    widths = [q[2 * j + 1] - q[2 * j] for j in range(n)]
    order = sorted(range(n), key=lambda j: -widths[j])[:MAX_CUTS]
    cut = [j for j in order if widths[j] >= 0.5 * widths[order[0]]]
    halves = []
    for j in range(n):
        lo, hi = q[2 * j], q[2 * j + 1]
        if j in cut:
            mid = (lo + hi) / 2
            halves.append((((lo, mid), _interval(arb, lo, mid)),
                           ((mid, hi), _interval(arb, mid, hi))))  # fmt: skip
        else:
            halves.append((((lo, hi), balls[j] if balls else None),))
    out = [(tuple(v for (pair, _) in choice for v in pair), tuple(b for _, b in choice))
           for choice in itertools.product(*halves)]  # fmt: skip
    return out if balls else [bounds for bounds, _ in out]


def branch_and_bound(
    params: Params,
    known: dict[int, tuple],
    short: float,
    min_width: float,
    start: int = 16,
) -> TorusProof:
    """`torus_search` for the paper's mechanism."""
    return torus_search(paper_landscape(params), known, short, min_width, start)


def torus_search(
    land: Landscape,
    known: dict[int, tuple],
    short: float,
    min_width: float,
    start: int | None = None,
) -> TorusProof:
    """Decide every box of the torus [0, 2 pi]^n, from a grid of `start` boxes an angle (16 in
    one or two angles, 8 in more; see the module docstring). Boxes where a
    spring with L0 > 0 is shorter than `short` are set aside (split to `min_width` where they
    may only be); `proof.longest_excluded` bounds the spring length over them, and
    `proof.shortest_length` the spring lengths from below over every other box."""
    from flint import arb

    limit = arb(short) ** 2
    # At the smallest width, a spring this short still makes the enclosures of the 1/d terms
    # too wide to decide: such boxes are set aside too (the reported bound covers them).
    wide = (arb(short) + 3 * arb(land.length_unit) * arb(min_width)) ** 2
    proof = TorusProof({k: [] for k in known}, [], [], [])
    centres = np.array([[float(e.mid()) for e in v] for v in known.values()])
    bounds = enclosure_bounds(known, land.n)
    start = start or (16 if land.n <= 2 else 8)
    edges = np.linspace(0.0, TWO_PI, start + 1)
    cells = list(zip(edges[:-1], edges[1:], strict=True))
    stack = [(q, box(*q)) for q in (tuple(v for c in choice for v in c)
             for choice in itertools.product(cells, repeat=land.n))]  # fmt: skip
    # How far: the share of the torus in boxes decided (neither on the stack nor split).
    report, pending = Progress("certificate search", 1.0, "of the poses decided"), 1.0
    low_square = math.inf  # at most the square of every spring's length over every leaf
    while stack:
        if not proof.boxes % 32:  # a line costs more than a box: not every box
            report.set(1.0 - pending, note=f"{proof.boxes} boxes")
        q, balls = stack.pop()
        share = _share(q)
        pending -= share
        proof.boxes += 1
        width = max(q[2 * j + 1] - q[2 * j] for j in range(land.n))
        lengths = land.lengths(balls)
        near = _short(lengths, limit if width > min_width else wide)
        if near == "all" or (near and width <= min_width):
            proof.excluded.append(q)
            shortest = min(float(dd.upper()) for dd in lengths)
            proof.longest_excluded = max(proof.longest_excluded, math.sqrt(shortest))
            continue
        outcome = _visit(land, (q, balls, width), not near, (bounds, centres, min_width), proof)
        if outcome != "done":
            floor = ROOT_MIN_WIDTH if outcome == "root" else _floor(lengths, min_width,
                                                                    land.length_unit)  # fmt: skip
            if width > floor:
                stack.extend(_split(q, balls))
                pending += share
                continue
            proof.undecided.append(q)
        # A leaf of the search (decided or undecided): its lengths bound them from below.
        for dd in lengths:
            low_square = min(low_square, math.nextafter(float(dd.lower()), -math.inf))
    report.set(1.0, note=f"{proof.boxes} boxes")  # the stack is empty: every box decided
    report.close()
    proof.shortest_length = _root_down(low_square)
    return proof


def _root_down(square: float) -> float:
    """A float at most the square root of `square` (0 for a square at most 0, inf for inf)."""
    if square == math.inf:
        return math.inf
    return math.nextafter(math.sqrt(square), 0.0) if square > 0 else 0.0


def _share(q: tuple) -> float:
    """The share of the torus [0, 2 pi]^n that the box q covers."""
    return math.prod((q[2 * j + 1] - q[2 * j]) / TWO_PI for j in range(len(q) // 2))


def length_floor(squares: list) -> float:
    """A float at most the smallest length whose square lies in one of these balls (0 if one
    may be 0 or less; inf for none), rounded down."""
    from flint import arb

    out = math.inf
    for dd in squares:
        low = dd.lower()
        out = min(out, 0.0 if not low > 0 else float(arb(low).sqrt().lower()))
    return math.nextafter(out, 0.0) if 0 < out < math.inf else out


def _visit(land: Landscape, where: tuple, smooth: bool, known: tuple, proof: TorusProof) -> str:
    """'done' (the box holds no critical point, or one matched to a known equilibrium, or one
    recorded as missing), 'split', or 'root' (split on down to ROOT_MIN_WIDTH: a known
    equilibrium is in or near the box; undecided below it). `where`: (the box's bounds, its
    balls, its widest side); `smooth`: every spring with a free length is longer than the limit
    over the box; `known`: (enclosure bounds, centres, min_width)."""
    if not smooth:
        return "split"
    q, balls, width = where
    grad, _ = land.enclose(balls, hessian=False)
    if not all(g.contains(0) for g in grad):
        return "done"
    if width > KRAWCZYK_WIDTH:
        return "split"
    verdict, _k = krawczyk_box(land, q, balls)
    if verdict == "none":
        return "done"
    bounds, centres, min_width = known
    inside, partial = _where(bounds, q)
    if verdict == "one":
        if len(inside) == 1 and not partial:
            proof.roots[inside[0]].append(q)
            return "done"
        if not inside and not partial:
            proof.missing.append(q)
            return "done"
    # Around a known equilibrium (a badly conditioned Hessian wants small boxes) split on.
    if inside or partial or _close(centres, q, 4 * min_width):
        return "root"
    return "split"


def _floor(lengths: list, min_width: float, length_unit: float) -> float:
    """The smallest box worth splitting to: `min_width`, or less where a spring is short (the
    enclosures of its 1/d terms widen like L3 width / d): a hundredth of d / L3."""
    if not lengths:
        return min_width
    shortest = math.sqrt(max(min(float(dd.lower()) for dd in lengths), 0.0))
    return max(min(min_width, 0.01 * shortest / length_unit), ROOT_MIN_WIDTH)
