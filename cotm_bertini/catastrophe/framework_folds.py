"""Fold curves, cusps and cable switches of any framework over two of its parameters.

For every taut set, fold points on real lines across the window (vertical and horizontal, the
window's edges among them) are found by one of two routes, both Bertini's:

- "witness": the fold system (model/framework/folds.py) is solved once at a random complex line
  of the (x, y) plane (a witness set of the fold curve) and brought to each real line by
  parameter homotopy: every fold point on the line;
- "sweep": the equilibria of the taut set are solved at the crossings of the seed lines
  (parameter homotopy from the equilibrium system's generic set), and every real branch through
  a crossing is traced along each line; its turning points are the folds on the line
  (catastrophe/fold_sweep.py, which says what it cannot see). For systems whose witness set is
  too costly (cotm.toml's: 1,408 paths, each slow in Bertini 2 for a 1,226-term fold equation).
  A relaxed fold (model/framework/folds.py), where the fold system is singular, is a turning
  point Newton cannot refine: the relaxed folds' own system is always solved by its witness set
  (small: 96 paths on cotm.toml), since a sweep could not tell relaxed folds from the others.

"auto" takes the witness route when the witness set's multihomogeneous path count is at most
WITNESS_MAX_PATHS, else the sweep. Each real fold point found seeds a pseudo-arclength trace of
its curve in (X, x, y) (catastrophe/curve_trace.py) to the window's edge or until it closes,
and a seed on a curve already traced is skipped. Cusps are where the curve's image in the plane
turns back (refined by bisection on the image's speed along the incoming direction) and are
confirmed by the vanishing of w . F_XX[v, v] (w, v the left and right null vectors of J_X F: the
cubic term of the energy along the null direction). Cable switches (a taut cable exactly at its
free length L0 > 0) are found and traced the same way on the switch system. Every point is
classified by the framework's own classification (analysis/framework_classify.py) at its (x, y).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..analysis.framework_classify import (
    column_names,
    framework_columns,
    local_hessian,
    reduced_eigh,
)
from ..backends.endpoints import Endpoints
from ..backends.homotopy import generic_set, track
from ..backends.pools import Run, worker_pool
from ..backends.start_system import bezout_number, fewest_paths_groups, group_degrees
from ..errors import ParameterError
from ..model.framework.compiled import framework_system
from ..model.framework.folds import (
    LINE,
    RELAXED,
    CurveSystem,
    curve_system,
    relaxed_applies,
)
from ..model.framework.spec import Framework
from ..model.framework.units import normalized_slots, units
from ..progress import Progress, say
from ..routes import choose
from ..settings import Settings, Tolerances
from .curve_trace import Traced, Window, trace, turning_point
from .fold_sweep import curve_equations, is_real, long_enough, run_reported, sweep_seeds

SEED_ROUTES = ("auto", "witness", "sweep")
WITNESS_MAX_PATHS = 600  # "auto": above this many paths the fold witness set is not solved
SPACING = 0.002  # consecutive points of a curve: at most this fraction of the window diagonal
LINES = 9  # seed lines in each direction (the window's edges among them)
HMAX = 0.05  # largest step in (X, mx, my), normalised units, relative to 1 + max |z|
CHUNK = 250  # points classified in one task (a worker's share)
NULL_BATCH = 16  # points whose null_cubic is evaluated together
TURN_COS = -0.5  # image segments turning by more than 120 deg: a cusp between them
TAUT_GRID = 9  # points per axis where the window's taut sets are enumerated
CUSP_TOL = 1e-6  # |w . F_XX[v, v]| / |F_XX[v, v]| below this confirms a cusp


@dataclass(frozen=True)
class _Curves:
    """A curve system's traced curves and what finding them took."""

    cs: CurveSystem
    traced: list[Traced]
    window: Window
    eqs: object  # the traced equations (curve_trace.Equations)


