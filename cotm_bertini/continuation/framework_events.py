"""Events of a framework's one-parameter sweep, refined by bisection on the parameter.

Between neighbouring points the numbers of physical and of stable equilibria are compared; where
they differ, the interval is bisected (each probe a full solve of the framework, continued from
the bracket's lower end by Newton, so the count there is complete) until the bracket is narrower
than BISECT_TOL. A probe within the solver's resolution of the event (at a fold the merging
pair is found as one degenerate root) matches neither end: it places no end, and the next probes
close in on it from both sides. Each event is named by what happens there:

- cable_switch: the equilibria that appear (or vanish) have a cable at its free length there
  (the taut and the slack branch end together, the Hessian regular): located where that cable's
  length equals its free length (framework_switch.py), not by the counts; one event per switch
  (a taut and a slack row born together: a border collision);
- pitchfork: the physical count changes by two on a third equilibrium, present on both sides,
  through the pair's meeting point (a min and two saddles, or a saddle and two minima meet);
- fold: the physical count changes by two otherwise (a pair is born or meets and vanishes, the
  reduced Hessian singular there);
- physical_change: it changes by one (a length reaching 0; an equilibrium leaving or entering
  a cone point of V is located where the pull there equals k L0: framework_cones.py);
- stability_change: the number of stable equilibria changes (at the events above too, as for
  the paper's model).

A sweep point whose solve is incomplete or degenerate places no bracket end (its neighbours
bracket the event; the description says which point was left out). A fold the probes cannot
close in on is placed by extrapolating the merging pair's eigenvalue product.

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
from .framework_cones import Cone, locate_cone
from .framework_switch import Follower, Switch, candidate_cable, locate_switch
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
    # A sweep point whose solve is incomplete (an equilibrium at a cable's free length, boxes
    # left undecided) or has a degenerate equilibrium places no bracket end: its counts may be
    # wrong, and an event there would be a fake. Its neighbours bracket what happens instead.
    kept = [r for r in range(len(order)) if usable(part[r])]
    events: list[dict] = []
    pairs = [(r, t) for r, t in zip(kept, kept[1:], strict=False)
             if _signature(part[r]) != _signature(part[t])]  # fmt: skip
    # Each bisection probe is a full solve (minutes on a large framework, more when a probe
    # needs another generic set): said as it goes, after the sweep's last point.
    with Progress("sweep: events refined", len(pairs), "intervals", heartbeat=True) as report:
        for r, t in pairs:
            (pa, pb), lo = (order[r][1], order[t][1]), order[r][1]
            note = _left_out(param, [order[k][1] for k in range(r + 1, t)])
            # The sweep point's own solve, not solved again; the complex route's probes are
            # continued from a solve of it (its `warm`: a start per taut set).
            past = _Known(part[r]) if _real(spec) else _solver(spec)(lo)
            ends = (past, _Known(part[t]))
            for _ in range(MAX_EVENTS):
                if lo >= pb:
                    break
                bracket = _pinned(spec, lo, pb, past, ends[1]) or _bisect(spec, lo, pb, past)
                bracket = replace(bracket, start=(pa, pb))
                switches = _switches(spec, bracket)
                events.extend(_describe(spec, bracket, (part[r], part[t]), switches, note))
                # Two events between neighbouring points (their counts change twice): the
                # rest of the interval is searched again from the bracket's upper end, its
                # solve kept.
                if _signature(bracket.above.columns) == _signature(part[t]):
                    break
                lo, past = bracket.hi, bracket.above
            report.update(1, note=f"{len(events)} events")
    return sorted(events, key=lambda e: (e[param], e["kind"], e["branches"]))


def usable(cols) -> bool:
    """A sweep point's solve is complete and has no degenerate equilibrium."""
    status = set(np.asarray(cols["status"], dtype=object).tolist())
    kind = np.asarray(cols["kind"], dtype=object)[np.asarray(cols["physical"], dtype=bool)]
    return status <= {"ok"} and not (kind == "degenerate").any()


def _left_out(param: str, values: list[float]) -> str:
    """The note of an event bracketed across sweep points left out of the comparison."""
    if not values:
        return ""
    said = ", ".join(f"{v:.10g}" for v in values)
    return f"; sweep point {param} = {said} left out (incomplete or degenerate solve)"


@dataclass(frozen=True)
class _Known:
    """A sweep point's solve as a bracket end: its columns and status (nothing to warm from: a
    probe continued from it solves in full)."""

    columns: dict
    warm: object = None

    @property
    def status(self) -> str:
        status = set(np.asarray(self.columns["status"], dtype=object).tolist())
        return "ok" if status <= {"ok"} else "incomplete"


