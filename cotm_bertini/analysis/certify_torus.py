"""Completeness, proved: every critical point of V on the torus, by branch and bound in ball
arithmetic (python-flint's arb), outside small neighbourhoods of the zero-length points.

Each box of angles is either excluded (an interval enclosure of grad V misses 0), or shown by the
Krawczyk operator to hold exactly one critical point (K(Q) in the interior of Q) or none (K(Q)
misses Q), or split. V is not smooth where a spring with L0 > 0 has zero length: boxes where
such a spring is certainly shorter than `short` are set aside, and so are boxes where it may be,
once split down to `min_width`; the proof bounds the spring length over every box set aside, so
the statement is: every critical point with both spring lengths above that bound is found. A box
with one critical point is matched to the known equilibrium
whose proved enclosure it contains; one with no known equilibrium in it is a missing one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np

from ..params import PARAM_NAMES, Params
from .energy_terms import gradient_hessian

TWO_PI = 2 * math.pi
ROOT_MIN_WIDTH = 1e-10  # boxes holding a known equilibrium's enclosure are split down to this


def arb_params(params: Params):
    """The parameters as exact balls (a float is an exact binary number)."""
    from flint import arb

    return SimpleNamespace(**{n: arb(getattr(params, n)) for n in PARAM_NAMES})


def box(lo1: float, hi1: float, lo2: float, hi2: float) -> tuple:
    """Balls holding [lo1, hi1] x [lo2, hi2] exactly."""
    from flint import arb

    return arb(lo1).union(arb(hi1)), arb(lo2).union(arb(hi2))


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
    notes: list[str] = field(default_factory=list)


def krawczyk_2d(params: Params, pa, q: tuple[float, float, float, float]) -> tuple[str, tuple]:
    """('one', K) (exactly one critical point in the box, and it lies in K), ('none', K), or
    ('unknown', K); K is the Krawczyk image of the box."""
    from flint import arb, arb_mat

    lo1, hi1, lo2, hi2 = q
    m = ((lo1 + hi1) / 2, (lo2 + hi2) / 2)
    g1, g2 = box(*q)
    grad_m, _ = enclosures(pa, arb(m[0]), arb(m[1]), hessian=False)
    _, hq = enclosures(pa, g1, g2)
    # The preconditioner: the inverse of the Hessian's midpoint (any matrix is sound here).
    h_mid = np.array([[float(h.mid()) for h in row] for row in hq])
    if not np.isfinite(h_mid).all() or abs(np.linalg.det(h_mid)) < 1e-300:
        return "unknown", ()
    y = np.linalg.inv(h_mid)
    ym = arb_mat([[arb(float(y[i, j])) for j in (0, 1)] for i in (0, 1)])
    hm = arb_mat([[hq[0][0], hq[0][1]], [hq[1][0], hq[1][1]]])
    step = ym * arb_mat([[grad_m[0]], [grad_m[1]]])
    spread = (arb_mat([[1, 0], [0, 1]]) - ym * hm) * arb_mat([[g1 - m[0]], [g2 - m[1]]])
    k = [arb(m[j]) - step[j, 0] + spread[j, 0] for j in (0, 1)]
    q_balls = (g1, g2)
    if all(q_balls[j].contains_interior(k[j]) for j in (0, 1)):
        return "one", tuple(k)
    if any(not q_balls[j].overlaps(k[j]) for j in (0, 1)):
        return "none", tuple(k)
    return "unknown", tuple(k)


def _close(centres: np.ndarray, q: tuple, margin: float) -> bool:
    """Whether a known equilibrium lies within `margin` of the box (on the torus)."""
    if not len(centres):
        return False
    mid = np.array([(q[0] + q[1]) / 2, (q[2] + q[3]) / 2])
    half = np.array([(q[1] - q[0]) / 2, (q[3] - q[2]) / 2])
    gap = np.abs((centres - mid + math.pi) % TWO_PI - math.pi) - half
    return bool((gap.max(axis=1) <= margin).any())


def enclosure_bounds(known: dict[int, tuple]) -> tuple[list[int], np.ndarray]:
    """The known enclosures as float bounds, rounded outwards, with their copies one turn away:
    (indices, array (n, 9, 4) of lo1, hi1, lo2, hi2)."""
    keys = list(known)
    out = np.zeros((len(keys), 9, 4))
    for a, k in enumerate(keys):
        e1, e2 = known[k]
        lo = [math.nextafter(float(e.lower()), -math.inf) for e in (e1, e2)]
        hi = [math.nextafter(float(e.upper()), math.inf) for e in (e1, e2)]
        for b, (s1, s2) in enumerate((s1, s2) for s1 in (-1, 0, 1) for s2 in (-1, 0, 1)):
            sh1, sh2 = s1 * TWO_PI, s2 * TWO_PI
            out[a, b] = (lo[0] + sh1, hi[0] + sh1, lo[1] + sh2, hi[1] + sh2)
    return keys, out


def _where(bounds: tuple[list[int], np.ndarray], q: tuple) -> tuple[list[int], list[int]]:
    """Known equilibria whose enclosure lies inside the box, and those it only touches.

    Float comparisons of outward-rounded bounds: a 'not inside' may be conservative (the box is
    then split), never an 'inside' that is not."""
    keys, b = bounds
    if not keys:
        return [], []
    inside = (q[0] < b[..., 0]) & (b[..., 1] < q[1]) & (q[2] < b[..., 2]) & (b[..., 3] < q[3])
    touch = (b[..., 0] <= q[1]) & (q[0] <= b[..., 1]) & (b[..., 2] <= q[3]) & (q[2] <= b[..., 3])
    ins, tou = inside.any(axis=1), touch.any(axis=1)
    return [keys[a] for a in np.flatnonzero(ins)], [keys[a] for a in np.flatnonzero(tou & ~ins)]


def spring_length_squares(params: Params, pa, g1, g2) -> list:
    """Balls holding d_i^2 over the box, for each spring with L0 > 0 (where V is not smooth)."""
    from ..model.kinematics import spring_vectors

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


def _split(q: tuple) -> list[tuple]:
    lo1, hi1, lo2, hi2 = q
    m1, m2 = (lo1 + hi1) / 2, (lo2 + hi2) / 2
    return [(lo1, m1, lo2, m2), (m1, hi1, lo2, m2), (lo1, m1, m2, hi2), (m1, hi1, m2, hi2)]


def branch_and_bound(
    params: Params,
    known: dict[int, tuple],
    short: float,
    min_width: float,
    start: int = 16,
) -> TorusProof:
    """Decide every box of the torus [0, 2 pi]^2 (see the module docstring). Boxes where a
    spring with L0 > 0 is shorter than `short` are set aside (split to `min_width` where they
    may only be); `proof.longest_excluded` bounds the spring length over them."""
    from flint import arb

    pa = arb_params(params)
    zero, limit = arb(0), arb(short) ** 2
    # At the smallest width, a spring this short still makes the enclosures of the 1/d terms
    # too wide to decide: such boxes are set aside too (the reported bound covers them).
    wide = (arb(short) + 3 * pa.L3 * arb(min_width)) ** 2
    proof = TorusProof({k: [] for k in known}, [], [], [])
    centres = np.array([[float(e[0].mid()), float(e[1].mid())] for e in known.values()])
    bounds = enclosure_bounds(known)
    edges = np.linspace(0.0, TWO_PI, start + 1)
    stack = [(a, b, c, d) for a, b in zip(edges[:-1], edges[1:], strict=True)
             for c, d in zip(edges[:-1], edges[1:], strict=True)]  # fmt: skip
    while stack:
        q = stack.pop()
        proof.boxes += 1
        g1, g2 = box(*q)
        width = max(q[1] - q[0], q[3] - q[2])
        lengths = spring_length_squares(params, pa, g1, g2)
        near = _short(lengths, limit if width > min_width else wide)
        if near == "all" or (near and width <= min_width):
            proof.excluded.append(q)
            shortest = min(float(dd.upper()) for dd in lengths)
            proof.longest_excluded = max(proof.longest_excluded, math.sqrt(shortest))
            continue
        if not near:
            grad, _ = enclosures(pa, g1, g2, hessian=False)
            if not (grad[0].contains(zero) and grad[1].contains(zero)):
                continue
            verdict, _k = krawczyk_2d(params, pa, q)
            if verdict == "none":
                continue
            inside, partial = _where(bounds, q)
            if verdict == "one":
                if len(inside) == 1 and not partial:
                    proof.roots[inside[0]].append(q)
                    continue
                if not inside and not partial:
                    proof.missing.append(q)
                    continue
            # Around a known equilibrium (a badly conditioned Hessian wants small boxes) split on.
            if (inside or partial or _close(centres, q, 4 * min_width)) and width > ROOT_MIN_WIDTH:
                stack.extend(_split(q))
                continue
        if width <= _floor(lengths, min_width, params.L3):
            proof.undecided.append(q)
            continue
        stack.extend(_split(q))
    return proof


def _floor(lengths: list, min_width: float, length_unit: float) -> float:
    """The smallest box worth splitting to: `min_width`, or less where a spring is short (the
    enclosures of its 1/d terms widen like L3 width / d): a hundredth of d / L3."""
    if not lengths:
        return min_width
    shortest = math.sqrt(max(min(float(dd.lower()) for dd in lengths), 0.0))
    return max(min(min_width, 0.01 * shortest / length_unit), ROOT_MIN_WIDTH)
