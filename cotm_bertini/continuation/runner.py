"""Run a sweep: every point solved by `solve_point`, in parallel, each stored durably, resumable.

Each point's columns are appended to the sweep folder's store (`points.bin`, continuation.store)
as soon as the point is solved, and kept in memory for the end, so a killed sweep loses at most
the points in flight and never stores a partial or duplicate row; a rerun skips the points
already stored. `sweep.csv` is assembled from the points at the end.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path

import numpy as np

from ..backends.pools import Run as Run
from ..backends.pools import as_done, check_workers
from ..backends.pools import default_workers as default_workers
from ..backends.pools import start_method as start_method
from ..backends.pools import worker_pool as worker_pool
from ..errors import ParameterError
from ..fs import write_json
from ..params import Params
from ..point import solve_point
from ..routes.result import PointSolution
from ..settings import Settings
from .spec import SweepSpec
from .store import PointStore, stored_indices
from .tables import Columns, concat_columns, rows_text, to_frame

SPEC_FILE = "sweep.json"


def point_columns(
    solved: PointSolution, values: dict[str, float], index: int = -1
) -> dict[str, np.ndarray]:
    """A point's rows as columns: point, the swept values, the solutions, how they were found."""
    cols = solved.columns
    n = len(cols["solution_id"])
    homotopy = solved.details.get("homotopy")
    method = homotopy["method"] if homotopy else f"cli ({solved.engine['flavour']})"
    if "taut_sets" in solved.details:  # a framework
        from .framework import point_method

        method = point_method(solved.details)
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


def solve_run(
    spec: SweepSpec, indices: list[int], names: list[str] | None = None
) -> Iterator[tuple[int, Columns, int, str | None]]:
    """Solve grid points in order, each continued from a solved neighbour: the one before when
    it has the same structure, else another one solved in this run (the row before, on a
    2-D grid: so a point next to a free length of 0 need not start from the generic set).
    Yields (index, the point's columns, lost paths, its sweep.csv lines under the columns
    `names`, or None without `names`): the lines are written here, in parallel, not at the end.
    """
    settings = point_settings(spec)
    if _searched_together(spec, indices, settings):
        from ..boxsearch.families import TOGETHER
        from ..point import solve_framework_points

        for at in range(0, len(indices), TOGETHER):
            chunk = indices[at : at + TOGETHER]
            solved = solve_framework_points([spec.params_at(i) for i in chunk], settings)
            for index, one in zip(chunk, solved, strict=True):
                yield _point_out(spec, index, one, names)
        return
    recent: dict[int, tuple] = {}  # the last two rows' points: index -> (warm start, structure)
    keep = 2 * (len(spec.values2) if spec.param2 else 1) + 2
    for index in indices:
        params = spec.params_at(index)
        structure = getattr(params, "zfl", None)  # a framework's starts are keyed by system
        solved = _solve(spec, params, settings, _start(spec, index, structure, recent))
        recent[index] = (solved.warm, structure)
        if len(recent) > keep:
            del recent[next(iter(recent))]
        yield _point_out(spec, index, solved, names)


def _searched_together(spec: SweepSpec, indices: list[int], settings: Settings) -> bool:
    """Whether the points are a framework's on the real route: their searches then run
    together, families.TOGETHER at a time (point.solve_framework_points: the batches of boxes,
    not Python's steps, set the pace; each point's search and rows as if solved alone)."""
    if spec.framework is None or not indices:
        return False
    from ..routes import choose

    return choose(spec.params_at(indices[0]), settings).real


def _point_out(
    spec: SweepSpec, index: int, solved: PointSolution, names: list[str] | None
) -> tuple[int, Columns, int, str | None]:
    """A solved point as solve_run yields it (certified first where the sweep asks)."""
    cols = point_columns(solved, spec.values_at(index), index)
    if spec.certify:
        _certify_point(spec.params_at(index), solved, cols)
    text = None if names is None else rows_text(cols, names)
    return index, cols, int(np.nan_to_num(cols["lost_paths"][:1]).sum()), text


