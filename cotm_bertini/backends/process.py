"""Run an external solver as a subprocess: own session, stdin from /dev/null, a time limit."""

from __future__ import annotations

import os
import signal
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class ProcessResult:
    """What one process did."""

    returncode: int
    stdout: str
    stderr: str
    seconds: float


class ProcessTimeout(Exception):
    """The process ran out of time and was killed (with its whole process group)."""

    def __init__(self, seconds: float, stdout: str, stderr: str) -> None:
        super().__init__(f"timed out after {seconds:g} s")
        self.seconds, self.stdout, self.stderr = seconds, stdout, stderr


def run_process(
    cmd: list[str], cwd: Path, timeout: float, env: dict[str, str] | None = None
) -> ProcessResult:
    """Run cmd in cwd; on timeout kill its process group and raise ProcessTimeout."""
    start = time.perf_counter()
    proc = subprocess.Popen(
        cmd,
        cwd=cwd,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=env,
        text=True,
        errors="replace",
        start_new_session=True,  # a timeout kills the solver's children too
    )
    try:
        stdout, stderr = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        stdout, stderr = proc.communicate()
        raise ProcessTimeout(timeout, stdout, stderr) from None
    return ProcessResult(proc.returncode, stdout, stderr, time.perf_counter() - start)


def tail(text: str, lines: int = 6) -> str:
    """The last non-empty lines of a solver's output, on one line."""
    kept = [ln.strip() for ln in text.strip().splitlines() if ln.strip()][-lines:]
    return " | ".join(kept) if kept else "(no output)"