def framework_fold_curves(
    fw: Framework,
    xname: str,
    xrange: tuple[float, float],
    yname: str,
    yrange: tuple[float, float],
    settings: Settings | None = None,
    kinds: tuple[str, ...] = ("fold", "cable_switch"),
    seeds: str = "auto",
    workers: int = 1,
) -> tuple[pd.DataFrame, dict]:
    """Fold curves, cusps and cable switches of `fw` in the window xrange x yrange of its
    parameters xname, yname: one row a point (docs/columns.md, "framework folds") and the record
    for run.json. `kinds`: which curves to compute (fold curves bring their cusps); `seeds`:
    how points on the seed lines are found ("witness", "sweep" or "auto", module docstring;
    relaxed folds always by their witness set, which the record says); `workers`: processes for
    the sweep route's solves and lines and for classifying the points."""
    settings = settings or Settings()
    _check(fw, xname, xrange, yname, yrange)
    if seeds not in SEED_ROUTES:
        raise ParameterError(f"seeds: {seeds!r} is not a seed route ({', '.join(SEED_ROUTES)})")
    for kind in kinds:
        if kind not in ("fold", "cable_switch"):
            raise ParameterError(f"kinds: {kind!r} is not a curve kind (fold, cable_switch)")
    t0 = time.perf_counter()
    centre = fw.replace(**{xname: sum(xrange) / 2, yname: sum(yrange) / 2})
    frames, record = [], {"taut_sets": {}}
    next_id = 0
    todo = _curve_systems(fw, centre, (xname, xrange, yname, yrange), kinds)
    branches: dict = {}  # the sweep route's branches along the seed lines, by fold_sweep.branch_key
    with worker_pool(workers) as run:
        for k, (taut, cable) in enumerate(todo):
            cs = curve_system(centre, taut, xname, yname, cable)
            name = {"": "fold", RELAXED: "relaxed fold"}.get(cable, f"switch {cable}")
            group = record["taut_sets"].setdefault(" ".join(taut) or "none", {})
            if not cs.ps.parameters:
                # Neither map parameter enters: its equilibria are the same all over the
                # window, so a fold would fill the plane (never, generically) or be absent,
                # and its witness system has a free line parameter (no isolated points).
                group[name] = {"curves_traced": 0, "points": 0, "why": "its equations "
                               f"involve neither {xname} nor {yname}"}  # fmt: skip
                continue
            axes = (xname, xrange), (yname, yrange)
            what = f"fold curves {k + 1}/{len(todo)} ({name}, taut set {' '.join(taut) or 'none'})"
            work = _Work(run, 2 * workers if workers > 1 else 1, what)
            curves, info = _find(fw, cs, axes, settings, seeds, work, branches)
            frame, next_id, about = _rows(fw, curves, (xname, yname), next_id, work)
            frames.append(frame)
            group[name] = {**info, **about}
    table = pd.concat(frames, ignore_index=True) if frames else _empty(fw, xname, yname)
    record.update(
        window={xname: list(xrange), yname: list(yrange)}, spacing=SPACING, lines=LINES,
        kinds=list(kinds), seeds=seeds, workers=workers,
        seed=settings.seed, seconds=time.perf_counter() - t0,
        counts={k: int((table["kind"] == k).sum()) for k in ("fold", "cusp", "cable_switch")},
        curves_found=int(table.loc[table["curve_id"] >= 0, "curve_id"].nunique()),
    )  # fmt: skip
    return table, record


@dataclass(frozen=True)
class _Work:
    """How a curve system's tasks run: the worker pool's `run`, in batches of `batch` tasks,
    their progress lines headed `what`."""

    run: Run
    batch: int
    what: str

    def __call__(self, fn, tasks: list, stage: str, unit: str) -> list:
        return run_reported(self.run, fn, tasks, f"{self.what}: {stage}", unit, self.batch)


def _curve_systems(fw: Framework, centre: Framework, window: tuple, kinds) -> list[tuple]:
    """(taut set, cable) of every curve system to find (curve_system's `cable`), in order: the
    window's taut sets that do not move freely (those have no isolated equilibria, so no
    folds: continuum_check's), each with its curve kinds."""
    return [
        (taut, cable)
        for taut in _window_taut_sets(fw, *window)
        if not framework_system(centre, taut).free
        for cable in _curve_kinds(centre, taut, kinds)
    ]


def _window_taut_sets(fw: Framework, xname: str, xrange, yname: str, yrange) -> list[tuple]:
    """The taut sets that can occur somewhere in the window: those of any of TAUT_GRID x
    TAUT_GRID points of it (corners included; a cable always taut at the centre may go slack
    near an edge), all taut first as model.framework.taut_sets orders them."""
    from ..model.framework.taut_sets import taut_sets

    found: set[tuple[str, ...]] = set()
    for x in np.linspace(*xrange, TAUT_GRID):
        for y in np.linspace(*yrange, TAUT_GRID):
            found.update(taut_sets(fw.replace(**{xname: float(x), yname: float(y)})))
    order = [c.name for c in fw.cables]
    return sorted(found, key=lambda t: (-len(t), [order.index(c) for c in t]))


