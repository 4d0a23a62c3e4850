"""One solve end to end: equations -> input file -> Bertini -> tables -> classified solutions."""

from __future__ import annotations

import datetime as dt
import sys
import tempfile
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from . import engine as engine_mod
from .compiled import polynomial_system
from .geometry import Params
from .parse import BertiniOutput, read_output
from .polynomial import PolySystem
from .render import render_input
from .results import link_latest, new_run_folder, write_csv, write_json
from .settings import Settings
from .solver import SolverError, run_bertini
from .stability import Tolerances, classify, morse_check


@dataclass
class Timings:
    """Wall-clock seconds per stage."""

    stages: dict[str, float] = field(default_factory=dict)

    @contextmanager
    def stage(self, name: str):
        start = time.perf_counter()
        try:
            yield
        finally:
            self.stages[name] = self.stages.get(name, 0.0) + time.perf_counter() - start


@dataclass(frozen=True)
class Solved:
    """The solutions of one run and what produced them."""

    solutions: pd.DataFrame
    system: PolySystem
    output: BertiniOutput
    input_text: str
    engine: engine_mod.Engine
    bertini_version: str
    bertini_seconds: float
    paths_tracked: int | None
    timings: dict[str, float]
    details: dict = field(default_factory=dict)


def solve_in(
    folder: Path,
    params: Params,
    settings: Settings,
    tolerances: Tolerances = Tolerances(),
    title: str = "",
) -> Solved:
    """Solve `params` in the empty `folder`: the input file(s) and Bertini's files are kept.

    Engine "homotopy" (default): parameter homotopy in-process from the cached generic solution
    set. Engine "cli": a total-degree solve by the bertini2 command (or a Bertini 1.x binary).
    """
    if settings.engine == "homotopy":
        return _solve_homotopy(folder, params, settings, tolerances)
    t = Timings()
    with t.stage("derive"):
        system = polynomial_system(params)
    with t.stage("render"):
        text = render_input(system, settings, params.as_dict(), title)
    eng = engine_mod.find_engine(settings.bertini)
    attempts: list[dict] = []
    with t.stage("solve"):
        try:
            run = run_bertini(text, folder, eng, settings.timeout, settings.threads)
        except SolverError as first:
            # One retry, as Bertini's own advice goes: a new random seed and tighter tracking.
            attempts.append(_set_aside(folder, 1, settings, first))
            retry = settings.retry()
            text = render_input(system, retry, params.as_dict(), title)
            try:
                run = run_bertini(text, folder, eng, retry.timeout, retry.threads)
            except SolverError as second:
                attempts.append(_set_aside(folder, 2, retry, second))
                raise SolverError(
                    f"{first} -- retried with seed {retry.seed} and tighter tolerances: {second}"
                ) from None
            attempts.append({"attempt": 2, "settings": retry.bertini_config(), "ok": True})
    with t.stage("parse"):
        out = read_output(folder)
    with t.stage("classify"):
        table = classify(params, out.endpoints, out.variables, tolerances)
    tracked = run.paths_tracked
    if tracked is None and settings.variable_groups == "total_degree":
        tracked = system.total_degree
    return Solved(
        table,
        system,
        out,
        text,
        eng,
        run.version,
        run.seconds,
        tracked,
        t.stages,
        {"attempts": attempts} if attempts else {},
    )


def _set_aside(folder: Path, n: int, settings: Settings, error: Exception) -> dict:
    """Move a failed attempt's files into folder/failed-attempt-n (kept, reported)."""
    from .solver import ATTEMPT_PREFIX

    keep = folder / f"{ATTEMPT_PREFIX}{n}"
    keep.mkdir(parents=True, exist_ok=True)
    for p in list(folder.iterdir()):
        if not p.name.startswith(ATTEMPT_PREFIX):
            p.rename(keep / p.name)
    print(f"cotm-bertini: attempt {n} failed ({error}); files in {keep}", file=sys.stderr)
    return {"attempt": n, "settings": settings.bertini_config(), "ok": False, "error": str(error)}


