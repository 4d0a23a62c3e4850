"""Fold points on seed lines from the equilibria along them (framework_folds' "sweep" route).

The seed lines form a grid (LINES vertical and LINES horizontal, the window's edges among
them). Every equilibrium of the taut set is solved at the grid's crossings (backends.target:
parameter homotopy from the equilibrium system's generic set, each crossing once for both of
its lines). Along each line, every real branch of equilibria with positive lengths through a
crossing is traced by pseudo-arclength continuation on F(X; line(t)) = 0 (curve_trace), to the
window's edge or until it closes; a crossing's equilibrium on a branch already traced is
skipped (Newton at the crossing's t from the branch lands on it). A fold on the line is a
turning point of a branch in t, refined by Newton on the fold system with (x, y) held to the
line. Not seen: a branch through no crossing (an isola of the line shorter than its grid
spacing), or a pair of turning points closer together than the trace's steps.
"""

from __future__ import annotations

import hashlib
from functools import cache

import numpy as np

from ..backends.pools import Run
from ..model.framework.compiled import framework_system, variable_groups
from ..model.framework.folds import CurveSystem
from ..model.framework.spec import Framework
from ..model.framework.units import normalized_slots
from ..model.polynomial import PolySystem
from ..progress import Progress
from ..routes import choose
from ..settings import Settings, Tolerances
from .curve_trace import Traced, Window, newton, remembered, trace, turning_point

BRANCH_SPACING = 0.02  # a branch's consecutive points: at most this fraction of the line apart
BRANCH_HMAX = 0.05  # largest step of a branch in (X, x, y), relative to 1 + max |z|
TURN_HALVINGS = 30  # bisections locating a turn: 1e-9 of a step, then Newton on the fold system
FLAT = 1e-6  # a branch's step moving t by less than this does not turn it back (noise: 1e-7)
SAME = 1e-6  # a crossing's equilibrium is on a branch when Newton from it lands this near


def run_reported(run: Run, fn, tasks: list, stage: str, unit: str, batch: int = 1) -> list:
    """run(fn, tasks) in batches of `batch` tasks (a worker pool's size or twice it), saying
    how far it has got after each (progress.Progress: silent if it is all quick)."""
    out: list = []
    with Progress(stage, len(tasks), unit) as report:
        for i in range(0, len(tasks), max(1, batch)):
            part = tasks[i : i + max(1, batch)]
            out += run(fn, part)
            report.update(len(part))
    return out


def sweep_seeds(
    fw: Framework, cs: CurveSystem, specs: list, names, settings: Settings, run: Run,
    what: str = "fold seeds", batch: int = 1, branches: dict | None = None,
) -> tuple[list[np.ndarray], list[dict]]:  # fmt: skip
    """The fold points on each line (x0, y0, dx, dy) of `specs` (a grid: see the module
    docstring), as points (X, mx, my), and a record of each line. `names`: the map parameters;
    `run`: runs the tasks (runner.worker_pool): the crossings' solves by vertical line, then
    the lines, in batches of `batch` with progress lines headed `what`. `branches`: the lines'
    branches traced so far (branch_key -> list of Traced), used and added to: a taut set's fold
    and switch systems share their equilibria, so each line's branches are traced once."""
    ts = np.linspace(0.0, 1.0, _samples(specs))
    vertical = [s for s in specs if s[2] == 0.0]  # every crossing lies on one of them
    run(_generic_sets, [(fw, cs, settings)])  # once, on disk, before the workers need them
    solved: dict = {}
    tasks = [(fw, cs, spec, ts, names, settings) for spec in vertical]
    stage = f"{what}: equilibria at {len(vertical)} x {len(ts)} crossings, by vertical line"
    # On the real route a crossing's search serves every curve system of the map (kept in this
    # process, families.real_equilibria): searched here, once, not in a worker each time.
    real = choose(fw, settings).real
    if real:  # all crossings searched together, in shared batches of boxes
        from ..boxsearch.families import real_equilibria_of

        real_equilibria_of([_crossing(fw, cs, names, spec, t) for spec in vertical for t in ts])
    for part in run_reported(_here if real else run, _solve_line, tasks, stage, "lines", batch):
        solved.update(part)
    branches = {} if branches is None else branches
    tasks, keys = [], []
    for spec in specs:
        on_line = [solved[_key(spec, t)] for t in ts]
        keys.append(branch_key(cs, spec, ts, [pts for pts, *_ in on_line]))
        tasks.append((cs, spec, ts, on_line, branches.get(keys[-1])))
    stage = f"{what}: branches and their turns along the seed lines"
    results = run_reported(run, _line_folds, tasks, stage, "lines", batch)
    seeds, lines = [], []
    for key, (found, record, traced) in zip(keys, results, strict=True):
        seeds += found
        lines.append(record)
        branches[key] = traced
    return seeds, lines