def _solve(spec: SweepSpec, params, settings: Settings, warm) -> PointSolution:
    """One point: the paper's model, or a framework (each taut set continued from `warm`)."""
    if spec.framework is not None:
        from ..point import solve_framework_point

        return solve_framework_point(params, settings, warm=warm)
    return solve_point(params, settings, warm=warm)


def sweep_names(spec: SweepSpec) -> list[str]:
    """The columns of sweep.csv (before `branch`), from the structures the grid holds: each
    point's columns in point_columns' order, joined in grid order (as pandas.concat joins)."""
    from ..analysis.classify import empty_columns
    from ..model.compiled import parametric_system

    if spec.framework is not None:
        from .framework import sweep_names as framework_names

        return framework_names(spec.model, spec.columns)
    structures: dict[tuple[bool, bool], None] = {}  # Params.zfl of each point, in grid order
    for index in range(spec.size() if {"L01", "L02"} & set(spec.columns) else 1):
        values = {**spec.base, **spec.values_at(index)}
        structures[(float(values["L01"]) == 0.0, float(values["L02"]) == 0.0)] = None
    names: dict[str, None] = dict.fromkeys(["point", *spec.columns])
    for zfl in structures:
        names.update(dict.fromkeys(empty_columns(parametric_system(zfl).variables)))
        names.update(dict.fromkeys(["method", "lost_paths", "status"]))
        if spec.certify:
            names.update(dict.fromkeys(CERTIFY_COLUMNS))
    return list(names)


CERTIFY_COLUMNS = ("certified", "certified_radius", "certificate", "certify_seconds")


def _start(spec: SweepSpec, index: int, zfl, recent: dict[int, tuple]):
    """The warm start of point `index`: the last point solved if it is a neighbour of the same
    structure, else another solved neighbour of that structure, else the last point if it is a
    neighbour (it is then refused, and says why), else None."""
    last = next(reversed(recent), None)
    near = [i for i in [last, *spec.grid_neighbours(index)] if i in recent]
    near = [i for i in near if spec.neighbours(i, index)]
    for i in near:
        warm, structure = recent[i]
        if warm is not None and structure == zfl:
            return warm
    return recent[last][0] if near and near[0] == last else None


def _certify_point(params: Params, solved: PointSolution, cols: dict) -> None:
    """Prove the point (columns certified, certified_radius, certificate, certify_seconds); a
    point whose proof is not complete is `incomplete`."""
    if isinstance(params, Params):
        from ..analysis.certify.mechanism import certify_table

        cert = certify_table(params, solved.columns)
    else:  # a framework (docs/certify.md, "Frameworks")
        from ..analysis.certify.framework import certify_framework_table

        cert = certify_framework_table(params, solved.columns)
    n = len(cols["point"])
    values = (cert.certified, cert.certified_radius, np.full(n, cert.status, dtype=object),
              np.full(n, cert.seconds))  # fmt: skip
    cols.update(zip(CERTIFY_COLUMNS, values, strict=True))
    if cert.status not in ("proved", "rows proved"):
        cols["status"] = np.full(n, "incomplete", dtype=object)


def _run_task(args: tuple) -> list[tuple[int, Columns, int, str | None]]:
    indices, spec_json, names = args
    return list(solve_run(SweepSpec.from_json(spec_json), indices, names))


def point_settings(spec: SweepSpec) -> Settings:
    """The settings of each point: the sweep's, one thread a point unless threads were given,
    no scheduler (the sweep's generic sets are split before its points start, and a point
    solved on a Dask worker must not wait for other tasks of its own cluster), and its search
    in its own process (an event's many solves would each start a pool of processes)."""
    settings = Settings(**spec.settings).replace(scheduler=None, workers=1)
    return settings if settings.threads is not None else settings.replace(threads=1)


def pending_points(spec: SweepSpec, folder: Path, store: PointStore | None = None) -> list[int]:
    """Indices of the grid points not stored yet."""
    done = stored_indices(folder) if store is None else store.points
    return [i for i in range(spec.size()) if i not in done]


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
        folder.mkdir(parents=True, exist_ok=True)
        write_json(spec_path, {"spec": spec.to_json(), "key": spec.key()})
    return folder


