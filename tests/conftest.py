"""Shared fixtures: paths, and each case solved once per test session."""

from __future__ import annotations

import sys
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
FIXTURES = ROOT.parent / "shared" / "fixtures" / "bertini-1.6"
sys.path.insert(0, str(Path(__file__).resolve().parent))


def pytest_configure(config):
    """One fresh cache for the whole session (generic solution sets and solves): tests never
    read a cache left by an earlier run or by a user, and child processes inherit it."""
    import os
    import tempfile

    os.environ["COTM_CACHE"] = tempfile.mkdtemp(prefix="cotm-test-cache-")


@cache
def solved(case: str, k2: float | None = None):
    """Solve a case once per session (optionally with another k2) and keep the Solved record."""
    import tempfile

    from cotm_bertini.geometry import make_params
    from cotm_bertini.pipeline import solve_in
    from cotm_bertini.settings import Settings

    params = make_params(case, {} if k2 is None else {"k2": k2})
    folder = Path(tempfile.mkdtemp(prefix=f"cotm-test-{case}-")) / "run"
    # The CLI route: an ab-initio total-degree solve by bertini2, independent of the homotopy.
    return solve_in(folder, params, Settings(seed=7, engine="cli")), params


@pytest.fixture(scope="session")
def fixtures_dir() -> Path:
    if not FIXTURES.is_dir():
        pytest.fail(f"Bertini 1.6 fixtures not found at {FIXTURES} (shared/ must sit beside main)")
    return FIXTURES