def branch_key(cs: CurveSystem, spec, ts: np.ndarray, reals: list) -> str:
    """What a line's branches (_branches) depend on: the equilibria F(X; mx, my) (a curve
    system's first rows: the same for a taut set's fold and switch systems), the unknowns, the
    line, its crossings and their real equilibria."""
    F = _equilibria(cs)
    h = hashlib.sha256(repr((F.variables, cs.variables, tuple(spec))).encode())
    for a in (*F.exponents, *F.coefficients, ts, *reals):
        h.update(repr(a.shape).encode())
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def _here(fn, tasks: list) -> list:
    """Run the tasks in this process (a `Run`'s signature)."""
    return [fn(task) for task in tasks]


def _samples(specs: list) -> int:
    """Crossings on each line: one per line of the other direction."""
    vertical = sum(1 for s in specs if s[2] == 0.0)
    return max(vertical, len(specs) - vertical, 2)


def _key(spec, t: float) -> tuple[float, float]:
    """A point of the plane, as its line gives it (rounded: the two lines through a crossing
    compute it differently)."""
    x0, y0, dx, dy = spec
    return round(x0 + t * dx, 12), round(y0 + t * dy, 12)


def _generic_sets(task) -> None:
    """Solve (or load) the equilibrium system's generic sets that every crossing's solve
    starts from (backends.target.solve_parameters), so that parallel workers find them cached
    rather than each solving them."""
    from ..backends.generic import evidence_sets

    fw, cs, settings = task
    if choose(fw, settings).real:
        return  # the crossings' equilibria come from the real route: no generic set
    fs = framework_system(fw.at_defaults(), cs.taut)
    slots = normalized_slots(fw.at_defaults())
    centre = {n: slots[n] for n in fs.ps.parameters}
    evidence_sets(fs.ps, settings, centre, variable_groups(fs))


def _solve_line(task) -> dict:
    """{point: (its real equilibria with positive lengths, lost paths, 0)} along one line, each
    continued from the one before when that is proved complete (backends.target)."""
    from ..backends.target import solve_parameters

    fw, cs, spec, ts, names, settings = task
    sx, sy = cs.scales
    if choose(fw, settings).real:
        return _real_line(task)
    centre = normalized_slots(fw.at_defaults())
    out, warm = {}, None
    for t in ts:
        mx, my = _key(spec, t)
        fwp = fw.replace(**{names[0]: mx * sx, names[1]: my * sy})
        fs = framework_system(fwp, cs.taut)
        if tuple(fs.ps.variables) != cs.variables:
            raise AssertionError("the fold system's unknowns differ from the equilibria's")
        hs = solve_parameters(fs.ps, normalized_slots(fwp), centre, settings,
                              variable_groups(fs), warm)  # fmt: skip
        out[mx, my], warm = (real_points(hs), int(hs.info["lost"]), 0), hs.warm
    return out


def _real_line(task) -> dict:
    """`_solve_line` by the real route: each crossing's real equilibria of the taut set (those
    consistent with its cable states: a branch that becomes consistent between two crossings
    enters through a cable switch), no path lost, and the boxes its search left undecided."""
    from ..boxsearch.families import real_equilibria

    fw, cs, spec, ts, names, _ = task
    out = {}
    for t in ts:
        groups, found = real_equilibria(_crossing(fw, cs, names, spec, t))
        eps = groups.get(tuple(sorted(cs.taut)))
        if eps is not None and tuple(eps.variables) != cs.variables:
            raise AssertionError("the fold system's unknowns differ from the equilibria's")
        pts = eps.points.real if eps is not None else np.zeros((0, len(cs.variables)))
        out[_key(spec, t)] = (pts, 0, len(found.undecided))
    return out


def _crossing(fw: Framework, cs: CurveSystem, names, spec, t: float) -> Framework:
    """The framework at the point t of a line."""
    mx, my = _key(spec, t)
    return fw.replace(**{names[0]: mx * cs.scales[0], names[1]: my * cs.scales[1]})


def _line_folds(task) -> tuple[list[np.ndarray], dict, list[Traced]]:
    """One line's fold points (its branches' turns), its record and its branches (traced
    here unless given)."""
    cs, spec, ts, solved, branches = task
    if branches is None:
        branches = _branches(cs, spec, ts, [pts for pts, *_ in solved])
    found, counts = _turning_folds(cs, spec, branches)
    record = {
        "line": [float(v) for v in spec], "points": len(ts), "branches": len(branches),
        "stalled_ends": sum(e in ("stalled", "max_points") for b in branches for e in b.ends),
        "real_in_window": len(found), **counts,
        # Each crossing's solve is counted once, on its vertical line (sweep_seeds solves it):
        # paths lost (complex route) and boxes its search left undecided (real route).
        "lost": sum(s[1] for s in solved) if spec[2] == 0.0 else 0,
        "undecided_boxes": sum(s[2] for s in solved) if spec[2] == 0.0 else 0,
    }  # fmt: skip
    return found, record, branches