def _curve_kinds(centre: Framework, taut: tuple[str, ...], kinds: tuple[str, ...]) -> list[str]:
    """The curve systems of a taut set, as curve_system's `cable`: "" (folds), RELAXED (relaxed
    folds, where they can occur), and each taut cable with L0 > 0 (its switch)."""
    cables = [c for c in taut if normalized_slots(centre)[f"L0_{c}"] != 0]
    chosen = ([""] if "fold" in kinds else []) + (cables if "cable_switch" in kinds else [])
    if "fold" in kinds and relaxed_applies(centre, taut):
        chosen.insert(1, RELAXED)
    return chosen


def _check(fw: Framework, xname: str, xrange, yname: str, yrange) -> None:
    """Refuse bad axes in one line naming the field and the value."""
    for name in (xname, yname):
        if name not in fw.values:
            raise ParameterError(
                f"{name}: unknown parameter of framework {fw.name!r} "
                f"(known: {' '.join(fw.values) or 'none'})"
            )
    if xname == yname:
        raise ParameterError(f"param2 = {yname!r}: the map's two parameters must differ")
    for name, (lo, hi) in ((xname, xrange), (yname, yrange)):
        if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
            raise ParameterError(f"{name}: window ({lo}, {hi}) must be finite with from < to")


def _centre(cs: CurveSystem, fw: Framework, xname: str, yname: str) -> dict:
    """The generic set's centre: the file's values, a line through them of unit direction."""
    d = fw.at_defaults()
    sx, sy = cs.scales
    line = {LINE[0]: d.values[xname] / sx, LINE[1]: d.values[yname] / sy, LINE[2]: 1.0,
            LINE[3]: 0.7}  # fmt: skip
    return {n: line[n] for n in cs.ps.parameters}


def _line_seeds(cs, gs, win: Window, settings, what: str) -> tuple[list, list[dict]]:
    """Real points of the curve on LINES vertical and LINES horizontal lines of the window."""
    seeds, lines = [], []
    specs = _line_specs(win)
    report = Progress(f"{what}: the witness set to the seed lines", len(specs), "lines")
    for x0, y0, dx, dy in specs:
        target = {LINE[0]: x0, LINE[1]: y0, LINE[2]: dx, LINE[3]: dy}
        # Straight from the witness set, no fallback: on a real line some paths go to infinity
        # (on every line tried, axis-parallel or not), which is expected, not a failure. A seed
        # is a point of order one, so a path that diverges in double precision is not retracked.
        ends, rep = track(cs.ps, gs, target, settings, retrack_diverged=False)
        pts = ends.points
        found = 0
        for p in pts[is_real(pts)].real if len(pts) else []:
            t = p[-1]
            if -1e-9 <= t <= 1 + 1e-9:
                seeds.append(np.concatenate([p[:-1], [x0 + t * dx, y0 + t * dy]]))
                found += 1
        lines.append({"line": [x0, y0, dx, dy], "finite": rep.finite, "infinite": rep.infinite,
                      "lost": rep.lost, "real_in_window": found})  # fmt: skip
        report.update(1, note=f"{len(seeds)} seeds")
    report.close()
    return seeds, lines