def _solve_homotopy(
    folder: Path, params: Params, settings: Settings, tolerances: Tolerances
) -> Solved:
    from .compiled import parametric_system
    from .homotopy import generic_set, solve_target
    from .render import render_parameter_homotopy

    t = Timings()
    with t.stage("derive"):
        ps = parametric_system(params.zfl)
        system = ps.instantiate([getattr(params, n) for n in ps.parameters])
    with t.stage("generic"):
        gs = generic_set(ps, settings.seed)
    with t.stage("render"):
        folder.mkdir(parents=True, exist_ok=True)
        target = {n: getattr(params, n) for n in ps.parameters}
        text = render_parameter_homotopy(ps, gs.start, target)
        (folder / "input").write_text(text)
    with t.stage("solve"):
        endpoints, info = solve_target(ps, params, settings.seed, threads=settings.threads)
    with t.stage("classify"):
        table = classify(params, endpoints, ps.variables, tolerances)
    out = BertiniOutput("in-process", ps.variables, endpoints, len(endpoints), None)
    eng = engine_mod.Engine("bertini module (in-process)", "homotopy", gs.bertini_version, {})
    details = {
        "homotopy": info,
        "generic_set": {
            "key": gs.key,
            "seed": gs.seed,
            "paths": gs.paths,
            "finite_endpoints": gs.finite_endpoints,
            "singular_endpoints": gs.singular_endpoints,
            "tracked_points": len(gs.points),
            "solve_seconds": gs.seconds,
            "start_parameters": {k: [v.real, v.imag] for k, v in gs.start.items()},
        },
    }
    return Solved(
        table,
        system,
        out,
        text,
        eng,
        gs.bertini_version,
        t.stages["solve"],
        info["tracked"],
        t.stages,
        details,
    )


def solve(
    params: Params, settings: Settings = Settings(), tolerances: Tolerances = Tolerances()
) -> pd.DataFrame:
    """Every finite solution of `params`, classified; Bertini runs in a throw-away folder."""
    with tempfile.TemporaryDirectory(prefix="cotm-") as tmp:
        return solve_in(Path(tmp) / "run", params, settings, tolerances).solutions


def summary_counts(solved: Solved) -> dict[str, int]:
    """Path and solution counts for run.json and the console."""
    s = solved.solutions
    tracked = solved.paths_tracked
    return {
        "paths_tracked": tracked,
        "finite_endpoints": len(solved.output.endpoints),
        "nonfinite_or_failed_paths": None
        if tracked is None
        else tracked - len(solved.output.endpoints),
        "bertini1_failed_paths_file": solved.output.failed_paths,
        "distinct_solutions": len(s),
        "real": int(s["is_real"].sum()),
        "physical": int(s["physical"].sum()),
        "stable": int(s["stable"].sum()),
        "zero_length_artefacts": int((s["reason"] == "zero_length_spring").sum()),
        "negative_d": int((s["reason"] == "negative_d").sum()),
        "singular": int(s["singular"].sum()),
    }


def run_and_record(
    params: Params,
    settings: Settings,
    root: Path,
    label: str,
    command: list[str] | None = None,
    tolerances: Tolerances = Tolerances(),
    plots: bool = True,
) -> tuple[Path, Solved, dict]:
    """Solve into a new run folder under root with solutions.csv and run.json.

    The folder is built under a hidden name and renamed when complete; a failed run is renamed
    to `<name>-failed` with run.json saying why, so nothing is half-written or silently lost.
    """
    work, final = new_run_folder(root)
    work.mkdir()
    record: dict = {
        "label": label,
        "created": dt.datetime.now().astimezone().isoformat(timespec="seconds"),
        "command": command,
        "parameters": params.as_dict(),
        "zero_free_length": {"spring1": params.zfl[0], "spring2": params.zfl[1]},
        "settings": settings.as_dict(),
        "seed": settings.seed,
        "tolerances": tolerances.__dict__,
        "versions": engine_mod.python_versions(),
    }
    start = time.perf_counter()
    try:
        solved = solve_in(work, params, settings, tolerances, title=label)
    except BaseException as exc:  # whatever stopped the run, the folder says so
        record.update(
            status="failed",
            error=f"{type(exc).__name__}: {exc}",
            timings={"total": time.perf_counter() - start},
        )
        write_json(work / "run.json", record)
        work.rename(final.with_name(final.name + "-failed"))
        raise
    timings = dict(solved.timings)
    with_stage = Timings(timings)
    with with_stage.stage("write"):
        write_csv(work / "solutions.csv", solved.solutions)
    if plots:
        with with_stage.stage("plot"):
            from .plot import plot_run  # matplotlib only when pictures are asked for

            figures = [p.name for p in plot_run(params, solved.solutions, work)]
    else:
        figures = []
    timings["total"] = time.perf_counter() - start
    record.update(
        status="ok",
        engine={
            "flavour": solved.engine.flavour,
            "path": solved.engine.path,
            "version": solved.bertini_version,
        },
        output_layout=solved.output.layout,
        details=solved.details,
        polynomial_system={
            "variables": list(solved.system.variables),
            "functions": list(solved.system.names),
            "degrees": list(solved.system.degrees),
            "total_degree": solved.system.total_degree,
        },
        counts=summary_counts(solved),
        morse=morse_check(params, solved.solutions),
        figures=figures,
        timings=timings,
    )
    write_json(work / "run.json", record)
    work.rename(final)
    link_latest(root, final)
    return final, solved, record
