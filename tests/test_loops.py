"""Closed loops on the real route (boxsearch/loops.py): a four-bar's equilibria, against its
statics in closed form (tests/fourbar_statics.py: both assembly branches by circle
intersection, V along each as a function of the crank angle, its critical points by a dense
scan bisected to 1e-13), on random Grashof crank-rockers nobody chose, and against the complex
route."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT
from fourbar_statics import FourBar, random_crank_rocker
from framework_physics import scan_critical_points

import cotm_bertini as cb

# A Grashof crank-rocker whose coupler point hangs on a spring, with a crank spring and a rocker
# cable, every free length non-zero (tests/fixtures/fourbar_springs.toml is this one).
SPRUNG = FourBar((0.0, 0.0), (2.0, 0.0), 0.8, 2.0, 1.6, (1.0, 0.6), 1.0, (
    ("crank_spring", "spring", "crank", (-0.5, 1.0), 1.5, 0.4),
    ("coupler_spring", "spring", "coupler", (1.2, 2.5), 1.0, 0.6),
    ("rocker_cable", "cable", "rocker", (3.0, -1.0), 2.0, 0.7),
))  # fmt: skip
# A crank spring, a coupler spring and a rocker cable (the triple rocker's and the change
# point's).
LINKS = (
    ("s0", "spring", "crank", (-0.5, 1.0), 1.5, 0.4),
    ("s1", "spring", "coupler", (1.2, 2.5), 1.0, 0.6),
    ("c2", "cable", "rocker", (3.0, -1.0), 2.0, 0.7),
)


def _slope(fb: FourBar, theta: float, branch: int, h: float = 1e-6) -> float:
    """dV/dtheta of the statics along a branch (a central difference)."""
    return (fb.energy(theta + h, branch) - fb.energy(theta - h, branch)) / (2 * h)


def _check(fb: FourBar, res) -> None:
    """The solve's rows are the scan's critical points on each branch (crank angle to 1e-4 deg,
    the scan's own accuracy where V is flat; the statics' slope at each row below 1e-7), min or
    max as the scan says, proved, and nothing else."""
    assert res.status == "ok", res.warnings
    phys = res.physical
    got = {1: [], -1: []}
    for _, row in phys.iterrows():
        b = fb.branch_of(row["crank.angle_deg"], row["coupler.angle_deg"])
        got[b].append((row["crank.angle_deg"] % 360, row["kind"]))
    for branch in (1, -1):
        crit = scan_critical_points(lambda t, b=branch: fb.energy(t, b), n=100_000)
        want = sorted((np.degrees(t) % 360, kind) for t, kind in crit)
        have = sorted(got[branch])
        assert len(have) == len(want), (branch, have, want)
        for (a, ka), (b, kb) in zip(have, want, strict=True):
            gap = abs((a - b + 180) % 360 - 180)
            assert gap < 1e-4 and ka == kb, (branch, have, want)
            assert abs(_slope(fb, np.radians(a), branch)) < 1e-7, (branch, a)


def test_the_sprung_four_bar_is_its_statics():
    """The four-bar of the fixture: every equilibrium on both assembly branches, proved."""
    path = ROOT / "tests" / "fixtures" / "fourbar_springs.toml"
    text = "".join(ln for ln in path.read_text().splitlines(True) if not ln.startswith("#"))
    assert text == SPRUNG.toml("fourbar_springs")  # the fixture is this mechanism
    res = cb.solve(cb.Framework.from_toml(path), cache=False)
    assert "real_search" in res.record["details"]  # the real route's
    _check(SPRUNG, res)
    assert res.morse["applicable"] and res.morse["ok"], res.morse


@pytest.mark.parametrize("seed", range(6))
def test_random_crank_rockers_are_their_statics(seed, tmp_path):
    """Random Grashof crank-rockers with springs and cables anywhere: the real route's rows
    are the closed-form statics' critical points on both branches."""
    fb = random_crank_rocker(np.random.default_rng(seed))
    path = tmp_path / "fb.toml"
    path.write_text(fb.toml(f"crank_rocker_{seed}"))
    _check(fb, cb.solve(cb.Framework.from_toml(path), cache=False))


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(6, 26))
def test_more_random_crank_rockers_are_their_statics(seed, tmp_path):
    test_random_crank_rockers_are_their_statics(seed, tmp_path)