def _find(
    fw: Framework,
    cs: CurveSystem,
    axes,
    settings,
    seeds: str,
    work: _Work,
    branches: dict | None = None,
) -> tuple:
    """Seeds on lines (by the chosen route), and every curve through a seed traced once
    (`branches`: the sweep route's, shared by the curve systems, fold_sweep.sweep_seeds;
    none given: this system's own)."""
    branches = {} if branches is None else branches
    (xname, xrange), (yname, yrange) = axes
    t0 = time.perf_counter()
    sx, sy = cs.scales
    nz = len(cs.variables)
    win = Window(nz, nz + 1, (xrange[0] / sx, yrange[0] / sy), (xrange[1] / sx, yrange[1] / sy),
                 (sx, sy))  # fmt: skip
    groups = _groups(cs, settings.seed)
    paths = bezout_number(_degrees(cs, settings.seed, groups), [len(g) for g in groups])
    route = seeds if seeds != "auto" else "witness" if paths <= WITNESS_MAX_PATHS else "sweep"
    if seeds == "auto" and choose(fw, settings).real:
        route = "sweep"  # each crossing's real equilibria by the real route: no witness set
    if cs.kind == "relaxed":
        route = "witness"  # module docstring: a sweep cannot tell relaxed folds from others
    info: dict = {"seed_route": route, "witness_paths": paths}
    how = f"a witness set of {paths} paths" if route == "witness" else "a sweep of the lines"
    say(f"{work.what}: seeds on {2 * LINES} lines by {how}")
    if route == "witness":
        centre = _centre(cs, fw, xname, yname)
        gs = generic_set(cs.ps, settings.seed, centre=centre, groups=groups)
        info.update(generic_set=gs.summary(), generic_seconds=time.perf_counter() - t0)
        t1 = time.perf_counter()
        seeds_found, lines = _line_seeds(cs, gs, win, settings, work.what)
    else:
        t1 = time.perf_counter()
        specs = _line_specs(win)
        seeds_found, lines = sweep_seeds(
            fw, cs, specs, (xname, yname), settings, work.run, work.what, work.batch, branches
        )
        info.update(sweep_points=lines[0]["points"])
    t2 = time.perf_counter()
    eqs = curve_equations(cs)
    traced, skipped = _trace_seeds(cs, eqs, seeds_found, win, work.what)
    info.update({
        "lines_seconds": t2 - t1, "trace_seconds": time.perf_counter() - t2,
        "seeds": len(seeds_found), "seeds_on_traced": skipped, "lines": lines,
        "ends": [list(c.ends) for c in traced],
        "lost_paths": int(sum(ln.get("lost", 0) for ln in lines)),
        "undecided_boxes": int(sum(ln.get("undecided_boxes", 0) for ln in lines)),
        "unrefined_turns": int(sum(ln.get("unrefined", 0) for ln in lines)),
    })  # fmt: skip
    return _Curves(cs, traced, win, eqs), info


def _trace_seeds(cs: CurveSystem, eqs, seeds: list, win: Window, what: str) -> tuple[list, int]:
    """Every curve through a seed traced once (a seed on a curve already traced is skipped):
    the curves, and how many seeds were skipped."""
    traced, skipped = [], 0
    lengths = [k for k, v in enumerate(cs.variables) if v.startswith("d_")]
    with Progress(f"{what}: tracing curves from seeds", len(seeds), "seeds",
                  heartbeat=True) as report:  # fmt: skip
        for z in seeds:
            report.update(1, note=f"{len(traced)} curves")
            if (z[lengths] <= 0).any():
                continue  # a length never changes sign on a curve (L0 > 0): never physical
            if any(_on(c.points, z, win, len(cs.variables)) for c in traced):
                skipped += 1
                continue
            traced.append(trace(eqs, z, win, SPACING, HMAX, long_enough(cs), relative=True))
    return traced, skipped


def _line_specs(win: Window) -> list[tuple[float, float, float, float]]:
    """(x0, y0, dx, dy) of the LINES vertical and LINES horizontal seed lines, edges included."""
    (xl, yl), (xh, yh) = win.lo, win.hi
    specs = [(xv, yl, 0.0, yh - yl) for xv in np.linspace(xl, xh, LINES)]
    return specs + [(xl, yv, xh - xl, 0.0) for yv in np.linspace(yl, yh, LINES)]


def _groups(cs: CurveSystem, seed: int) -> list[list[str]]:
    """The witness set's variable groups: the equilibrium system's plus tline, merged where that
    lowers the path count (the degree structure read at random complex line coefficients)."""
    return fewest_paths_groups(_at_random_line(cs, seed), cs.groups)


def _at_random_line(cs: CurveSystem, seed: int):
    rng = np.random.default_rng(seed)
    line = rng.normal(size=len(cs.ps.parameters)) + 1j * rng.normal(size=len(cs.ps.parameters))
    return cs.ps.instantiate(line)


def _degrees(cs: CurveSystem, seed: int, groups: list[list[str]]) -> np.ndarray:
    """The witness system's degree in each group, equation by equation."""
    return group_degrees(_at_random_line(cs, seed), groups)


