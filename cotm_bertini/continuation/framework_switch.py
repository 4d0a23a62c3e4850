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

from dataclasses import dataclass, replace

import numpy as np

from .framework import pose_coordinates

SWITCH_GAP = 1e-2  # an appearing row's |d - L0| below this (length units) is tried as a switch
SECANT_STEPS = 30  # at most this many solves to locate one switch
NEWTON_STEPS = 20  # Newton steps on a smooth piece of V from a neighbouring pose


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


def locate_switch(fw, param: str, follow, start: tuple, other: float, tol: float):
    """The Switch on a branch where `cable` is at its free length: `follow(value)` gives (g,
    columns, row) of the branch at `value` (g = d - L0 of the cable) or None; `start` = (value,
    columns, row) of the branch at one end, `other` the value at the other end, where g has the
    other sign. None if g does not change sign between them or the branch is lost."""
    (pa, cols_a, row), pb = start, other
    cable = follow.cable
    gb = follow(pb)
    ga = _gap(fw, param, cols_a, row, cable, pa)
    if gb is None or np.sign(ga) == np.sign(gb[0]):
        return None
    lo, hi = (pa, ga), (pb, gb[0])  # g changes sign between them
    prev, last = lo, hi
    found = gb[1:]
    for _ in range(SECANT_STEPS):
        (p1, g1), (p2, g2) = prev, last
        guess = p2 - g2 * (p2 - p1) / (g2 - g1) if g2 != g1 else None
        a, b = sorted((lo[0], hi[0]))
        value = guess if guess is not None and a < guess < b else 0.5 * (a + b)
        got = follow(value)
        if got is None:
            return None
        g, found = got[0], got[1:]
        # The accuracy: the next secant step (where d - L0 is linear in the parameter, as on a
        # branch that does not depend on it, the first step lands on the switch).
        step = abs(g * (value - p2) / (g - g2)) if g != g2 else abs(value - p2)
        prev, last = last, (value, g)
        lo, hi = ((value, g), hi) if np.sign(g) == np.sign(lo[1]) else (lo, (value, g))
        if g == 0.0 or step <= tol:
            return Switch(cable, value, step, True, abs(g), *found)
    return Switch(cable, last[0], abs(last[0] - prev[0]), False, abs(last[1]), *found)


@dataclass(frozen=True)
class Follower:
    """follow(value) -> (g, columns, row) | None: the branch through row `row` of `cols` (taut
    set and pose) at another value of the parameter, g = d - L0 of `cable` on it. On a circle or
    torus, Newton on that taut set's smooth piece of V from the row's angles (the branch goes on
    past the switch, where it is no equilibrium: the real route reports none there); elsewhere
    the row of that taut set nearest in pose in a full solve (`solve(value)`)."""

    fw: object
    param: str
    cols: dict
    row: int
    cable: str
    solve: object

    def __call__(self, value: float):
        from ..boxsearch.real_route import covers

        taut = self.cols["taut_set"][self.row]
        key = pose_coordinates(self.fw, self.cols)[self.row]
        if covers(self.fw):
            cols = self.solve(value).columns
        else:
            cols = _piece(self.fw, self.param, value, taut, self.cols, self.row)
        got = _follow(self.fw, self.param, cols, taut, key, self.cable, value)
        return None if got is None else (got[0], cols, got[1])


def _piece(fw, param: str, value: float, taut: str, cols: dict, row: int) -> dict:
    """The columns of the one solution of taut set `taut`'s system at `value` that Newton
    reaches from the body angles of row `row` of `cols` (physical or not)."""
    from ..analysis.framework_classify import framework_columns
    from ..analysis.refine import newton_refine
    from ..boxsearch.real_route import TorusFramework
    from ..model.framework.compiled import framework_system
    from ..model.framework.units import normalized_slots, units

    here = fw.replace(**{param: value})
    land = TorusFramework(here)
    on = taut.split() if isinstance(taut, str) else []
    names = tuple(c.name for c in fw.cables if c.name in on)
    angles = np.radians([[float(cols[f"{b}.angle_deg"][row]) for b in land.bodies]])
    start = land.endpoints_of(names, angles)
    fs = framework_system(here, names)
    slots_n = normalized_slots(here)
    system = fs.ps.instantiate([slots_n[n] for n in fs.ps.parameters])
    x, _ = newton_refine(system, start.points, NEWTON_STEPS)
    return framework_columns(here, fs, replace(start, points=x), units(here))


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
