"""Batch parameter sweeps: every point by parameter homotopy, in parallel, resumable.

Each point's rows are written to `points/NNNNN.csv` atomically as soon as the point is solved, so a
killed sweep loses at most the points in flight and never writes a partial or duplicate row; a
rerun skips the points whose file exists. `sweep.csv` is assembled from them at the end.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from .geometry import PARAM_NAMES, ParameterError, Params
from .results import write_csv, write_json

SPEC_FILE = "sweep.json"


@dataclass(frozen=True)
class SweepSpec:
    """What to sweep: one or two parameters over ranges, the rest fixed, and the solver seed."""

    base: dict[str, float]
    param: str
    start: float
    stop: float
    points: int
    param2: str | None = None
    start2: float | None = None
    stop2: float | None = None
    points2: int | None = None
    seed: int = 1

    def __post_init__(self) -> None:
        for name in (self.param, self.param2):
            if name is not None and name not in PARAM_NAMES:
                raise ParameterError(
                    f"--param {name!r}: unknown parameter (known: {' '.join(PARAM_NAMES)})"
                )
        if self.points < 1:
            raise ParameterError(f"--points {self.points}: must be at least 1")
        if self.param2 is not None:
            if None in (self.start2, self.stop2, self.points2) or self.points2 < 1:
                raise ParameterError("--param2 needs --from2, --to2 and --points2 >= 1")
            if self.param2 == self.param:
                raise ParameterError(f"--param2 {self.param2!r}: same as --param")

    @property
    def columns(self) -> list[str]:
        """The swept parameters' names, in order."""
        return [self.param] + ([self.param2] if self.param2 else [])

    def grid(self) -> list[dict[str, float]]:
        """Every point's swept values, point index = list index (param2 varies fastest)."""
        a = np.linspace(self.start, self.stop, self.points)
        if self.param2 is None:
            return [{self.param: float(v)} for v in a]
        b = np.linspace(self.start2, self.stop2, self.points2)
        return [{self.param: float(u), self.param2: float(w)} for u in a for w in b]

    def key(self) -> str:
        """Content hash: the same request maps to the same folder (and so resumes)."""
        from . import __version__

        blob = json.dumps({**asdict(self), "version": __version__}, sort_keys=True)
        return hashlib.sha256(blob.encode()).hexdigest()[:10]

    def folder_name(self) -> str:
        """A readable, unique folder name."""
        rng = f"{self.param}-{self.start:g}-{self.stop:g}-{self.points}"
        if self.param2:
            rng += f"-{self.param2}-{self.start2:g}-{self.stop2:g}-{self.points2}"
        return f"sweep-{rng}-{self.key()}"


def solve_point(
    base: dict[str, float], values: dict[str, float], seed: int, threads: int | None = 1
) -> pd.DataFrame:
    """All finite solutions at one point, classified, with how they were obtained."""
    from .compiled import parametric_system
    from .homotopy import solve_target
    from .stability import classify

    params = Params(**{**base, **values})
    ps = parametric_system(params.zfl)
    endpoints, info = solve_target(ps, params, seed, threads=threads)
    table = classify(params, endpoints, ps.variables)
    table.insert(0, "point", -1)
    for k, name in enumerate(values):
        table.insert(1 + k, name, values[name])
    table["method"] = info["method"]
    table["lost_paths"] = info["lost"]
    return table


def _point_task(args: tuple) -> tuple[int, pd.DataFrame, float]:
    index, base, values, seed = args
    start = time.perf_counter()
    table = solve_point(base, values, seed, threads=1)
    table["point"] = index
    return index, table, time.perf_counter() - start


def _point_file(folder: Path, index: int) -> Path:
    return folder / "points" / f"{index:05d}.csv"


def pending_points(spec: SweepSpec, folder: Path) -> list[int]:
    """Indices of the grid points that have no finished point file yet."""
    return [i for i in range(len(spec.grid())) if not _point_file(folder, i).is_file()]


def prepare(spec: SweepSpec, root: Path, resume: Path | None = None) -> Path:
    """The sweep folder: `resume` (checked against spec), or root/<name> for this request."""
    folder = resume if resume is not None else root / spec.folder_name()
    spec_path = folder / SPEC_FILE
    if spec_path.is_file():
        saved = json.loads(spec_path.read_text())
        if resume is None and saved.get("spec") != asdict(spec):
            raise ParameterError(f"{folder}: holds a different sweep; use another --out")
    else:
        if resume is not None:
            raise ParameterError(f"--resume {str(resume)!r}: no {SPEC_FILE} there")
        (folder / "points").mkdir(parents=True, exist_ok=True)
        write_json(spec_path, {"spec": asdict(spec), "key": spec.key()})
    (folder / "points").mkdir(parents=True, exist_ok=True)
    return folder


