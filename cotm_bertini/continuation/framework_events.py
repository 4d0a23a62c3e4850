"""Events of a framework's one-parameter sweep, refined by bisection on the parameter.

Between neighbouring points the numbers of physical and of stable equilibria are compared; where
they differ, the interval is bisected (each probe a full solve of the framework, continued from
the bracket's lower end by Newton, so the count there is complete) until the bracket is narrower
than BISECT_TOL. A change of the physical count by two is a fold (a pair of equilibria is born
or meets and vanishes: the smallest reduced-Hessian eigenvalue of both tends to 0 there); by
one, a physical change (a length reaching 0, a cable reaching its free length); a change of the
stable count is a stability change (at a fold too, as for the paper's model).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

import numpy as np

from .framework import pose_names
from .matching import point_keys, point_order

BISECT_TOL = 1e-9  # relative to max(1, |parameter|): the bracket's final width
_KINDS = ("min", "saddle", "max", "degenerate")


def framework_event_columns(fw, param: str) -> list[str]:
    """The columns of a framework's events.csv."""
    return ["kind", "branches", param, *pose_names(fw), "hess_min_eig", "refined", "bracket",
            "description", "lo", "hi"]  # fmt: skip


def _signature(cols) -> tuple[int, int]:
    """(physical equilibria, stable ones) of a point's rows."""
    return int(np.sum(cols["physical"])), int(np.sum(cols["stable"]))


def framework_event_records(spec, table) -> list[dict]:
    """Folds, physical changes and stability changes along a framework's 1-D sweep, refined."""
    param = spec.param
    keys, _ = point_keys(table, param)
    order = point_order(table, param)
    rows = {k: np.flatnonzero(keys == k) for k, _ in order}
    part = [{n: np.asarray(table[n])[rows[k]] for n in table} for k, _ in order]
    events: list[dict] = []
    for r in range(len(order) - 1):
        if _signature(part[r]) != _signature(part[r + 1]):
            bracket = _bisect(spec, order[r][1], order[r + 1][1])
            events.extend(_describe(spec, bracket, part[r], part[r + 1]))
    return sorted(events, key=lambda e: (e[param], e["kind"], e["branches"]))


@dataclass
class _Bracket:
    lo: float
    hi: float
    below: object  # the PointSolution at lo
    above: object  # ... at hi
    refined: bool
    start: tuple[float, float]  # the sweep points on either side


def _bisect(spec, pa: float, pb: float) -> _Bracket:
    """Shrink [pa, pb] around the change of the (physical, stable) counts, each probe a full
    solve continued from the lower end's complete set; not refined if a probe's completeness
    check fails. At a fold the product of the merging pair's smallest Hessian eigenvalues
    vanishes linearly: its secant extrapolation picks the next probe (when two probes have not
    halved the bracket, a bisection)."""
    from ..point import solve_framework_point
    from .runner import point_settings

    settings = point_settings(spec)

    def solve(value: float, warm=None):
        fw = spec.model.replace(**{spec.param: value})
        return solve_framework_point(fw, settings, warm=warm)

    lo, hi = pa, pb
    below = solve(lo)
    above = solve(hi, below.warm)
    ok = below.status == "ok" and above.status == "ok"
    start, end = _signature(below.columns), _signature(above.columns)
    fold = abs(start[0] - end[0]) == 2
    real_low = start[0] > end[0]
    seen = (
        [(lo, _pair_product(below.columns))] if real_low else [(hi, _pair_product(above.columns))]
    )
    tol = BISECT_TOL * max(1.0, abs(pa), abs(pb))
    widths, last = [hi - lo, hi - lo], None
    while hi - lo > tol:
        value, guess = 0.5 * (lo + hi), _secant(seen) if fold else None
        if guess is not None and lo < guess < hi and hi - lo <= 0.5 * widths[-2]:
            # Beside the guess by its last change (about its error), towards the farther end
            # of the bracket, so that both ends close in.
            move = max(tol / 4, abs(guess - last) if last is not None else (hi - lo) / 8)
            near = guess - move if guess - lo > hi - guess else guess + move
            value, last = (near if lo < near < hi else value), guess
        probe = solve(value, below.warm)
        ok = ok and probe.status == "ok"
        low_side = _signature(probe.columns) == start
        if low_side:
            lo, below = value, probe
        else:
            hi, above = value, probe
        if low_side == real_low:
            seen.append((value, _pair_product(probe.columns)))
        widths.append(hi - lo)
    return _Bracket(lo, hi, below, above, ok, (pa, pb))


