"""What the real route's landscapes share: springs and cables as V sees them, their force
densities over boxes (with the cables' states there), and the generated code's outputs as
arrays."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..backends.endpoints import Endpoints
from ..model.framework.spec import Framework
from ..model.framework.units import normalized_slots
from ..model.intervals import Interval

TAUT, SLACK, EITHER = 1, 0, 2


@dataclass(frozen=True, eq=False)
class Link:
    """A spring or cable as the landscape sees it (normalised units)."""

    name: str
    k: float
    L0: float | None  # None: zero free length (w = k, smooth everywhere)
    cable: bool


def links(fw: Framework, active: tuple[str, ...], slots: dict | None = None) -> tuple[Link, ...]:
    """The springs and cables `active` (as first_order lists them) in normalised units (from
    `slots` where given: the framework's normalised slots)."""
    slots = normalized_slots(fw) if slots is None else slots
    zfl = {x.name for x in fw.links if x.kind != "bar" and slots[f"L0_{x.name}"] == 0}
    cables = {c.name for c in fw.cables}
    return tuple(
        Link(x, slots[f"k_{x}"], None if x in zfl else slots[f"L0_{x}"], x in cables)
        for x in active
    )


def taut_groups(cables: tuple[str, ...], links: tuple[Link, ...], d: dict[str, np.ndarray],
                count: int) -> list[tuple[tuple[str, ...], np.ndarray]]:  # fmt: skip
    """`count` points grouped by the cables taut at them (a cable with a free length: its
    length `d` at least L0; one without: always): (the taut cables' names, the rows) each."""
    taut = np.ones((count, len(cables)), dtype=bool)
    for j, c in enumerate(cables):
        x = next((y for y in links if y.name == c), None)
        if x is not None and x.L0 is not None:
            taut[:, j] = d[c] >= x.L0
    return [(tuple(c for c, on in zip(cables, key, strict=True) if on),
             np.flatnonzero((taut == np.array(key)).all(axis=1)))
            for key in {tuple(row) for row in taut}]  # fmt: skip


def force_density(x: Link, dd: Interval) -> tuple[Interval, np.ndarray]:
    """w over each box from the squared length `dd`, and a cable's state there (TAUT, SLACK
    or EITHER: then w is enclosed by the hull of 0 and k (1 - L0/d))."""
    shape = dd.lo.shape
    k = Interval.of(x.k)
    if x.L0 is None:
        return Interval(np.broadcast_to(k.lo, shape), np.broadcast_to(k.hi, shape)), np.full(
            shape, TAUT)  # fmt: skip
    w = x.k * (1.0 - x.L0 / dd.sqrt())
    if not x.cable:
        return w, np.full(shape, TAUT)
    low, high = squared_bounds(x.L0)
    state = np.where(dd.lo > high, TAUT, np.where(dd.hi < low, SLACK, EITHER))
    hull_lo = np.where(np.isfinite(w.lo), np.minimum(w.lo, 0.0), 0.0)
    hull_hi = np.where(np.isfinite(w.hi), np.maximum(w.hi, 0.0), k.hi)
    lo = np.where(state == TAUT, w.lo, np.where(state == SLACK, 0.0, hull_lo))
    hi = np.where(state == TAUT, w.hi, np.where(state == SLACK, 0.0, hull_hi))
    return Interval(lo, hi), state


def squared_bounds(L0) -> tuple:
    """(least, largest) L0^2: a free length is a number, one per box, or an interval of them
    (a family of frameworks enclosed at once: TorusFamily.hull)."""
    if isinstance(L0, Interval):
        return L0.lo * L0.lo, L0.hi * L0.hi
    return L0 * L0, L0 * L0


def columns(values: list, count: int) -> np.ndarray:
    """Generated code's outputs (arrays of `count`, or constants) as the columns of one array."""
    out = np.empty((count, len(values)))
    for k, v in enumerate(values):
        out[:, k] = v
    return out


def interval_sum(items) -> Interval:
    """The sum of intervals (or numbers), as an Interval."""
    out = None
    for v in items:
        out = Interval.of(v) if out is None else out + v
    return out


def found_endpoints(variables, values: np.ndarray, rows) -> Endpoints:
    """Critical points the real route found as endpoints of a taut set's system: the values
    (R, variables) and each one's number; no path, so no path data (NaN)."""
    count = len(values)
    nan = np.full(count, np.nan)
    return Endpoints(
        tuple(variables), values, np.asarray(rows, dtype=np.int64), nan, nan, nan,
        np.zeros(count), nan, nan, nan, np.ones(count, dtype=np.int64),
        np.zeros(count, dtype=bool),
    )  # fmt: skip


def meet(a: Interval, b: Interval) -> Interval:
    """The intersection of two enclosures of one quantity (each may be unbounded)."""
    return Interval(np.maximum(a.lo, b.lo), np.minimum(a.hi, b.hi))


def unit_enclosure(r: Interval, d: Interval) -> Interval:
    """r / d over each box, r (B, dim) a link's vector and d (B,) its length: within [-1, 1]
    whatever the box (a unit vector, or at d = 0 any vector of the unit ball: the Clarke
    gradient of d there)."""
    pos = (d.lo > 0)[:, None]
    safe = Interval(np.where(pos, d.lo[:, None], 1.0), np.where(pos, d.hi[:, None], 1.0))
    q = r / safe
    return Interval(np.where(pos, np.maximum(q.lo, -1.0), -1.0),
                    np.where(pos, np.minimum(q.hi, 1.0), 1.0))  # fmt: skip


def cone_term(x: Link, dd: Interval, a: list, r: list, dr: list) -> list[Interval]:
    """A spring's gradient k (d - L0) u . dr/dangle as k r . dr - k L0 u . dr over each box
    (`a` the r . dr per angle, r and dr as the generated code lists them): finite where its
    length may be 0, where k (1 - L0/d) r . dr is not."""
    count = dd.lo.shape[0]
    dim = len(r)
    m = len(a)
    u = unit_enclosure(matrix([r], count)[:, 0], dd.sqrt())
    kl0 = x.k * x.L0  # numbers, per box, or intervals (TorusFamily.hull)
    return [x.k * a[j] - kl0 * interval_sum(u[:, c] * dr[c * m + j] for c in range(dim))
            for j in range(m)]  # fmt: skip


def link_terms(x: Link, dd: Interval, a: Interval, r: Interval, J: Interval, M: Interval):
    """A link's gradient (B, n) and Hessian (B, n, n) over each box, from r (B, dim), J = dr
    (B, dim, n), a = J^T r and M = J^T J + sum_c r_c d2r_c: w a and w M + (k L0 / d) (J^T u)
    (J^T u)^T (w = k (1 - L0/d); the gradient met with its cone form); a cable as its state
    says: taut, 0 where slack, the hull of both where it may be either."""
    count = dd.lo.shape[0]
    w, state = force_density(x, dd)  # a cable's w: 0 where slack, with 0 where it may be
    grad = scaled(a, w)
    hess = scaled(M, w)
    if x.L0 is not None:
        d = dd.sqrt()
        ju = (J * unit_enclosure(r, d)[:, :, None]).isum(axis=1)
        kl0 = np.broadcast_to(np.asarray(x.k * x.L0, dtype=float), (count,))
        hess = hess + scaled(ju[:, :, None] * ju[:, None, :], kl0 * d.reciprocal())
        if not x.cable:  # a cable is slack near length 0: no cone
            k = np.broadcast_to(np.asarray(x.k, dtype=float), (count,))
            grad = meet(grad, scaled(a, k) - scaled(ju, kl0))
    if x.cable:
        zero = Interval(np.zeros(hess.lo.shape))
        hess = Interval.where((state == TAUT)[:, None, None], hess, Interval.hull(zero, hess))
        hess = Interval.where((state == SLACK)[:, None, None], zero, hess)
    return grad, hess


def scaled(v: Interval, s) -> Interval:
    """Each box's block of v (B, ...) times its scale s ((B,) numbers or an Interval)."""
    extra = v.lo.ndim - 1
    if isinstance(s, Interval):
        shape = s.lo.shape + (1,) * extra
        return v * Interval(s.lo.reshape(shape), s.hi.reshape(shape))
    s = np.asarray(s, dtype=float)
    return v * (s.reshape(s.shape + (1,) * extra) if s.ndim else s)


def add_diagonal(h: Interval, diag: Interval) -> Interval:
    """h (B, n, n) plus diag (B, n) on its diagonal."""
    n = h.lo.shape[1]
    eye = np.eye(n, dtype=bool)
    return h + Interval(np.where(eye, diag.lo[:, :, None], 0.0),
                        np.where(eye, diag.hi[:, :, None], 0.0))  # fmt: skip


def matrix(rows: list, count: int) -> Interval:
    """Generated code's outputs (Intervals over `count` boxes, or constants) as one Interval
    (count, rows, columns)."""
    lo = np.empty((count, len(rows), len(rows[0])))
    hi = np.empty_like(lo)
    for i, row in enumerate(rows):
        for j, v in enumerate(row):
            v = Interval.of(v)
            lo[:, i, j], hi[:, i, j] = v.lo, v.hi
    return Interval(lo, hi)
