"""Sweeps of a framework (issue 18): Zeeman's catastrophe machine along x = 0.1, checked against a
dense scan of an independent numpy energy (tests/framework_physics.py); the CLI; resume."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from framework_physics import scan_critical_points, zeeman_energy

import cotm_bertini as cb
from cotm_bertini.cli.main import main
from cotm_bertini.continuation.runner import prepare, run_points
from cotm_bertini.continuation.spec import SweepSpec
from cotm_bertini.continuation.store import STORE_FILE, PointStore

ZEEMAN = "examples/zeeman.toml"
X = 0.1
VALUES = np.linspace(-1.0, 0.5, 301)
CLI = ["sweep", "--framework", ZEEMAN, "--set", f"x={X}", "--param", "y", "--from", "-1",
       "--to", "0.5", "--points", "301", "--workers", "1", "--quiet"]  # fmt: skip


def _minima(y: float, n: int = 20_000) -> int:
    """Local minima of V(theta) at u = (X, y): sign changes - to + of dV/dtheta on a grid."""
    theta = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    h = 1e-7
    u = (X, y)
    g = (zeeman_energy(theta + h, u, False) - zeeman_energy(theta - h, u, False)) / (2 * h)
    return int(((g < 0) & (np.roll(g, -1) >= 0)).sum())


def _scan_folds() -> list[float]:
    """The y values where the number of minima of V changes: found on a fine y grid, each
    bracket bisected on the count to 1e-8."""
    grid = np.linspace(-1.0, 0.5, 601)
    counts = [_minima(y) for y in grid]
    out = []
    for k in np.flatnonzero(np.diff(counts)):
        lo, hi, start = grid[k], grid[k + 1], counts[k]
        while hi - lo > 1e-8:
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if _minima(mid, 200_000) == start else (lo, mid)
        out.append(0.5 * (lo + hi))
    return out


@pytest.fixture(scope="module")
def cli_run(tmp_path_factory):
    """The issue's command, run in-process: (exit code, the sweep folder)."""
    root = tmp_path_factory.mktemp("fwsweep")
    code = main([*CLI, "--out", str(root), "--no-plots"])
    return code, next(root.glob("sweep-*")), root


@pytest.fixture(scope="module")
def zeeman_sweep(cli_run):
    """The same sweep through the API (the CLI's folder: nothing is solved again)."""
    fw = cb.Framework.from_toml(ZEEMAN)
    return cb.sweep(fw.replace(x=X), "y", VALUES, out=cli_run[2])


def test_cli_sweep_writes_the_framework_columns(cli_run):
    code, folder, _ = cli_run
    assert code == 0
    table = pd.read_csv(folder / "sweep.csv")
    fw = cb.Framework.from_toml(ZEEMAN)
    from cotm_bertini.analysis.framework_classify import column_names

    assert list(table.columns) == ["point", "y", *column_names(fw), "method", "lost_paths",
                                   "status", "branch"]  # fmt: skip
    assert table["point"].nunique() == 301 and (table["status"] == "ok").all()
    events = pd.read_csv(folder / "events.csv")
    assert {"kind", "branches", "y", "wheel.angle_deg", "hess_min_eig"} <= set(events.columns)


def test_folds_match_a_dense_scan_of_the_energy(zeeman_sweep):
    """Folds of the sweep where the independent scan's number of minima changes, to 1e-6."""
    events = zeeman_sweep.events
    folds = np.sort(events.loc[events["kind"] == "fold", "y"].to_numpy(float))
    expected = np.sort(_scan_folds())
    assert len(expected) == 2 and len(folds) == len(expected)
    assert np.abs(folds - expected).max() < 1e-6, (folds, expected)
    assert events.loc[events["kind"] == "fold", "refined"].all()
    # A minimum is born or dies at each: a stability change at the same value.
    changes = np.sort(events.loc[events["kind"] == "stability_change", "y"].to_numpy(float))
    assert np.allclose(changes, folds, atol=1e-12)


def test_stable_equilibria_match_the_scan_at_every_tenth_point(zeeman_sweep):
    table = zeeman_sweep.table
    for y in VALUES[::10]:
        rows = table[np.isclose(table["y"], y, atol=1e-12, rtol=0)]
        stable = np.sort(rows.loc[rows["stable"], "wheel.angle_deg"].to_numpy(float))
        scan = scan_critical_points(lambda t, y=y: zeeman_energy(t, (X, y), False), n=20_000)
        minima = np.sort([np.degrees(t) for t, kind in scan if kind == "min"])
        assert len(stable) == len(minima), y
        gap = (stable - minima + 180.0) % 360.0 - 180.0
        assert np.abs(gap).max() < 1e-4, y  # deg; the scan is coarse where V is flat


