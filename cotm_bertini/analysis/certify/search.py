"""Completeness, proved along the parallel curve: every critical point of V on the torus, in ball
arithmetic (python-flint's arb), outside small neighbourhoods of the zero-length points.

grad V = sum_i k_i (1 - L0_i/d_i) a_i, so a critical point is relaxed (d_i = L0_i for both
springs, both with free lengths) or lies on the parallel curve C (a_1 x a_2 = 0): off C the a_i
are independent and both weights must vanish. Two searches, each complete for its kind:

1. **Along C** (`certify/curve`): C is covered by leaves in each of which it is the graph of a
   function of one angle. Each leaf's parameter interval is bisected; above a piece I, interval
   Newton steps on f = a_1 x a_2 in the other angle (its derivative there excludes 0 over the
   leaf) enclose every point of C in a thin box I x J. A thin box is decided like a box of the
   torus: the enclosure of grad V excludes 0 (no critical point), or the Krawczyk operator on
   grad V shows exactly one (matched to a known equilibrium) or none; else it is bisected.
2. **Relaxed**: a branch and bound over the torus on r = (d_1^2 - L01^2, d_2^2 - L02^2), whose
   Jacobian is 2 (a_1; a_2): boxes where r_1 or r_2 excludes 0 hold no relaxed point; others are
   decided by the Krawczyk operator on r (on grad V where r is singular, on C) or split.

A box proved to hold exactly one critical point is matched to a known equilibrium when the
known one's proved enclosure lies inside the box, or when the box's Krawczyk image lies inside
the small box in which the known one was proved unique. One that matches none is missing.

V is not smooth where a spring with a free length has zero length (C passes through those
points): boxes where such a spring is shorter than `short` are set aside, and so are those where
its length may be 0 once they are narrower than `min_width`; `longest_excluded` bounds the
spring length over every box set aside.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

from flint import arb

from ...params import Params
from .curve import (
    Springs,
    cross,
    cross_and_slopes,
    curve_cover,
    interval,
    spring_parts,
    springs,
    uniform_edges,
)  # fmt: skip
from .torus import length_floor

TWO_PI = 2 * math.pi
ROOT_MIN_WIDTH = 1e-10  # boxes around a known equilibrium are split down to this
KRAWCZYK_WIDTH = 2.0**-4  # rad: wider boxes are split without trying the Krawczyk operator
COVER_CELLS = 16 * 2**16  # the grid of the curve's cover (its smallest box: 2 pi / this)
GEOMETRY = ("L3", "p2x", "p3x", "p3y", "p6x", "p5x", "p5y")  # what C depends on


@dataclass(frozen=True)
class Known:
    """A reported equilibrium proved unique in `region` (lo1, hi1, lo2, hi2, rad), lying in
    `enclosure` (the Krawczyk image, rounded outwards)."""

    sid: int
    region: tuple[float, float, float, float]
    enclosure: tuple[float, float, float, float]


@dataclass
class SearchProof:
    """What the searches established (boxes as lo1, hi1, lo2, hi2 in rad)."""

    roots: dict[int, list]  # known equilibrium -> boxes proved to hold it alone
    missing: list[tuple]  # boxes proved to hold a critical point that no known one is in
    undecided: list[tuple]  # boxes no test decided
    excluded: list[tuple]  # boxes set aside: a spring with a free length may be short there
    boxes: int = 0  # boxes examined by the searches (thin boxes along C, relaxed boxes)
    cover_boxes: int = 0  # boxes of the curve's quadtree
    leaves: int = 0
    longest_excluded: float = 0.0  # the shortest spring is at most this long in every one
    # Every spring with a free length is at least this long over every box decided or left
    # undecided (not set aside): these boxes cover C, on which each spring's shortest pose lies.
    shortest_length: float = math.inf
    notes: list[str] = field(default_factory=list)


@dataclass
class _Search:
    """The state shared by both searches."""

    sp: Springs
    known: list[Known]
    short: float
    min_width: float
    proof: SearchProof


def search(params: Params, known: list[Known], short: float, min_width: float) -> SearchProof:
    """Every critical point of V with both springs longer than the returned bound lies in a
    known equilibrium's region, or is reported (module docstring)."""
    sp = springs(params)
    proof = SearchProof({k.sid: [] for k in known}, [], [], [])
    state = _Search(sp, known, short, min_width, proof)
    cover = _cover(tuple(getattr(params, n) for n in GEOMETRY))
    proof.cover_boxes, proof.leaves = cover.boxes, len(cover.leaves)
    for leaf in cover.leaves:
        _along_leaf(state, leaf)
    for q in cover.undecided:  # near a singular point of C: boxes of the torus
        _boxes(state, [q])
    if sp.free[0] and sp.free[1]:
        _relaxed(state)
    return proof


