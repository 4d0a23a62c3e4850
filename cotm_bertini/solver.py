"""Run Bertini as a subprocess in its own, fresh run folder."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path

from .engine import Engine, child_environment

REQUIRED_OUTPUTS = ("main_data", "finite_solutions")
ATTEMPT_PREFIX = "failed-attempt-"


class SolverError(RuntimeError):
    """Bertini failed: non-zero exit, timeout, or missing output. The message quotes Bertini."""


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


def _tail(text: str, lines: int = 6) -> str:
    kept = [ln.strip() for ln in text.strip().splitlines() if ln.strip()][-lines:]
    return " | ".join(kept) if kept else "(no output)"


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
    start = time.perf_counter()
    proc = subprocess.Popen(
        [engine.path, "input"],
        cwd=folder,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=child_environment(engine, threads),
        text=True,
        errors="replace",
        start_new_session=True,
    )
    try:
        stdout, stderr = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        stdout, stderr = proc.communicate()
        _save_logs(folder, stdout, stderr)
        raise SolverError(
            f"Bertini timed out after {timeout:g} s in {folder} (raise --timeout, or loosen the "
            f"tolerances); last output: {_tail(stdout + stderr)}"
        ) from None
    seconds = time.perf_counter() - start
    _save_logs(folder, stdout, stderr)
    if proc.returncode != 0:
        raise SolverError(
            f"Bertini exited with code {proc.returncode} in {folder}: {_tail(stderr or stdout)}"
        )
    missing = [f for f in REQUIRED_OUTPUTS if not (folder / f).is_file()]
    if missing:
        raise SolverError(
            f"Bertini wrote no {', '.join(missing)} in {folder}: {_tail(stderr or stdout)}"
        )
    m = re.search(r"Paths Tracked:\s*(\d+)", stdout)
    return SolverRun(
        folder,
        engine,
        proc.returncode,
        seconds,
        stdout,
        stderr,
        _version(engine, stdout),
        int(m.group(1)) if m else None,
    )


def _save_logs(folder: Path, stdout: str, stderr: str) -> None:
    (folder / "bertini.stdout").write_text(stdout)
    (folder / "bertini.stderr").write_text(stderr)