def test_points_are_continued_by_newton(tmp_path):
    """On the complex route all but the first point continue from their neighbour with a
    completeness proof; on the real route (the default here) every point is searched."""
    fw = cb.Framework.from_toml(ZEEMAN).replace(x=X)
    sw = cb.sweep(fw, "y", VALUES[:60], out=tmp_path, route="complex")
    methods = sw.record["methods"]
    newton = sum(n for m, n in methods.items() if m.startswith("Newton"))
    assert newton >= 0.95 * sw.record["rows"]
    assert sw.table.groupby("point").size().eq(16).all()  # the generic count at every point


def test_the_default_sweep_searches_every_point_on_the_real_route(zeeman_sweep):
    assert set(zeeman_sweep.record["methods"]) == {"real route (branch and bound)"}
    assert zeeman_sweep.table["is_real"].all()


def test_branches_follow_the_equilibria(zeeman_sweep):
    """The stable branch that dies at the upper fold is one branch up to it."""
    table = zeeman_sweep.table
    fold = zeeman_sweep.events.query("kind == 'fold'")["y"].max()
    before = table[(table["y"] < fold) & table["stable"] & (table["wheel.angle_deg"] > 250)]
    assert before["branch"].nunique() == 1


def test_a_bad_param_is_refused_naming_it(capsys, tmp_path):
    args = [a if a != "y" else "L01" for a in CLI]
    assert main([*args, "--out", str(tmp_path)]) == 2
    assert "'L01'" in capsys.readouterr().err and not list(tmp_path.iterdir())
    fw = cb.Framework.from_toml(ZEEMAN)
    with pytest.raises(cb.ParameterError, match="'z': unknown parameter of framework"):
        cb.sweep(fw, "z", [0.0, 1.0], out=tmp_path)


def test_resume_after_an_interruption(tmp_path, zeeman_sweep):
    """A sweep stopped after 40 points, its last record torn, then rerun: the same table."""
    fw = cb.Framework.from_toml(ZEEMAN).replace(x=X)
    spec = zeeman_sweep.spec
    folder = prepare(spec, tmp_path / spec.folder_name())

    def stop(done, _todo, _lost):
        if done == 40:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_points(spec, folder, progress=stop)
    path = folder / STORE_FILE
    path.write_bytes(path.read_bytes()[:-100])  # killed while writing the last point
    assert len(PointStore(folder).points) == 39
    again = cb.sweep(fw, "y", VALUES, out=tmp_path)
    assert again.folder == folder and again.record["stats"]["skipped"] == 39
    a, b = again.table, zeeman_sweep.table
    assert len(a) == len(b) and not a.duplicated(["point", "solution_id"]).any()
    # How a point was reached (method, path numbers) may differ. A complex-conjugate pair
    # shares every column (real parts): its two branch ids may swap, so the real rows'
    # branches are the same up to relabelling.
    route = ["method", "branch", "paths"]
    pd.testing.assert_frame_equal(
        a.drop(columns=route), b.drop(columns=route), check_exact=False, rtol=1e-7, atol=1e-9
    )
    real = a["is_real"].to_numpy()
    pairs = set(zip(a["branch"][real], b["branch"][real], strict=True))
    assert len(pairs) == len({p for p, _ in pairs}) == len({q for _, q in pairs})


def test_spec_round_trips_the_framework():
    fw = cb.Framework.from_toml("examples/zeeman_cables.toml").replace(x=0.2)
    from cotm_bertini.continuation.framework import encode

    spec = SweepSpec(fw.as_dict(), "y", (0.0, 0.1), framework=encode(fw))
    again = SweepSpec.from_json(spec.to_json())
    assert again == spec and again.key() == spec.key()
    assert again.params_at(1) == fw.replace(y=0.1)


def test_two_workers_give_the_same_rows_and_events(tmp_path):
    """Worker processes decode the framework from the spec: the rows and events of one."""
    fw = cb.Framework.from_toml(ZEEMAN).replace(x=X)
    values = np.linspace(-0.5, 0.0, 21)
    two = cb.sweep(fw, "y", values, out=tmp_path / "two", workers=2)
    one = cb.sweep(fw, "y", values, out=tmp_path / "one")
    route = ["method", "branch", "paths"]
    pd.testing.assert_frame_equal(
        two.table.drop(columns=route), one.table.drop(columns=route), check_exact=False,
        rtol=1e-7, atol=1e-9,
    )  # fmt: skip
    assert np.allclose(two.events["y"], one.events["y"], rtol=0, atol=1e-8)
    assert len(one.events) == 4