@lru_cache(maxsize=8)
def _cover(geometry: tuple[float, ...]):
    """The cover of C for a geometry (C does not depend on stiffness or free lengths: a sweep
    over them reuses it)."""
    params = Params(**dict(zip(GEOMETRY, geometry, strict=True)))
    edges = uniform_edges(COVER_CELLS)
    return curve_cover(springs(params), edges, edges)


def _along_leaf(state: _Search, leaf: tuple) -> None:
    """Bisect the leaf's parameter interval; decide each thin box holding C above a piece.
    A piece's thin ball comes from its parent's: by the mean value form of psi where the parent
    followed C (`_along_curve`), else by interval Newton from the parent's thin ball."""
    lo1, hi1, lo2, hi2, axis, slope = leaf
    lo, hi, olo, ohi = (lo1, hi1, lo2, hi2) if axis == 0 else (lo2, hi2, lo1, hi1)
    stack = [(lo, hi, interval(olo, ohi), slope, False)]
    while stack:
        a, b, thin, slope, ready = stack.pop()
        state.proof.boxes += 1
        piece = interval(a, b)
        thin = thin if ready else _thin(state.sp, piece, thin, slope, axis)
        if thin is None:
            continue  # no point of C above this piece
        t_lo = math.nextafter(float(thin.lower()), -math.inf)
        t_hi = math.nextafter(float(thin.upper()), math.inf)
        q = (a, b, t_lo, t_hi) if axis == 0 else (t_lo, t_hi, a, b)
        balls = (piece, thin) if axis == 0 else (thin, piece)
        # C above the piece lies strictly inside the leaf: a graph over all of it, or absent.
        curve = (axis, 0.5 * (a + b), thin, slope) if olo < t_lo and t_hi < ohi else None
        verdict, parts, along = _decide(state, q, balls, b - a, curve)
        if verdict == "split":
            stack.extend(_halves(a, b, thin, slope, cross_and_slopes(parts)[2 - axis], along))


def _halves(a: float, b: float, thin, slope, inner, along) -> list[tuple]:
    """The two halves of a piece, each with a thin ball and a slope for the next step."""
    if inner > 0 or inner < 0:
        slope = inner  # the derivative over this thin box: tighter for the halves
    mid = 0.5 * (a + b)
    if along is None:
        return [(a, mid, thin, slope, False), (mid, b, thin, slope, False)]
    psi0, rate, t0 = along  # psi over a half: psi(t0) + psi' (half - t0)
    out = []
    for lo, hi in ((a, mid), (mid, b)):
        ball = psi0 + rate * (interval(lo, hi) - t0)
        if ball.overlaps(thin):
            out.append((lo, hi, ball.intersection(thin), slope, True))
    return out