def _on(points: np.ndarray, z: np.ndarray, win: Window, nx: int) -> bool:
    """Whether z lies on a traced polyline: near one of its points in the plane and in X (within
    three steps, which are relative: curve_trace.trace)."""
    near_xy = win.xy_distance(points, z) <= 3 * SPACING * win.diagonal
    step = HMAX * (1 + np.abs(points).max(axis=1))
    near_x = np.abs(points[:, :nx] - z[:nx]).max(axis=1) <= 3 * step
    return bool((near_xy & near_x).any())


def _solution_columns(fw: Framework) -> list[str]:
    """The solutions.csv columns that describe a configuration (poses to energy)."""
    names = column_names(fw)
    return names[1 : names.index("energy") + 1]


def _empty(fw: Framework, xname: str, yname: str) -> pd.DataFrame:
    cols = [xname, yname, *_solution_columns(fw), "curve_id", "arc", "kind", "physical",
            "changes_stable_count", "taut", "null_cubic"]  # fmt: skip
    return pd.DataFrame({c: [] for c in cols})


def _classify(fw: Framework, cs: CurveSystem, z: np.ndarray, xname: str, yname: str) -> dict:
    """One point's solution columns, physical, and changes_stable_count (None: an artefact, a
    singular Jacobian with a regular reduced Hessian)."""
    sx, sy = cs.scales
    nx = len(cs.variables)
    x, y = z[nx] * sx, z[nx + 1] * sy
    fwp = fw.replace(**{xname: x, yname: y})
    fs = framework_system(fwp, cs.taut)
    ends = Endpoints.from_records(fs.ps.variables, [{"coords": z[:nx].astype(complex)}])
    cols = framework_columns(fwp, fs, ends, units(fw), Tolerances())
    row = {xname: x, yname: y, **{c: cols[c][0] for c in _solution_columns(fw)}}
    row["physical"] = bool(cols["physical"][0])
    index, zero = _index(fs, fwp, z[:nx])
    if cs.kind in ("fold", "relaxed"):
        if not zero:
            return {**row, "changes_stable_count": None}
        row["changes_stable_count"] = index == 0  # a minimum meets an index-1 saddle
    else:
        # With the cable slack the Hessian loses the cable's positive rank-one term, so its index
        # is the same or one more. Same index (same sign of the determinant): the equilibrium
        # passes from one taut set to the other and stays as stable as it was. One more: by the
        # degree, the two branches end together here (a nonsmooth fold); a stable state is lost
        # exactly when the taut branch is a minimum.
        slack = tuple(c for c in cs.taut if c != cs.cable)
        fss = framework_system(fwp, slack)
        X = dict(zip(fs.ps.variables, z[:nx], strict=True))
        index_s, _ = _index(fss, fwp, np.array([X[v] for v in fss.ps.variables]))
        row["changes_stable_count"] = index == 0 and index_s >= 1
    return row


def _index(fs, fwp: Framework, X: np.ndarray) -> tuple[int, bool]:
    """The reduced Hessian's index (eigenvalues < 0, the one nearest 0 left out) and whether
    that one is 0 (within 1e-6 of the largest |eigenvalue|)."""
    P = np.array(list(normalized_slots(fwp).values()))
    H, G = local_hessian(fs, X[None, :].real, P)
    eig = reduced_eigh(H[0], G[0])[0]
    if not len(eig):
        return 0, False
    k = int(np.argmin(np.abs(eig)))
    zero = abs(eig[k]) <= 1e-6 * max(1.0, float(np.abs(eig).max()))
    rest = np.delete(eig, k) if zero else eig
    return int((rest < 0).sum()), bool(zero)


