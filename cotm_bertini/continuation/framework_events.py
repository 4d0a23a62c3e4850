"""Events of a framework's one-parameter sweep, refined by bisection on the parameter.

Between neighbouring points the numbers of physical and of stable equilibria are compared; where
they differ, the interval is bisected (each probe a full solve of the framework, continued from
the bracket's lower end by Newton, so the count there is complete) until the bracket is narrower
than BISECT_TOL. A probe within the solver's resolution of the event (at a fold the merging
pair is found as one degenerate root) matches neither end: it places no end, and the next probes
close in on it from both sides. Each event is named by what happens there:

- cable_switch: the equilibria that appear (or vanish) have a cable at its free length there
  (the taut and the slack branch end together, the Hessian regular): located where that cable's
  length equals its free length (framework_switch.py), not by the counts;
- pitchfork: the physical count changes by two on a third equilibrium, present on both sides,
  through the pair's meeting point (a min and two saddles, or a saddle and two minima meet);
- fold: the physical count changes by two otherwise (a pair is born or meets and vanishes, the
  reduced Hessian singular there);
- physical_change: it changes by one (a length reaching 0);
- stability_change: the number of stable equilibria changes (at the events above too, as for
  the paper's model).

The pose is that of the equilibria that appear: the rows of the bracket's end with more that
have no counterpart at the other end (of a cable switch, the followed row where the cable is at
its free length).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, replace

import numpy as np

from ..progress import Progress
from .framework import pose_coordinates, pose_names
from .framework_switch import Switch, candidate_cable, locate_switch
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
    """Folds, pitchforks, cable switches, physical and stability changes along a framework's
    1-D sweep, refined."""
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
                switch = _switch(spec, bracket)
                events.extend(_describe(spec, bracket, (part[r], part[r + 1]), switch))
                # Two events between neighbouring points (their counts change twice): the
                # rest of the interval is searched again from the bracket's upper end, its
                # solve kept.
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
    solve = _solver(spec)
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


def _solver(spec):
    """solve(value, warm=None): the framework's complete solve at `value` of the parameter."""
    from ..point import solve_framework_point
    from .runner import point_settings

    settings = point_settings(spec)

    def solve(value: float, warm=None):
        fw = spec.model.replace(**{spec.param: value})
        return solve_framework_point(fw, settings, warm=warm)

    return solve


def _switch(spec, b: _Bracket) -> Switch | None:
    """The cable switch that causes the bracket's count change, located where its cable is at
    its free length (framework_switch.py), if the equilibria that appear have a cable near its
    free length and the located switch lies in the bracket (widened by its width); else None."""
    (n_lo, _), (n_hi, _) = _signature(b.below.columns), _signature(b.above.columns)
    if n_lo == n_hi:
        return None
    fw, param = spec.model, spec.param
    ends = [(b.lo, b.below.columns), (b.hi, b.above.columns)]
    (p_more, more), (p_less, less) = ends if n_lo > n_hi else ends[::-1]
    take = _new_rows(fw, more, less, abs(n_hi - n_lo))
    found = candidate_cable(fw, more, take, p_more, param)
    if found is None:
        return None
    solve, warm = _solver(spec), b.below.warm
    tol = BISECT_TOL * max(1.0, abs(b.lo), abs(b.hi))
    switch = locate_switch(
        spec, lambda v: solve(v, warm), (p_more, more, found[0]), (p_less, less), found[1], tol
    )
    width = b.hi - b.lo + tol
    if switch is None or not b.lo - width <= switch.value <= b.hi + width:
        return None
    return switch


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


