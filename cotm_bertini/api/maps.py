"""Design maps over two parameters (cb.design_map): fold curves, stable-count regions. The
paper's mechanism over (L01, L02), or a framework (cb.Framework) over any two of its
parameters; one DesignMap for both."""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from ..catastrophe.maps import (
    FREE_LENGTHS,
    counts_on_grid,
    explained,
    fold_points,
    grid_values,
    map_axes,
)
from ..columns import reference
from ..fs import atomic_write_text, link_tree, new_folder, write_csv, write_json
from ..params import Params
from ..progress import duration, say
from ..settings import Settings

SWEEP_FOLDER = "sweep"  # in a saved map: the 2-D sweep behind regions.csv


@dataclass(frozen=True)
class DesignMap:
    """Fold points inside the window (`folds`), the grid of counts (`regions`, columns named
    as the two `axes`), timings; the 2-D sweep that counted them is in
    `record["sweep_folder"]`. `params`: the paper's Params or the cb.Framework mapped."""

    params: object
    folds: pd.DataFrame
    regions: pd.DataFrame
    record: dict
    axes: tuple[str, str] = FREE_LENGTHS

    @property
    def cusps(self) -> pd.DataFrame:
        """The cusp rows of `folds`."""
        return self.folds[self.folds.kind == "cusp"].reset_index(drop=True)

    @property
    def status(self) -> str:
        """ok, or incomplete (a sweep point failed a check, or a count change is unexplained)."""
        return self.record["status"]

    def plot(self, path: str | Path) -> list[Path]:
        """map.png/svg: stable counts coloured, fold curves on top (the paper's cases marked
        on the paper's map)."""
        from ..plot.design_map import plot_map

        return plot_map(self.params, self.regions, self.folds, path, self.axes)

    def explore(self, path: str | Path) -> Path:
        """explore.html: the map in a browser, offline; a click on a grid point draws its
        equilibria (from the map's 2-D sweep)."""
        from ..plot.explore_pages import map_page

        return map_page(self, path)

    def save(self, folder: str | Path, plots: bool = True, html: bool = False) -> Path:
        """folds.csv, regions.csv, columns.md, run.json [, map.png/svg] [, explore.html] and
        sweep/ (the 2-D sweep behind regions.csv, hard-linked from where it was solved) in a
        new folder, built under a hidden name and renamed when complete."""
        source = Path(self.record["sweep_folder"])
        tables = ("folds", "regions") if isinstance(self.params, Params) else MAP_TABLES
        with new_folder(folder) as work:
            write_csv(work / "folds.csv", self.folds)
            write_csv(work / "regions.csv", self.regions)
            atomic_write_text(work / "columns.md", reference(*tables))
            if plots:
                self.plot(work / "map")
            if html:
                self.explore(work / "explore.html")
            link_tree(source, work / SWEEP_FOLDER)
            record = {**self.record, "sweep_folder": SWEEP_FOLDER, "sweep_solved_in": str(source)}
            write_json(work / "run.json", record)
        return Path(folder)


MAP_TABLES = ("framework_folds", "framework_regions")  # columns.md of a framework's map


