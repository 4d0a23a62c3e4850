"""`solve` and its result, `Solutions`: every equilibrium of one parameter set."""

from __future__ import annotations

import shutil
import time
import weakref
from dataclasses import asdict, fields
from pathlib import Path

from ..errors import CotmError, ParameterError
from ..fs import temp_folder, timestamp, write_csv, write_json
from ..io import cache
from ..io.runfolder import (
    RUN_JSON,
    SOLUTIONS_CSV,
    figure_files,
    finish_copy,
    read_record,
    read_solutions,
    solve_record,
    start_copy,
    summary_head,
    write_solution_files,
)
from ..model.framework.spec import Framework
from ..params import Params
from ..settings import Settings, Tolerances


class Solutions:
    """The classified solutions of one parameter set, as a table and counts, savable as a run.

    `table` has exactly the solutions.csv columns (docs/columns.md), and its index is the
    solution_id, so `res.stable.loc[7]` is solution 7; `physical`, `stable`, `real` and
    `nonsingular` are its filtered views. `counts`, `morse`, `status` and `warnings`
    say what was found and whether a completeness check failed. `save(folder)` writes the run
    folder the command line writes.
    """

    def __init__(
        self, params: Params, settings: Settings, record: dict, folder: Path, columns=None
    ):
        self.params = params
        self.settings = settings
        self.record = record
        self.folder = Path(folder)  # holds solutions.csv, run.json, input and solver files
        self._columns = columns  # a fresh solve's numpy columns (the table is built from them)
        self._table = None
        self.certificate = None  # set by cb.certify

    def __repr__(self) -> str:
        c = self.counts
        return (
            f"<Solutions {c['distinct_solutions']} finite, {c['real']} real, "
            f"{c['physical']} physical, {c['stable']} stable; status {self.status}>"
        )

    @property
    def table(self):
        """Every distinct finite solution (pandas DataFrame, the solutions.csv columns), indexed
        by solution_id."""
        if self._table is None:
            if self._columns is not None:
                import pandas as pd

                self._table = by_solution_id(pd.DataFrame(self._columns))
            else:
                self._table = by_solution_id(read_solutions(self.folder))
        return self._table

    def attach_certificate(self, cert) -> None:
        """Keep a certificate: the table gains `certified` and `certified_radius`."""
        self.certificate = cert
        self._table = self.table.assign(
            certified=cert.certified, certified_radius=cert.certified_radius
        )

    @property
    def real(self):
        """The real solutions (physical or not)."""
        return self.table[self.table["is_real"].astype(bool)]

    @property
    def nonsingular(self):
        """The solutions that are not singular."""
        return self.table[~self.table["singular"].astype(bool)]

    @property
    def physical(self):
        """The physical equilibria: real, both spring lengths > 0."""
        return self.table[self.table["physical"].astype(bool)]

    @property
    def stable(self):
        """The stable equilibria: strict local minima of the energy."""
        return self.table[self.table["stable"].astype(bool)]

    @property
    def counts(self) -> dict:
        """Paths tracked, finite endpoints, distinct, real, physical, stable solutions, ..."""
        return self.record["counts"]

    @property
    def morse(self) -> dict:
        """The Morse count on the torus (ok, min, saddle, max, zero_length_maxima, ...)."""
        return self.record["morse"]

    @property
    def status(self) -> str:
        """'ok'; 'incomplete' when a completeness check failed; 'contradiction' when a proof
        and an independent check disagree, a bug (see `warnings`)."""
        return self.record["status"]

    @property
    def warnings(self) -> list[str]:
        """Why equilibria may be missing, if they may."""
        return list(self.record.get("warnings", []))

    @property
    def summary(self) -> str:
        """The console report: counts and the real solutions; for an answer from the cache,
        the solve's time is labelled as that of the cached solve."""
        text = self.record["summary"]
        if not self.cache_hit:
            return text
        rest = text.split("\n", 1)[1:]
        return "\n".join([summary_head(self.record, cached=True), *rest])

    @property
    def cache_hit(self) -> bool:
        """Whether this result was read from the cache rather than solved now."""
        return bool(self.record.get("cache", {}).get("hit"))

    def save(
        self, folder: str | Path, plots: bool = True, command: list[str] | None = None
    ) -> Path:
        """Write the run folder: solutions.csv, run.json, columns.md, input, solver files and,
        with `plots`, configurations.* and energy_map.*; built under a hidden name, then renamed.
        """
        start = time.perf_counter()
        dest = Path(folder)
        work = start_copy(self.folder, dest, with_figures=plots)
        record = read_record(work)
        record.update(created=timestamp(), command=command, cache=self.record.get("cache"))
        timings = dict(record.get("timings", {}))
        if self.cache_hit:  # this run's own costs; the cached solve's are kept, labelled so
            record["cache"] = {**record["cache"], "solve_timings": timings}
            record["summary"] = self.summary
            timings = {"cache_lookup": self.record["cache"]["seconds"]}
        if plots and not figure_files(work):
            t0 = time.perf_counter()
            from ..plot.run import plot_run  # matplotlib only when pictures are asked for

            drawn = plot_run(self.params, self.table, work)
            timings["plot"] = time.perf_counter() - t0
            key = self.record.get("cache_key")
            if key and self.folder == cache.entry(key):
                cache.add_files(key, drawn)  # the next identical request finds them
        record["figures"] = [p.name for p in figure_files(work)] if plots else []
        if self.certificate is not None:
            write_csv(work / SOLUTIONS_CSV, self.table)
            record["certificate"] = self.certificate.record()
            record["status"] = _status_with(record["status"], self.certificate.status)
        timings["save"] = time.perf_counter() - start
        record["timings"] = timings
        return finish_copy(work, dest, record)


