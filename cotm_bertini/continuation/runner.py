"""Run a sweep: every point solved by `solve_point`, in parallel, each stored atomically, resumable.

Each point's rows are written to `points/NNNNN.csv` atomically as soon as the point is solved, so a
killed sweep loses at most the points in flight and never writes a partial or duplicate row; a
rerun skips the points whose file exists. `sweep.csv` is assembled from them at the end.
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable, Iterable
from pathlib import Path

import pandas as pd

from ..analysis.classify import read_table
from ..errors import ParameterError
from ..fs import write_csv, write_json
from ..params import Params
from ..point import solve_point
from ..settings import Settings
from .spec import SweepSpec

SPEC_FILE = "sweep.json"


def point_table(params: Params, settings: Settings, values: dict[str, float]) -> pd.DataFrame:
    """All finite solutions at one point, classified, with how they were obtained."""
    solved = solve_point(params, settings)
    table = solved.table.copy()
    table.insert(0, "point", -1)
    for k, name in enumerate(values):
        table.insert(1 + k, name, values[name])
    homotopy = solved.details.get("homotopy")
    table["method"] = homotopy["method"] if homotopy else f"cli ({solved.engine['flavour']})"
    lost = solved.counts["lost_paths"]
    table["lost_paths"] = pd.array([lost] * len(table), dtype="Int64")
    table["status"] = solved.status
    return table


def _point_task(args: tuple) -> tuple[int, pd.DataFrame, float]:
    index, spec_json = args
    spec = SweepSpec.from_json(spec_json)
    start = time.perf_counter()
    table = point_table(spec.params_at(index), point_settings(spec), spec.grid()[index])
    table["point"] = index
    return index, table, time.perf_counter() - start


def point_settings(spec: SweepSpec) -> Settings:
    """The settings of each point: the sweep's, one thread a point unless threads were given."""
    settings = Settings(**spec.settings)
    return settings if settings.threads is not None else settings.replace(threads=1)


def point_file(folder: Path, index: int) -> Path:
    """Where point `index` is stored."""
    return folder / "points" / f"{index:05d}.csv"


def pending_points(spec: SweepSpec, folder: Path) -> list[int]:
    """Indices of the grid points that have no finished point file yet."""
    return [i for i in range(len(spec.grid())) if not point_file(folder, i).is_file()]


def prepare(spec: SweepSpec, folder: Path) -> Path:
    """The sweep folder for `spec`: created, or an earlier one for the same spec (resumed)."""
    if folder.exists() and not folder.is_dir():
        raise ParameterError(f"--out {str(folder)!r}: exists and is not a directory")
    spec_path = folder / SPEC_FILE
    if spec_path.is_file():
        saved = json.loads(spec_path.read_text())
        if saved.get("spec") != spec.to_json():
            raise ParameterError(f"{folder}: holds a different sweep; use another --out")
    else:
        (folder / "points").mkdir(parents=True, exist_ok=True)
        write_json(spec_path, {"spec": spec.to_json(), "key": spec.key()})
    (folder / "points").mkdir(parents=True, exist_ok=True)
    return folder


def load_spec(folder: Path) -> SweepSpec:
    """The spec a sweep folder was made for."""
    path = Path(folder) / SPEC_FILE
    if not path.is_file():
        raise ParameterError(f"--resume {str(folder)!r}: no {SPEC_FILE} there")
    return SweepSpec.from_json(json.loads(path.read_text())["spec"])


def warm_generic_sets(spec: SweepSpec) -> None:
    """Solve (or load) the generic sets every point needs, once, before workers start."""
    if Settings(**spec.settings).engine != "homotopy":
        return
    from ..backends.homotopy import generic_set
    from ..model.compiled import parametric_system

    structures = {spec.params_at(i).zfl for i in range(len(spec.grid()))}
    for zfl in sorted(structures):
        generic_set(parametric_system(zfl), spec.settings["seed"])


def run_points(
    spec: SweepSpec,
    folder: Path,
    workers: int = 1,
    scheduler: str | None = None,
    progress: Callable[[int, int, int], None] | None = None,
) -> dict:
    """Solve every pending point (local processes, or a Dask cluster) and store each atomically."""
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ParameterError(f"--workers {workers!r}: must be an integer >= 1")
    todo = pending_points(spec, folder)
    grid = spec.grid()
    stats = {"points": len(grid), "skipped": len(grid) - len(todo), "solved": 0, "lost_paths": 0}
    stats["seconds"] = 0.0
    if not todo:
        return stats
    warm_generic_sets(spec)
    start = time.perf_counter()
    tasks = [(i, spec.to_json()) for i in todo]
    for index, table, _ in _execute(tasks, workers, scheduler):
        write_csv(point_file(folder, index), table)
        stats["solved"] += 1
        lost = table["lost_paths"].dropna()
        stats["lost_paths"] += int(lost.max()) if len(lost) else 0
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
    if workers == 1:
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
    frames = [read_table(point_file(folder, i)) for i in range(len(spec.grid()))]
    return pd.concat(frames, ignore_index=True)


def default_workers() -> int:
    """One worker per core."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return max(1, os.cpu_count() or 1)