def design_map(
    model,
    *axes,
    points: int | None = None,
    settings: Settings | None = None,
    workers: int = 1,
    progress: bool = False,
    l01: tuple[float, float] | None = None,
    l02: tuple[float, float] | None = None,
    grid: str = "auto",
) -> DesignMap:
    """Fold curves in the window, and the number of physical and stable equilibria on a
    points x points grid of it (by a 2-D sweep: parameter homotopies).

    A framework: design_map(fw, "x", (-0.6, 0.8), "y", (-0.8, 0.2), points=101), any two of
    its parameters. The paper's mechanism: design_map(params, l01=(0, 14), l02=(0, 14),
    points=101) (or positionally design_map(params, (0, 14), (0, 14), 101)). `grid`: "search"
    (a 2-D sweep), "continuation" (catastrophe/chart_map.py) or "auto" (grid_route)."""
    from ..backends.pools import check_workers
    from ..continuation.spec import check_grid
    from ..routes.choice import check_route
    from .sweeps import sweep

    (x, xr), (y, yr), points = map_axes(model, axes, l01, l02, points)
    for a in xr:  # the window's corners validated before any work is announced or done
        for b in yr:
            model.replace(**{x: a, y: b})
    xs, ys = grid_values(*xr, points), grid_values(*yr, points)
    check_grid(model, x, tuple(map(float, xs)), y, tuple(map(float, ys)))  # every point too
    check_workers(workers)  # before any process starts
    check_route(model, settings or Settings(), "map")
    grid = grid_route(model, grid, settings or Settings())
    key = _map_key(model, (x, xr), (y, yr), points, settings, grid)
    made = _made_before(model, key, (x, y))
    if made is not None:
        return made
    if grid == "continuation":
        return _chart_design_map(model, (x, xr, xs), (y, yr, ys), settings, workers, key)
    t0 = time.perf_counter()
    job = (model, x, xr, y, yr, settings, workers)
    aside = _FoldsAside(job) if isinstance(model, Params) and workers > 1 else None
    after = _folds_after(model, settings or Settings())
    window = f"{x} {xr[0]:g}..{xr[1]:g}, {y} {yr[0]:g}..{yr[1]:g}"
    if after:
        say(
            f"map: the stable states searched at each point of a {points} x {points} grid over "
            f"{window}; then the fold curves where a minimum vanishes between neighbours"
        )
    elif aside is None:
        say(f"map: fold curves in the window {window}")
        folds, fold_record, t_folds = _timed_folds(job)
        say(f"map: {len(folds)} fold points in {duration(t_folds)}; now the stable counts on a "
            f"{points} x {points} grid (a 2-D sweep)")  # fmt: skip
    else:
        say(f"map: fold curves in the window {window}, and beside them the stable counts on a "
            f"{points} x {points} grid")  # fmt: skip
    t1 = time.perf_counter()
    try:
        sw = sweep(model, x, xs, settings, param2=y, values2=ys, workers=workers,
                   progress=progress)  # fmt: skip
        if aside is not None:
            folds, fold_record, t_folds = aside.result()
        if after:
            folds, fold_record, t_folds = _timed_edge_folds(model, sw.columns, (x, xs), (y, ys))
    finally:
        if aside is not None:
            aside.close()
    regions = counts_on_grid(sw.columns, xs, ys, (x, y))
    t_regions = time.perf_counter() - t1 - (t_folds if after else 0.0)
    if after:
        say(f"map: {len(folds)} fold points traced in {duration(t_folds)} from "
            f"{fold_record['seeds']} seeds on the grid's edges")  # fmt: skip
    if aside is not None:
        say(f"map: {len(folds)} fold points in {duration(t_folds)} (beside the sweep)")
    record = _map_record(model, ((x, xr), (y, yr)), points, (folds, fold_record), sw, regions)
    record["timings"] = {"folds": t_folds, "regions": t_regions, **record["timings"],
                         "total": time.perf_counter() - t0}  # fmt: skip
    _keep(key, folds, regions, record)
    return DesignMap(model, folds, regions, record, (x, y))


def _map_record(model, axes: tuple, points: int, folds: tuple, sw, regions) -> dict:
    """A searched map's record (run.json): window, fold counts, the sweep behind it, and for a
    framework the completeness check (timed)."""
    (x, xr), (y, yr) = axes
    folds, fold_record = folds
    t0 = time.perf_counter()
    record = {
        "params": model.as_dict(), "window": {x: list(xr), y: list(yr)}, "axes": [x, y],
        "points": points, "fold_points": len(folds),
        "fold_curves": int(folds.curve_id[folds.curve_id >= 0].nunique()),
        "cusps": int((folds.kind == "cusp").sum()), "timings": {},
        "sweep_folder": str(sw.folder), "sweep_status": sw.status, "command": sys.argv[:],
        "reused": False,
    }  # fmt: skip
    if isinstance(model, Params):
        record.update(certificate=fold_record, status=sw.status)
    else:
        record.update(framework=model.name, fold_record=fold_record)
        record.update(explained(regions, folds, (x, y), sw.status))
        record["timings"]["check"] = time.perf_counter() - t0
    return record


