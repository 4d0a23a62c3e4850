"""Sweeps continue each point from its neighbour; every continued point is checked, and a failed
check falls back to the generic route (answers compared with independent solves)."""

from __future__ import annotations

import numpy as np
import pytest

from cotm_bertini.backends import neighbour, target
from cotm_bertini.continuation.spec import SweepSpec
from cotm_bertini.params import Params
from cotm_bertini.point import solve_point
from cotm_bertini.settings import Settings


def _angles(table) -> np.ndarray:
    cols = ["gamma1_deg", "gamma2_deg", "gamma1_imag_deg", "gamma2_imag_deg", "d1", "d2"]
    return np.sort(table[cols].to_numpy(), axis=0)


NEWTON = "Newton from the neighbouring point (complete)"
SEGMENT = "continued from the neighbouring point"


@pytest.mark.parametrize(
    ("step", "method", "newton"), [(0.05, NEWTON, True), (1.0, NEWTON, True), (1.0, SEGMENT, False)]
)
def test_continued_point_equals_the_generic_route(step, method, newton, monkeypatch):
    """From L01 = 10.9 to 10.9 + step: Newton for a short step; across the fold at 11.0128 (step
    1, where a pair of real roots is born) Newton along a detour through complex L01, or (Newton
    off) the segment homotopy. Each equals an ab-initio total-degree solve by the bertini2
    command."""
    a = solve_point(Params(L01=10.9))
    assert a.warm is not None
    if not newton:
        monkeypatch.setattr(target, "newton_continue", lambda *a: (None, "off for this test"))
    b = solve_point(Params(L01=10.9 + step), warm=a.warm)
    assert b.details["homotopy"]["method"] == method
    fresh = solve_point(Params(L01=10.9 + step), Settings(engine="cli"))
    assert len(b.table) == len(fresh.table)
    assert np.abs(_angles(b.table) - _angles(fresh.table)).max() < 1e-6
    assert b.counts["stable"] == fresh.counts["stable"]


def test_a_path_double_precision_cannot_finish_is_retracked(monkeypatch):
    """L02 12.88 -> 12.74 at L01 = 8.26 (case 3): one real root passes next to a cone point (d2
    near 0; -1.3e-3 m at the target), ill-conditioned there, and its path fails in double
    precision. It is
    tracked again in adaptive precision, not the whole point solved from the generic set; the
    answer equals an ab-initio total-degree solve by the bertini2 command."""
    a = solve_point(Params.case("case3", L01=8.26, L02=12.88))
    monkeypatch.setattr(target, "newton_continue", lambda *a: (None, "off for this test"))
    b = solve_point(Params.case("case3", L01=8.26, L02=12.74), warm=a.warm)
    info = b.details["homotopy"]
    assert info["method"] == SEGMENT + " + adaptive retrack"
    assert info["retracked_adaptive"] == 1 and info["lost"] == 0
    fresh = solve_point(Params.case("case3", L01=8.26, L02=12.74), Settings(engine="cli"))
    assert len(b.table) == len(fresh.table) and b.status == fresh.status == "ok"
    assert np.abs(_angles(b.table) - _angles(fresh.table)).max() < 1e-6
    tiny = [
        t.loc[(t["d2"].abs() < 1e-2) & (t["reason"] != "zero_length_spring"), "d2"].to_numpy()
        for t in (b.table, fresh.table)
    ]
    assert len(tiny[0]) == len(tiny[1]) == 1 and abs(tiny[0][0] - tiny[1][0]) < 1e-9