@dataclass(frozen=True)
class _Bracket:
    lo: float
    hi: float
    below: object  # the PointSolution at lo
    above: object  # ... at hi
    refined: bool
    start: tuple[float, float]  # the sweep points on either side
    estimate: tuple[float, float] | None = None  # a fold left wider than tol: (value, error)
    located: float | None = None  # a fold located by Newton on its system (fold_point.py)


PIN_WIDEN = 16  # _pinned: a probe at the fold itself moves this many times farther out


def _pinned(spec, lo: float, hi: float, below, above) -> _Bracket | None:
    """The bracket of a fold between solves `below` (at lo) and `above` (at hi): the fold
    located by Newton on its system from the pair that meets there (fold_point.py), then one
    full solve on each side of it, tol / 2 away (moved out while a probe sees the pair as one
    degenerate root). None where the pair is not found, Newton does not converge, or a probe
    lands on the wrong side: bisection takes over."""
    from .fold_point import locate_fold

    start, end = _signature(below.columns), _signature(above.columns)
    meet = 1 if _minima_only(spec) else 2  # (a minimum's partner at its fold: not searched)
    if abs(start[0] - end[0]) != meet or below.status != "ok" or above.status != "ok":
        return None
    (p_more, more), (p_less, less) = ((lo, below), (hi, above))[:: 1 if start[0] > end[0] else -1]
    pair = new_rows(spec.model, more.columns, less.columns, meet)
    if len(pair) != meet or not _charted(spec):
        return None
    fold = locate_fold(spec.model, spec.param, more.columns, pair, p_more, p_less)
    if fold is None or not lo < fold.value < hi:
        return None
    solve, tol = _solver(spec), BISECT_TOL * max(1.0, abs(lo), abs(hi))
    sides = {-1: (tol / 2, None, start), 1: (tol / 2, None, end)}
    while any(got is None for _, got, _ in sides.values()):
        for side, (gap, got, want) in sides.items():
            if got is not None:
                continue
            value = fold.value + side * gap
            if not lo < value < hi or gap > (hi - lo) / 4:
                return None
            probe = solve(value, below.warm)
            if _signature(probe.columns) == want and not _at_event(probe):
                sides[side] = (gap, probe, want)
            elif _signature(probe.columns) in (start, end) and not _at_event(probe):
                return None  # on the wrong side: the fold is not where the counts change
            else:
                sides[side] = (gap * PIN_WIDEN, None, want)
    (g_lo, b_lo, _), (g_hi, b_hi, _) = sides[-1], sides[1]
    ok = b_lo.status == "ok" and b_hi.status == "ok"
    return _Bracket(fold.value - g_lo, fold.value + g_hi, b_lo, b_hi, ok, (lo, hi),
                    located=fold.value)  # fmt: skip


def _minima_only(spec) -> bool:
    """The sweep's points hold their stable equilibria alone (Settings.only)."""
    return spec.settings.get("only", "all") == "stable"


def _real(spec) -> bool:
    """The sweep's points are solved on the real route."""
    from ..routes import choose
    from .runner import point_settings

    return choose(spec.model, point_settings(spec)).real


def _charted(spec) -> bool:
    """The swept framework has chart angles (a circle, torus or product of spheres)."""
    from ..boxsearch.real_route import covers

    return not covers(spec.model)


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
    estimate = _extrapolated(seen, hi - lo) if fold and hi - lo > tol else None
    if estimate is not None and not 2 * lo - hi <= estimate[0] <= 2 * hi - lo:
        estimate = None  # not where the probes saw the event: the middle is said instead
    return _Bracket(lo, hi, below, above, ok, (pa, pb), estimate)


def _solver(spec):
    """solve(value, warm=None): the framework's complete solve at `value` of the parameter."""
    from ..point import solve_framework_point
    from .runner import point_settings

    settings = point_settings(spec)

    def solve(value: float, warm=None):
        fw = spec.model.replace(**{spec.param: value})
        return solve_framework_point(fw, settings, warm=warm)

    return solve


