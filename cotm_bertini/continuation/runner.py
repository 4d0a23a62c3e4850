"""Run a sweep: every point solved by `solve_point`, in parallel, each stored atomically, resumable.

Each point's rows are written to `points/NNNNN.csv` atomically as soon as the point is solved, so a
killed sweep loses at most the points in flight and never writes a partial or duplicate row; a
rerun skips the points whose file exists. `sweep.csv` is assembled from them at the end.
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path

import numpy as np

from ..analysis.classify import read_table
from ..errors import ParameterError
from ..fs import atomic_write_text, columns_csv, write_json
from ..params import Params
from ..point import PointSolution, solve_point
from ..settings import Settings
from .spec import SweepSpec

SPEC_FILE = "sweep.json"


def point_columns(
    solved: PointSolution, values: dict[str, float], index: int = -1
) -> dict[str, np.ndarray]:
    """A point's rows as columns: point, the swept values, the solutions, how they were found."""
    cols = solved.columns
    n = len(cols["solution_id"])
    homotopy = solved.details.get("homotopy")
    method = homotopy["method"] if homotopy else f"cli ({solved.engine['flavour']})"
    lost = solved.counts["lost_paths"]
    out = {"point": np.full(n, index)}
    out.update({name: np.full(n, float(v)) for name, v in values.items()})
    out.update(cols)
    out["method"] = np.full(n, method, dtype=object)
    out["lost_paths"] = np.full(n, np.nan if lost is None else float(lost))
    out["status"] = np.full(n, solved.status, dtype=object)
    return out


def point_table(params: Params, settings: Settings, values: dict[str, float]):
    """All finite solutions at one point, classified, with how they were obtained (DataFrame)."""
    import pandas as pd

    table = pd.DataFrame(point_columns(solve_point(params, settings), values))
    table["lost_paths"] = table["lost_paths"].astype("Int64")
    return table


def solve_run(spec: SweepSpec, indices: list[int]) -> Iterator[tuple[int, str, int]]:
    """Solve grid points in order, each continued from the one before when they are neighbours:
    yields (index, the point's CSV text, lost paths)."""
    settings = point_settings(spec)
    warm, previous = None, None
    for index in indices:
        if previous is None or not spec.neighbours(previous, index):
            warm = None
        solved = solve_point(spec.params_at(index), settings, warm=warm)
        warm, previous = solved.warm, index
        cols = point_columns(solved, spec.values_at(index), index)
        if spec.certify:
            _certify_point(spec.params_at(index), solved, cols)
        yield index, columns_csv(cols), int(np.nan_to_num(cols["lost_paths"][:1]).sum())


def _certify_point(params: Params, solved: PointSolution, cols: dict) -> None:
    """Prove the point (columns certified, certified_radius, certificate, certify_seconds); a
    point whose proof is not complete is `incomplete`."""
    from ..analysis.certify import certify_table

    cert = certify_table(params, solved.columns)
    n = len(cols["point"])
    cols["certified"] = cert.certified
    cols["certified_radius"] = cert.certified_radius
    cols["certificate"] = np.full(n, cert.status, dtype=object)
    cols["certify_seconds"] = np.full(n, cert.seconds)
    if cert.status != "proved":
        cols["status"] = np.full(n, "incomplete", dtype=object)


def _run_task(args: tuple) -> list[tuple[int, str, int]]:
    indices, spec_json = args
    return list(solve_run(SweepSpec.from_json(spec_json), indices))


def point_settings(spec: SweepSpec) -> Settings:
    """The settings of each point: the sweep's, one thread a point unless threads were given."""
    settings = Settings(**spec.settings)
    return settings if settings.threads is not None else settings.replace(threads=1)


def point_file(folder: Path, index: int) -> Path:
    """Where point `index` is stored."""
    return folder / "points" / f"{index:05d}.csv"


def pending_points(spec: SweepSpec, folder: Path) -> list[int]:
    """Indices of the grid points that have no finished point file yet."""
    points = folder / "points"
    done = {p.name for p in points.glob("*.csv")} if points.is_dir() else set()
    return [i for i in range(spec.size()) if point_file(folder, i).name not in done]


