"""Shared fixtures: paths, and each case solved once per test session."""

from __future__ import annotations

import os
import subprocess
import sys
from functools import cache
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parent.parent
FIXTURES = Path(__file__).resolve().parent / "fixtures" / "bertini-1.6"
sys.path.insert(0, str(Path(__file__).resolve().parent))


def pytest_configure(config):
    """One fresh cache for the whole session (generic solution sets and solves): tests never
    read a cache left by an earlier run or by a user, and child processes inherit it. Under
    pytest-xdist the workers inherit the controller's, so a generic set is solved once."""
    import os
    import tempfile

    if os.environ.get("PYTEST_XDIST_WORKER") and os.environ.get("COTM_TEST_SESSION_CACHE"):
        return
    os.environ["COTM_CACHE"] = tempfile.mkdtemp(prefix="cotm-test-cache-")
    os.environ["COTM_TEST_SESSION_CACHE"] = "1"


@cache
def solved(case: str, k2: float | None = None):
    """Solve a case once per session (optionally with another k2): (PointSolution, params)."""
    import tempfile

    from cotm_bertini.params import make_params
    from cotm_bertini.point import solve_point
    from cotm_bertini.settings import Settings

    params = make_params(case, {} if k2 is None else {"k2": k2})
    folder = Path(tempfile.mkdtemp(prefix=f"cotm-test-{case}-")) / "run"
    # The CLI route: an ab-initio total-degree solve by bertini2, independent of the homotopy.
    return solve_point(params, Settings(seed=7, engine="cli"), folder=folder), params


def solve(params, settings=None):
    """The solutions table of one parameter set (no cache, no files)."""
    from cotm_bertini.point import solve_point
    from cotm_bertini.settings import Settings

    return solve_point(params, settings or Settings()).table


@pytest.fixture(scope="session")
def fixtures_dir() -> Path:
    """Real Bertini 1.6 output of the paper's three cases (tests/fixtures/bertini-1.6)."""
    return FIXTURES


def run_cli(*args: str, env: dict | None = None, cwd: Path | None = None,
            umask: int | None = None, timeout: float = 600):  # fmt: skip
    """Run `cotm-bertini` as a user would, in a fresh process (optionally under a umask)."""
    return subprocess.run(
        [sys.executable, "-m", "cotm_bertini.cli", *args],
        capture_output=True,
        text=True,
        env={**os.environ, **(env or {})},
        cwd=cwd,
        timeout=timeout,
        preexec_fn=None if umask is None else (lambda: os.umask(umask)),
    )


def same_sets(a: np.ndarray, b: np.ndarray, tol: float = 1e-8) -> bool:
    """Every row of a matches a distinct row of b to `tol` (relative), and the sizes agree."""
    if a.shape != b.shape:
        return False
    left = list(range(len(b)))
    for p in a:
        gaps = [np.abs(b[k] - p).max() / (1 + np.abs(p).max()) for k in left]
        if not gaps or min(gaps) > tol:
            return False
        left.pop(int(np.argmin(gaps)))
    return True


def lose_first_root(monkeypatch) -> list:
    """Sabotage the real route: its search drops the first root it proves (returned in the
    list, once it has): the checks downstream must see the hole."""
    from cotm_bertini.boxsearch import boxes

    real_roots, dropped = boxes._roots, []

    def lossy(land, lo, hi, k_lo, k_hi, steps=40):
        roots, found, good = real_roots(land, lo, hi, k_lo, k_hi, steps)
        if len(roots) and not dropped:
            dropped.append(roots[0])
            return roots[1:], found[1:], good[1:]
        return roots, found, good

    monkeypatch.setattr(boxes, "_roots", lossy)
    return dropped
