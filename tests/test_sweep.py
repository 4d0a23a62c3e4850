"""Sweeps: parameter homotopy against fresh solves, resume after kill -9, the Dask path."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from conftest import solve

from cotm_bertini.continuation.runner import assemble, prepare, run_points
from cotm_bertini.continuation.spec import SweepSpec
from cotm_bertini.continuation.store import stored_indices
from cotm_bertini.params import TABLE1, Params, make_params
from cotm_bertini.settings import Settings


def _physical(table: pd.DataFrame) -> np.ndarray:
    phys = table[table["physical"]]
    return phys[["gamma1_deg", "gamma2_deg"]].to_numpy()


def _same_points(a: np.ndarray, b: np.ndarray, tol: float = 1e-6) -> bool:
    if a.shape != b.shape:
        return False
    for p in a:
        d = np.abs((b - p + 180.0) % 360.0 - 180.0).max(axis=1)
        if d.min() > tol:
            return False
    return True


@pytest.fixture(scope="module")
def sweep21(tmp_path_factory):
    """The paper's sweep at 21 points (L01 from 0 to 12 m, L02 = 0, Table 1)."""
    spec = SweepSpec.linspace(Params(**TABLE1), "L01", 0.0, 12.0, 21)
    folder = prepare(spec, tmp_path_factory.mktemp("sweep"))
    stats = run_points(spec, folder, workers=2)
    return spec, folder, assemble(spec, folder), stats


def test_sweep_points_equal_fresh_solves(sweep21):
    """Every point's physical equilibria are those of an ab-initio bertini2 solve there."""
    spec, _, table, stats = sweep21
    assert stats["solved"] == 21 and stats["lost_paths"] == 0
    for k, values in enumerate(spec.grid()):
        fresh = solve(make_params(None, {**TABLE1, **values}), Settings(engine="cli"))
        rows = table[table["point"] == k]
        assert len(rows) == len(fresh), values  # every finite solution, not just physical ones
        assert _same_points(_physical(rows), _physical(fresh)), values
        assert rows["stable"].sum() == fresh["stable"].sum()


def test_dask_cluster_gives_the_same_rows(sweep21, tmp_path):
    """The same points on a dask.distributed LocalCluster give the same rows as local processes."""
    from distributed import LocalCluster

    spec0, folder0, _, _ = sweep21
    # The first 6 points of the local sweep (L01 = 0, 0.6, ..., 3), solved afresh on the cluster.
    sub = SweepSpec.linspace(Params(**TABLE1), "L01", 0.0, 3.0, 6)
    folder_sub = prepare(sub, tmp_path / "sub")
    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        stats = run_points(sub, folder_sub, scheduler=cluster.scheduler_address)
    assert stats["solved"] == 6
    dask_rows = assemble(sub, folder_sub)
    local = assemble(spec0, folder0)
    local = local[local["point"] < 6].reset_index(drop=True)
    # The route to a point (its first one of a run is solved from the generic set, the others
    # continued from their neighbour) depends on how the points were cut into runs: compare the
    # solutions, not the `method` column.
    pd.testing.assert_frame_equal(
        dask_rows.drop(columns="method"), local.drop(columns="method"), check_exact=False,
        rtol=1e-9,
    )  # fmt: skip


def _cli(*args: str, **kw):
    return subprocess.Popen(
        [sys.executable, "-m", "cotm_bertini.cli", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        **kw,
    )


def test_resume_after_kill_9(tmp_path):
    """kill -9 mid-sweep, rerun the same command: the CSV equals an uninterrupted run's."""
    args = [
        "sweep",
        "--param",
        "L01",
        "--from",
        "1",
        "--to",
        "11",
        "--points",
        "31",
        "--workers",
        "1",
        "--no-plots",
        "--quiet",
    ]
    proc = _cli(*args, "--out", str(tmp_path / "a"))
    deadline = time.time() + 120
    points: set[int] = set()
    while time.time() < deadline:
        folders = list((tmp_path / "a").glob("sweep-*"))
        points = stored_indices(folders[0]) if folders else set()
        if len(points) >= 5:
            break
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    folder = next((tmp_path / "a").glob("sweep-*"))
    stored = stored_indices(folder)
    assert 5 <= len(points) <= len(stored) < 31, "the kill should land mid-sweep"
    assert not (folder / "sweep.csv").exists()
    again = _cli(*args, "--out", str(tmp_path / "a"))
    out, err = again.communicate(timeout=300)
    assert again.returncode == 0, err
    assert "resumed" in out
    clean = _cli(*args, "--out", str(tmp_path / "b"))
    clean.communicate(timeout=300)
    assert clean.returncode == 0
    a = pd.read_csv(folder / "sweep.csv")
    b = pd.read_csv(next((tmp_path / "b").glob("sweep-*")) / "sweep.csv")
    assert len(a) == len(b) and not a.duplicated(["point", "solution_id"]).any()
    # The resumed run solves its first point from the generic set, the uninterrupted one
    # continues it from its neighbour: same solutions, another `method`.
    pd.testing.assert_frame_equal(
        a.drop(columns="method"), b.drop(columns="method"), check_exact=False, rtol=1e-9
    )


def test_bad_sweep_requests():
    """Unknown parameter, empty range, a range that leaves the valid domain: exit 2, one line."""
    for args, needle in (
        (["--param", "q9"], "q9"),
        (["--points", "0"], "--points 0"),
        (["--param", "k1", "--from", "-1", "--to", "2"], "k1 = -1.0"),
    ):
        p = _cli("sweep", *args, "--out", "/nonexistent/never", "--quiet")
        out, err = p.communicate(timeout=60)
        assert p.returncode == 2, (args, err)
        assert needle in err and len(err.strip().splitlines()) == 1, err
        assert not Path("/nonexistent/never").exists()
