"""Fold curves, cusps and cable switches traced in chart angles (catastrophe/chart_curves.py:
grad V and the minimally augmented fold function of the chart Hessian), against routes that
share none of its equations: the bordered Hessian's determinant of the polynomial system in the
bodies' c, s (catastrophe/framework_folds.py, model/framework/folds.py), and the plain-numpy
statics of tests/tensegrity_physics.py (Newton on its own Lagrange conditions, its Hessian on
the bars' tangent space)."""

from __future__ import annotations

from functools import cache

import numpy as np
import pandas as pd
import pytest
import tensegrity_physics as tp
from conftest import ROOT

import cotm_bertini as cb
from cotm_bertini.boxsearch.families import real_equilibria
from cotm_bertini.catastrophe.chart_curves import Seed, chart_fold_curves
from cotm_bertini.catastrophe.curve_trace import Window, newton, tangent, trace
from cotm_bertini.catastrophe.fold_sweep import curve_equations, long_enough
from cotm_bertini.catastrophe.framework_folds import framework_fold_curves
from cotm_bertini.continuation.charts import ChartPlane, advance
from cotm_bertini.continuation.charts import newton as chart_newton
from cotm_bertini.errors import ParameterError
from cotm_bertini.model.framework.folds import curve_system

ZEEMAN = ((-0.6, 0.8), (-0.8, 0.2))  # x, y
XMODULE = ((1.0, 1.6), (-0.2, 0.0))  # L0c, fy: the benchmark window
NEAR = 1e-3  # window diagonals: a traced point's farthest distance from the other route's curve
SPHERE = ROOT / "tests" / "fixtures" / "zeeman_sphere.toml"


def _diagonal(window) -> float:
    return float(np.hypot(*(hi - lo for lo, hi in window)))


def _polyline_distance(points: np.ndarray, line: np.ndarray) -> np.ndarray:
    """Each point's (m, 2) distance to the polyline `line` (k, 2)."""
    a, ab = line[:-1], np.diff(line, axis=0)
    rel = points[:, None, :] - a[None]
    t = np.clip((rel * ab).sum(-1) / np.maximum((ab * ab).sum(-1), 1e-300), 0.0, 1.0)
    return np.linalg.norm(rel - t[..., None] * ab, axis=-1).min(axis=1)


def _on_lines(table: pd.DataFrame, names, lines: list[np.ndarray], window) -> None:
    """Every fold point of `table` within NEAR window diagonals of one of `lines`, curve by
    curve (a curve on one line)."""
    for _, curve in table[table["kind"] == "fold"].groupby("curve_id"):
        xy = curve[list(names)].to_numpy()
        assert min(_polyline_distance(xy, line).max() for line in lines) <= NEAR * _diagonal(window)


@cache
def _zeeman_reference() -> pd.DataFrame:
    """Zeeman's machine's fold curves and cusps by the determinant route (2 s)."""
    fw = cb.Framework.from_toml(ROOT / "examples" / "zeeman_cables.toml")
    return framework_fold_curves(fw, "x", ZEEMAN[0], "y", ZEEMAN[1], kinds=("fold",))[0]