def load_spec(folder: Path) -> SweepSpec:
    """The spec a sweep folder was made for."""
    path = folder / SPEC_FILE
    if not path.is_file():
        raise ParameterError(f"--resume {str(folder)!r}: no {SPEC_FILE} there")
    return SweepSpec(**json.loads(path.read_text())["spec"])


def warm_generic_sets(spec: SweepSpec) -> None:
    """Solve (or load) the generic sets every point needs, once, before workers start."""
    from .compiled import parametric_system
    from .homotopy import generic_set

    structures = {Params(**{**spec.base, **v}).zfl for v in spec.grid()}
    for zfl in sorted(structures):
        generic_set(parametric_system(zfl), spec.seed)


def run_points(
    spec: SweepSpec,
    folder: Path,
    workers: int = 1,
    scheduler: str | None = None,
    progress: Callable[[int, int, int], None] | None = None,
) -> dict:
    """Solve every pending point (local processes, or a Dask cluster) and store each atomically."""
    grid = spec.grid()
    todo = pending_points(spec, folder)
    tasks = [(i, spec.base, grid[i], spec.seed) for i in todo]
    stats = {
        "points": len(grid),
        "skipped": len(grid) - len(todo),
        "solved": 0,
        "lost_paths": 0,
        "seconds": 0.0,
    }
    if not tasks:
        return stats
    warm_generic_sets(spec)
    start = time.perf_counter()
    for index, table, _ in _execute(tasks, workers, scheduler):
        write_csv(_point_file(folder, index), table)
        stats["solved"] += 1
        stats["lost_paths"] += int(table["lost_paths"].max()) if len(table) else 0
        if progress:
            progress(stats["solved"], len(tasks), stats["lost_paths"])
    stats["seconds"] = time.perf_counter() - start
    return stats


def _execute(tasks: list[tuple], workers: int, scheduler: str | None) -> Iterable[tuple]:
    if scheduler is not None:
        from distributed import Client, as_completed

        with Client(scheduler) as client:
            futures = client.map(_point_task, tasks, pure=False)
            for fut in as_completed(futures):
                yield fut.result()
        return
    if workers <= 1:
        for t in tasks:
            yield _point_task(t)
        return
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor, as_completed

    ctx = mp.get_context("spawn")  # the bertini module is not fork-safe with its threads
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as pool:
        futures = [pool.submit(_point_task, t) for t in tasks]
        for fut in as_completed(futures):
            yield fut.result()


def assemble(spec: SweepSpec, folder: Path) -> pd.DataFrame:
    """All point files as one table, in grid order (errors if a point is missing)."""
    missing = pending_points(spec, folder)
    if missing:
        raise RuntimeError(f"{folder}: {len(missing)} points not solved yet (first {missing[0]})")
    frames = [
        pd.read_csv(_point_file(folder, i), keep_default_na=True) for i in range(len(spec.grid()))
    ]
    table = pd.concat(frames, ignore_index=True)
    return table


def default_workers() -> int:
    """One worker per core."""
    return max(
        1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    )


def finish(
    spec: SweepSpec,
    folder: Path,
    stats: dict,
    plots: bool = True,
    show_all: bool = False,
    workers: int = 1,
    scheduler: str | None = None,
    command: list[str] | None = None,
) -> dict:
    """Assemble sweep.csv (with branches for 1-D sweeps), events.csv, figures and run.json."""
    from . import engine

    t0 = time.perf_counter()
    table = assemble(spec, folder)
    events = pd.DataFrame(columns=["kind", "branches", "value", "gamma1_deg", "gamma2_deg"])
    if spec.param2 is None:
        from .branches import assign_branches, find_events

        table = assign_branches(table, spec.param)
        events = find_events(table, spec.param, Params(**spec.base), spec.seed)
    write_csv(folder / "sweep.csv", table)
    write_csv(folder / "events.csv", events)
    figures: list[str] = []
    if plots:
        from .plot import plot_bifurcation, plot_sweep_counts

        if spec.param2 is None:
            paths = plot_bifurcation(
                table, spec.param, folder / "bifurcation", show_all=show_all, events=events
            )
        else:
            paths = plot_sweep_counts(table, spec.columns, folder / "counts")
        figures = [p.name for p in paths]
    record = {
        "spec": asdict(spec),
        "key": spec.key(),
        "command": command,
        "points": len(spec.grid()),
        "rows": len(table),
        "events": len(events),
        "stats": stats,
        "workers": workers,
        "scheduler": scheduler,
        "methods": table["method"].value_counts().to_dict() if len(table) else {},
        "lost_paths": int(table["lost_paths"].sum()) if len(table) else 0,
        "versions": engine.python_versions(),
        "figures": figures,
        "timings": {"solve": stats["seconds"], "finish": time.perf_counter() - t0},
    }
    write_json(folder / "run.json", record)
    return record