GRIDS = ("auto", "search", "continuation")


def grid_route(model, grid: str, settings: Settings) -> str:
    """How the map's grid is made: "search" (every grid point solved), "continuation" (a
    framework on the real route: anchors searched, equilibria followed in chart angles), "auto"
    (continuation for a product of spheres, whose fold systems sympy cannot expand; a search
    of every point where only the stable equilibria are asked for); or a one-line refusal."""
    from ..boxsearch.real_route import covers
    from ..errors import ParameterError
    from ..routes import choose

    if grid not in GRIDS:
        raise ParameterError(f"grid = {grid!r}: not a grid route ({', '.join(GRIDS)})")
    real = not isinstance(model, Params) and choose(model, settings).real
    real = real and _followed(model)
    if grid == "continuation" and not real:
        raise ParameterError("grid = 'continuation': only for a framework on the real route "
                             "(a torus of body angles or a product of spheres)")  # fmt: skip
    if grid == "continuation" and settings.only != "all":
        raise ParameterError(
            f"grid = 'continuation' with only = {settings.only!r}: continuation follows every "
            "equilibrium from the anchors; the stable ones alone are proved at every grid point "
            "by grid = 'search'"
        )
    if grid == "auto" and settings.only != "all":
        return "search"
    if grid == "auto":
        return "continuation" if real and covers(model) == "" and model.dim == 3 else "search"
    return grid


def _followed(model) -> bool:
    """Whether continuation in chart angles follows the framework's equilibria: a torus of body
    angles or a product of spheres (not yet a loop's curve nor free nodes' coordinates)."""
    from ..boxsearch.free_nodes import free_nodes_only
    from ..model.framework.structure import layout

    return not layout(model).closing_pins and bool(free_nodes_only(model))


def _chart_design_map(model, xa: tuple, ya: tuple, settings, workers: int, key: str):
    """design_map by continuation in chart angles (catastrophe/chart_map.py): its grid rows
    written as a 2-D sweep's table (sweep.csv) in the cache, the map's record with the
    completeness test; status incomplete where a grid point was not searched."""
    from ..catastrophe.chart_map import chart_map
    from ..fs import cache_root

    (x, xr, xs), (y, yr, ys) = xa, ya
    t0 = time.perf_counter()
    say(f"map: {x} {xr[0]:g}..{xr[1]:g}, {y} {yr[0]:g}..{yr[1]:g} by continuation in chart angles")
    cm = chart_map(model, x, xs, y, ys, settings or Settings(), workers)
    table = cm.table
    regions = counts_on_grid({c: table[c].to_numpy() for c in ("point", "physical", "stable")},
                             xs, ys, (x, y))  # fmt: skip
    folder = cache_root() / "chart_maps" / key
    if folder.exists():  # an identical map's grid whose entry was lost: made again
        import shutil

        shutil.rmtree(folder)
    with new_folder(folder) as work:
        write_csv(work / "sweep.csv", table)
    folds = cm.folds
    proved = cm.record["anchors_proved"] == len(xs) * len(ys)
    clean = (
        proved and not cm.record["propagation"]["lost_branches"] and not cm.record["morse_failed"]
    )
    record = {
        "params": model.as_dict(), "window": {x: list(xr), y: list(yr)}, "axes": [x, y],
        "points": len(xs), "fold_points": len(folds),
        "fold_curves": int(folds.curve_id[folds.curve_id >= 0].nunique()) if len(folds) else 0,
        "cusps": int((folds.kind == "cusp").sum()) if len(folds) else 0,
        "framework": model.name, "sweep_folder": str(folder), "command": sys.argv[:],
        "sweep_status": "ok" if clean else "incomplete", "chart": cm.record,
    }  # fmt: skip
    record.update(explained(regions, folds, (x, y), record["sweep_status"]))
    record["timings"] = {**cm.record["timings"], "total": time.perf_counter() - t0}
    record["reused"] = False
    _keep(key, folds, regions, record)
    return DesignMap(model, folds, regions, record, (x, y))