def solve(
    params: Params | Framework,
    settings: Settings | None = None,
    *,
    cache: bool = True,
    tolerances=None,
    label: str = "",
    **options,
) -> Solutions:
    """Every equilibrium of `params` (the paper's mechanism, or a cb.Framework): all finite
    solutions, classified real, physical, stable.

    Options are Settings fields (seed, engine, mptype, final_tol, timeout, threads, ...), each
    honoured or refused with ParameterError; `scheduler="tcp://host:8786"` splits the paths of
    a generic set solved ab initio over that Dask cluster's workers, or a framework's real
    search (its boxes), which `workers=N` splits over N local processes (docs/frameworks.md). An
    identical earlier request is answered from the content-hash cache (`cache=False` solves
    again). A solver failure raises SolverError; its
    `folder` attribute holds what the solver left (input, output, failed attempts, run.json).
    """
    from ..io import cache as solve_cache

    start = time.perf_counter()
    settings = (settings or Settings()).replace(**options)
    tol = _tolerances(tolerances)
    key = solve_cache.request_key(params.key_fields(), settings.result_key(), tol)
    if cache:
        hit = solve_cache.lookup(key)
        if hit is not None:
            record = read_record(hit)
            record["cache"] = {"hit": True, "key": key, "solved": record.get("solved"),
                               "seconds": time.perf_counter() - start}  # fmt: skip
            return Solutions(params, settings, record, hit)
    from ..routes.choice import check_route

    check_route(params, settings)  # a refused request has no cached answer; refused here
    if settings.scheduler is not None:  # an address nobody answers: refused before any work
        from ..backends.dask_jobs import check_scheduler

        check_scheduler(settings.scheduler)
    work = solve_cache.staging_folder() if cache else temp_folder("cotm-")
    point = _solve_in(work, params, settings, tol, label or "custom")
    record = solve_record(point, tol, label or "custom", key if cache else None)
    record["cache"] = {"hit": False, "key": key if cache else None}
    t0 = time.perf_counter()
    write_solution_files(work, point)
    record["timings"].update(write=time.perf_counter() - t0, total=time.perf_counter() - start)
    write_json(work / RUN_JSON, record)
    if cache:
        folder = solve_cache.commit(key, work)
    else:
        folder = work
    result = Solutions(params, settings, record, folder, point.columns)
    if not cache:
        weakref.finalize(result, shutil.rmtree, str(work), True)
    return result


def _solve_in(work: Path, params: Params, settings: Settings, tol: dict, label: str):
    from ..point import solve_framework_point, solve_point

    start = time.perf_counter()
    try:
        if not isinstance(params, Params):
            from .costs import announce

            announce(params, settings)  # the total work first, when there is some to do
            return solve_framework_point(params, settings, Tolerances(**tol))
        return solve_point(params, settings, Tolerances(**tol), folder=work, title=label)
    except (CotmError, KeyboardInterrupt) as exc:
        failed = temp_folder("cotm-failed-")
        shutil.copytree(work, failed, dirs_exist_ok=True)
        shutil.rmtree(work, ignore_errors=True)
        _failure_record(failed, params, settings, label, exc, time.perf_counter() - start)
        if isinstance(exc, CotmError):
            exc.folder = failed
        raise


def _failure_record(folder, params, settings, label, exc, seconds) -> None:
    from ..versions import versions

    write_json(
        folder / RUN_JSON,
        {
            "label": label,
            "created": timestamp(),
            "status": "failed",
            "error": f"{type(exc).__name__}: {exc}",
            "parameters": params.as_dict(),
            "settings": settings.as_dict(),
            "versions": versions(),
            "timings": {"total": seconds},
        },
    )


def by_solution_id(frame):
    """A solutions table indexed by its solution_id column (the column stays), so labels shown
    and `.loc` agree with the ids that other tables and messages use."""
    import pandas as pd

    return frame.set_axis(pd.Index(frame["solution_id"].to_numpy(dtype=int)), axis=0)


def _tolerances(tolerances: Tolerances | dict | None) -> dict:
    if tolerances is None:
        tolerances = Tolerances()
    elif isinstance(tolerances, dict):
        known = {f.name for f in fields(Tolerances)}
        for name in tolerances:
            if name not in known:
                raise ParameterError(f"{name}: unknown tolerance (known: {' '.join(known)})")
        tolerances = Tolerances(**tolerances)
    return asdict(tolerances)


def _status_with(status: str, certificate: str) -> str:
    """A run's status once certified: a contradiction or an undecided proof overrides ok."""
    if certificate == "contradiction":
        return "contradiction"
    if certificate == "undecided" and status == "ok":
        return "incomplete"
    return status