def _pair_product(cols) -> float:
    """|eig1 eig2| of the two physical rows whose smallest Hessian eigenvalue is nearest 0."""
    rows = _closest_to_zero(cols, 2)
    eig = np.abs(np.asarray(cols["hess_min_eig"], dtype=float)[rows])
    return float(np.prod(eig)) if len(eig) == 2 else float("nan")


def _secant(seen: list[tuple[float, float]]) -> float | None:
    """Where the secant through the two real-side probes nearest the fold reaches 0, or None."""
    if len(seen) < 2:
        return None
    (p1, g1), (p2, g2) = seen[-2], seen[-1]
    if not np.isfinite([g1, g2]).all() or g1 == g2:
        return None
    return p2 + g2 * (p2 - p1) / (g1 - g2)


def _describe(spec, b: _Bracket, grid_lo: dict, grid_hi: dict) -> list[dict]:
    """The events of one refined bracket."""
    fw, param = spec.model, spec.param
    lo_cols, hi_cols = b.below.columns, b.above.columns
    (n_lo, s_lo), (n_hi, s_hi) = _signature(lo_cols), _signature(hi_cols)
    more, grid = (lo_cols, grid_lo) if n_lo >= n_hi else (hi_cols, grid_hi)
    change = abs(n_hi - n_lo)
    gone = _kinds(lo_cols) - _kinds(hi_cols) if n_lo >= n_hi else _kinds(hi_cols) - _kinds(lo_cols)
    names = " and ".join(f"a {k}" for k in gone.elements()) or "equilibria"
    value = 0.5 * (b.lo + b.hi)
    base = {param: value, "refined": b.refined, "bracket": b.hi - b.lo,
            "lo": float(b.start[0]), "hi": float(b.start[1])}  # fmt: skip
    events = []
    if change:
        take = _closest_to_zero(more, change)
        pose, eig = _pose(fw, more, take), float(np.abs(more["hess_min_eig"][take]).max())
        branches = "+".join(str(x) for x in sorted(grid["branch"][_closest_to_zero(grid, change)]))
        grows = "are born" if n_hi > n_lo else "meet and vanish"
        kind = "fold" if change % 2 == 0 else "physical_change"
        what = (f"{names} {grows} as {param} grows past {value:.10g}" if kind == "fold" else
                f"{names} {'appears' if n_hi > n_lo else 'disappears'} as {param} grows past "
                f"{value:.10g} (a length or a cable reaches its limit)")  # fmt: skip
        events.append({"kind": kind, "branches": branches, **pose, "hess_min_eig": eig,
                       "description": what, **base})  # fmt: skip
    if s_lo != s_hi:
        take = _closest_to_zero(more if change else lo_cols, max(change, 1))
        pose = _pose(fw, more if change else lo_cols, take)
        events.append({
            "kind": "stability_change", "branches": events[0]["branches"] if events else "",
            **pose, "hess_min_eig": float(np.abs(more["hess_min_eig"][take]).max()),
            "description": f"stable equilibria: {s_lo} below, {s_hi} above {param} = {value:.10g}",
            **base,
        })  # fmt: skip
    return events


def _kinds(cols) -> Counter:
    physical = np.asarray(cols["physical"], dtype=bool)
    return Counter(k for k in np.asarray(cols["kind"], dtype=object)[physical] if k in _KINDS)


def _closest_to_zero(cols, count: int) -> np.ndarray:
    """The `count` physical rows whose smallest reduced-Hessian eigenvalue is nearest 0."""
    physical = np.flatnonzero(np.asarray(cols["physical"], dtype=bool))
    eig = np.abs(np.asarray(cols["hess_min_eig"], dtype=float)[physical])
    return physical[np.argsort(np.nan_to_num(eig, nan=np.inf), kind="stable")[:count]]


def _pose(fw, cols, rows: np.ndarray) -> dict[str, float]:
    """The mean pose of `rows` (angles averaged on the circle)."""
    out = {}
    for name in pose_names(fw):
        values = np.asarray(cols[name], dtype=float)[rows]
        if name.endswith(".angle_deg"):
            rad = np.radians(values)
            mean = np.degrees(np.arctan2(np.sin(rad).mean(), np.cos(rad).mean())) % 360.0
            out[name] = float(mean)
        else:
            out[name] = float(values.mean()) if len(values) else float("nan")
    return out