def real_points(hs) -> np.ndarray:
    """The real endpoints of a solve with every length positive (real parts), one row each: a
    length never changes sign along a branch (L0 > 0), so only these meet at physical folds."""
    pts = hs.endpoints.points
    if not len(pts):
        return np.zeros((0, pts.shape[1] if pts.ndim == 2 else 0))
    lengths = [k for k, v in enumerate(hs.endpoints.variables) if v.startswith("d_")]
    return pts[is_real(pts) & (pts.real[:, lengths] > 0).all(axis=1)].real


def is_real(pts: np.ndarray) -> np.ndarray:
    """Which rows are real: every imaginary part below 1e-6 relative to the real part."""
    return (np.abs(pts.imag) / (1 + np.abs(pts.real))).max(axis=1) < 1e-6


def long_enough(cs: CurveSystem):
    """z -> whether every length of z = (X, mx, my) is above the solutions' zero-length rule
    (normalised units): a branch or curve whose length tends to zero leaves the physical
    equilibria there (its force density grows without bound), so a trace stops."""
    lengths = [k for k, v in enumerate(cs.variables) if v.startswith("d_")]
    short = Tolerances().zero_length

    def keep(z: np.ndarray) -> bool:
        return bool((z[lengths] > short).all())

    return keep


def _line_t(z: np.ndarray, spec) -> np.ndarray:
    """The line parameter of points z (..., N) (their last two coordinates: mx, my)."""
    x0, y0, dx, dy = spec
    return ((z[..., -2] - x0) * dx + (z[..., -1] - y0) * dy) / (dx * dx + dy * dy)


def _at_t(spec, t: float):
    """Newton's extra equation holding the line parameter at t."""
    x0, y0, dx, dy = spec

    def extra(z: np.ndarray):
        grad = np.zeros(len(z))
        grad[-2:] = np.array([dx, dy]) / (dx * dx + dy * dy)
        return _line_t(z, spec) - t, grad

    return extra


def _branches(cs: CurveSystem, spec, ts: np.ndarray, reals: list) -> list[Traced]:
    """Every real branch of the line through a crossing's real equilibria, traced once."""
    eqs, win = _branch_equations(cs, spec), _line_window(spec)
    x0, y0, dx, dy = spec
    keep = long_enough(cs)

    out: list[Traced] = []
    for t, pts in zip(ts, reals, strict=True):
        for X in pts:
            z = np.concatenate([X, [x0 + t * dx, y0 + t * dy]])
            if not any(_passes_through(eqs, b.points, z, t, spec) for b in out):
                out.append(trace(eqs, z, win, BRANCH_SPACING, BRANCH_HMAX, keep, relative=True))
    return out


def _passes_through(eqs, points: np.ndarray, z: np.ndarray, t: float, spec) -> bool:
    """Whether the branch `points` passes through z (at line parameter t): Newton at t from the
    branch's chords across t lands on z."""
    tp = _line_t(points, spec)
    for i in np.flatnonzero((tp[:-1] - t) * (tp[1:] - t) <= 0):
        span = tp[i + 1] - tp[i]
        s = 0.5 if span == 0 else (t - tp[i]) / span
        start = points[i] + s * (points[i + 1] - points[i])
        if np.abs(start - z).max() > 10 * BRANCH_HMAX:
            continue
        w = newton(eqs, start, start, _at_t(spec, t))
        if w is not None and np.abs(w - z).max() <= SAME * (1 + np.abs(z).max()):
            return True
    return False


def curve_equations(cs: CurveSystem):
    """The traced equations of z = (X, mx, my): the curve system's residual and Jacobian."""

    def eqs(z: np.ndarray, zref: np.ndarray):
        F, J = cs.trace.value_and_jacobian(z)
        return F[0].real, J[0].real

    return remembered(eqs)


@cache
def _equilibria(cs: CurveSystem) -> PolySystem:
    """F(X; mx, my): the curve system's first rows (the fold and switch systems are F plus one)."""
    n = len(cs.variables)
    tr = cs.trace
    return PolySystem(tr.variables, tr.names[:n], tr.exponents[:n], tr.coefficients[:n])


def _branch_equations(cs: CurveSystem, spec):
    """The traced equations of a branch: F = 0 with (mx, my) on the line."""
    F = _equilibria(cs)
    x0, y0, dx, dy = spec
    normal = np.zeros(len(cs.variables) + 2)
    normal[-2:] = -dy, dx

    def eqs(z: np.ndarray, zref: np.ndarray):
        value, jac = F.value_and_jacobian(z)
        line = normal @ z - (-dy * x0 + dx * y0)
        return np.append(value[0].real, line), np.vstack([jac[0].real, normal])

    return remembered(eqs)


