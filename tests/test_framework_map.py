"""Design maps of frameworks (issue 19): `cb.design_map(fw, x, (..), y, (..))` and `map
--framework`. The stable counts of the grid are checked against a dense scan of Zeeman's energy
(tests/framework_physics.py: no package code); the completeness check (every change of the
stable count between grid neighbours crossed by a fold curve that changes it, or a cable
switch) is checked on curves drawn by hand, then run on the Zeeman maps."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from conftest import run_cli
from framework_physics import (
    fourbar_branch,
    fourbar_energy,
    gradient_norm,
    hessian_eigenvalues,
    pendulum_energy,
    scan_critical_points,
    zeeman_energy,
)

import cotm_bertini as cb
from cotm_bertini.catastrophe.maps import grid_values
from cotm_bertini.catastrophe.regions import count_changes, unexplained

pytestmark = pytest.mark.xdist_group("framework_examples")  # the Zeeman fold sets: solved once

EXAMPLES = "examples"
WINDOW = {"x": (-0.6, 0.8), "y": (-0.8, 0.2)}  # the window: Zeeman's diamond inside
N = 21  # grid points a side in make test


# ---- the completeness check itself, on hand-made regions and curves -------------------------


def _disc(n: int = 21, r: float = 0.3) -> pd.DataFrame:
    xs = np.linspace(0, 1, n)
    gx, gy = np.meshgrid(xs, xs, indexing="ij")
    inside = np.hypot(gx - 0.5, gy - 0.5) < r
    return pd.DataFrame(
        {"a": gx.ravel(), "b": gy.ravel(), "physical": 3, "stable": 1 + inside.ravel()}
    )


def _circle(r: float = 0.3, centre=(0.5, 0.5), points: int = 400, **cols) -> pd.DataFrame:
    t = np.linspace(0, 2 * np.pi, points)
    return pd.DataFrame(
        {"a": centre[0] + r * np.cos(t), "b": centre[1] + r * np.sin(t), "curve_id": 0,
         "arc": t, "kind": "fold", "physical": True, "changes_stable_count": True, **cols}
    )  # fmt: skip


def test_the_check_accepts_a_boundary_crossed_by_its_curve():
    regions, folds = _disc(), _circle()
    assert len(count_changes(regions, "a", "b")) > 20
    missed, tol = unexplained(regions, folds, "a", "b")
    assert missed.empty and 0 < tol < 0.01
    # A cable switch explains a change whatever its changes_stable_count.
    switch = folds.assign(kind="cable_switch", changes_stable_count=False)
    assert unexplained(regions, switch, "a", "b")[0].empty


def test_the_check_finds_changes_no_curve_explains():
    regions, folds = _disc(), _circle()
    upper = folds.b > 0.5
    silent = folds.assign(changes_stable_count=~upper)  # the upper half: folds of no consequence
    missed, _ = unexplained(regions, silent, "a", "b")
    assert len(missed) > 5 and (missed[["y0", "y1"]].min(axis=1) >= 0.5).all()
    # A curve cut into two pieces where it leaves a gap: the gap is not bridged.
    gap = folds[(folds.arc < 1.0) | (folds.arc > 2.0)]
    assert not unexplained(regions, gap, "a", "b")[0].empty
    # The same circle displaced by a grid step: the changes it no longer crosses are found.
    shifted = _circle(centre=(0.55, 0.5))
    assert not unexplained(regions, shifted, "a", "b")[0].empty


# ---- Zeeman's machine: the map's regions against a scan of V --------------------------------


def _scan_counts(x: float, y: float, cables: bool, n: int = 20_000) -> tuple[int, int]:
    """(critical points, minima) of V on the circle of wheel angles, by sign changes of dV on a
    dense grid (independent of the package)."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    v = zeeman_energy(t, (x, y), cables)
    dv = np.roll(v, -1) - v
    change = np.sign(dv) != np.sign(np.roll(dv, -1))
    minima = change & (dv < 0)
    return int(change.sum()), int(minima.sum())


ZEEMAN_ARGS = ("map", "--framework", f"{EXAMPLES}/zeeman.toml", "--quiet")
CLI_WINDOW = ("--param", "x", "--from", "-0.6", "--to", "0.8", "--param2", "y",
              "--from2", "-0.8", "--to2", "0.2", "--points", str(N))  # fmt: skip


@pytest.fixture(scope="module")
def zeeman_cli(tmp_path_factory):
    """`map --framework examples/zeeman.toml` over the issue's window: the run and its folder."""
    out = tmp_path_factory.mktemp("zeeman-map")
    run = run_cli(*ZEEMAN_ARGS, *CLI_WINDOW, "--workers", "2", "--out", str(out))
    assert run.returncode == 0, run.stderr
    return run, (out / "latest").resolve()