def _zeeman_seeds(to_chart) -> list[Seed]:
    """Two fold points of each curve of the reference, the wheel's angle turned into chart
    angles by `to_chart`; the second lies on the curve the first traces (so it is skipped)."""
    ref = _zeeman_reference()
    out = []
    for _, curve in ref[ref["kind"] == "fold"].groupby("curve_id"):
        for row in (curve.iloc[len(curve) // 3], curve.iloc[2 * len(curve) // 3]):
            out.append(Seed("fold", np.array([*to_chart(row["wheel.angle_deg"]), row.x, row.y])))
    return out


def _zeeman_checks(table: pd.DataFrame, record: dict) -> None:
    """The traced curves on the reference's polylines, each traced once, its cusps found."""
    ref = _zeeman_reference()
    lines = [c.sort_values("arc")[["x", "y"]].to_numpy()
             for _, c in ref[ref["kind"] == "fold"].groupby("curve_id")]  # fmt: skip
    assert len(record["curves"]) == len(lines) and record["seeds_on_traced"] == len(lines)
    _on_lines(table, ("x", "y"), lines, ZEEMAN)
    theirs = ref.loc[ref["kind"] == "cusp", ["x", "y"]].to_numpy()
    ours = table.loc[table["kind"] == "cusp", ["x", "y"]].to_numpy()
    assert len(theirs) == 4 and len(ours) == len(theirs)
    for p in theirs:
        assert np.hypot(*(ours - p).T).min() <= 1e-5 * _diagonal(ZEEMAN)
    assert not record["warnings"] and table["physical"].all()


def test_zeeman_folds_and_cusps_on_the_torus_are_the_determinant_routes():
    """Zeeman's machine (a circle of wheel angles): its closed fold curve, its four cusps."""
    fw = cb.Framework.from_toml(ROOT / "examples" / "zeeman_cables.toml")
    plane = ChartPlane(fw, "x", "y")
    table, record = chart_fold_curves(plane, _zeeman_seeds(lambda deg: [np.radians(deg)]),
                                      *ZEEMAN)  # fmt: skip
    _zeeman_checks(table, record)
    assert record["curves"][0]["ends"] == ["closed", "closed"]
    # a minimum meets an index-1 saddle all along (one angle: the nearest 0 is the only one)
    assert table["changes_stable_count"].astype(bool).all()


def _fold_seeds(plane: ChartPlane, p0, p1) -> list[Seed]:
    """Rough fold points on the segment p0 -> p1: each equilibrium at p0 (the real route)
    followed towards p1 (charts.advance) where it is lost with a Hessian nearly singular."""
    _, found = real_equilibria(plane.fw.replace(**{plane.x: p0[0], plane.y: p0[1]}))
    got = advance(plane, found.roots, p0, p1)
    out = []
    for theta, ok, f in zip(got.points, got.ok, got.reached, strict=True):
        p = np.asarray(p0) + f * (np.asarray(p1) - np.asarray(p0))
        if not ok and abs(plane.index(theta[None], p)[1][0]) < 0.1:  # a turn, not a kink
            out.append(Seed("fold", np.concatenate([theta, p])))
    return out


def _determinant_curve(plane: ChartPlane, z: np.ndarray, taut, window) -> np.ndarray:
    """The fold curve through z of the taut set's determinant system (model/framework/folds.py:
    variables c, s, d, w; framework_folds' steps), traced from z brought onto it: (m, 2)."""
    (xr, yr), n = window, plane.n
    centre = plane.fw.replace(**{plane.x: np.mean(xr), plane.y: np.mean(yr)})
    cs = curve_system(centre, taut, plane.x, plane.y, "")
    (sx, sy), nz = cs.scales, len(cs.variables)
    ends = plane.land(z[n:]).endpoints_of(taut, z[None, :n])
    assert list(ends.variables) == list(cs.variables)
    w = np.concatenate([ends.points[0].real, [z[n] / sx, z[n + 1] / sy]])
    eqs = curve_equations(cs)
    t = tangent(eqs, w, w)
    w = newton(eqs, w, w, lambda v: (t @ (v - w), t))
    win = Window(nz, nz + 1, (xr[0] / sx, yr[0] / sy), (xr[1] / sx, yr[1] / sy), (sx, sy))
    got = trace(eqs, w, win, 0.002, 0.05, long_enough(cs), relative=True)
    return got.points[:, nz:] * np.array([sx, sy])


def test_xmodule_folds_in_chart_angles_lie_on_the_determinant_curves():
    """The X-module's fold curves in the benchmark window (two angles: the bordered system
    proper), each traced point within NEAR of the determinant system's curve through it."""
    fw = cb.Framework.from_toml(ROOT / "examples" / "xmodule.toml")
    plane = ChartPlane(fw, "L0c", "fy")
    seeds = _fold_seeds(plane, (1.3, -0.1), (1.0, -0.1))
    assert len(seeds) >= 2
    table, record = chart_fold_curves(plane, seeds, *XMODULE)
    assert not record["warnings"] and len(record["curves"]) >= 2
    for cid, curve in table.groupby("curve_id"):
        start = curve.iloc[len(curve) // 2]
        taut = tuple(start["taut"].split())
        z = np.concatenate([np.radians([start[f"{b}.angle_deg"] for b in ("bar1", "bar2")]),
                            [start["L0c"], start["fy"]]])  # fmt: skip
        line = _determinant_curve(plane, z, taut, XMODULE)
        _on_lines(curve, ("L0c", "fy"), [line], XMODULE)
        # All of the other curve too, but for its last 0.01 in fy: the window's edge fy = 0
        # (no load: the module is mirror-symmetric) is where the two curves meet, and Newton
        # converges only linearly there: both routes stop a little short of it.
        ours = curve.sort_values("arc")[["L0c", "fy"]].to_numpy()
        inner = line[line[:, 1] < -0.01]
        assert _polyline_distance(inner, ours).max() <= NEAR * _diagonal(XMODULE)
        assert record["curves"][cid]["ends"] == ["edge", "edge"]


def test_bad_seeds_are_refused_in_one_line():
    fw = cb.Framework.from_toml(ROOT / "examples" / "zeeman_cables.toml")
    plane = ChartPlane(fw, "x", "y")
    z = np.zeros(3)
    with pytest.raises(ParameterError, match="seed kind: 'cusp'"):
        chart_fold_curves(plane, [Seed("cusp", z)], (0, 1), (0, 1))
    with pytest.raises(ParameterError, match="seed cable: 'band_q'"):
        chart_fold_curves(plane, [Seed("cable_switch", z, "band_q")], (0, 1), (0, 1))
    with pytest.raises(ParameterError, match="x: window"):
        chart_fold_curves(plane, [], (1, 0), (0, 1))


def _sphere_reference(x: float, y: float) -> tp.Spatial:
    """tests/fixtures/zeeman_sphere.toml as the plain-numpy statics see it, at (x, y)."""
    anchors = {"ground.c": [0.0, 0.0, 0.0], "ground.p": [0.25, 0.0, 1.0],
               "ground.u": [y, 0.0, x - 1.0]}  # fmt: skip
    cables = (("band_u", "R", "ground.u", 1.0, 0.25), ("band_p", "R", "ground.p", 1.0, 0.25))
    return tp.Spatial(anchors, ("R",), (("ground.c", "R", 0.5),), cables)


def test_sphere_folds_change_chart_and_are_singular_equilibria_of_the_statics():
    """Zeeman's machine on a sphere (fixture): its fold curve runs past both poles of the
    sphere's first chart, so it is traced in pieces; it is the plane machine's (the
    determinant route's polyline and cusps); and at its points the plain-numpy statics find an
    equilibrium (Newton stays put) whose Hessian on the sphere's tangent plane is singular,
    with the other eigenvalue's sign that changes_stable_count says."""
    fw = cb.Framework.from_toml(SPHERE)
    plane = ChartPlane(fw, "x", "y")

    def to_chart(deg: float) -> list[float]:  # the plane's angle: from its first axis, now z
        u = np.array([np.sin(np.radians(deg)), 0.0, np.cos(np.radians(deg))])
        return [np.arccos(u[2]), np.arctan2(u[1], u[0])]  # chart A (rechart moves it)

    table, record = chart_fold_curves(plane, _zeeman_seeds(to_chart), *ZEEMAN)
    _zeeman_checks(table, record)
    assert record["curves"][0]["pieces"] >= 4  # both ends cross chart edges
    folds = table[table["kind"] != "cable_switch"]
    for _, row in folds.iloc[:: max(1, len(folds) // 12)].iterrows():
        ref = _sphere_reference(row.x, row.y)
        X0 = row[["R.x", "R.y", "R.z"]].to_numpy(float)[None]
        X, residual, H, A = tp.newton(ref, X0, None, steps=4)
        assert residual[0] < 1e-9 and np.abs(X - X0).max() < 1e-6
        null = np.linalg.svd(A[0])[2][len(ref.bars) :].T
        ev = np.linalg.eigvalsh(null.T @ H[0] @ null)
        k = np.argmin(np.abs(ev))
        assert abs(ev[k]) < 1e-6 * np.abs(ev).max()
        assert bool(row["changes_stable_count"]) == bool((np.delete(ev, k) >= 0).all())


def _prism_reference(L0t: float, h: float) -> tp.Spatial:
    """examples/prism_slack.toml as the plain-numpy statics see it, at (L0t, h)."""
    s = np.sqrt(3) / 2
    anchors = {"ground.a": [1.0, 0.0, 0.0], "ground.b": [-0.5, s, 0.0],
               "ground.c": [-0.5, -s, 0.0]}  # fmt: skip
    bars = tuple((f"ground.{g}", n, h) for g, n in zip("abc", "ABC", strict=True))
    tops = [(f"top_{a}{b}".lower(), a, b, 1.0, L0t) for a, b in ("AB", "BC", "CA")]
    diagonals = [(f"diag_{n}".lower(), n, f"ground.{g}", 1.5, 0.4)
                 for n, g in zip("ABC", "bca", strict=True)]  # fmt: skip
    return tp.Spatial(anchors, ("A", "B", "C"), bars, tuple(tops + diagonals))


def _tangent_index(ref: tp.Spatial, X: np.ndarray, taut: tuple) -> int:
    """Negative eigenvalues of the taut set's Lagrangian Hessian on the bars' tangent space."""
    _, _, H, A = tp.newton(ref, X, taut, steps=0)
    null = np.linalg.svd(A[0])[2][len(ref.bars) :].T
    return int((np.linalg.eigvalsh(null.T @ H[0] @ null) < 0).sum())


def test_prism_switch_curve_is_where_the_statics_put_a_cable_at_its_free_length():
    """prism_slack over (L0t, h): a flat saddle of index 4 (Newton from a rounded start at
    the file's values) followed down h until top_ab goes slack seeds that cable's switch curve;
    at its points the plain-numpy statics find an equilibrium with top_ab at its free length,
    and changes_stable_count is their Morse indices' on the two sides."""
    fw = cb.Framework.from_toml(ROOT / "examples" / "prism_slack.toml")
    plane = ChartPlane(fw, "L0t", "h")
    theta, ok = chart_newton(plane, np.array([[1.571, 2.97, 1.571, 1.479, 1.571, 4.118]]),
                             (1.7, 1.2))  # fmt: skip
    assert ok[0]
    got = advance(plane, theta, (1.7, 1.2), (1.7, 0.96))  # top_ab slack from h = 0.97
    assert got.ok[0] and plane.margins(got.points, (1.7, 0.96))[0, 0] < 0
    seed = Seed("cable_switch", np.concatenate([got.points[0], [1.7, 0.96]]), "top_ab")
    table, record = chart_fold_curves(plane, [seed], (1.0, 2.4), (0.9, 1.6))
    assert record["curves"][0]["ends"] == ["edge", "edge"] and not record["warnings"]
    assert len(table) > 20 and (table["kind"] == "cable_switch").all()
    for _, row in table.iloc[:: len(table) // 8].iterrows():
        ref = _prism_reference(row.L0t, row.h)
        X0 = row[[f"{n}.{c}" for n in "ABC" for c in "xyz"]].to_numpy(float)[None]
        X, residual, _, _ = tp.newton(ref, X0, None, steps=4)
        assert residual[0] < 1e-9 and np.abs(X - X0).max() < 1e-6
        lengths = dict(zip((c[0] for c in ref.cables), ref.lengths(X)[0], strict=True))
        assert abs(lengths["top_ab"] - row.L0t) < 1e-7
        free = {c[0]: c[4] for c in ref.cables}
        both = tuple(sorted(c for c, d in lengths.items() if d > free[c] or c == "top_ab"))
        slack = tuple(c for c in both if c != "top_ab")
        changes = _tangent_index(ref, X, both) == 0 and _tangent_index(ref, X, slack) >= 1
        assert bool(row["changes_stable_count"]) == changes
        assert row["taut"] == " ".join(both)
