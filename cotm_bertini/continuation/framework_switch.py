"""Cable switches among a framework sweep's events: a cable of an equilibrium reaching its free
length.

Where a cable of an equilibrium reaches its free length L0, the energy is piecewise: the branch
with the cable taut and the branch with it slack meet there. Either one continues as the other
(no count changes) or both end together (a nonsmooth fold: a pair of equilibria is born or
vanishes, the Hessian regular on both, so this is no fold in the smooth sense). Bisection on the
counts cannot close in on such a switch: probes within the zero-length tolerance of it see a
cable at its free length (a degenerate row) and place no end. The switch is located instead
where it is defined: along the branch of the appearing row whose cable is nearest its free
length, g(p) = d_c(p) - L0_c(p) = 0, by a safeguarded secant on the parameter, each step a
solve continued from the bracket's lower end, the row followed by its taut set and pose.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .framework import pose_coordinates

SWITCH_GAP = 1e-2  # an appearing row's |d - L0| below this (length units) is tried as a switch
SECANT_STEPS = 30  # at most this many solves to locate one switch


@dataclass(frozen=True)
class Switch:
    """A located cable switch: the cable, where (`value`, to within `step`), and the followed
    row there (`columns`, `row`) with the cable at its free length up to `gap` (length units)."""

    cable: str
    value: float
    step: float
    converged: bool
    gap: float
    columns: dict
    row: int


def candidate_cable(fw, cols, rows: np.ndarray, value: float, param: str) -> tuple | None:
    """(row, cable, gap) of the appearing row whose cable is nearest its free length at the
    parameter `value`, if within SWITCH_GAP length units of it; else None."""
    from ..model.framework.units import units

    slots = fw.replace(**{param: value}).slots()
    best = None
    for cable in fw.cables:
        L0 = slots[f"L0_{cable.name}"]
        for r in rows:
            gap = abs(float(np.asarray(cols[f"{cable.name}.length"], dtype=float)[r]) - L0)
            if best is None or gap < best[2]:
                best = (int(r), cable.name, gap)
    if best is None or best[2] > SWITCH_GAP * units(fw)[0]:
        return None
    return best


def locate_switch(spec, solve, start: tuple, other: tuple, cable: str, tol: float):
    """The Switch on the branch through row `start[2]` of `start[1]` (the solve's columns at
    parameter start[0]) where `cable` is at its free length, bracketed by `other` (value,
    columns) where g has the other sign; None if g does not change sign between them or the
    row cannot be followed. `solve(value)` gives a PointSolution."""
    fw, param = spec.model, spec.param
    (pa, cols_a, row), (pb, cols_b) = start, other
    taut = cols_a["taut_set"][row]
    key = pose_coordinates(fw, cols_a)[row]
    gb = _follow(fw, param, cols_b, taut, key, cable, pb)
    ga = _gap(fw, param, cols_a, row, cable, pa)
    if gb is None or np.sign(ga) == np.sign(gb[0]):
        return None
    lo, hi = (pa, ga), (pb, gb[0])  # g changes sign between them
    prev, last = lo, hi
    found = (cols_b, gb[1])
    for _ in range(SECANT_STEPS):
        (p1, g1), (p2, g2) = prev, last
        guess = p2 - g2 * (p2 - p1) / (g2 - g1) if g2 != g1 else None
        a, b = sorted((lo[0], hi[0]))
        value = guess if guess is not None and a < guess < b else 0.5 * (a + b)
        cols = solve(value).columns
        got = _follow(fw, param, cols, taut, key, cable, value)
        if got is None:
            return None
        g, r = got
        found, step = (cols, r), abs(value - p2)
        prev, last = last, (value, g)
        lo, hi = ((value, g), hi) if np.sign(g) == np.sign(lo[1]) else (lo, (value, g))
        if g == 0.0 or step <= tol:
            return Switch(cable, value, step, True, abs(g), *found)
    return Switch(cable, last[0], abs(last[0] - prev[0]), False, abs(last[1]), *found)


def _gap(fw, param: str, cols, row: int, cable: str, value: float) -> float:
    """d - L0 of `cable` on row `row` (signed: > 0 where it would be stretched)."""
    L0 = fw.replace(**{param: value}).slots()[f"L0_{cable}"]
    return float(np.asarray(cols[f"{cable}.length"], dtype=float)[row]) - L0


def _follow(fw, param: str, cols, taut: str, key: np.ndarray, cable: str, value: float):
    """(g, row) of the real row of taut set `taut` nearest in pose to `key`, or None."""
    same = np.flatnonzero(
        (np.asarray(cols["taut_set"], dtype=object) == taut)
        & np.asarray(cols["is_real"], dtype=bool)
    )
    if not len(same):
        return None
    dist = np.linalg.norm(pose_coordinates(fw, cols)[same] - key, axis=1)
    row = int(same[np.argmin(dist)])
    return _gap(fw, param, cols, row, cable, value), row