def _thin(sp: Springs, piece, other, slope, axis: int, steps: int = 3):
    """The ball holding every point of C in piece x other (axis 0; other x piece for axis 1)
    in the other angle, by interval Newton steps N = m - f(piece, m) / slope (`slope`: the
    derivative of f in the other angle over a box holding these, excluding 0); None if there
    is no point of C there."""
    for _ in range(steps):
        m = arb(other.mid())
        g = (piece, m) if axis == 0 else (m, piece)
        newton = m - cross(spring_parts(sp, *g)) / slope
        if not newton.overlaps(other):
            return None
        before, other = other.rad(), newton.intersection(other)
        if other.rad() > 0.5 * before:
            break
    return other


def _boxes(state: _Search, stack: list[tuple]) -> None:
    """Decide boxes of the torus, splitting in four where undecided."""
    while stack:
        q = stack.pop()
        state.proof.boxes += 1
        balls = (interval(q[0], q[1]), interval(q[2], q[3]))
        if _decide(state, q, balls, max(q[1] - q[0], q[3] - q[2]))[0] == "split":
            stack.extend(_quarters(q))


def _quarters(q: tuple) -> list[tuple]:
    m1, m2 = 0.5 * (q[0] + q[1]), 0.5 * (q[2] + q[3])
    return [(q[0], m1, q[2], m2), (m1, q[1], q[2], m2), (q[0], m1, m2, q[3]), (m1, q[1], m2, q[3])]


def _decide(state: _Search, q: tuple, balls: tuple, width: float, curve=None) -> tuple:
    """('done' or 'split', the box's spring parts with second derivatives, what
    `_along_curve` found or None): 'done' when no critical point lies in the box outside the
    known equilibria's regions, or when the box is set aside, or recorded as missing or
    undecided. `width`: the size that bisection reduces; `curve`: for a thin box whose C is a
    graph over the whole piece, (axis, the piece's midpoint, the thin ball, the slope). The
    spring lengths over each box done and not set aside bound them from below
    (`SearchProof.shortest_length`)."""
    verdict, parts, along = _judge(state, q, balls, width, curve)
    if verdict == "done":
        free = [p[2] for p, f in zip(parts, state.sp.free, strict=True) if f]
        state.proof.shortest_length = min(state.proof.shortest_length, length_floor(free))
    return ("done" if verdict == "aside" else verdict), parts, along


def _judge(state: _Search, q: tuple, balls: tuple, width: float, curve=None) -> tuple:
    """`_decide`, with 'aside' for a box set aside."""
    sp, proof = state.sp, state.proof
    parts = spring_parts(sp, *balls, second=True)
    size = max(q[1] - q[0], q[3] - q[2])  # a thin box may be taller than its piece
    near = _short(sp, parts, state.short, state.min_width, size)
    if near == "aside":
        proof.excluded.append(q)
        shortest = min(float(p[2].upper()) for p, free in zip(parts, sp.free, strict=True) if free)
        proof.longest_excluded = max(proof.longest_excluded, math.sqrt(shortest))
        return "aside", parts, None
    outcome, along = "split", None
    if near == "":
        grad = gradient(sp, parts)
        if not (grad[0].contains(0) and grad[1].contains(0)):
            return "done", parts, None
        found = _along_curve(sp, parts, balls, curve) if curve else None
        if found == "none":
            return "done", parts, None
        centre, along = found if found else (None, None)
        if width <= KRAWCZYK_WIDTH:
            outcome = _match(state, q, *krawczyk_grad(sp, q, balls, parts, centre))
    if outcome == "done":
        return "done", parts, None
    floor = ROOT_MIN_WIDTH if outcome == "close" else _floor(sp, parts, state.min_width)
    if curve is not None:  # bisecting one angle is cheap: go 100 times further
        floor = max(floor / 100, ROOT_MIN_WIDTH)
    if width <= floor:
        proof.undecided.append(q)
        return "done", parts, None
    return "split", parts, along


