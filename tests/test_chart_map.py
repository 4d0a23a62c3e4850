"""design_map by continuation in chart angles (catastrophe/chart_map.py): the grid's counts
against routes that share no code with it (Newton on the plain-numpy statics of
tests/tensegrity_physics.py from random poses at every grid point; the searched grid of the
"search" route), its completeness test, and what it says it has not proved."""

from __future__ import annotations

import numpy as np
import pytest
import tensegrity_physics as tp
from conftest import ROOT

import cotm_bertini as cb
from cotm_bertini.catastrophe import chart_map as cm
from cotm_bertini.catastrophe.regions import count_changes, unexplained
from cotm_bertini.errors import ParameterError

SPHERE = ROOT / "tests" / "fixtures" / "zeeman_sphere.toml"
WINDOW = ("x", (-0.6, 0.8), "y", (-0.8, 0.2))  # Zeeman's cusp and both its fold curves


def _statics(x: float, y: float) -> tp.Spatial:
    """The fixture as the plain-numpy statics see it, at (x, y)."""
    anchors = {"ground.c": [0.0, 0.0, 0.0], "ground.p": [0.25, 0.0, 1.0],
               "ground.u": [y, 0.0, x - 1.0]}  # fmt: skip
    cables = (("band_u", "R", "ground.u", 1.0, 0.25), ("band_p", "R", "ground.p", 1.0, 0.25))
    return tp.Spatial(anchors, ("R",), (("ground.c", "R", 0.5),), cables)


def _counts(xs, ys) -> tuple[np.ndarray, np.ndarray]:
    """Equilibria and minima (index 0) of the statics at each grid point, (len(ys), len(xs))
    each."""
    every = np.zeros((len(ys), len(xs)), dtype=int)
    minima = np.zeros_like(every)
    for i, x in enumerate(xs):
        for j, y in enumerate(ys):
            found = tp.critical_points(_statics(x, y), starts=200, seed=i * len(ys) + j)
            every[j, i] = len(found)
            minima[j, i] = sum(p["index"] == 0 for p in found)
    return every, minima


@pytest.fixture(scope="module")
def zeeman_map():
    fw = cb.Framework.from_toml(SPHERE)
    return cb.design_map(fw, *WINDOW, points=9, grid="continuation")


def test_spatial_zeeman_map_counts_are_the_statics_at_every_grid_point(zeeman_map):
    """Every grid point's equilibria (2 outside Zeeman's cusp, 4 inside) and minima equal what
    Newton finds on the independent statics from random poses; every change of the count
    between grid neighbours is crossed by a traced fold curve (the machine's spoke is in
    compression here: its folds meet saddles of index 1 and 2, and the stable count stays 1);
    and the status says what is not proved."""
    m = zeeman_map
    grids = {c: m.regions.pivot(index="y", columns="x", values=c).sort_index()
             for c in ("physical", "stable")}  # fmt: skip
    xs, ys = grids["stable"].columns.to_numpy(float), grids["stable"].index.to_numpy(float)
    every, minima = _counts(xs, ys)
    assert {2, 4} <= set(every.ravel())  # the window holds both regions
    np.testing.assert_array_equal(grids["physical"].to_numpy(int), every)
    np.testing.assert_array_equal(grids["stable"].to_numpy(int), minima)
    folds = m.folds.assign(changes_stable_count=True)  # any fold changes the count of all
    missed, _ = unexplained(m.regions, folds, "x", "y", column="physical")
    assert len(count_changes(m.regions, "x", "y", "physical")) > 0 and missed.empty
    chart = m.record["chart"]
    assert chart["anchors_proved"] == 9 and chart["morse_failed"] == 0
    assert (m.folds.kind == "cusp").sum() >= 1
    assert (
        m.status == "incomplete"
        and "72 of 81 grid points were not searched" in (chart["not_proved"])
    )


def test_a_lost_equilibrium_is_caught_by_the_morse_sum(monkeypatch):
    """Sabotage: every anchor loses its maxima, and no fold is passed (`through` stalls, so
    no partner brings it back): the Morse sum fails at every grid point, the lost branches are
    listed, and the status is incomplete."""
    from cotm_bertini.catastrophe import chart_grid

    fw = cb.Framework.from_toml(SPHERE)
    real = cm.anchor_task

    def lossy(task):
        out = real(task)
        land = cm.ChartPlane(task[0], "x", "y")
        _, H = land.derivatives(out["roots"], (task[0].values["x"], task[0].values["y"]))
        index = (np.linalg.eigvalsh(H) < 0).sum(axis=1)  # a root found in two charts: both
        return {**out, "roots": out["roots"][index < 2]}

    monkeypatch.setattr(cm, "anchor_task", lossy)
    monkeypatch.setattr(chart_grid, "through", lambda *a: ("stalled", None, []))
    m = cb.design_map(fw, *WINDOW, points=5, grid="continuation")
    chart = m.record["chart"]
    assert chart["morse_failed"] == 25 and chart["propagation"]["lost_branches"] > 0
    assert m.status == "incomplete"


