"""An equilibrium that appears or vanishes at a cone point of V along a framework sweep.

Where a spring with a free length L0 > 0 reaches zero length, V has a cone point (not smooth, no
equilibrium): V = 1/2 k L0^2 - k L0 |P| + the rest. It is a local maximum while the other
elements' pull there, |J^-T grad(rest)|, is weaker than k L0; where the pull crosses k L0 the
cone tips over or back and one equilibrium (a saddle on a torus) comes out of it or goes into it:
the physical count changes by one. Bisection on the counts cannot close in on it (near the cone
the equilibrium's Hessian grows without bound and the real search leaves boxes undecided); it is
located instead where it is defined: pull = k L0 at that cone point, a secant on the parameter,
each step the cone points of the framework there (analysis.framework_checks.cone_points).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SECANT_STEPS = 30  # at most this many cone solves to locate one event


@dataclass(frozen=True)
class Cone:
    """A located cone event: the spring, where (`value`, to within `step`), its pose there
    (pose column -> value) and whether the cone is a maximum above it."""

    spring: str
    value: float
    step: float
    converged: bool
    pose: dict
    max_above: bool


def locate_cone(fw, param: str, lo: float, hi: float, tol: float) -> Cone | None:
    """The cone point whose pull - k L0 changes sign between `lo` and `hi`, located; None if
    none does (or the framework has no cone point)."""
    a, b = _cones(fw, param, lo), _cones(fw, param, hi)
    for cone in a:
        near = min(b, key=lambda c: _apart(c, cone), default=None)
        if near is None or near["spring"] != cone["spring"] or _apart(near, cone) > 1e-3:
            continue
        if cone["is_max"] != near["is_max"]:
            return _secant(fw, param, cone, (lo, _excess(cone)), (hi, _excess(near)), tol)
    return None


def _secant(fw, param: str, cone: dict, lo: tuple, hi: tuple, tol: float) -> Cone | None:
    """Where pull = push at `cone` (followed by pose) between lo and hi = (value, pull - push)."""
    prev, last, here = lo, hi, cone
    for _ in range(SECANT_STEPS):
        (p1, g1), (p2, g2) = prev, last
        a, b = sorted((lo[0], hi[0]))
        guess = p2 - g2 * (p2 - p1) / (g2 - g1) if g2 != g1 else None
        value = guess if guess is not None and a < guess < b else 0.5 * (a + b)
        found = _cones(fw, param, value)
        if not found:
            return None
        here = min(found, key=lambda c: _apart(c, cone))
        g = _excess(here)
        step = abs(g * (value - p2) / (g - g2)) if g != g2 else abs(value - p2)
        prev, last = last, (value, g)
        lo, hi = ((value, g), hi) if np.sign(g) == np.sign(lo[1]) else (lo, (value, g))
        if g == 0.0 or step <= tol:
            return _cone(fw, here, value, step, True, hi)
    return _cone(fw, here, last[0], abs(last[0] - prev[0]), False, hi)


def _cone(fw, cone: dict, value: float, step: float, converged: bool, hi: tuple) -> Cone:
    from ..model.framework.compiled import framework_system
    from ..model.framework.structure import layout

    names = framework_system(fw, tuple(c.name for c in fw.cables)).cones[cone["spring"]].variables
    var = dict(zip(names, cone["pose"], strict=True))
    pose = {f"{b}.angle_deg": float(np.degrees(np.arctan2(var[f"s_{b}"], var[f"c_{b}"])) % 360.0)
            for b in layout(fw).rotations}  # fmt: skip
    return Cone(cone["spring"], value, step, converged, pose, bool(hi[1] < 0))


def _cones(fw, param: str, value: float) -> list[dict]:
    from ..analysis.framework_checks import cone_points
    from ..boxsearch.real_route import covers

    if covers(fw) or fw.dim != 2:  # cone points are placed on a circle or torus only
        return []
    return cone_points(fw.replace(**{param: value}))


def _excess(cone: dict) -> float:
    return float(cone["pull"] - cone["push"])


def _apart(a: dict, b: dict) -> float:
    return float(np.abs(np.array(a["pose"]) - np.array(b["pose"])).max())