def _along_curve(sp: Springs, parts: list, balls: tuple, curve: tuple):
    """grad V along C over a thin box in which C is the graph of psi over the whole piece I:
    'none' when its mean value form G(t0, psi(t0)) + (dG/dt)(I) (I - t0), dG/dt = H_t + H_o
    psi' and psi' = -f_t / f_o over the box, excludes 0 (no critical point: the cancellation
    along C that the box's own enclosure cannot see); else ((the small box around
    (t0, psi(t0)), grad V over it), (psi(t0), psi', t0)) for the Krawczyk operator and the
    halves' thin balls; None if psi' is not bounded."""
    axis, t0, thin, slope = curve
    point = arb(t0)
    psi0 = _thin(sp, point, thin, slope, axis, steps=1)
    if psi0 is None:
        return "none"  # C is a graph over the whole piece or absent above it: absent
    _, fx, fy = cross_and_slopes(parts)
    f_t, f_o = (fx, fy) if axis == 0 else (fy, fx)
    if not (f_o > 0 or f_o < 0):
        return None
    rate = -f_t / f_o
    centre = (point, psi0) if axis == 0 else (psi0, point)
    g0 = gradient(sp, spring_parts(sp, *centre))
    h = hessian(sp, parts)
    step = balls[axis] - point
    along = [g0[j] + (h[j][axis] + h[j][1 - axis] * rate) * step for j in (0, 1)]
    if not (along[0].contains(0) and along[1].contains(0)):
        return "none"
    return (centre, g0), (psi0, rate, point)


def _match(state: _Search, q: tuple, verdict: str, image: tuple) -> str:
    """After a Krawczyk verdict on box q (and its image, lo1, hi1, lo2, hi2 clipped to q):
    'done', 'close' (a known equilibrium is in or near the box: split on, down to
    ROOT_MIN_WIDTH) or 'split'."""
    if verdict == "none":
        return "done"
    inside, touching, owner, near, seen = [], [], None, False, False
    reach = 4 * state.min_width
    for k in _nearby(state.known, q, reach):
        e, r = _shifted(k.enclosure, q), _shifted(k.region, q)
        if _contains(q, e, strict=True):
            inside.append(k.sid)
        elif _overlaps(q, e):
            touching.append(k.sid)
        if verdict == "one" and _contains(r, _shifted(image, r), strict=False):
            owner = k.sid
        seen = seen or _overlaps(_shifted(image, r), r)
        near = near or _gap(q, e) <= reach
    if verdict == "one":
        if owner is None and len(inside) == 1 and not touching:
            owner = inside[0]
        if owner is not None:
            state.proof.roots[owner].append(q)
            return "done"
        if not seen:  # the critical point in the box is in no known equilibrium's region
            state.proof.missing.append(q)
            return "done"
    return "close" if near else "split"


def _nearby(known: list[Known], q: tuple, reach: float) -> list[Known]:
    """The known equilibria whose regions come within `reach` of box q (on the torus)."""
    c1, c2 = 0.5 * (q[0] + q[1]), 0.5 * (q[2] + q[3])
    h1, h2 = 0.5 * (q[1] - q[0]) + reach, 0.5 * (q[3] - q[2]) + reach
    out = []
    for k in known:
        r = k.region
        d1 = abs((0.5 * (r[0] + r[1]) - c1 + math.pi) % TWO_PI - math.pi)
        d2 = abs((0.5 * (r[2] + r[3]) - c2 + math.pi) % TWO_PI - math.pi)
        if d1 <= h1 + (r[1] - r[0]) and d2 <= h2 + (r[3] - r[2]):
            out.append(k)
    return out


def _shifted(b: tuple, ref: tuple) -> tuple:
    """Box b moved by whole turns so that its centre is within pi of ref's, in each angle."""
    out = []
    for j in (0, 2):
        turns = round(((ref[j] + ref[j + 1]) - (b[j] + b[j + 1])) / (2 * TWO_PI))
        out += [b[j] + turns * TWO_PI, b[j + 1] + turns * TWO_PI]
    return tuple(out)