def _map_key(model, xa: tuple, ya: tuple, points: int, settings: Settings | None,
             grid: str = "search") -> str:  # fmt: skip
    """What a map depends on (the model, its window and grid, the settings, this package's
    code): two requests with one key make one map (the workers do not change it)."""
    from ..io.cache import request_key

    window = {"axes": [xa[0], ya[0]], "window": [list(xa[1]), list(ya[1])], "points": points,
              **({"grid": grid} if grid != "search" else {})}  # fmt: skip
    settings = (settings or Settings()).as_dict()
    return request_key({**model.key_fields(), "map": window}, settings, {})


def _map_entry(key: str) -> Path:
    from ..fs import cache_root

    return cache_root() / "maps" / f"{key}.pickle"


def _keep(key: str, folds: pd.DataFrame, regions: pd.DataFrame, record: dict) -> None:
    """The map kept in the cache under `key` (its 2-D sweep stays where it was solved)."""
    import pickle

    from ..fs import atomic_write_bytes

    entry = _map_entry(key)
    entry.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(entry, pickle.dumps((folds, regions, record)))


def _made_before(model, key: str, axes: tuple[str, str]) -> DesignMap | None:
    """The map of an identical earlier request, said and marked (record["reused"]), when it
    and its 2-D sweep are still in the cache; else None."""
    import pickle

    entry = _map_entry(key)
    if not entry.is_file():
        return None
    try:
        folds, regions, record = pickle.loads(entry.read_bytes())
    except Exception:  # a damaged entry is made again, not trusted
        entry.unlink(missing_ok=True)
        return None
    if not (Path(record["sweep_folder"]) / "sweep.csv").is_file():
        return None
    say(f"map: the same map (same model, window, grid and settings) was made before: reused "
        f"(made in {duration(record['timings']['total'])}; no new solve)")  # fmt: skip
    record = {**record, "reused": True, "command": sys.argv[:]}
    return DesignMap(model, folds, regions, record, axes)


def _folds_after(model, settings: Settings) -> bool:
    """The map's fold curves come from its grid (catastrophe/edge_folds.py), after it: a
    framework in space searched for its stable states alone (its fold systems are out of
    sympy's reach, and its grid holds no saddles to trace them from)."""
    return not isinstance(model, Params) and model.dim == 3 and settings.only == "stable"


def _timed_edge_folds(model, columns: dict, xa: tuple, ya: tuple) -> tuple:
    """stable_fold_curves of the grid, kept to the window, its record and seconds."""
    from ..catastrophe.edge_folds import stable_fold_curves

    start = time.perf_counter()
    (x, xs), (y, ys) = xa, ya
    folds, record = stable_fold_curves(model, columns, x, xs, y, ys)
    inside = folds[x].between(xs[0], xs[-1]) & folds[y].between(ys[0], ys[-1])
    return folds[inside].reset_index(drop=True), record, time.perf_counter() - start


def _timed_folds(job: tuple) -> tuple:
    """fold_points(*job) kept to its physical points in the window, its record and seconds."""
    start = time.perf_counter()
    folds, record = fold_points(*job)
    _, x, xr, y, yr = job[:5]
    inside = folds.physical.astype(bool) & folds[x].between(*xr) & folds[y].between(*yr)
    return folds[inside].reset_index(drop=True), record, time.perf_counter() - start


class _FoldsAside:
    """_timed_folds(job) in a process of its own, started now.

    The paper's fold curves are one process's numpy work (a framework's already use the
    `workers`): with two workers or more they run beside the 2-D sweep's set-up (its generic
    sets are solved in this process before its workers start), 3-4 s earlier on the 101 x 101
    map's wall clock."""

    def __init__(self, job: tuple):
        import multiprocessing as mp
        from concurrent.futures import ProcessPoolExecutor

        from ..backends.pools import start_method

        self.pool = ProcessPoolExecutor(max_workers=1, mp_context=mp.get_context(start_method()))
        self.future = self.pool.submit(_timed_folds, job)

    def result(self) -> tuple:
        """The folds, their record and seconds (raises what the fold curves raised)."""
        return self.future.result()

    def close(self) -> None:
        """Let the process go (after result(), or when the sweep failed: not waited for)."""
        self.pool.shutdown(wait=self.future.done(), cancel_futures=True)