def _switches(spec, b: _Bracket) -> list[tuple[Switch, list[int]]]:
    """The cable switches that cause the bracket's count change: each appearing row followed
    along its branch to where a cable near its free length is at it (framework_switch.py), the
    rows that meet at one switch grouped (a taut and a slack row born together); [] unless every
    appearing row has one in the bracket (widened by its width)."""
    (n_lo, _), (n_hi, _) = _signature(b.below.columns), _signature(b.above.columns)
    if n_lo == n_hi:
        return []
    fw, param = spec.model, spec.param
    ends = [(b.lo, b.below.columns), (b.hi, b.above.columns)]
    (p_more, more), (p_less, less) = ends if n_lo > n_hi else ends[::-1]
    take = new_rows(fw, more, less, abs(n_hi - n_lo))
    solve, warm = _solver(spec), b.below.warm
    tol = BISECT_TOL * max(1.0, abs(b.lo), abs(b.hi))
    width = b.hi - b.lo + tol
    found = []
    for row in take:
        cable = candidate_cable(fw, more, [row], p_more, param)
        if cable is None:
            return []
        follow = Follower(fw, param, more, cable[0], cable[1], lambda v: solve(v, warm))
        switch = locate_switch(fw, param, follow, (p_more, more, cable[0]), p_less, tol)
        if switch is None or not b.lo - width <= switch.value <= b.hi + width:
            return []
        found.append((switch, int(row)))
    return _grouped(fw, more, found, width)


def _grouped(fw, cols, found: list, width: float) -> list[tuple[Switch, list[int]]]:
    """Switches of one cable at one value (within `width`) paired with the nearest in pose
    (a pair born or vanishing together there); the rest alone."""
    pose = pose_coordinates(fw, cols)
    left, out = list(found), []
    while left:
        switch, row = left.pop(0)
        mates = [k for k, (s, r) in enumerate(left)
                 if s.cable == switch.cable and abs(s.value - switch.value) <= width]  # fmt: skip
        if mates:
            k = min(mates, key=lambda k: np.linalg.norm(pose[left[k][1]] - pose[row]))
            out.append((switch, [row, left.pop(k)[1]]))
        else:
            out.append((switch, [row]))
    return out


def _cone(spec, b: _Bracket) -> Cone | None:
    """The cone event (framework_cones.py) that causes the bracket's count change of one, if
    one lies in the bracket (widened by its width)."""
    tol = BISECT_TOL * max(1.0, abs(b.lo), abs(b.hi))
    width = b.hi - b.lo + tol
    cone = locate_cone(spec.model, spec.param, b.start[0], b.start[1], tol)
    return cone if cone is not None and b.lo - width <= cone.value <= b.hi + width else None


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


def _extrapolated(seen: list[tuple[float, float]], width: float) -> tuple[float, float] | None:
    """(value, error) of a fold the probes could not close in on (the solver sees the merging
    pair as one degenerate root, or none, within `width` of it): the zero of the parabola through
    three real-side probes of the pair's eigenvalue product (it vanishes linearly there), each
    at least width / 2 from the last, the nearest first; the error its distance from the line's
    zero through the first two. None with fewer than two such probes."""
    pts = sorted(seen, key=lambda v: abs(v[0] - seen[-1][0]))
    chosen = [pts[0]]
    for v in pts[1:]:
        if len(chosen) < 3 and abs(v[0] - chosen[-1][0]) >= width / 2 and np.isfinite(v[1]):
            chosen.append(v)
    if len(chosen) < 2 or not np.isfinite(chosen[0][1]):
        return None
    x = np.array([p for p, _ in chosen]) - chosen[0][0]
    y = np.array([g for _, g in chosen])
    if y[1] == y[0]:
        return None  # no change to extrapolate (no fold: a cable switch, say)
    line = chosen[0][0] - y[0] * x[1] / (y[1] - y[0])
    if len(chosen) == 2:
        return float(line), float(width)
    c = np.linalg.solve(np.vander(x, 3), y)  # c0 x^2 + c1 x + c2
    roots = np.roots(c)  # np.roots drops leading zeros: a line's one root
    roots = roots[np.isreal(roots)].real + chosen[0][0]
    if not len(roots) or not np.isfinite(roots).all():
        return float(line), float(width)
    value = float(roots[np.argmin(np.abs(roots - line))])
    return value, float(abs(value - line))


def _secant(seen: list[tuple[float, float]]) -> float | None:
    """Where the secant through the two real-side probes nearest the fold reaches 0, or None."""
    if len(seen) < 2:
        return None
    (p1, g1), (p2, g2) = seen[-2], seen[-1]
    if not np.isfinite([g1, g2]).all() or g1 == g2:
        return None
    return p2 + g2 * (p2 - p1) / (g1 - g2)


