"""Sweep figures: bifurcation diagram (gamma1, gamma2 against a parameter) and 2-D count map.

The data are solved here (case-2 geometry, L02 = 0: about 0.1 s a point after the cached generic
solve). Branch ids come from a simple nearest-neighbour stand-in defined below, so these tests do
not depend on the package's branch module.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
L01_VALUES = np.linspace(0.5, 12.0, 11)


def _solve(points: list[dict[str, float]]) -> pd.DataFrame:
    from cotm_bertini.continuation.runner import point_table
    from cotm_bertini.params import Params
    from cotm_bertini.settings import Settings

    frames = []
    for k, values in enumerate(points):
        table = point_table(Params(**values), Settings(seed=1), values)
        table["point"] = k
        frames.append(table)
    return pd.concat(frames, ignore_index=True)


def stand_in_branches(sweep: pd.DataFrame, param: str, tol: float = 60.0) -> pd.DataFrame:
    """Join real rows of neighbouring parameter values greedily, nearest first (a stand-in)."""
    sweep = sweep.copy()
    sweep["branch"] = pd.array([pd.NA] * len(sweep), dtype="Int64")
    real = sweep[sweep["is_real"].astype(bool)]
    next_id, prev = 0, None
    for value in np.unique(real[param]):
        cur = real[real[param] == value]
        ids: dict = {}
        if prev is not None and len(prev):
            a = prev[["gamma1_deg", "gamma2_deg"]].to_numpy()
            b = cur[["gamma1_deg", "gamma2_deg"]].to_numpy()
            dist = np.abs((b[:, None, :] - a[None, :, :] + 180) % 360 - 180).max(axis=2)
            dist += 10 * np.abs(cur["d1"].to_numpy()[:, None] - prev["d1"].to_numpy()[None, :])
            used_i, used_j = set(), set()
            for i, j in sorted(np.ndindex(dist.shape), key=lambda ij: dist[ij]):
                if dist[i, j] <= tol and i not in used_i and j not in used_j:
                    used_i.add(i)
                    used_j.add(j)
                    ids[cur.index[i]] = sweep.at[prev.index[j], "branch"]
        for idx in cur.index:
            if idx not in ids:
                ids[idx], next_id = next_id, next_id + 1
            sweep.at[idx, "branch"] = ids[idx]
        prev = cur
    return sweep


def stand_in_events(sweep: pd.DataFrame, param: str) -> pd.DataFrame:
    """Interior branch ends as folds, stable flag flips along a branch as stability changes."""
    values = np.unique(sweep[param])
    rows = []
    for _, grp in sweep.dropna(subset=["branch"]).groupby("branch"):
        grp = grp.sort_values(param)
        for end in (grp.iloc[0], grp.iloc[-1]):
            if values[0] < end[param] < values[-1]:
                rows.append(("fold", end[param], end["gamma1_deg"], end["gamma2_deg"]))
        stable = grp["stable"].astype(bool).to_numpy()
        for i in np.flatnonzero(stable[1:] != stable[:-1]):
            r = grp.iloc[i + 1]
            rows.append(("stability_change", r[param], r["gamma1_deg"], r["gamma2_deg"]))
    return pd.DataFrame(rows, columns=["kind", "value", "gamma1_deg", "gamma2_deg"])


@pytest.fixture(scope="module")
def sweep1d() -> pd.DataFrame:
    return stand_in_branches(_solve([{"L01": float(v)} for v in L01_VALUES]), "L01")


@pytest.fixture(scope="module")
def sweep2d() -> pd.DataFrame:
    grid = [
        {"L01": float(a), "k1": float(k)} for a in (1.0, 5.0, 9.0, 11.5) for k in (1.5, 2.81, 5)
    ]
    return _solve(grid)


def _collections(ax) -> dict:
    return {c.get_gid(): c for c in ax.collections if c.get_gid()}


def _panels(fig) -> dict:
    return {ax.get_gid(): ax for ax in fig.axes if ax.get_gid() in ("gamma1", "gamma2")}


def _offsets(ax, gid: str) -> np.ndarray:
    coll = _collections(ax).get(gid)
    return np.empty((0, 2)) if coll is None else np.asarray(coll.get_offsets())


def _sorted_rows(xy: np.ndarray) -> np.ndarray:
    xy = np.round(np.asarray(xy, dtype=float), 9)
    return xy[np.lexsort(xy.T[::-1])] if len(xy) else xy.reshape(0, 2)


def _check_png_svg(paths, stem) -> None:
    assert [p.name for p in paths] == [f"{stem.name}.png", f"{stem.name}.svg"]
    for path in paths:
        assert path.stat().st_size > 10_000, path
        head = path.read_bytes()[:200]
        if path.suffix == ".png":
            assert head.startswith(PNG_SIGNATURE), path
        else:
            assert b"<svg" in path.read_bytes(), path
    # Atomic writes leave no temporary file behind.
    assert sorted(p.name for p in stem.parent.iterdir()) == sorted(p.name for p in paths)


def test_data_has_what_the_figures_need(sweep1d):
    """The solved sweep has stable, unstable and non-physical real rows, and wraps past 360."""
    assert sweep1d["stable"].any()
    assert (sweep1d["physical"] & ~sweep1d["stable"]).any()
    assert (sweep1d["is_real"] & ~sweep1d["physical"]).any()
    assert sweep1d["branch"].notna().sum() == sweep1d["is_real"].sum()


def test_bifurcation_writes_png_and_svg(sweep1d, tmp_path):
    from cotm_bertini.plot.bifurcation import plot_bifurcation

    stem = tmp_path / "bifurcation"
    events = stand_in_events(sweep1d, "L01")
    paths = plot_bifurcation(sweep1d, "L01", stem, show_all=True, events=events)
    _check_png_svg(paths, stem)


@pytest.mark.parametrize("with_branches", [True, False])
def test_plotted_points_are_the_rows(sweep1d, with_branches):
    """Stable markers = stable rows, unstable markers = the other physical rows, in both panels."""
    from cotm_bertini.plot.bifurcation import bifurcation_figure

    data = sweep1d if with_branches else sweep1d.drop(columns="branch")
    fig = bifurcation_figure(data, "L01")
    panels = _panels(fig)
    assert set(panels) == {"gamma1", "gamma2"}
    stable = data[data["stable"].astype(bool)]
    unstable = data[data["physical"].astype(bool) & ~data["stable"].astype(bool)]
    for name, ax in panels.items():
        assert ax.get_ylabel() == f"{name} (deg)"
        for gid, rows in (("stable", stable), ("unstable", unstable)):
            got = _offsets(ax, gid)
            assert len(got) == len(rows), (name, gid)
            want = np.column_stack([rows["L01"], rows[f"{name}_deg"]])
            np.testing.assert_allclose(_sorted_rows(got), _sorted_rows(want), atol=1e-9)
        assert len(_offsets(ax, "nonphysical")) == 0
        lines = _collections(ax)
        if with_branches:
            assert len(lines["stable-lines"].get_segments()) > 0
            assert len(lines["unstable-lines"].get_segments()) > 0
        else:
            assert not any(gid.endswith("-lines") for gid in lines)
    assert panels["gamma2"].get_xlabel() == "L01 (m)"  # the lower panel carries the shared axis


def _all_pieces(fig) -> list[np.ndarray]:
    return [
        np.asarray(seg)
        for ax in _panels(fig).values()
        for gid, coll in _collections(ax).items()
        if gid.endswith("-lines")
        for seg in coll.get_segments()
    ]


def test_no_line_jumps_across_the_plot(sweep1d):
    """No drawn segment spans more than 180 deg; lines cut at 0/360 reach the edge instead."""
    from cotm_bertini.plot.bifurcation import bifurcation_figure

    fig = bifurcation_figure(sweep1d, "L01", show_all=True)
    pieces = _all_pieces(fig)
    assert pieces
    steps = np.concatenate([np.abs(np.diff(p[:, 1])) for p in pieces])
    assert steps.max() <= 180.0
    ys = np.concatenate([p[:, 1] for p in pieces])
    assert ys.min() >= 0.0 and ys.max() <= 360.0
    # This sweep's gamma2 does wrap (stable branch past 360 near L01 = 8.7 m): the cut shows.
    assert np.isclose(ys, 360.0).any() and np.isclose(ys, 0.0).any()
    # Lines never run backwards in the parameter (no joins between unrelated rows).
    assert all((np.diff(p[:, 0]) >= 0).all() for p in pieces)


def test_wrap_and_gap_on_a_hand_made_branch():
    """350 -> 10 deg is cut at 360/0; a missing parameter value or a 170 deg step is a gap."""
    from cotm_bertini.plot.bifurcation import bifurcation_figure

    # Branch 0 at x = 0..5 and 7 (wraps at 1-2, turns unstable at 3-4, steps 170 deg at 4-5,
    # skips x = 6); branch 1 is a single row at x = 6.
    x = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 7.0, 6.0]
    rows = pd.DataFrame(
        {
            "point": [0, 1, 2, 3, 4, 5, 7, 6],
            "L01": x,
            "gamma1_deg": [340.0, 350.0, 10.0, 20.0, 30.0, 200.0, 210.0, 100.0],
            "gamma2_deg": 100.0,
            "d1": 1.0,
            "d2": 1.0,
            "is_real": True,
            "physical": True,
            "stable": [True] * 4 + [False] * 4,
            "branch": [0] * 7 + [1],
        }
    )
    fig = bifurcation_figure(rows, "L01")
    ax = _panels(fig)["gamma1"]
    stable = [np.asarray(s) for s in _collections(ax)["stable-lines"].get_segments()]
    unstable = [np.asarray(s) for s in _collections(ax)["unstable-lines"].get_segments()]
    # Stable 0..3 cut at the edge: [340, 350, 360] and [0, 10, 20, 30 -> midpoint to x = 3.5].
    assert len(stable) == 2
    np.testing.assert_allclose(stable[0][:, 1], [340.0, 350.0, 360.0])
    np.testing.assert_allclose(stable[0][-1, 0], 1.5)  # 350 -> 370 crosses 360 halfway
    np.testing.assert_allclose(stable[1][0], [1.5, 0.0])
    np.testing.assert_allclose(stable[1][-1], [3.5, 25.0])  # style changes at the midpoint
    # Unstable: midpoint to x = 4 (30 deg), then the 170 deg step 4 -> 5 is not drawn.
    assert len(unstable) == 1
    np.testing.assert_allclose(unstable[0], [[3.5, 25.0], [4.0, 30.0]])
    assert len(_offsets(ax, "stable")) == 4 and len(_offsets(ax, "unstable")) == 4


def test_show_all_adds_the_nonphysical_real_rows(sweep1d):
    from cotm_bertini.plot.bifurcation import bifurcation_figure

    default = _panels(bifurcation_figure(sweep1d, "L01"))
    every = _panels(bifurcation_figure(sweep1d, "L01", show_all=True))
    extra = sweep1d[sweep1d["is_real"].astype(bool) & ~sweep1d["physical"].astype(bool)]
    assert len(extra) > 0
    for name in ("gamma1", "gamma2"):
        assert len(_offsets(default[name], "nonphysical")) == 0
        got = _offsets(every[name], "nonphysical")
        want = np.column_stack([extra["L01"], extra[f"{name}_deg"]])
        np.testing.assert_allclose(_sorted_rows(got), _sorted_rows(want), atol=1e-9)
        # The physical markers are the same either way.
        for gid in ("stable", "unstable"):
            np.testing.assert_allclose(
                _sorted_rows(_offsets(every[name], gid)),
                _sorted_rows(_offsets(default[name], gid)),
            )
        assert len(_collections(every[name])["nonphysical-lines"].get_segments()) > 0
        assert len(_collections(default[name])["nonphysical-lines"].get_segments()) == 0


def test_events_are_marked_with_a_legend(sweep1d):
    from cotm_bertini.plot.bifurcation import EVENT_STYLE, bifurcation_figure

    events = pd.DataFrame(
        [
            ("fold", 11.05, 107.0, 265.0),
            ("stability_change", 4.5, 77.35, 300.0),
            ("fold", 3.0, 200.0, 10.0),
        ],
        columns=["kind", "value", "gamma1_deg", "gamma2_deg"],
    )
    fig = bifurcation_figure(sweep1d, "L01", events=events)
    for name, ax in _panels(fig).items():
        for kind in ("fold", "stability_change"):
            ev = events[events["kind"] == kind]
            want = np.column_stack([ev["value"], ev[f"{name}_deg"]])
            np.testing.assert_allclose(_sorted_rows(_offsets(ax, kind)), _sorted_rows(want))
        assert len(_offsets(ax, "physical_change")) == 0
    labels = [t.get_text() for leg in fig.legends for t in leg.get_texts()]
    assert EVENT_STYLE["fold"][3] in labels and EVENT_STYLE["stability_change"][3] in labels
    assert EVENT_STYLE["physical_change"][3] not in labels
    assert any("stable" in t for t in labels) and any("unstable" in t for t in labels)
    # branches.find_events names the value column after the parameter: same markers.
    renamed = bifurcation_figure(sweep1d, "L01", events=events.rename(columns={"value": "L01"}))
    for name, ax in _panels(renamed).items():
        np.testing.assert_allclose(_offsets(ax, "fold"), _offsets(_panels(fig)[name], "fold"))


def test_count_map_equals_the_per_point_counts(sweep2d, tmp_path):
    from cotm_bertini.plot.counts import plot_sweep_counts, sweep_counts_figure

    per_point = sweep2d.groupby("point").agg(
        L01=("L01", "first"),
        k1=("k1", "first"),
        stable=("stable", "sum"),
        physical=("physical", "sum"),
    )
    assert per_point["stable"].nunique() > 1  # the map has something to show
    fig = sweep_counts_figure(sweep2d, ["L01", "k1"])
    mesh = next(c for ax in fig.axes for c in ax.collections if c.get_gid() == "stable-count")
    xs, ks = np.unique(per_point["L01"]), np.unique(per_point["k1"])
    values = np.asarray(mesh.get_array()).reshape(len(ks), len(xs))
    for r in per_point.itertuples():
        j, i = np.searchsorted(ks, r.k1), np.searchsorted(xs, r.L01)
        assert values[j, i] == r.stable, (r.L01, r.k1)
    # Annotated cells say "stable/physical" for every point.
    texts = {t.get_text() for ax in fig.axes for t in ax.texts}
    assert {f"{r.stable}/{r.physical}" for r in per_point.itertuples()} <= texts

    stem = tmp_path / "counts"
    _check_png_svg(plot_sweep_counts(sweep2d, ["L01", "k1"], stem), stem)
    # Unannotated: the physical count as contours instead.
    fig = sweep_counts_figure(sweep2d, ["L01", "k1"], annotate=False)
    texts = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert not any("/" in t for t in texts)
    assert texts and all(t.endswith("phys.") for t in texts)