def test_newton_starts_a_line_of_points_from_the_secant():
    """Points on a line: the third is started from the secant through the first two (closer
    than the second point's roots are), and what Newton finds from there is still checked."""
    from cotm_bertini.backends.generic import generic_for
    from cotm_bertini.model.compiled import parametric_system

    a = solve_point(Params(L01=5.0))
    b = solve_point(Params(L01=5.1), warm=a.warm)
    assert b.warm.before is not None and b.warm.before[0] == a.warm.params
    guess = neighbour._secant(b.warm, Params(L01=5.2))
    c = solve_point(Params(L01=5.2), warm=b.warm)
    assert c.details["homotopy"]["method"] == NEWTON
    mine = c.warm.points
    assert np.abs(guess - mine).max() < np.abs(b.warm.points - mine).max()
    assert neighbour._secant(b.warm, Params(L01=5.1, k1=3.0)) is None  # off the line
    ps = parametric_system((False, True))
    gs = generic_for(ps, 1, Settings())  # the set the solves started from (default route)
    result, why = neighbour.newton_continue(ps, gs, b.warm, Params(L01=5.2))
    assert why == "" and len(result[0]) == len(mine)


def test_newton_refuses_a_set_it_cannot_prove_complete():
    """A neighbour's set with one start doubled: two starts converge to one root, so Newton
    cannot have found every root and refuses; the point is solved by another route, and the
    answer equals a fresh solve."""
    from dataclasses import replace

    from cotm_bertini.backends.generic import generic_for
    from cotm_bertini.model.compiled import parametric_system

    a = solve_point(Params(L01=5.0))
    points = a.warm.points.copy()
    points[1] = points[0]
    doubled = replace(a.warm, points=points)
    ps = parametric_system((False, True))
    gs = generic_for(ps, 1, Settings())  # the set the solve started from (default route)
    result, why = neighbour.newton_continue(ps, gs, doubled, Params(L01=5.05))
    assert result is None and why == "two starts converged to one root"
    b = solve_point(Params(L01=5.05), warm=doubled)
    assert b.details["homotopy"]["method"] != NEWTON
    fresh = solve_point(Params(L01=5.05))
    assert np.abs(_angles(b.table) - _angles(fresh.table)).max() < 1e-9


def test_a_path_that_jumps_sends_the_point_to_the_generic_route(monkeypatch):
    """Two continued paths ending at one point (a jump): refused, solved from the generic set,
    and the method says why."""
    # Newton off, so the segment homotopy is what continues the point.
    monkeypatch.setattr(target, "newton_continue", lambda *a: (None, "off for this test"))
    real = neighbour._run_homotopy

    def jumping(*args, **kw):
        meta, pts = real(*args, **kw)
        pts = list(pts)
        pts[1] = pts[0]  # path 1 lands where path 0 did
        return meta, pts

    a = solve_point(Params(L01=5.0))
    monkeypatch.setattr(neighbour, "_run_homotopy", jumping)
    b = solve_point(Params(L01=5.1), warm=a.warm)
    method = b.details["homotopy"]["method"]
    assert method.startswith("parameter homotopy") and "two paths ended at the same point" in method
    monkeypatch.undo()
    fresh = solve_point(Params(L01=5.1))
    assert np.abs(_angles(b.table) - _angles(fresh.table)).max() < 1e-9


def test_a_start_of_another_structure_is_not_continued():
    """L01 = 0 (spring 1 zero-free-length) has other variables: the next point starts afresh."""
    a = solve_point(Params(L01=0.0))
    b = solve_point(Params(L01=0.05), warm=a.warm)
    assert "another structure" in b.details["homotopy"]["method"]
    assert b.counts["distinct_solutions"] == 22


def test_runs_follow_the_grid_in_snake_order():
    """A 3 x 4 grid: one run visits every point, each a neighbour of the one before; pending
    points of a resumed sweep are cut where the grid order skips."""
    spec = SweepSpec(Params().as_dict(), "L01", (1.0, 2.0, 3.0), "L02", (1.0, 2.0, 3.0, 4.0))
    (run,) = spec.runs(list(range(12)), parts=1)
    assert sorted(run) == list(range(12))
    assert all(spec.neighbours(a, b) for a, b in zip(run[:-1], run[1:], strict=True))
    assert spec.runs([0, 1, 5, 6], parts=1) == [[0, 1], [6, 5]]
    assert [len(r) for r in spec.runs(list(range(12)), parts=4)] == [3, 3, 3, 3]