def load_spec(folder: Path) -> SweepSpec:
    """The spec a sweep folder was made for."""
    path = Path(folder) / SPEC_FILE
    if not path.is_file():
        raise ParameterError(f"folder {str(folder)!r}: no {SPEC_FILE} there (not a sweep folder)")
    return SweepSpec.from_json(json.loads(path.read_text())["spec"])


def warm_generic_sets(spec: SweepSpec, scheduler: str | None = None) -> None:
    """Solve (or load) the generic sets every point needs, once, before workers start; a set
    solved now has its paths split over the Dask cluster at `scheduler`, if given."""
    settings = Settings(**spec.settings)
    if settings.engine != "homotopy":
        return
    if scheduler:
        settings = settings.replace(scheduler=scheduler)
    if spec.framework is not None:
        from ..routes import choose
        from .framework import warm_generic_sets as framework_sets

        if choose(spec.params_at(0), settings).real:
            return  # the real route solves no generic set

        framework_sets(spec.params_at, sorted({0, spec.size() - 1}), settings)
        return
    from ..backends.generic import generic_for
    from ..model.compiled import parametric_system

    structures = {spec.params_at(i).zfl for i in range(spec.size())}
    for zfl in sorted(structures):
        generic_for(parametric_system(zfl), settings.seed, settings)


def run_points(
    spec: SweepSpec,
    folder: Path,
    workers: int = 1,
    scheduler: str | None = None,
    progress: Callable[[int, int, int], None] | None = None,
    store: PointStore | None = None,
) -> dict:
    """Solve every pending point (local processes, or a Dask cluster) and store each durably
    (in `store`, the folder's PointStore, which also keeps them in memory, if given).

    Pending points are cut into runs of grid neighbours (snake order over a 2-D grid); each run
    is solved in order on one worker, every point continued from the one before.
    """
    check_workers(workers)
    store = PointStore(folder) if store is None else store
    todo = pending_points(spec, folder, store)
    total = spec.size()
    stats = {"points": total, "skipped": total - len(todo), "solved": 0, "lost_paths": 0}
    stats["seconds"] = 0.0
    if not todo:
        return stats
    warm_generic_sets(spec, scheduler)
    start = time.perf_counter()
    runs = spec.runs(todo, parts=1 if (workers == 1 and scheduler is None) else 2 * workers)
    names = sweep_names(spec)
    try:
        for index, cols, lost, text in _execute(runs, spec, workers, scheduler, names):
            store.append(index, cols, text)
            stats["solved"] += 1
            stats["lost_paths"] += lost
            if progress:
                progress(stats["solved"], len(todo), stats["lost_paths"])
    finally:
        store.close()
    stats["seconds"] = time.perf_counter() - start
    return stats


def _execute(
    runs: list[list[int]], spec: SweepSpec, workers: int, scheduler: str | None, names: list[str]
) -> Iterable[tuple[int, Columns, int, str | None]]:
    if scheduler is None and workers == 1:
        for run in runs:
            yield from solve_run(spec, run, names)  # in process: point by point, with progress
        return
    tasks = [(run, spec.to_json(), names) for run in runs]
    for _, rows in as_done(_run_task, tasks, workers, scheduler):
        yield from rows


def assemble_columns(spec: SweepSpec, folder: Path, store: PointStore | None = None) -> Columns:
    """Every point's rows as one table of numpy columns, in grid order, from `store` (default:
    the folder's); errors if a point is missing."""
    store = PointStore(folder) if store is None else store
    missing = pending_points(spec, folder, store)
    if missing:
        raise RuntimeError(f"{folder}: {len(missing)} points not solved yet (first {missing[0]})")
    return concat_columns([store.points[i] for i in range(spec.size())])


def assemble(spec: SweepSpec, folder: Path, store: PointStore | None = None):
    """Every point's rows as one DataFrame, in grid order, with the dtypes of sweep.csv."""
    return to_frame(assemble_columns(spec, folder, store))