def _null_cubics(cs: CurveSystem, pts: np.ndarray) -> np.ndarray:
    """|w . F_XX[v, v]| / |F_XX[v, v]| at fold points, the rows of pts (v, w: unit right and
    left null vectors of J_X F; F_XX[v, v] by central differences): zero at a cusp, not at an
    ordinary fold. Vectorised over the points, NULL_BATCH at a time (memory: terms x points)."""
    n = len(cs.variables)
    out = []
    for batch in np.array_split(pts, -(-len(pts) // NULL_BATCH)):
        J = cs.trace.jacobian(batch).real[:, :n, :n]
        u, _, vt = np.linalg.svd(J)
        v, w = vt[:, -1, :], u[:, :, -1]
        h = 1e-5
        shift = np.concatenate([h * v, np.zeros((len(batch), 2))], axis=1)
        Jpm = cs.trace.jacobian(np.concatenate([batch + shift, batch - shift])).real
        q = np.einsum("kij,kj->ki", Jpm[: len(batch), :n, :n] - Jpm[len(batch) :, :n, :n], v)
        q /= 2 * h
        out.append(np.abs((w * q).sum(axis=1)) / np.maximum(np.linalg.norm(q, axis=1), 1e-300))
    return np.concatenate(out) if out else np.zeros(0)


def _rows(fw: Framework, curves: _Curves, names, next_id: int, work: _Work) -> tuple:
    """The table of one curve system's curves (physical points only, a curve split where it
    stops being physical), the next free curve_id, and counts for the record."""
    cs, win = curves.cs, curves.window
    kind = "cable_switch" if cs.kind == "switch" else "fold"  # a relaxed fold is a fold
    parts = [np.array_split(c.points, -(-len(c.points) // CHUNK)) for c in curves.traced]
    tasks = [(fw, cs, pts, names) for ps in parts for pts in ps]
    unit = f"chunks of {CHUNK} points"
    done = iter(work(_classify_points, tasks, "classifying the points", unit))
    rows, artefacts, cusps = [], 0, 0
    for curve, ps in zip(curves.traced, parts, strict=True):
        classified = [r for _ in ps for r in next(done)]
        artefacts += sum(r["changes_stable_count"] is None for r in classified)
        keep = np.array([r["physical"] and r["changes_stable_count"] is not None
                         for r in classified])  # fmt: skip
        for piece in _runs(keep):
            pts = curve.points[piece]
            arc = np.concatenate([[0.0], np.cumsum(win.xy_distance(pts[1:], pts[:-1]))])
            arc /= win.diagonal
            for k, i in enumerate(piece):
                rows.append({**classified[i], "curve_id": next_id, "arc": arc[k], "kind": kind})
            if cs.kind == "fold":
                for k, z in _cusps(curves.eqs, pts, win):
                    row = _classify_points((fw, cs, z[None, :], names))[0]
                    if row["physical"]:
                        cusps += 1
                        rows.append({**row, "curve_id": next_id, "arc": arc[k], "kind": "cusp"})
            next_id += 1
    frame = pd.DataFrame(rows) if rows else _empty(fw, *names)
    if "null_cubic" not in frame:
        frame["null_cubic"] = np.nan
    frame["taut"] = " ".join(cs.taut) or "none"
    about = {"curves_traced": len(curves.traced), "points": len(frame), "artefacts": artefacts,
             "cusps": cusps}  # fmt: skip
    return frame[list(_empty(fw, *names).columns)], next_id, about


def _classify_points(task) -> list[dict]:
    """_classify of each point (rows of pts), with null_cubic on a fold curve (a task: it may
    run in a worker process)."""
    fw, cs, pts, (xname, yname) = task
    rows = [_classify(fw, cs, z, xname, yname) for z in pts]
    if cs.kind == "fold":
        for r, c in zip(rows, _null_cubics(cs, pts), strict=True):
            r["null_cubic"] = float(c)
    return rows


def _runs(keep: np.ndarray) -> list[np.ndarray]:
    """Maximal runs of consecutive True, as index arrays (of two points or more)."""
    idx = np.flatnonzero(keep)
    if not len(idx):
        return []
    parts = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1)
    return [p for p in parts if len(p) > 1]


def _cusps(eqs, pts: np.ndarray, win: Window, halvings: int = 50) -> list[tuple[int, np.ndarray]]:
    """(index, refined point) of each cusp of a polyline: where its image turns back (refined
    by `halvings` bisections, curve_trace.turning_point)."""
    xy = np.stack([pts[:, win.ix] * win.scale[0], pts[:, win.iy] * win.scale[1]], axis=1)
    seg = np.diff(xy, axis=0)
    norm = np.linalg.norm(seg, axis=1)
    out, k = [], 0
    while k < len(seg) - 1:
        a, b = seg[k], seg[k + 1]
        if norm[k] > 0 and norm[k + 1] > 0 and a @ b < TURN_COS * norm[k] * norm[k + 1]:
            z = turning_point(eqs, pts[k], pts[k + 2], a / norm[k], win, halvings)
            if z is not None:
                out.append((k + 1, z))
            k += 2
        else:
            k += 1
    return out
