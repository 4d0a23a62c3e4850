"""The `cli` engine: a Bertini binary (bertini2, or a user's Bertini 1.x) in its own run folder.

The total-degree input file is rendered into an empty folder and Bertini runs there as a
subprocess with a time limit; its output files stay in the folder and are parsed into endpoints.
A crash, timeout or missing output is retried once with a new seed and tighter tracking; the
failed attempt's files are kept in `failed-attempt-1/` and reported. So is a run after which
Bertini warned that path crossings remained unresolved (crossings.py): the retry's crossings,
if any are left, are counted (`CliSolve.crossings_unresolved`) and make the status incomplete.
"""

from __future__ import annotations

import re
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import SolverError
from ..model.polynomial import PolySystem
from ..settings import Settings
from .crossings import count_in
from .endpoints import Endpoints
from .engine import Engine, child_environment, find_engine
from .parse import BertiniOutput, read_output
from .process import ProcessTimeout, run_process, tail
from .render import render_input

REQUIRED_OUTPUTS = ("main_data", "finite_solutions")
ATTEMPT_PREFIX = "failed-attempt-"


@dataclass(frozen=True)
class SolverRun:
    """What one Bertini process did."""

    folder: Path
    engine: Engine
    returncode: int
    seconds: float
    stdout: str
    stderr: str
    version: str
    paths_tracked: int | None  # as Bertini 1 prints it; None where not printed

    @property
    def crossings_unresolved(self) -> int:
        """Path crossings Bertini warned it left unresolved (on stderr)."""
        return count_in(self.stderr)


@dataclass(frozen=True)
class CliSolve:
    """A finished cli solve: the endpoints, Bertini's output, the input text, the attempts."""

    endpoints: Endpoints
    output: BertiniOutput
    run: SolverRun
    input_text: str
    paths_tracked: int | None
    attempts: list[dict] = field(default_factory=list)
    timings: dict[str, float] = field(default_factory=dict)  # render, bertini, parse


def _version(engine: Engine, stdout: str) -> str:
    m = re.search(r"Bertini\(TM\)\s+v([\d.]+)", stdout)
    return m.group(1) if m else engine.version


def run_bertini(
    input_text: str, folder: Path, engine: Engine, timeout: float, threads: int | None = None
) -> SolverRun:
    """Write `input` into an empty `folder` and run Bertini there, stdin from /dev/null."""
    folder.mkdir(parents=True, exist_ok=True)
    # Earlier failed attempts are kept in subfolders; anything else would be stale output.
    if any(not p.name.startswith(ATTEMPT_PREFIX) for p in folder.iterdir()):
        raise SolverError(f"run folder {folder} is not empty: refusing to mix with stale output")
    (folder / "input").write_text(input_text)
    env = child_environment(engine, threads)
    try:
        proc = run_process([engine.path, "input"], folder, timeout, env)
    except ProcessTimeout as exc:
        _save_logs(folder, exc.stdout, exc.stderr)
        raise SolverError(
            f"Bertini timed out after {timeout:g} s in {folder} (raise --timeout, or loosen the "
            f"tolerances); last output: {tail(exc.stdout + exc.stderr)}"
        ) from None
    _save_logs(folder, proc.stdout, proc.stderr)
    if proc.returncode != 0:
        raise SolverError(
            f"Bertini exited with code {proc.returncode} in {folder}: "
            f"{tail(proc.stderr or proc.stdout)}"
        )
    missing = [f for f in REQUIRED_OUTPUTS if not (folder / f).is_file()]
    if missing:
        raise SolverError(
            f"Bertini wrote no {', '.join(missing)} in {folder}: {tail(proc.stderr or proc.stdout)}"
        )
    m = re.search(r"Paths Tracked:\s*(\d+)", proc.stdout)
    return SolverRun(
        folder,
        engine,
        proc.returncode,
        proc.seconds,
        proc.stdout,
        proc.stderr,
        _version(engine, proc.stdout),
        int(m.group(1)) if m else None,
    )


def _save_logs(folder: Path, stdout: str, stderr: str) -> None:
    (folder / "bertini.stdout").write_text(stdout)
    (folder / "bertini.stderr").write_text(stderr)


def solve_cli(
    system: PolySystem, settings: Settings, folder: Path, params: dict[str, float], title: str = ""
) -> CliSolve:
    """Solve `system` with the Bertini binary in `folder`, retrying once; parse the output."""
    engine = find_engine(settings.bertini)
    t0 = time.perf_counter()
    text = render_input(system, settings, params, title)
    timings = {"render": time.perf_counter() - t0}
    attempts: list[dict] = []
    t0 = time.perf_counter()
    try:
        run = run_bertini(text, folder, engine, settings.cli_timeout, settings.threads)
        if run.crossings_unresolved:
            raise SolverError(
                f"Bertini left {run.crossings_unresolved} path crossings unresolved: the "
                "affected solutions may be wrong"
            )
    except SolverError as first:
        # One retry, as Bertini's own advice goes: a new random seed and tighter tracking.
        attempts.append(_set_aside(folder, 1, settings, first))
        retry = settings.retry()
        text = render_input(system, retry, params, title)
        try:
            run = run_bertini(text, folder, engine, retry.cli_timeout, retry.threads)
        except SolverError as second:
            attempts.append(_set_aside(folder, 2, retry, second))
            raise SolverError(
                f"{first} -- retried with seed {retry.seed} and tighter tolerances: {second}"
            ) from None
        attempts.append({"attempt": 2, "settings": retry.bertini_config(), "ok": True,
                         "crossings_unresolved": run.crossings_unresolved})  # fmt: skip
    timings["bertini"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    out = read_output(folder)
    timings["parse"] = time.perf_counter() - t0
    tracked = run.paths_tracked
    if tracked is None and settings.variable_groups == "total_degree":
        tracked = system.total_degree
    return CliSolve(out.endpoints, out, run, text, tracked, attempts, timings)


def _set_aside(folder: Path, n: int, settings: Settings, error: Exception) -> dict:
    """Move a failed attempt's files into folder/failed-attempt-n (kept, reported)."""
    keep = folder / f"{ATTEMPT_PREFIX}{n}"
    keep.mkdir(parents=True, exist_ok=True)
    for p in list(folder.iterdir()):
        if not p.name.startswith(ATTEMPT_PREFIX):
            p.rename(keep / p.name)
    print(f"cotm-bertini: attempt {n} failed ({error}); files in {keep}", file=sys.stderr)
    return {"attempt": n, "settings": settings.bertini_config(), "ok": False, "error": str(error)}