@pytest.fixture(scope="module", params=["zeeman", "zeeman_cables"])
def zeeman_map(request):
    """The springs' map as `map` saved it (read back), the cables' by cb.design_map."""
    fw = cb.Framework.from_toml(f"{EXAMPLES}/{request.param}.toml")
    if request.param == "zeeman":
        _, folder = request.getfixturevalue("zeeman_cli")
        rec = json.loads((folder / "run.json").read_text())
        tables = [pd.read_csv(folder / f) for f in ("folds.csv", "regions.csv")]
        return cb.DesignMap(fw, *tables, rec, tuple(rec["axes"])), False
    m = cb.design_map(fw, "x", WINDOW["x"], "y", WINDOW["y"], points=N, workers=2)
    return m, True


@pytest.mark.slow  # the Zeeman fold witness sets, solved cold: minutes (make stress)
def test_zeeman_regions_match_a_scan_of_the_energy(zeeman_map):
    m, cables = zeeman_map
    regions = m.regions
    assert list(regions.columns) == ["x", "y", "physical", "stable"]
    assert np.array_equal(np.unique(regions.x), grid_values(*WINDOW["x"], N))
    for _, r in regions.iterrows():
        critical, minima = _scan_counts(r.x, r.y, cables)
        assert (r.physical, r.stable) == (critical, minima), (r.x, r.y)
    assert set(regions.stable) == {1, 2}  # the bistable diamond, and the rest


@pytest.mark.slow  # the Zeeman fold witness sets, solved cold: minutes (make stress)
def test_zeeman_map_count_changes_are_explained(zeeman_map):
    m, cables = zeeman_map
    rec = m.record
    assert rec["count_changes"] > 10
    assert rec["unexplained_changes"] == 0, rec["unexplained"]
    assert rec["status"] == "ok" and m.status == "ok"
    missed, _ = unexplained(m.regions, m.folds, "x", "y")
    assert missed.empty
    # Without the curves that change the stable count, the changes are not explained.
    bare = m.folds.assign(changes_stable_count=False, kind="fold")
    assert len(unexplained(m.regions, bare, "x", "y")[0]) == rec["count_changes"]


@pytest.mark.slow  # the Zeeman fold witness sets, solved cold: minutes (make stress)
def test_zeeman_map_cusps_and_folds(zeeman_map):
    m, _ = zeeman_map
    folds = m.folds
    assert folds.physical.all() and len(folds) > 0
    assert folds.x.between(*WINDOW["x"]).all() and folds.y.between(*WINDOW["y"]).all()
    assert m.cusps.kind.eq("cusp").all() and len(m.cusps) == m.record["cusps"]
    assert m.axes == ("x", "y") and set(m.record["timings"]) >= {"folds", "regions"}


# ---- the command line ---------------------------------------------------------------------


@pytest.mark.parametrize(
    ("args", "named"),
    [
        (("--param", "z", "--from", "0", "--to", "1", "--param2", "y", "--from2", "0",
          "--to2", "1"), "--param 'z'"),
        (("--param", "x", "--from", "0", "--to", "1", "--param2", "y", "--from2", "0"),
         "--to2 is required"),
        (("--param", "x", "--from", "1", "--to", "0", "--param2", "y", "--from2", "0",
          "--to2", "1"), "x: the range 1 to 0 is empty"),
    ],
)  # fmt: skip
def test_map_framework_refuses_bad_input_in_one_line(tmp_path, args, named):
    run = run_cli(*ZEEMAN_ARGS, *args, "--out", str(tmp_path / "m"))
    assert run.returncode == 2, run.stderr
    assert run.stderr.count("\n") == 1 and named in run.stderr, run.stderr
    assert not (tmp_path / "m").exists() or not any((tmp_path / "m").iterdir())