def _contains(outer: tuple, inner: tuple, strict: bool) -> bool:
    if strict:
        return outer[0] < inner[0] and inner[1] < outer[1] and outer[2] < inner[2] and (
            inner[3] < outer[3])  # fmt: skip
    return outer[0] <= inner[0] and inner[1] <= outer[1] and outer[2] <= inner[2] and (
        inner[3] <= outer[3])  # fmt: skip


def _overlaps(a: tuple, b: tuple) -> bool:
    return a[0] <= b[1] and b[0] <= a[1] and a[2] <= b[3] and b[2] <= a[3]


def _gap(a: tuple, b: tuple) -> float:
    """The larger of the two per-angle gaps between boxes a and b (0 if they overlap)."""
    return max(b[0] - a[1], a[0] - b[1], b[2] - a[3], a[2] - b[3], 0.0)


def _short(sp: Springs, parts: list, short: float, min_width: float, width: float) -> str:
    """'aside' (a spring with a free length is shorter than `short` on the whole box, or its
    length may be 0 and the box is narrower than `min_width`), 'zero' (its length may be 0: V
    may not be smooth, split on), or '' (V smooth on the box)."""
    verdict = ""
    limit = short * short
    for (_, _, dd, *_), free in zip(parts, sp.free, strict=True):
        if not free:
            continue
        if dd < limit:
            return "aside"
        if not dd > 0:
            verdict = "zero"
    if verdict and width <= min_width:
        return "aside"
    return verdict


def gradient(sp: Springs, parts: list) -> list:
    """grad V over the box: sum_i k_i (1 - L0_i / d_i) a_i, from `spring_parts`."""
    gx = gy = 0
    for consts, (a1, a2, dd, *_), free in zip(sp.springs, parts, sp.free, strict=True):
        k, l0 = consts[4], consts[5]
        w = k * (1 - l0 / dd.sqrt()) if free else k
        gx, gy = gx + w * a1, gy + w * a2
    return [gx, gy]


def hessian(sp: Springs, parts: list) -> list:
    """The Hessian of V over the box: sum_i k_i [(L0_i/d_i^3) a_i a_i^T + (1 - L0_i/d_i) b_i],
    from `spring_parts(..., second=True)`."""
    h11 = h12 = h22 = 0
    for consts, (a1, a2, dd, b11, b12, b22), free in zip(sp.springs, parts, sp.free, strict=True):
        k, l0 = consts[4], consts[5]
        if free:
            ratio = l0 / dd.sqrt()
            cubic = k * ratio / dd
            w = k * (1 - ratio)
            h11 = h11 + cubic * a1 * a1 + w * b11
            h12 = h12 + cubic * a1 * a2 + w * b12
            h22 = h22 + cubic * a2 * a2 + w * b22
        else:
            h11, h12, h22 = h11 + k * b11, h12 + k * b12, h22 + k * b22
    return [[h11, h12], [h12, h22]]


def krawczyk(value: list, jac: list, q: tuple, balls: tuple, centre: tuple | None = None) -> tuple:
    """('one' (exactly one zero of the map in the box), 'none' or 'unknown', the image clipped
    to the box as floats), from the map over a small box `centre` inside the box (default: its
    midpoint) and its Jacobian over the box (balls): K(Q) = c - Y F(c) + (I - Y J(Q)) (Q - c),
    Y the inverse of J's midpoint (any matrix is sound). Every zero in the box lies in K(Q),
    for each point c of `centre`."""
    jm = [[float(jac[i][j].mid()) for j in (0, 1)] for i in (0, 1)]
    det = jm[0][0] * jm[1][1] - jm[0][1] * jm[1][0]
    if not math.isfinite(det) or abs(det) < 1e-300:
        return "unknown", q
    y = [[jm[1][1] / det, -jm[0][1] / det], [-jm[1][0] / det, jm[0][0] / det]]
    if centre is None:
        centre = (arb(0.5 * (q[0] + q[1])), arb(0.5 * (q[2] + q[3])))
    k = []
    for i in (0, 1):
        step = y[i][0] * value[0] + y[i][1] * value[1]
        spread = 0
        for j in (0, 1):
            coef = (1 if i == j else 0) - (y[i][0] * jac[0][j] + y[i][1] * jac[1][j])
            spread = spread + coef * (balls[j] - centre[j])
        k.append(centre[i] - step + spread)
    if any(not balls[i].overlaps(k[i]) for i in (0, 1)):
        return "none", q
    image = []
    for i in (0, 1):
        lo = math.nextafter(float(k[i].lower()), -math.inf)
        hi = math.nextafter(float(k[i].upper()), math.inf)
        image += [max(lo, q[2 * i]), min(hi, q[2 * i + 1])]
    if all(balls[i].contains_interior(k[i]) for i in (0, 1)):
        return "one", tuple(image)
    return "unknown", tuple(image)


