"""Fold curves (issue 10, part 1, closed-form route): every fold point is an equilibrium with a
singular Hessian by the independent energy code, direct solves either side differ by two
physical equilibria, and the paper's 1-D fold (L01 = 11.0128 m at L02 = 0) lies on the curve."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

import cotm_bertini as cb
from cotm_bertini.model.compiled import energy_gradient, energy_hessian
from cotm_bertini.point import solve_point
from cotm_bertini.settings import Tolerances

P = cb.Params.case("case3")


@pytest.fixture(scope="module")
def folds():
    return cb.fold_curves(P)


def test_fold_points_are_degenerate_equilibria(folds):
    phys = folds[folds.physical]
    assert len(phys) > 1000
    for _, r in phys.iloc[::40].iterrows():
        q = P.replace(L01=r.L01, L02=r.L02)
        g1, g2 = math.radians(r.gamma1_deg), math.radians(r.gamma2_deg)
        scale = max(P.k1, P.k2) * P.L3 * max(r.L01, r.L02, r.d1, r.d2)
        assert np.abs(energy_gradient(q, g1, g2)[0]).max() < 1e-8 * scale
        hess = energy_hessian(q, g1, g2)[0]
        assert abs(np.linalg.det(hess)) < 1e-8 * np.linalg.norm(hess) ** 2
        assert abs(r.hess_eig_min) < 1e-8 * np.linalg.norm(hess)


def _crossings(folds, value: float, axis: str = "L02") -> np.ndarray:
    """Where the sampled fold curves cross the line `axis` = value: the other free length,
    interpolated between fold points within 0.1 m of the line on either side that are
    neighbouring samples of one curve (poses within 1 deg but not the same pose, so not the two
    roots of one pose; free lengths within 0.1 m)."""
    other = "L01" if axis == "L02" else "L02"
    pts = folds[[other, axis, "gamma1_deg", "gamma2_deg"]].to_numpy(float)
    pts = pts[np.abs(pts[:, 1] - value) < 0.1]
    below, above = pts[pts[:, 1] < value], pts[pts[:, 1] >= value]
    gap = below[:, None, 2:] - above[None, :, 2:]
    gap = np.abs((gap + 180) % 360 - 180).max(axis=2)
    close = np.abs(below[:, None, 0] - above[None, :, 0]) < 0.1
    i, j = np.nonzero((gap < 1.0) & (gap > 1e-9) & close)
    a, b = below[i], above[j]
    return a[:, 0] + (value - a[:, 1]) / (b[:, 1] - a[:, 1]) * (b[:, 0] - a[:, 0])


def test_the_paper_fold_lies_on_the_curve(folds):
    # The 1-D sweep of the paper (Fig. 5, L02 = 0) has its fold at L01 = 11.0128 m.
    crossings = _crossings(folds, 0.0)
    assert np.abs(crossings - 11.0128).min() < 2e-3


@pytest.mark.parametrize("index", [0, 1, 2])
def test_direct_solves_either_side_differ_by_two(folds, index):
    rng = np.random.default_rng(100 + index)
    plain = folds.physical & (folds.kind == "fold")
    phys = folds[plain & folds.L01.between(1, 13) & folds.L02.between(1, 13)]
    r = phys.iloc[int(rng.integers(len(phys)))]
    counts = []
    for step in (-1e-4, 1e-4):
        res = cb.solve(P.replace(L01=r.L01 + step, L02=r.L02), cache=False)
        counts.append(len(res.physical))
    assert abs(counts[0] - counts[1]) == 2


def _neighbour_segments(folds, window) -> np.ndarray:
    """The sampled fold curves as segments (window units, for regions.uncrossed): every
    pair of fold points that are neighbouring samples of one curve (poses within 1 deg but not
    the same pose, free lengths within 0.1 m), as in `_crossings`."""
    (x0, x1), (y0, y1) = window
    pts = folds[["L01", "L02", "gamma1_deg", "gamma2_deg"]].to_numpy(float)
    pts = pts[np.argsort(pts[:, 0])]
    ends = np.searchsorted(pts[:, 0], pts[:, 0] + 0.1)
    segs = []
    for i in range(len(pts)):
        near = pts[i + 1 : ends[i]]
        gap = np.abs((near[:, 2:] - pts[i, 2:] + 180) % 360 - 180).max(axis=1)
        close = np.abs(near[:, 1] - pts[i, 1]) < 0.1
        for q in near[(gap < 1.0) & (gap > 1e-9) & close]:
            segs.append((pts[i, 0], pts[i, 1], q[0], q[1]))
    scale = np.array([x1 - x0, y1 - y0] * 2)
    return (np.array(segs) - np.array([x0, y0] * 2)) / scale


def test_stable_count_changes_only_across_fold_curves(folds):
    """Completeness on the paper geometry: wherever direct solves on neighbouring grid points
    disagree on the number of stable equilibria, a fold curve crosses the segment between them
    (41 x 41 over (0, 14] with COTM_STRESS=full, 11 x 11 otherwise). The check is the one of
    every framework's map (catastrophe.regions), on the paper's sampled curve."""
    from cotm_bertini.catastrophe.regions import count_changes, grid_window, uncrossed

    n = 41 if os.environ.get("COTM_STRESS") == "full" else 11
    lo = 14.0 / n
    regions = cb.design_map(P, (lo, 14.0), (lo, 14.0), n, workers=2).regions
    window = grid_window(regions, "L01", "L02")
    changes = count_changes(regions, "L01", "L02")
    segments = _neighbour_segments(folds, window)
    missed = uncrossed(changes, segments, window, 1e-3 / (14.0 - lo))
    assert len(changes) > 0
    assert missed.empty, missed


def test_fold_curves_beside_the_sweep_are_the_same(monkeypatch):
    """With two workers the paper's fold curves are computed in a process of their own beside
    the sweep's set-up; the map is the one a single worker makes (which starts no such
    process: the workers setting is honoured)."""
    from cotm_bertini.api import maps

    window = ((9.0, 13.0), (0.5, 4.5))
    two = cb.design_map(P, *window, 3, workers=2)

    def refused(job):
        raise AssertionError("a second process with workers = 1")

    monkeypatch.setattr(maps, "_FoldsAside", refused)
    one = cb.design_map(P, *window, 3, workers=1)
    pd.testing.assert_frame_equal(two.folds, one.folds)
    pd.testing.assert_frame_equal(two.regions, one.regions)
    assert len(two.folds) > 100 and two.record["timings"]["folds"] > 0


def _map_cli(*args: str) -> subprocess.CompletedProcess:
    cmd = [sys.executable, "-m", "cotm_bertini.cli", "map", "--quiet", *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=600)


@pytest.mark.parametrize(
    ("args", "named"),
    [
        (("--param", "p5y"), "--param p5y"),
        (("--from", "5", "--to", "5"), "L01: the range 5 to 5 is empty"),
        (("--from2", "-1"), "L02 from -1"),
        (("--points", "1"), "--points 1"),
    ],
)
def test_map_refuses_bad_input_in_one_line(tmp_path, args, named):
    run = _map_cli(*args, "--out", str(tmp_path / "m"))
    assert run.returncode == 2
    assert run.stderr.count("\n") == 1 and named in run.stderr
    assert not (tmp_path / "m").exists() or not any((tmp_path / "m").iterdir())


def test_map_writes_folds_regions_and_the_picture(tmp_path):
    window = ("--from", "10", "--to", "12", "--from2", "10", "--to2", "12", "--points", "5")
    run = _map_cli(*window, "--workers", "1", "--out", str(tmp_path))
    assert run.returncode == 0, run.stderr
    folder = tmp_path / "latest"
    folds = pd.read_csv(folder / "folds.csv")
    for col in ("L01", "L02", "gamma1_deg", "gamma2_deg", "d1", "d2", "curve_id", "kind"):
        assert col in folds.columns
    assert folds.L01.between(10, 12).all() and folds.L02.between(10, 12).all()
    regions = pd.read_csv(folder / "regions.csv")
    assert len(regions) == 25 and (regions.stable <= regions.physical).all()
    case3 = regions[(regions.L01 == 11.5) & (regions.L02 == 11.5)]
    assert int(case3.stable.iloc[0]) == len(cb.solve(P).stable)
    assert (folder / "map.png").is_file() and (folder / "run.json").is_file()
    cert = json.loads((folder / "run.json").read_text())["certificate"]
    assert cert["status"] == "proved" and cert["statement"].startswith("proved: the parallel")
    assert cert["leaves"] > 1000 and cert["edge_crossings"] > 1000
    assert "python-flint" in cert["library"]


def test_no_physical_fold_point_has_a_zero_length_spring(folds):
    """Issue 16 item 15: where a fold curve runs into a zero-length configuration of a spring
    (V not smooth there) it ends: kind zero_length, not physical, by the solutions' rule. The
    paper geometry's spring 2 has two (the case 3 rows of reason zero_length_spring)."""
    threshold = Tolerances().zero_length * P.L3
    phys = folds[folds.physical]
    assert (phys[["d1", "d2"]].to_numpy() >= threshold).all()
    assert set(phys.kind) <= {"fold", "cusp"}
    ends = folds[folds.kind == "zero_length"]
    assert not ends.physical.any() and (ends[["d1", "d2"]].min(axis=1) < threshold).all()
    zero = solve_point(P).table
    zero = zero[(zero.reason == "zero_length_spring") & zero.is_real & (zero.d1.abs() > 1)]
    for _, row in zero.drop_duplicates(["gamma1_deg", "gamma2_deg"]).iterrows():
        pose = ends[["gamma1_deg", "gamma2_deg"]].to_numpy(float)
        gap = np.abs((pose - [row.gamma1_deg, row.gamma2_deg] + 180) % 360 - 180).max(axis=1)
        assert gap.min() < 0.01, (row.gamma1_deg, row.gamma2_deg)
    # The end the map reported as a cusp (L01 = 10.9677, L02 = 5.7659, gamma 122.9, 46.3 deg).
    near = ends[(ends.L01 - 10.9677).abs().lt(1e-3) & (ends.L02 - 5.7659).abs().lt(1e-3)]
    assert len(near) == 1 and abs(near.gamma1_deg.iloc[0] - 122.9053) < 1e-3


def test_cusps_are_degenerate_folds(folds):
    """At a cusp of a tensioned fold curve the energy's third derivative along the Hessian's null
    vector vanishes too (by finite differences of the energy code's Hessian); at ordinary
    tensioned fold points it does not."""
    cusp = folds[(folds.kind == "cusp") & folds.physical]
    assert set(cusp.family) == {"relaxed", "tensioned"} and len(cusp) >= 6

    def cubic(r, eps=1e-5):
        q = P.replace(L01=r.L01, L02=r.L02)
        g = np.radians([r.gamma1_deg, r.gamma2_deg])
        hess = energy_hessian(q, *g)[0]
        ev, vec = np.linalg.eigh(hess)
        w = vec[:, np.argmin(abs(ev))]
        along = [w @ energy_hessian(q, *(g + e * w))[0] @ w for e in (eps, -eps)]
        return abs(along[0] - along[1]) / (2 * eps) / np.linalg.norm(hess)

    for _, r in cusp[cusp.family == "tensioned"].iterrows():
        assert cubic(r) < 1e-6
    plain = folds[(folds.kind == "fold") & (folds.family == "tensioned") & folds.physical]
    assert np.median([cubic(r) for _, r in plain.sample(20, random_state=0).iterrows()]) > 1e-3
