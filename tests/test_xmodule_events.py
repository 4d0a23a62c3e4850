"""Events of an X-module sweep over its cables' free length L0c (issue 39, item 3), each kind and
place decided by the X-module's energy written here with plain numpy (tests/test_real_route.py's
_x_energy and _x_reference; no package code): a pair born where a cable reaches its free length
(a cable_switch: the switch pose solved from the gradient and d = L0c, the pair from the signs
of the two smooth pieces' Hessian determinants there), a sweep point sitting on such a switch
(left out, no fake event), an equilibrium leaving the cone point where the spring between the
tips has zero length (pull = k L0), a smooth fold (gradient and Hessian determinant both 0)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT
from test_real_route import _x_reference

import cotm_bertini as cb

XMODULE = ROOT / "examples" / "xmodule.toml"
B = np.array([1.0, 0.0])  # ground.b; ground.a is the origin; bars of length 1.3


def _tips(t):
    """bar1's tip p, bar2's tip q and their derivatives in t1, t2."""
    t1, t2 = t
    p, dp = 1.3 * np.array([np.cos(t1), np.sin(t1)]), 1.3 * np.array([-np.sin(t1), np.cos(t1)])
    q, dq = B + 1.3 * np.array([np.cos(t2), np.sin(t2)]), 1.3 * np.array([-np.sin(t2), np.cos(t2)])
    return p, dp, q, dq


def _piece_grad(t, L, taut, spring=True):
    """grad V of one smooth piece: the cables (right, left) taut or slack as `taut` says, pulling
    or pushing as springs while taut whatever their length (without the spring between the
    tips if not `spring`)."""
    p, dp, q, dq = _tips(t)
    g = np.array([0.05 * dp[1], 0.0])  # the load (0, -0.05) on bar1's tip
    links = [(p - q, dp, -dq, 1.0, 0.6, spring), (p - B, dp, 0 * dp, 2.0, L, taut[0]),
             (q, 0 * dq, dq, 2.0, L, taut[1])]  # fmt: skip
    for r, r1, r2, k, L0, on in links:
        if on:
            d = np.linalg.norm(r)
            g = g + k * (d - L0) / d * np.array([r @ r1, r @ r2])
    return g


def _piece_hess(t, L, taut, h=1e-6):
    e = np.eye(2)
    return np.stack([(_piece_grad(t + h * e[i], L, taut) - _piece_grad(t - h * e[i], L, taut))
                     / (2 * h) for i in range(2)], axis=1)  # fmt: skip


def _switch_angle(cable, L, sign):
    """The body angle at which `cable` has length L (right: bar1's, left: bar2's)."""
    c = (2.69 - L * L) / 2.6 if cable == "right" else (L * L - 2.69) / 2.6
    return sign * np.arccos(c)


def _collisions(cable, lo, hi):
    """Every equilibrium lying on `cable`'s switch (d = L0c) for L0c in [lo, hi]: Newton on
    (L0c, the other angle) from a grid, with the cable slack there (the gradient is continuous
    across the switch); each with whether a pair is born or dies there (the slack and the taut
    piece's Hessian determinants of opposite sign) or the branch goes on across."""
    j = 0 if cable == "right" else 1  # the angle the switch fixes

    def pose(x, sign):
        t = np.empty(2)
        t[j], t[1 - j] = _switch_angle(cable, x[0], sign), x[1]
        return t

    found = []
    for sign in (1, -1):
        for start in np.linspace(0, 2 * np.pi, 72, endpoint=False):
            x = np.array([0.5 * (lo + hi), start])
            f = lambda x, s=sign: _slack(cable, pose(x, s), x[0])  # noqa: E731
            for _ in range(40):
                J = np.stack([(f(x + 1e-7 * e) - f(x - 1e-7 * e)) / 2e-7 for e in np.eye(2)], 1)
                x = x - np.linalg.lstsq(J, f(x), rcond=None)[0]
                x[0] = np.clip(x[0], lo - 0.05, hi + 0.05)
            t = pose(x, sign) % (2 * np.pi)
            if np.abs(f(x)).max() < 1e-12 and lo <= x[0] <= hi:
                if all(np.abs(t - u).max() > 1e-6 for _, u, _ in found):
                    found.append((x[0], t, _pair_born(cable, t, x[0])))
    return found


def _state(cable, t, L, on):
    """(right taut, left taut) at pose t with `cable` forced to `on`, the other by its length."""
    p, _, q, _ = _tips(t)
    taut = [np.linalg.norm(p - B) > L, np.linalg.norm(q) > L]
    taut[0 if cable == "right" else 1] = on
    return tuple(taut)


def _slack(cable, t, L):
    return _piece_grad(t, L, _state(cable, t, L, False))


def _pair_born(cable, t, L):
    dets = [np.linalg.det(_piece_hess(t, L, _state(cable, t, L, on))) for on in (False, True)]
    return bool(np.sign(dets[0]) != np.sign(dets[1]))


def _counts(L):
    """(critical points, minima) of the X-module's energy at L0c = L."""
    _, _, eig = _x_reference(L0c=L)
    return len(eig), int((eig > 0).all(axis=1).sum())


def _sweep(values):
    return cb.sweep(cb.Framework.from_toml(XMODULE), "L0c", values).events


def _angles(row):
    return np.array([row["bar1.angle_deg"], row["bar2.angle_deg"]])


def _deg_gap(a, b):
    return float(np.abs((np.asarray(a) - np.asarray(b) + 180.0) % 360.0 - 180.0).max())


def test_a_pair_born_where_the_left_cable_reaches_its_free_length_is_a_cable_switch():
    """Was `fold 16+17 at L0c = 1.703500` (bracket 1.8e-4, softest eigenvalue 0.25)."""
    lo, hi = 1.695, 1.71
    ((value, pose, born),) = [c for c in _collisions("left", lo, hi) if c[2]]
    assert (np.array(_counts(hi)) - _counts(lo)).tolist() == [2, 1]  # a min and a saddle
    events = _sweep([lo, 1.70, 1.705, hi])
    assert set(events["kind"]) == {"cable_switch", "stability_change"}
    (row,) = [r for _, r in events.iterrows() if r["kind"] == "cable_switch"]
    assert abs(row["L0c"] - value) < 1e-9, (row["L0c"], value)
    assert _deg_gap(_angles(row), np.degrees(pose)) < 1e-6
    assert "a min and a saddle are born at a cable switch (left reaches its free length)" in (
        row["description"])  # fmt: skip
    assert row["hess_min_eig"] > 0.1  # both pieces regular: no fold
    assert row["refined"] and row["bracket"] < 1e-9
    (change,) = [r for _, r in events.iterrows() if r["kind"] == "stability_change"]
    assert abs(change["L0c"] - value) < 1e-9


def test_a_sweep_point_sitting_on_a_switch_makes_no_fake_event():
    """L0c = 1.64 is 1.2e-4 below sqrt(2.69), where bar1 upright or hanging has the right cable
    at its free length: its solve is incomplete. Was a `fold` with a count change of 6 and a
    `stability_change` 4 -> 2 beside it; now two pairs born at the switch, the point left out."""
    lo, hi = 1.635, 1.645
    found = _collisions("right", lo, hi)
    births = sorted((c for c in found if c[2]), key=lambda c: c[1][1])
    assert len(found) == 4 and len(births) == 2  # two go on across the switch (bar1 hanging)
    assert all(abs(v - np.sqrt(2.69)) < 1e-9 for v, _, _ in found)
    assert (np.array(_counts(hi)) - _counts(lo)).tolist() == [4, 2]
    fw = cb.Framework.from_toml(XMODULE)
    sw = cb.sweep(fw, "L0c", [lo, 1.64, hi])
    table = sw.table
    assert set(table.loc[np.isclose(table["L0c"], 1.64), "status"]) == {"incomplete"}
    events = sw.events
    assert sorted(events["kind"]) == ["cable_switch", "cable_switch", "stability_change"]
    switches = events[events["kind"] == "cable_switch"].sort_values("bar2.angle_deg")
    for (_, row), (value, pose, _) in zip(switches.iterrows(), births, strict=True):
        assert abs(row["L0c"] - value) < 1e-9
        assert _deg_gap(_angles(row), np.degrees(pose)) < 1e-6
        assert "a min and a saddle are born at a cable switch (right reaches its free length)" in (
            row["description"])  # fmt: skip
        assert "L0c = 1.64 left out" in row["description"]
    change = events[events["kind"] == "stability_change"].iloc[0]
    assert "4 below, 6 above" in change["description"]


def _cone_value(sign):
    """Where the pull of the cables and the load at the cone point (the tips meet at (0.5,
    sign 1.2)) carried through J^-T equals the spring's k L0 = 0.6: bisection."""
    p = np.array([0.5, sign * 1.2])
    t = np.array([np.arctan2(p[1], p[0]), np.arctan2(p[1], p[0] - 1.0)])

    def excess(L):
        _, dp, _, dq = _tips(t)
        g = _piece_grad(t, L, (True, True), spring=False)  # both cables 1.3 long there
        return np.linalg.norm(np.linalg.solve(np.stack([dp, -dq], axis=1).T, g)) - 0.6

    a, b = 0.85, 1.0
    for _ in range(80):
        m = 0.5 * (a + b)
        a, b = (m, b) if np.sign(excess(m)) == np.sign(excess(a)) else (a, m)
    return 0.5 * (a + b), np.degrees(t) % 360.0


def test_a_saddle_leaving_the_cone_point_is_placed_where_pull_equals_k_l0():
    """Was `physical_change` 'a saddle appears (a length reaches its limit)' at 0.904898, a
    bisection that the incomplete solves near the cone could not close."""
    value, pose = _cone_value(-1)
    assert 0.90 < value < 0.91
    events = _sweep([0.895, 0.915])  # 0.9171: the other cone's, beyond
    (row,) = [r for _, r in events.iterrows() if r["kind"] == "physical_change"]
    assert abs(row["L0c"] - value) < 1e-9, (row["L0c"], value)
    assert _deg_gap(_angles(row), pose) < 1e-6
    assert "a saddle appears" in row["description"]
    assert "cone point of spring top" in row["description"]


@pytest.mark.parametrize("lo, hi", [(1.055, 1.06)])
def test_a_smooth_fold_is_placed_where_the_hessian_is_singular(lo, hi):
    """Both cables taut: a min and a saddle born where grad V = 0 and det H = 0 (Newton on the
    three equations from each reference equilibrium); the real search sees the merging pair as
    undecided boxes within 3e-5 of it, the parabola through the probes places it."""
    count_lo, count_hi = _counts(lo), _counts(hi)
    assert (np.array(count_hi) - count_lo).tolist() == [2, 1]
    theta, _, eig = _x_reference(L0c=hi)
    soft = theta[np.argmin(np.abs(eig).min(axis=1))]
    x = np.array([*soft, hi])

    def F(x):
        taut = (True, True)
        return np.array([*_piece_grad(x[:2], x[2], taut),
                         np.linalg.det(_piece_hess(x[:2], x[2], taut))])  # fmt: skip

    for _ in range(40):
        J = np.stack([(F(x + 1e-7 * e) - F(x - 1e-7 * e)) / 2e-7 for e in np.eye(3)], axis=1)
        x = x - np.linalg.solve(J, F(x))
    assert np.abs(F(x)).max() < 1e-9 and lo < x[2] < hi
    events = _sweep([lo, hi])
    (row,) = [r for _, r in events.iterrows() if r["kind"] == "fold"]
    assert abs(row["L0c"] - x[2]) < 1e-8, (row["L0c"], x[2])
    assert row["bracket"] < 1e-6
    assert "a min and a saddle are born" in row["description"]