def _line_window(spec) -> Window:
    """A window holding the line segment: a sliver around its constant coordinate."""
    x0, y0, dx, dy = spec
    pad = 1e-9 * (1 + abs(x0) + abs(y0))
    lo = (min(x0, x0 + dx) - (pad if dx == 0 else 0), min(y0, y0 + dy) - (pad if dy == 0 else 0))
    hi = (max(x0, x0 + dx) + (pad if dx == 0 else 0), max(y0, y0 + dy) + (pad if dy == 0 else 0))
    return Window(-2, -1, lo, hi, (1.0, 1.0))


def _turning_folds(cs: CurveSystem, spec, branches: list[Traced]) -> tuple[list, dict]:
    """The fold points of the branches: where t turns back, located on the branch by bisection
    and refined by Newton on the fold system; with counts of the turns that are
    relaxed folds (every force density 0: the fold system is singular there, and the relaxed
    folds have their own) and of those that could not be located or refined."""
    if cs.kind == "switch":
        return _switch_points(cs, spec, branches)
    eqs, win, fold_eqs = _branch_equations(cs, spec), _line_window(spec), curve_equations(cs)
    along = np.array(spec[2:]) / np.hypot(*spec[2:])
    forces = [k for k, v in enumerate(cs.variables) if v.startswith("w_")]
    found, counts = [], {"turns": 0, "relaxed": 0, "unrefined": 0}
    for b in branches:
        for za, zb in _turns(b, spec):
            counts["turns"] += 1
            turn = turning_point(eqs, za, zb, along, win, TURN_HALVINGS)
            ends = [z for z in (turn,) if z is not None] or [za, zb]
            # A turn at a relaxed pose (every force density 0, located or, where Newton cannot
            # locate it there, at one end of the bracket): the fold system is singular there,
            # and the relaxed folds have their own.
            if forces and any(np.abs(z[forces]).max() <= SAME for z in ends):
                counts["relaxed"] += 1
                continue
            hit = None if turn is None else _line_newton(fold_eqs, turn, spec)
            if hit is None or np.abs(hit[0] - turn).max() > SAME * (1 + np.abs(turn).max()):
                counts["unrefined"] += 1
            elif 0.0 <= hit[1] <= 1.0 and not any(
                np.abs(hit[0] - f).max() <= SAME * (1 + np.abs(f).max()) for f in found
            ):
                found.append(hit[0])
    return found, counts


def _switch_points(cs: CurveSystem, spec, branches: list[Traced]) -> tuple[list, dict]:
    """The switch points of the branches (a switch system: the equilibria and d_c = L0_c):
    where its last equation changes sign between two points of a branch, refined by Newton on
    the switch system with (mx, my) held to the line."""
    switch_eqs = curve_equations(cs)
    found, counts = [], {"turns": 0, "relaxed": 0, "unrefined": 0}
    for b in branches:
        pts = np.vstack([b.points, b.points[:1]]) if b.closed else b.points
        gap = np.array([cs.trace.value_and_jacobian(z)[0][0][-1].real for z in pts])
        for i in np.flatnonzero(gap[:-1] * gap[1:] < 0):
            counts["turns"] += 1
            s = gap[i] / (gap[i] - gap[i + 1])
            hit = _line_newton(switch_eqs, pts[i] + s * (pts[i + 1] - pts[i]), spec)
            if hit is None:
                counts["unrefined"] += 1
            elif 0.0 <= hit[1] <= 1.0 and not any(
                np.abs(hit[0] - f).max() <= SAME * (1 + np.abs(f).max()) for f in found
            ):
                found.append(hit[0])
    return found, counts


def _turns(branch: Traced, spec) -> list[tuple[np.ndarray, np.ndarray]]:
    """The pairs of points of a branch between which t turns back: a change of sign between
    consecutive steps that move t by more than FLAT (smaller moves are rounding, where a branch
    crawls towards a zero-length end)."""
    pts = np.vstack([branch.points, branch.points[1:2]]) if branch.closed else branch.points
    dt = np.diff(_line_t(pts, spec))
    moving = np.flatnonzero(np.abs(dt) > FLAT)
    flips = np.flatnonzero(dt[moving[:-1]] * dt[moving[1:]] < 0)
    return [(pts[moving[i]], pts[moving[i + 1] + 1]) for i in flips]


def _line_newton(eqs, z: np.ndarray, spec) -> tuple | None:
    """Newton on the curve system from z with (mx, my) held to the line: (z, its t)."""
    x0, y0, dx, dy = spec
    normal = np.zeros(len(z))
    normal[-2:] = -dy, dx
    w = newton(eqs, z, z, lambda v: (normal @ (v - z), normal))
    return None if w is None else (w, float(_line_t(w, spec)))
