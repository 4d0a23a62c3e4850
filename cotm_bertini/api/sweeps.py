"""`sweep` and its result, `Sweep`: every equilibrium along one or two parameter ranges."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

from ..errors import ParameterError
from ..fs import cache_root, output_root, write_json
from ..params import Params
from ..settings import Settings


class Sweep:
    """A finished sweep: `table` (sweep.csv), `events` (events.csv), `record` (run.json)."""

    def __init__(self, spec, folder: Path, record: dict, columns: dict | None = None):
        self.spec = spec
        self.folder = Path(folder)
        self.record = record
        self._columns = columns  # the table as numpy columns, when the sweep was just finished
        self._table = None
        self._events = None

    def __repr__(self) -> str:
        return (
            f"<Sweep {self.spec.param} x {len(self.spec.values)}"
            + (f", {self.spec.param2} x {len(self.spec.values2)}" if self.spec.param2 else "")
            + f": {self.record['rows']} rows, {self.record['events']} events in {self.folder}>"
        )

    @property
    def table(self):
        """One row per finite solution per point (pandas DataFrame, the sweep.csv columns)."""
        if self._table is None and self._columns is not None:
            from ..continuation.tables import to_frame

            self._table, self._columns = to_frame(self._columns), None
        if self._table is None:
            from ..analysis.classify import read_table

            self._table = read_table(self.folder / "sweep.csv")
        return self._table

    @property
    def columns(self) -> dict:
        """The table as numpy columns (no DataFrame built when the sweep has just run)."""
        if self._columns is not None:
            return self._columns
        table = self.table
        return {name: table[name].to_numpy() for name in table.columns}

    @property
    def events(self):
        """Folds, pitchforks, stability and physical changes, refined (events.csv)."""
        if self._events is None:
            import pandas as pd

            self._events = pd.read_csv(self.folder / "events.csv")
        return self._events

    @property
    def status(self) -> str:
        """'ok', or 'incomplete' when some point's completeness check failed."""
        return self.record["status"]

    def explore(self, path: str | Path | None = None) -> Path:
        """explore.html (default: in the sweep folder): the bifurcation diagram in a browser,
        offline, with a slider that draws the equilibria at each point (one-parameter sweeps;
        a two-parameter sweep is explored through its map, cb.DesignMap.explore)."""
        from ..plot.explore_pages import sweep_page

        if self.spec.param2 is not None:
            raise ParameterError("explore: a two-parameter sweep is explored as a map "
                                 "(cb.design_map(...).explore)")  # fmt: skip
        model = self.spec.model if self.spec.framework is not None else Params(**self.spec.base)
        path = Path(path) if path is not None else self.folder / "explore.html"
        return sweep_page(model, self.table, self.spec.param, self.spec.values, path)

    def plot(self, path: str | Path | None = None, show_all: bool = False) -> list[Path]:
        """The bifurcation diagram (1-D) or the stable-count map (2-D).

        `path` with a suffix (.png, .svg, .pdf) writes that file; without one, `<path>.png` and
        `<path>.svg`; by default `bifurcation` or `counts` in the sweep folder.
        """
        one_d = self.spec.param2 is None
        path = (
            Path(path) if path is not None else self.folder / ("bifurcation" if one_d else "counts")
        )
        if one_d and self.spec.framework is not None:
            from ..plot.framework_sweep import plot_framework_sweep

            written = plot_framework_sweep(
                self.spec.model, self.table, self.spec.param, path, self.events
            )
        elif one_d:
            from ..plot.bifurcation import plot_bifurcation

            fixed = {k: v for k, v in self.spec.base.items() if k != self.spec.param}
            written = plot_bifurcation(
                self.table, self.spec.param, path, show_all=show_all, events=self.events,
                fixed=fixed,
            )  # fmt: skip
        else:
            from ..plot.counts import plot_sweep_counts

            written = plot_sweep_counts(self.table, self.spec.columns, path)
        inside = [p.name for p in written if p.parent.resolve() == self.folder.resolve()]
        if inside:
            self.record["figures"] = sorted(set(self.record.get("figures", [])) | set(inside))
            write_json(self.folder / "run.json", self.record)
        return written


