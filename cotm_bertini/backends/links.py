"""What the real route's landscapes share: springs and cables as V sees them, their force
densities over boxes (with the cables' states there), and the generated code's outputs as
arrays."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.framework.spec import Framework
from ..model.framework.units import normalized_slots
from ..model.intervals import Interval
from .endpoints import Endpoints

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
    if x.L0 is None:
        return Interval(np.full(shape, x.k)), np.full(shape, TAUT)
    w = x.k * (1.0 - x.L0 / dd.sqrt())
    if not x.cable:
        return w, np.full(shape, TAUT)
    l2 = x.L0 * x.L0
    state = np.where(dd.lo > l2, TAUT, np.where(dd.hi < l2, SLACK, EITHER))
    hull_lo = np.where(np.isfinite(w.lo), np.minimum(w.lo, 0.0), 0.0)
    hull_hi = np.where(np.isfinite(w.hi), np.maximum(w.hi, 0.0), x.k)
    lo = np.where(state == TAUT, w.lo, np.where(state == SLACK, 0.0, hull_lo))
    hi = np.where(state == TAUT, w.hi, np.where(state == SLACK, 0.0, hull_hi))
    return Interval(lo, hi), state


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