def prepare(spec: SweepSpec, folder: Path) -> Path:
    """The sweep folder for `spec`: created, or an earlier one for the same spec (resumed)."""
    if folder.exists() and not folder.is_dir():
        raise ParameterError(f"sweep folder {str(folder)!r}: exists and is not a directory")
    spec_path = folder / SPEC_FILE
    if spec_path.is_file():
        saved = json.loads(spec_path.read_text())
        if saved.get("spec") != spec.to_json():
            raise ParameterError(f"{folder}: holds a different sweep; write to another folder")
    else:
        (folder / "points").mkdir(parents=True, exist_ok=True)
        write_json(spec_path, {"spec": spec.to_json(), "key": spec.key()})
    (folder / "points").mkdir(parents=True, exist_ok=True)
    return folder


def load_spec(folder: Path) -> SweepSpec:
    """The spec a sweep folder was made for."""
    path = Path(folder) / SPEC_FILE
    if not path.is_file():
        raise ParameterError(f"folder {str(folder)!r}: no {SPEC_FILE} there (not a sweep folder)")
    return SweepSpec.from_json(json.loads(path.read_text())["spec"])


def warm_generic_sets(spec: SweepSpec) -> None:
    """Solve (or load) the generic sets every point needs, once, before workers start."""
    if Settings(**spec.settings).engine != "homotopy":
        return
    from ..backends.homotopy import generic_set
    from ..model.compiled import parametric_system

    structures = {spec.params_at(i).zfl for i in range(spec.size())}
    for zfl in sorted(structures):
        generic_set(parametric_system(zfl), spec.settings["seed"])


def run_points(
    spec: SweepSpec,
    folder: Path,
    workers: int = 1,
    scheduler: str | None = None,
    progress: Callable[[int, int, int], None] | None = None,
) -> dict:
    """Solve every pending point (local processes, or a Dask cluster) and store each atomically.

    Pending points are cut into runs of grid neighbours (snake order over a 2-D grid); each run
    is solved in order on one worker, every point continued from the one before.
    """
    check_workers(workers)
    todo = pending_points(spec, folder)
    total = spec.size()
    stats = {"points": total, "skipped": total - len(todo), "solved": 0, "lost_paths": 0}
    stats["seconds"] = 0.0
    if not todo:
        return stats
    warm_generic_sets(spec)
    start = time.perf_counter()
    runs = spec.runs(todo, parts=1 if (workers == 1 and scheduler is None) else 2 * workers)
    for index, text, lost in _execute(runs, spec, workers, scheduler):
        atomic_write_text(point_file(folder, index), text)
        stats["solved"] += 1
        stats["lost_paths"] += lost
        if progress:
            progress(stats["solved"], len(todo), stats["lost_paths"])
    stats["seconds"] = time.perf_counter() - start
    return stats


def _execute(
    runs: list[list[int]], spec: SweepSpec, workers: int, scheduler: str | None
) -> Iterable[tuple[int, str, int]]:
    if scheduler is None and workers == 1:
        for run in runs:
            yield from solve_run(spec, run)  # in process: point by point, progress as it goes
        return
    tasks = [(run, spec.to_json()) for run in runs]
    if scheduler is not None:
        from distributed import Client, as_completed

        with Client(scheduler) as client:
            for fut in as_completed(client.map(_run_task, tasks, pure=False)):
                yield from fut.result()
        return
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor, as_completed

    ctx = mp.get_context("spawn")  # the bertini module is not fork-safe with its threads
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as pool:
        for fut in as_completed([pool.submit(_run_task, t) for t in tasks]):
            yield from fut.result()


def assemble(spec: SweepSpec, folder: Path):
    """All point files as one table (DataFrame), in grid order (errors if a point is missing)."""
    import pandas as pd

    missing = pending_points(spec, folder)
    if missing:
        raise RuntimeError(f"{folder}: {len(missing)} points not solved yet (first {missing[0]})")
    frames = [read_table(point_file(folder, i)) for i in range(spec.size())]
    return pd.concat(frames, ignore_index=True)


def check_workers(workers: object) -> None:
    """Refuse a worker count that is not an integer >= 1, naming the argument `workers`."""
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ParameterError(f"workers = {workers!r}: must be an integer >= 1")


def default_workers() -> int:
    """One worker per core."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return max(1, os.cpu_count() or 1)