def sweep(
    params,
    param: str,
    values: Sequence[float],
    settings: Settings | None = None,
    *,
    param2: str | None = None,
    values2: Sequence[float] | None = None,
    workers: int = 1,
    scheduler: str | None = None,
    out: str | Path | None = None,
    progress: bool | Callable[[int, int, int], None] = False,
    command: list[str] | None = None,
    certify: bool = False,
    **options,
) -> Sweep:
    """Solve `params` (cb.Params, or a cb.Framework: then `param` names one of its parameters)
    at every value of `param` (and of `param2`: a grid), then find branches and events. Options
    are Settings fields, as for `solve`.

    The points are solved on `workers` local processes (or a Dask cluster at `scheduler`) and
    stored one by one under `out` (default: the cache folder), so the same request resumes where
    it stopped and an unchanged finished sweep is not solved again. With `certify`, every point
    is proved as `cb.certify` proves a solve (columns certified, certified_radius, certificate).
    """
    from ..continuation.runner import check_workers, prepare
    from ..continuation.spec import SweepSpec, check_grid
    from ..routes.choice import check_route

    check_workers(workers)  # before any folder is made
    settings = (settings or Settings()).replace(**options)
    check_route(params, settings, "sweep")
    framework = None
    if not isinstance(params, Params):  # a cb.Framework: its parameters are swept
        from ..continuation.framework import encode

        framework = encode(params)
    spec = SweepSpec(
        params.as_dict(), param, tuple(values), param2,
        None if values2 is None else tuple(values2), settings.as_dict(), certify, framework,
    )  # fmt: skip
    check_grid(params, param, spec.values, param2, spec.values2)  # before any folder is made
    root = cache_root() / "sweeps" if out is None else output_root(out, "out")
    folder = prepare(spec, root / spec.folder_name())
    return _run(spec, folder, workers, scheduler, progress, command)


def _run(spec, folder: Path, workers: int, scheduler, progress, command) -> Sweep:
    """Solve a prepared sweep folder's pending points and finish it."""
    from ..continuation.results import finish_columns
    from ..continuation.runner import pending_points, run_points
    from ..continuation.store import PointStore

    store = PointStore(folder)  # the points stored so far, then every point, in memory
    bar, callback = _progress(progress, spec.size(), len(pending_points(spec, folder, store)))
    try:
        stats = run_points(
            spec, folder, workers=workers, scheduler=scheduler, progress=callback, store=store
        )
    finally:
        if bar is not None:
            bar.close()
    record, columns = finish_columns(spec, folder, stats, workers, scheduler, command, store)
    return Sweep(spec, folder, record, columns)


def resume_sweep(
    folder: str | Path,
    workers: int = 1,
    scheduler: str | None = None,
    progress: bool | Callable[[int, int, int], None] = False,
    command: list[str] | None = None,
) -> Sweep:
    """Continue the sweep stored in `folder` (after an interruption) and finish it."""
    from ..continuation.runner import check_workers, load_spec

    check_workers(workers)
    folder = Path(folder)
    if not folder.is_dir():
        raise ParameterError(f"folder {str(folder)!r}: no such folder")
    return _run(load_spec(folder), folder, workers, scheduler, progress, command)


def _progress(progress, total: int, pending: int):
    """The sweep's report (progress.Progress: a tqdm bar on a terminal, a line every few
    seconds otherwise, with the measured rate and the time left); or the caller's callback."""
    if callable(progress):
        return None, progress
    if not progress:
        return None, None
    from ..progress import Progress

    report = Progress("sweep", total, "points", delay=0.0, initial=total - pending, force=True)

    def update(_done: int, _todo: int, lost: int) -> None:
        report.update(1, note=f"{lost} paths lost")

    return report, update
