"""Events of a framework's one-parameter sweep, refined by bisection on the parameter.

Between neighbouring points the numbers of physical and of stable equilibria are compared; where
they differ, the interval is bisected (each probe a full solve of the framework, continued from
the bracket's lower end by Newton, so the count there is complete) until the bracket is narrower
than BISECT_TOL. A probe within the solver's resolution of the event (at a fold the merging
pair is found as one degenerate root) matches neither end: it places no end, and the next probes
close in on it from both sides. A change of the physical count by two is a fold (a pair of
equilibria is born or meets and vanishes); by one, a physical change (a length reaching 0, a
cable reaching its free length); a change of the stable count is a stability change (at a fold
too, as for the paper's model). The pose is that of the equilibria that appear: the rows of the
bracket's end with more that have no counterpart at the other end.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, replace

import numpy as np

from ..progress import Progress
from .framework import pose_coordinates, pose_names
from .matching import point_keys, point_order

BISECT_TOL = 1e-9  # relative to max(1, |parameter|): the bracket's final width
MAX_EVENTS = 4  # events looked for between two neighbouring sweep points
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
    changed = [r for r in range(len(order) - 1) if _signature(part[r]) != _signature(part[r + 1])]
    # Each bisection probe is a full solve (minutes on a large framework, more when a probe
    # needs another generic set): said as it goes, after the sweep's last point.
    with Progress("sweep: events refined", len(changed), "intervals", heartbeat=True) as report:
        for r in changed:
            (pa, pb), lo, past = (order[r][1], order[r + 1][1]), order[r][1], None
            for _ in range(MAX_EVENTS):
                if lo >= pb:
                    break
                bracket = replace(_bisect(spec, lo, pb, past), start=(pa, pb))
                events.extend(_describe(spec, bracket, part[r], part[r + 1]))
                # Two events between neighbouring points (their counts change twice): the
                # rest of the interval is searched again from the bracket's upper end.
                if _signature(bracket.above.columns) == _signature(part[r + 1]):
                    break
                lo, past = bracket.hi, bracket.above
            report.update(1, note=f"{len(events)} events")
    return sorted(events, key=lambda e: (e[param], e["kind"], e["branches"]))


@dataclass(frozen=True)
class _Bracket:
    lo: float
    hi: float
    below: object  # the PointSolution at lo
    above: object  # ... at hi
    refined: bool
    start: tuple[float, float]  # the sweep points on either side


def _bisect(spec, pa: float, pb: float, below=None) -> _Bracket:
    """Shrink [pa, pb] around the change of the (physical, stable) counts, each probe a full
    solve continued from the lower end's complete set (`below`: the solve at pa, if known);
    not refined if the completeness check of a probe that placed an end fails (a probe at the
    event itself places none). At a fold the product of the merging pair's smallest Hessian
    eigenvalues vanishes linearly: its secant extrapolation picks the next probe (when two
    probes have not halved the bracket, a bisection)."""
    from ..point import solve_framework_point
    from .runner import point_settings

    settings = point_settings(spec)

    def solve(value: float, warm=None):
        fw = spec.model.replace(**{spec.param: value})
        return solve_framework_point(fw, settings, warm=warm)

    lo, hi = pa, pb
    below = solve(lo) if below is None else below
    above = solve(hi, below.warm)
    ok = below.status == "ok" and above.status == "ok"  # every probe that placed an end
    start, end = _signature(below.columns), _signature(above.columns)
    fold = abs(start[0] - end[0]) == 2
    real_low = start[0] > end[0]
    seen = (
        [(lo, _pair_product(below.columns))] if real_low else [(hi, _pair_product(above.columns))]
    )
    tol = BISECT_TOL * max(1.0, abs(pa), abs(pb))
    widths, last, unresolved = [hi - lo, hi - lo], None, []
    clean = not (_at_event(below) or _at_event(above))
    while hi - lo > tol:
        guess = _secant(seen) if fold else None
        value, last = _next_probe(lo, hi, tol, guess, last, widths, unresolved)
        if value is None:
            break
        probe = solve(value, below.warm)
        sign = _signature(probe.columns)
        if (clean or sign not in (start, end)) and _at_event(probe):
            # The event is within the solver's resolution of this probe (at a fold the merging
            # pair is one degenerate root, and the Morse count fails): it places no end. So
            # does a probe that sees a degenerate equilibrium where both sweep points saw none.
            unresolved.append(value)
            continue
        ok = ok and probe.status == "ok"
        low_side = sign == start
        if low_side:
            lo, below = value, probe
        else:
            hi, above = value, probe
        if low_side == real_low:
            seen.append((value, _pair_product(probe.columns)))
        widths.append(hi - lo)
    return _Bracket(lo, hi, below, above, ok, (pa, pb))


def _next_probe(
    lo: float, hi: float, tol: float, guess: float | None, last: float | None,
    widths: list[float], unresolved: list[float],
) -> tuple[float | None, float | None]:  # fmt: skip
    """The next probe (None: stop) and the secant guess it used. Beside probes that saw the
    event unresolved: the middle of the wider gap between them and an end, until both are
    within tol / 2. Else the middle, or beside the guess by its last change (about its error),
    towards the farther end so that both ends close in; the guess only once two probes have
    halved the bracket."""
    inside = [u for u in unresolved if lo < u < hi]
    if inside:
        width, a, b = max((min(inside) - lo, lo, min(inside)), (hi - max(inside), max(inside), hi))
        return (0.5 * (a + b) if width > tol / 2 else None), last
    if guess is None or not lo < guess < hi or hi - lo > 0.5 * widths[-2]:
        return 0.5 * (lo + hi), last
    move = max(tol / 4, abs(guess - last) if last is not None else (hi - lo) / 8)
    near = guess - move if guess - lo > hi - guess else guess + move
    return (near if lo < near < hi else 0.5 * (lo + hi)), guess


def _at_event(probe) -> bool:
    """The probe sees an equilibrium at its limit: a physical degenerate row (a merged pair,
    a zero eigenvalue) or a failed completeness check."""
    kind = np.asarray(probe.columns["kind"], dtype=object)
    physical = np.asarray(probe.columns["physical"], dtype=bool)
    return probe.status != "ok" or bool((physical & (kind == "degenerate")).any())


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
    more, less, grid = (lo_cols, hi_cols, grid_lo) if n_lo >= n_hi else (hi_cols, lo_cols, grid_hi)
    change = abs(n_hi - n_lo)
    gone = _kinds(more) - _kinds(less)
    names = " and ".join(f"a {k}" for k in gone.elements()) or "equilibria"
    value = 0.5 * (b.lo + b.hi)
    base = {param: value, "refined": b.refined, "bracket": b.hi - b.lo,
            "lo": float(b.start[0]), "hi": float(b.start[1])}  # fmt: skip
    # The equilibria that appear (or vanish): those of the side with more that have no
    # counterpart on the other (the rest barely move across the bracket); with none, the one
    # whose smallest eigenvalue crosses 0.
    cols = more if change else lo_cols
    take = _new_rows(fw, more, less, change) if change else _closest_to_zero(lo_cols, 1)
    pose = _pose(fw, cols, take)
    eig = np.abs(np.asarray(cols["hess_min_eig"], dtype=float)[take])
    eig = float(eig.max()) if len(eig) else float("nan")
    branches = "+".join(str(x) for x in sorted(grid["branch"][_nearest(fw, grid, cols, take)]))
    events = []
    if change:
        grows = "are born" if n_hi > n_lo else "meet and vanish"
        kind = "fold" if change % 2 == 0 else "physical_change"
        what = (f"{names} {grows} as {param} grows past {value:.10g}" if kind == "fold" else
                f"{names} {'appears' if n_hi > n_lo else 'disappears'} as {param} grows past "
                f"{value:.10g} (a length or a cable reaches its limit)")  # fmt: skip
        events.append({"kind": kind, "branches": branches, **pose, "hess_min_eig": eig,
                       "description": what, **base})  # fmt: skip
    if s_lo != s_hi:
        events.append({
            "kind": "stability_change", "branches": branches, **pose, "hess_min_eig": eig,
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


def _new_rows(fw, more, less, count: int) -> np.ndarray:
    """The `count` physical rows of `more` farthest in pose (and link lengths) from every
    physical row of `less`."""
    mine = np.flatnonzero(np.asarray(more["physical"], dtype=bool))
    theirs = pose_coordinates(fw, less)[np.asarray(less["physical"], dtype=bool)]
    here = pose_coordinates(fw, more)[mine]
    gap = np.linalg.norm(here[:, None, :] - theirs[None, :, :], axis=2).min(axis=1, initial=np.inf)
    return mine[np.argsort(-gap, kind="stable")[:count]]


def _nearest(fw, grid, cols, rows: np.ndarray) -> np.ndarray:
    """The len(rows) physical rows of the sweep point `grid` nearest in pose to the mean of
    `rows` of `cols` (an event's equilibria, seen from the neighbouring sweep point)."""
    physical = np.flatnonzero(np.asarray(grid["physical"], dtype=bool))
    if not len(rows):
        return physical[:0]
    centre = pose_coordinates(fw, cols)[rows].mean(axis=0)
    gap = np.linalg.norm(pose_coordinates(fw, grid)[physical] - centre, axis=1)
    return physical[np.argsort(gap, kind="stable")[: len(rows)]]


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