def krawczyk_grad(sp: Springs, q: tuple, balls: tuple, parts: list | None = None,
                  centre: tuple | None = None) -> tuple:  # fmt: skip
    """The Krawczyk verdict and image for grad V on the box q (`balls`; `parts`: its
    `spring_parts(..., second=True)` if known; `centre`: (a small box in it, grad V over that)
    if known, else its midpoint)."""
    if centre is None:
        point = (arb(0.5 * (q[0] + q[1])), arb(0.5 * (q[2] + q[3])))
        centre = (point, gradient(sp, spring_parts(sp, *point)))
    parts = parts or spring_parts(sp, *balls, second=True)
    return krawczyk(centre[1], hessian(sp, parts), q, balls, centre[0])


def _relaxed(state: _Search, start: int = 16) -> None:
    """Branch and bound on r = (d_1^2 - L01^2, d_2^2 - L02^2) over the torus."""
    sp, proof = state.sp, state.proof
    l0 = [c[5] ** 2 for c in sp.springs]
    edges = [-math.pi + TWO_PI * n / start for n in range(start)] + [math.pi]
    stack = [(a, b, c, d) for a, b in zip(edges[:-1], edges[1:], strict=True)
             for c, d in zip(edges[:-1], edges[1:], strict=True)]  # fmt: skip
    while stack:
        q = stack.pop()
        proof.boxes += 1
        balls = (interval(q[0], q[1]), interval(q[2], q[3]))
        parts = spring_parts(sp, *balls)
        if not all(p[2].contains(s) for p, s in zip(parts, l0, strict=True)):
            continue
        width = max(q[1] - q[0], q[3] - q[2])
        m = (arb(0.5 * (q[0] + q[1])), arb(0.5 * (q[2] + q[3])))
        rm = [p[2] - s for p, s in zip(spring_parts(sp, *m), l0, strict=True)]
        jac = [[2 * p[0], 2 * p[1]] for p in parts]
        verdict = krawczyk(rm, jac, q, balls, m)
        if verdict[0] == "unknown" and width <= 1e-6:
            verdict = krawczyk_grad(sp, q, balls)  # a relaxed point on C: r is singular
        outcome = _match(state, q, *verdict)
        if outcome != "done" and width <= ROOT_MIN_WIDTH:
            proof.undecided.append(q)
        elif outcome != "done":
            stack.extend(_quarters(q))


def _floor(sp: Springs, parts: list, min_width: float) -> float:
    """The smallest box worth splitting to: `min_width`, or less where a spring is short (the
    enclosures of its 1/d terms widen like L3 width / d): a hundredth of d / L3."""
    lengths = [p[2] for p, free in zip(parts, sp.free, strict=True) if free]
    if not lengths:
        return min_width
    shortest = math.sqrt(max(min(float(dd.lower()) for dd in lengths), 0.0))
    return max(min(min_width, 0.01 * shortest / float(sp.L3.mid())), ROOT_MIN_WIDTH)