def _describe(spec, b: _Bracket, grids: tuple[dict, dict], switch: Switch | None) -> list[dict]:
    """The events of one refined bracket (`grids`: the sweep points on either side; `switch`:
    the located cable switch that causes its count change, if one does)."""
    fw, param = spec.model, spec.param
    lo_cols, hi_cols = b.below.columns, b.above.columns
    (n_lo, s_lo), (n_hi, s_hi) = _signature(lo_cols), _signature(hi_cols)
    more, less = (lo_cols, hi_cols) if n_lo >= n_hi else (hi_cols, lo_cols)
    grid, other = grids if n_lo >= n_hi else grids[::-1]
    change = abs(n_hi - n_lo)
    value = switch.value if switch else 0.5 * (b.lo + b.hi)
    base = {param: value, "refined": b.refined and (switch is None or switch.converged),
            "bracket": switch.step if switch else b.hi - b.lo,
            "lo": float(b.start[0]), "hi": float(b.start[1])}  # fmt: skip
    # The equilibria that appear (or vanish): those of the side with more that have no
    # counterpart on the other (the rest barely move across the bracket); with none, the one
    # whose smallest eigenvalue crosses 0. At a pitchfork, with the branch they meet on.
    cols = more if change else lo_cols
    take = _new_rows(fw, more, less, change) if change else _closest_to_zero(lo_cols, 1)
    third = _third_branch(fw, more, less, take) if change == 2 and not switch else None
    involved = take if third is None else np.append(take, third)
    pose = _pose(fw, switch.columns, np.array([switch.row])) if switch else _pose(fw, cols, take)
    eig = np.abs(np.asarray(cols["hess_min_eig"], dtype=float)[take])
    eig = float(eig.max()) if len(eig) else float("nan")
    near = _nearest(fw, grid, cols, involved)
    row = {"branches": "+".join(str(x) for x in sorted(grid["branch"][near])), **pose,
           "hess_min_eig": eig, **base}  # fmt: skip
    events = []
    if change:
        born = n_hi > n_lo
        if third is not None:  # the third branch: the row nearest the meeting point, each side
            kinds = np.asarray(grid["kind"], dtype=object)
            across = np.asarray(other["kind"], dtype=object)[_nearest(fw, other, more, [third])]
            kind, head, tail = "pitchfork", _pitchfork_words(kinds[near], across[0], born), ""
        else:
            kind, head, tail = _kind_words(_kinds(more) - _kinds(less), change, switch, eig, born)
        what = f"{head} as {param} grows past {value:.10g}{tail}"
        events.append({"kind": kind, **row, "description": what})
    if s_lo != s_hi:
        events.append({"kind": "stability_change", **row, "description": f"stable equilibria: "
                       f"{s_lo} below, {s_hi} above {param} = {value:.10g}"})  # fmt: skip
    return events


def _kind_words(gone: Counter, change: int, switch: Switch | None, eig: float, born: bool):
    """(kind, what happens, a note) of a count change that is no pitchfork."""
    names = " and ".join(f"a {k}" for k in gone.elements()) or "equilibria"
    if change % 2:
        verb = "appears" if born else "disappears"
    else:
        verb = "are born" if born else "meet and vanish"
    if switch is not None:
        return "cable_switch", f"{names} {verb} where cable {switch.cable} reaches its free " \
            "length", (f" (the taut and the slack branch end together, a cable switch: the "
                       f"softest Hessian eigenvalue {eig:.3g}, not singular)")  # fmt: skip
    if change % 2:
        return "physical_change", f"{names} {verb}", " (a length reaches its limit)"
    return "fold", f"{names} {verb}", ""


def _pitchfork_words(kinds, across: str, born: bool) -> str:
    """What happens at a pitchfork: `kinds` of the grid rows nearest it (the third branch
    first), `across` the third branch's kind at the other grid point."""
    pair = " and ".join(f"a {k}" for k in sorted(kinds[1:]))
    verb = "branch off" if born else "merge into"
    side = f"a {kinds[0]} on their side and a {across} on the other"
    return f"a pitchfork: {pair} {verb} a branch, {side},"


def _third_branch(fw, more, less, pair: np.ndarray) -> int | None:
    """The row of `more` on a third branch through the meeting point of the appearing `pair`
    (a pitchfork), if any: the one physical row of `more` besides the pair, and the one of
    `less`, within the pair's separation of the pair's mean pose."""
    if len(pair) != 2:
        return None
    here, there = pose_coordinates(fw, more), pose_coordinates(fw, less)
    centre = here[pair].mean(axis=0)
    reach = np.linalg.norm(here[pair[0]] - here[pair[1]])
    mine = np.setdiff1d(np.flatnonzero(np.asarray(more["physical"], dtype=bool)), pair)
    theirs = np.flatnonzero(np.asarray(less["physical"], dtype=bool))
    close = mine[np.linalg.norm(here[mine] - centre, axis=1) <= reach]
    across = theirs[np.linalg.norm(there[theirs] - centre, axis=1) <= reach]
    return int(close[0]) if len(close) == 1 and len(across) == 1 else None


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
            out[name] = float(mean) if mean < 360.0 else 0.0  # -1e-15 % 360 rounds to 360
        else:
            out[name] = float(values.mean()) if len(values) else float("nan")
    return out