def _describe(spec, b: _Bracket, grids: tuple[dict, dict], switches: list, note: str) -> list:
    """The events of one refined bracket (`grids`: the sweep points on either side; `switches`:
    the located cable switches that cause its count change, with their rows; `note`: sweep
    points left out between them)."""
    fw, param = spec.model, spec.param
    lo_cols, hi_cols = b.below.columns, b.above.columns
    (n_lo, s_lo), (n_hi, s_hi) = _signature(lo_cols), _signature(hi_cols)
    more, less = (lo_cols, hi_cols) if n_lo >= n_hi else (hi_cols, lo_cols)
    grid, other = grids if n_lo >= n_hi else grids[::-1]
    change, born = abs(n_hi - n_lo), n_hi > n_lo
    span = {"lo": float(b.start[0]), "hi": float(b.start[1])}
    events = []
    for switch, rows in switches:
        head = {param: switch.value, "refined": b.refined and switch.converged,
                "bracket": switch.step, **span}  # fmt: skip
        row = _event_row(fw, grid, more, np.array(rows), np.array(rows), head)
        row.update(_pose(fw, switch.columns, np.array([switch.row])))
        names = " and ".join(f"a {k}" for k in sorted(np.asarray(more["kind"])[rows]))
        verb = ("appears" if born else "disappears") if len(rows) == 1 else (
            "are born" if born else "meet and vanish")  # fmt: skip
        what = (
            f"{names} {verb} at a cable switch ({switch.cable} reaches its free length) as "
            f"{param} grows past {switch.value:.10g} (the taut and the slack branch end "
            f"together, the softest Hessian eigenvalue {row['hess_min_eig']:.3g}: no fold)"
        )
        events.append({"kind": "cable_switch", **row, "description": what + note})
    value = 0.5 * (b.lo + b.hi) if b.located is None else b.located
    bracket = b.hi - b.lo
    head = {param: value, "refined": b.refined, "bracket": bracket, **span}
    take = new_rows(fw, more, less, change) if change else _closest_to_zero(lo_cols, 1)
    if change and not switches:
        third = _third_branch(fw, more, less, take) if change == 2 else None
        if third is None and change == 2 and b.estimate is not None:  # a fold: extrapolated
            head.update({param: b.estimate[0], "bracket": b.estimate[1]})
        involved = take if third is None else np.append(take, third)
        row = _event_row(fw, grid, more, take, involved, head)
        if third is not None:  # the third branch: the row nearest the meeting point, each side
            kinds = np.asarray(grid["kind"], dtype=object)[_nearest(fw, grid, more, involved)]
            across = np.asarray(other["kind"], dtype=object)[_nearest(fw, other, more, [third])]
            kind, words, tail = "pitchfork", _pitchfork_words(kinds, across[0], born), ""
        elif b.located is not None and change == 1 and _minima_only(spec):
            verb = "is born" if born else "vanishes"
            kind, words, tail = (
                "fold",
                f"a min {verb} at a fold (with a saddle, not looked for)",
                "",
            )
        else:
            kind, words, tail = _kind_words(_kinds(more) - _kinds(less), change, born)
            cone = _cone(spec, b) if change == 1 else None
            if cone is not None:  # located where the cone's pull equals k L0, its pose
                row.update({param: cone.value, "bracket": cone.step, **cone.pose,
                            "refined": b.refined and cone.converged})  # fmt: skip
                tail = (
                    f" at the cone point of spring {cone.spring} (its length 0, its ends "
                    f"meet): the other elements' pull there equals k L0, the cone a local "
                    f"maximum of V {'above' if cone.max_above else 'below'} it"
                )
        what = f"{words} as {param} grows past {row[param]:.10g}{tail}"
        events.append({"kind": kind, **row, "description": what + note})
    if s_lo != s_hi:
        row = {**events[0]} if events else _event_row(fw, grid, lo_cols, take, take, head)
        what = f"stable equilibria: {s_lo} below, {s_hi} above {param} = {row[param]:.10g}"
        events.append({**row, "kind": "stability_change", "description": what + note})
    return events


def _event_row(fw, grid, cols, take, involved, head: dict) -> dict:
    """An event's branches (of the grid point's rows nearest the `involved` rows of `cols`),
    pose and softest eigenvalue (of the `take` rows)."""
    eig = np.abs(np.asarray(cols["hess_min_eig"], dtype=float)[take])
    near = _nearest(fw, grid, cols, involved)
    return {"branches": "+".join(str(x) for x in sorted(grid["branch"][near])),
            **_pose(fw, cols, take), "hess_min_eig": float(eig.max()) if len(eig) else np.nan,
            **head}  # fmt: skip


def _kind_words(gone: Counter, change: int, born: bool) -> tuple[str, str, str]:
    """(kind, what happens, a note) of a count change that is no pitchfork and no switch."""
    names = " and ".join(f"a {k}" for k in gone.elements()) or "equilibria"
    if change % 2:
        verb = "appears" if born else "disappears"
        return "physical_change", f"{names} {verb}", " (a length reaches its limit)"
    return "fold", f"{names} {'are born' if born else 'meet and vanish'}", ""


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


def new_rows(fw, more, less, count: int) -> np.ndarray:
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