def test_the_four_bar_on_both_routes_agrees():
    """examples/fourbar.toml: the real route's rows and kinds are the complex route's."""
    fw = cb.Framework.from_toml(ROOT / "examples" / "fourbar.toml")
    real, cplx = cb.solve(fw, cache=False), cb.solve(fw, route="complex")
    assert "real_search" in real.record["details"] and real.status == cplx.status == "ok"
    cols = ["crank.angle_deg", "coupler.angle_deg", "rocker.angle_deg"]
    a = real.physical.sort_values(cols[0])
    b = cplx.physical.sort_values(cols[0])
    np.testing.assert_allclose(a[cols].to_numpy(float), b[cols].to_numpy(float), atol=1e-8)
    assert list(a["kind"]) == list(b["kind"])


def test_a_fold_on_the_loop_is_where_the_statics_lose_a_pair(tmp_path):
    """examples/fourbar.toml swept over ex on the real route: one fold, located by Newton on
    the fold system of F (the loop's critical points) and bracketed by two proved solves; the
    closed-form statics of tests/framework_physics.py have two critical points more on one
    side of it, 1e-5 away, than on the other."""
    from framework_physics import fourbar_energy

    fw = cb.Framework.from_toml(ROOT / "examples" / "fourbar.toml")
    sw = cb.sweep(fw, "ex", [2.6, 2.65, 2.7, 2.75, 2.8], out=tmp_path)
    folds = sw.events[sw.events["kind"] == "fold"]
    assert sw.status == "ok" and len(folds) == 1
    at = float(folds["ex"].iloc[0])

    def count(ex: float) -> int:
        return sum(len(scan_critical_points(lambda t, b=b: fourbar_energy(t, b, ex=ex)))
                   for b in (1, -1))  # fmt: skip

    assert abs(count(at - 1e-5) - count(at + 1e-5)) == 2


@pytest.mark.slow
def test_a_triple_rocker_on_both_routes_agrees(tmp_path):
    """A non-Grashof four-bar (no link turns fully: its poses are one circle through both
    assembly branches, which meet where the crank turns back): the real route's rows and kinds
    are the complex route's (whose first solve tracks 4,096 paths, some 3 minutes)."""
    fb = FourBar((0.0, 0.0), (2.6, 0.0), 1.2, 1.3, 1.4, (0.6, 0.4), 0.8, LINKS)
    path = tmp_path / "triple_rocker.toml"
    path.write_text(fb.toml("triple_rocker"))
    fw = cb.Framework.from_toml(path)
    real, cplx = cb.solve(fw, cache=False), cb.solve(fw, route="complex")
    assert real.status == cplx.status == "ok" and real.morse["ok"]
    cols = ["crank.angle_deg", "coupler.angle_deg", "rocker.angle_deg"]
    a, b = real.physical.sort_values(cols[0]), cplx.physical.sort_values(cols[0])
    np.testing.assert_allclose(a[cols].to_numpy(float), b[cols].to_numpy(float), atol=1e-8)
    assert list(a["kind"]) == list(b["kind"]) and len(a) == 4


def test_a_change_point_four_bar_says_what_it_could_not_prove(tmp_path):
    """A four-bar at Grashof's change point (s + l = p + q: it folds flat, and its curve of
    poses crosses itself there, J of rank 1): the search cannot prove the box at the flat pose,
    which is reported as a degenerate row, with the status incomplete and the boxes left said;
    the smooth equilibria are still the statics' (both branches meet at the flat pose)."""
    fb = FourBar((0.0, 0.0), (2.5, 0.0), 1.0, 2.0, 1.5, (0.6, 0.4), 0.8, LINKS)
    path = tmp_path / "change_point.toml"
    path.write_text(fb.toml("change_point"))
    res = cb.solve(cb.Framework.from_toml(path), cache=False)
    assert res.status == "incomplete"
    assert any("undecided" in w for w in res.warnings)
    flat = res.physical[res.physical["kind"] == "degenerate"]
    assert len(flat) == 1 and abs(flat["crank.angle_deg"].iloc[0] % 360 - 180) < 1e-4
    smooth = res.physical[res.physical["kind"] != "degenerate"]
    for _, row in smooth.iterrows():
        b = fb.branch_of(row["crank.angle_deg"], row["coupler.angle_deg"])
        assert abs(_slope(fb, np.radians(row["crank.angle_deg"]), b)) < 1e-7