def test_grid_route_is_refused_where_it_cannot_run():
    """grid = 'continuation' for the paper's mechanism, or a grid name that does not exist:
    one line naming the value."""
    with pytest.raises(ParameterError, match="grid = 'continuation': only for a framework"):
        cb.design_map(
            cb.Params.case("case1"), l01=(0, 1), l02=(0, 1), points=3, grid="continuation"
        )
    fw = cb.Framework.from_toml(SPHERE)
    with pytest.raises(ParameterError, match="grid = 'sideways'"):
        cb.design_map(fw, *WINDOW, points=3, grid="sideways")


@pytest.mark.slow
def test_prism_map_by_continuation_equals_searches_off_the_anchors():
    """prism_slack over (L0t, h) (make stress): its mirror pitchfork (flat poses meeting the
    pair of mirror minima they break into, 8 against 10 equilibria), labelled so, explains
    every change of the stable count; at grid points that are no anchor, on both sides of it,
    the rows followed equal a proved search of the point (the branch and bound, not the
    continuation)."""
    from cotm_bertini.boxsearch.families import real_equilibria

    fw = cb.Framework.from_toml(ROOT / "examples" / "prism_slack.toml")
    m = cb.design_map(fw, "L0t", (0.2, 0.8), "h", (1.2, 1.6), points=11, grid="continuation",
                      workers=2)  # fmt: skip
    assert m.record["count_changes"] > 0 and m.record["unexplained_changes"] == 0
    assert m.record["chart"]["morse_failed"] == 0 and (m.folds.kind == "pitchfork").any()
    regions = m.regions.set_index(["L0t", "h"])
    for L0t, h in ((0.26, 1.56), (0.32, 1.52), (0.5, 1.32), (0.74, 1.56), (0.62, 1.24)):
        groups, found = real_equilibria(fw.replace(L0t=L0t, h=h))
        assert not len(found.undecided)
        plane = cm.ChartPlane(fw, "L0t", "h")
        index, _ = plane.index(found.roots, (L0t, h))
        row = regions.loc[(L0t, h)]
        assert (row.physical, row.stable) == (len(found.roots), int((index == 0).sum()))


def test_zeeman_pitchforks_break_the_mirror_and_folds_do_not(zeeman_map):
    """The spatial Zeeman machine is symmetric in the mirror y -> -y. At a point of the mirror
    plane labelled pitchfork the independent statics' soft direction (the Hessian on the
    sphere's tangent plane, its eigenvalue nearest 0) leaves the plane (along y); at one
    labelled fold it lies in the plane (the plane machine's own fold)."""
    folds = zeeman_map.folds
    folds = folds[np.abs(folds["R.y"]) < 1e-9]  # in the mirror plane (off it: the mirror pairs)
    for kind, along_y in (("pitchfork", True), ("fold", False)):
        rows = folds[folds.kind == kind]
        assert len(rows) > 0
        for _, row in rows.iloc[:: max(1, len(rows) // 8)].iterrows():
            ref = _statics(row.x, row.y)
            X0 = row[["R.x", "R.y", "R.z"]].to_numpy(float)[None]
            _, _, H, A = tp.newton(ref, X0, None, steps=4)
            null = np.linalg.svd(A[0])[2][len(ref.bars) :].T
            ev, vec = np.linalg.eigh(null.T @ H[0] @ null)
            soft = null @ vec[:, np.argmin(np.abs(ev))]
            assert (abs(soft[1]) > 0.99) == along_y, (kind, row.x, row.y, soft)


def test_the_propagation_never_goes_silent(monkeypatch, capfd):
    """Issue 46: a map went silent for minutes after its anchors; the propagation (and the
    curves and the classification after it) report how far they got, line by line."""
    from cotm_bertini import progress

    monkeypatch.setenv(progress.ENV_DELAY, "0")
    monkeypatch.setenv(progress.ENV_SECONDS, "0")
    fw = cb.Framework.from_toml(SPHERE)
    cb.design_map(fw, *WINDOW, points=3, grid="continuation")
    err = capfd.readouterr().err
    followed = [ln for ln in err.splitlines() if ln.startswith("map: equilibria followed")]
    assert followed and "grid lines," in followed[-1], err
    assert "9/9 grid points reached" in followed[-1] and "0 lines to pass" in followed[-1]
    assert "map: grid points classified: 9/9 points" in err