@pytest.mark.slow  # the Zeeman fold witness sets, solved cold: minutes (make stress)
def test_map_framework_writes_the_map(zeeman_cli):
    run, folder = zeeman_cli
    regions = pd.read_csv(folder / "regions.csv")
    assert list(regions.columns) == ["x", "y", "physical", "stable"] and len(regions) == N * N
    folds = pd.read_csv(folder / "folds.csv")
    for col in ("x", "y", "wheel.angle_deg", "curve_id", "arc", "kind", "changes_stable_count"):
        assert col in folds.columns
    rec = json.loads((folder / "run.json").read_text())
    assert rec["window"] == {"x": [-0.6, 0.8], "y": [-0.8, 0.2]} and rec["points"] == N
    assert rec["framework"] == "zeeman" and rec["unexplained_changes"] == 0
    assert {"folds", "regions"} <= set(rec["timings"]) and rec["fold_record"]
    assert {"map", "--framework", "--points"} <= set(rec["command"])
    assert (folder / "map.png").is_file() and (folder / "sweep" / "sweep.csv").is_file()
    assert "framework_folds" not in (folder / "columns.md").read_text()  # titles, not keys
    assert "folds.csv of a framework's map" in (folder / "columns.md").read_text()
    line = next(ln for ln in run.stdout.splitlines() if ln.startswith("map:"))
    assert "in the window x -0.6..0.8, y -0.8..0.2" in line
    assert f"{len(folds)} fold points" in line
    assert f"{rec['count_changes']}, 0 not explained" in run.stdout


# ---- make stress: the completeness check on two-body and closed-loop frameworks --------------

STRESS_MAPS = {
    "double_pendulum": ("weight", (0.0, 3.0), "L0", (0.05, 1.0)),
    "fourbar": ("ex", (2.0, 4.0), "ey", (1.5, 4.0)),
}


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(STRESS_MAPS))
def test_map_count_changes_are_explained_stress(name):
    """Every stable-count change between grid neighbours is crossed by a fold curve that changes
    it (make stress: minutes each)."""
    x, xr, y, yr = STRESS_MAPS[name]
    fw = cb.Framework.from_toml(f"{EXAMPLES}/{name}.toml")
    m = cb.design_map(fw, x, xr, y, yr, points=21, workers=2)
    rec = m.record
    assert rec["sweep_status"] == "ok"
    assert rec["unexplained_changes"] == 0, rec["unexplained"]
    assert m.status == "ok"
    # Windows where the stable count changes (else the check above could not fail).
    assert rec["count_changes"] > 0 and len(m.folds)
    if name == "fourbar":
        _fourbar_against_the_loop(m)
    else:
        _pendulum_folds_against_the_torus(m)


def _pendulum_folds_against_the_torus(m) -> None:
    """Each fold row of the double pendulum is a degenerate critical point of its energy on the
    torus in closed form (tests/framework_physics.py): gradient and one Hessian eigenvalue 0."""
    assert set(m.folds.kind) <= {"fold", "cusp"}
    for _, row in m.folds.iterrows():
        th = np.radians([row["link1.angle_deg"], row["link2.angle_deg"]])

        def V(a, b, row=row):
            return pendulum_energy(a, b, weight=row.weight, L0=row.L0)

        assert gradient_norm(V, th) < 1e-6, (row.weight, row.L0)
        assert np.abs(hessian_eigenvalues(V, th)).min() < 1e-4, (row.weight, row.L0)


def _fourbar_against_the_loop(m) -> None:
    """The four-bar's map against its energy on the two assembly circles in closed form
    (tests/framework_physics.py): the grid's counts against scans, each fold row a degenerate
    critical point, each switch row a critical point with the lift cable at its free length."""
    for r in m.regions.itertuples():
        crit = [kind for b in (1, -1)
                for _, kind in scan_critical_points(
                    lambda t, b=b, r=r: fourbar_energy(t, b, r.ex, r.ey), n=50_000)]  # fmt: skip
        assert (r.physical, r.stable) == (len(crit), crit.count("min")), (r.ex, r.ey)
    h = 1e-4
    for _, row in m.folds.iterrows():
        b = fourbar_branch(row["crank.angle_deg"], row["coupler.angle_deg"])
        t, u = np.radians(row["crank.angle_deg"]), (row.ex, row.ey)
        # Small steps for the slope: at a switch V'' jumps, which a step h would see.
        slope = (fourbar_energy(t + 1e-7, b, *u) - fourbar_energy(t - 1e-7, b, *u)) / 2e-7
        assert abs(slope) < 1e-6, (u, slope)
        if row.kind != "cable_switch":  # a fold or a cusp: a degenerate critical point
            V = [fourbar_energy(t + k * h, b, *u) for k in (-1, 0, 1)]
            curvature = (V[2] - 2 * V[1] + V[0]) / h**2
            assert abs(curvature) < 1e-4, (u, curvature)
        else:  # the lift cable at 0.5: its energy at L0 = 0 is lift^2 / 2, at L0 = 100 none
            lift = fourbar_energy(t, b, *u, L0=0.0) - fourbar_energy(t, b, *u, L0=100.0)
            assert abs(np.sqrt(2 * lift) - 0.5) < 1e-6, (u, lift)
