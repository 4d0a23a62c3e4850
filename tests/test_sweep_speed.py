"""Issue 17 (sweeps at numpy speed) and issue 16 item 16 (the bifurcation figure).

The points of a sweep live in memory and in one append-only file (continuation.store); the
table is joined and written without pandas (continuation.tables); branches and events are
found on numpy columns. Checked here: the store survives a torn or damaged record and reads an
earlier version's folder; the CSV text and the joined columns are what pandas gives; the
assignment's shortcut is the optimum; branches and events are the same from a DataFrame and
from columns. Timings are in bench/speed.py, not here.
"""

from __future__ import annotations

import itertools
import os

import numpy as np
import pandas as pd
import pytest

from cotm_bertini.continuation.store import STORE_FILE, PointStore, read_records, stored_indices
from cotm_bertini.continuation.tables import concat_columns, csv_text, nullable_ints, to_frame


def _point(index: int, rows: int = 3, extra: bool = False) -> dict[str, np.ndarray]:
    cols = {
        "point": np.full(rows, index),
        "L01": np.full(rows, 0.1 * index),
        "solution_id": np.arange(1, rows + 1),
        "gamma1_deg": np.linspace(0, 1, rows) + index,
        "is_real": np.arange(rows) % 2 == 0,
        "reason": np.array(["", "complex", "negative_d"][:rows] * (rows // 3 + 1), object)[:rows],
        "kind": np.array(["min, or not", 'say "x"', ""][:rows] * (rows // 3 + 1), object)[:rows],
        "max_imag": np.where(np.arange(rows) == 1, np.nan, 1e-300 * index),
        "paths": np.array([f"{k} {k + 7}" for k in range(rows)], dtype=object),
    }
    if extra:
        cols["d1_re"] = np.full(rows, np.inf)
    cols["lost_paths"] = np.full(rows, np.nan if index % 2 else float(index))
    return cols


def _same(a: dict, b: dict) -> None:
    assert list(a) == list(b)
    for name in a:
        x, y = np.asarray(a[name]), np.asarray(b[name])
        if x.dtype.kind == "f":
            np.testing.assert_array_equal(x, y)
        else:
            assert x.tolist() == y.tolist(), name


def test_store_keeps_points_through_a_torn_record(tmp_path):
    with PointStore(tmp_path) as store:
        for k in range(3):
            store.append(k, _point(k, extra=k == 2))
    path = tmp_path / STORE_FILE
    size = path.stat().st_size
    with PointStore(tmp_path) as store:
        store.append(3, _point(3))
    whole = path.read_bytes()
    path.write_bytes(whole[: size + (len(whole) - size) // 2])  # killed while writing point 3
    assert stored_indices(tmp_path) == {0, 1, 2}
    again = PointStore(tmp_path)
    assert sorted(again.points) == [0, 1, 2]
    assert path.stat().st_size == size  # the torn tail is cut before the next append
    for k in range(3):
        _same(again.points[k], _point(k, extra=k == 2))
    again.append(3, _point(3))
    again.append(1, _point(7))  # a point stored twice: the first record wins
    again.close()
    points, end = read_records(path)
    assert sorted(points) == [0, 1, 2, 3] and end == path.stat().st_size
    _same(points[1], _point(1))


def test_store_stops_at_a_damaged_record(tmp_path):
    with PointStore(tmp_path) as store:
        for k in range(3):
            store.append(k, _point(k))
    data = bytearray((tmp_path / STORE_FILE).read_bytes())
    data[len(data) // 2] ^= 0xFF  # a flipped bit in the middle record
    (tmp_path / STORE_FILE).write_bytes(bytes(data))
    assert stored_indices(tmp_path) == {0}


def test_store_reads_an_earlier_versions_point_files(tmp_path):
    """Earlier versions kept points/NNNNN.csv: they are read, and moved into the store."""
    from cotm_bertini.fs import columns_csv

    (tmp_path / "points").mkdir()
    for k in (0, 2):
        (tmp_path / "points" / f"{k:05d}.csv").write_text(columns_csv(_point(k)))
    assert stored_indices(tmp_path) == {0, 2}
    store = PointStore(tmp_path)
    store.close()
    assert sorted(read_records(tmp_path / STORE_FILE)[0]) == [0, 2]
    np.testing.assert_array_equal(store.points[2]["gamma1_deg"], _point(2)["gamma1_deg"])


def test_store_file_mode_follows_the_umask(tmp_path):
    old = os.umask(0o022)
    try:
        with PointStore(tmp_path) as store:
            store.append(0, _point(0))
    finally:
        os.umask(old)
    assert (tmp_path / STORE_FILE).stat().st_mode & 0o777 == 0o644


def test_joined_columns_and_csv_text_are_what_pandas_gives():
    parts = [_point(0), _point(1, rows=0), _point(2, extra=True), _point(3, rows=4)]
    parts[1] = {k: v[:0].astype(float) for k, v in parts[1].items()}  # an empty point
    joined = concat_columns(parts)
    frames = [pd.DataFrame(p) for p in parts if len(p["point"])]
    expected = pd.concat(frames, ignore_index=True)
    assert list(joined) == list(expected.columns)
    pd.testing.assert_frame_equal(pd.DataFrame(joined), expected)
    expected["lost_paths"] = expected["lost_paths"].astype("Int64")
    out = dict(joined)
    out["lost_paths"] = nullable_ints(out["lost_paths"])
    assert csv_text(out) == expected.to_csv(index=False)
    events = {"kind": ["fold"], "x": [(1.0, -0.5)], "null_vector": [None], "ok": [True]}
    assert csv_text(events) == pd.DataFrame(events).to_csv(index=False)
    assert csv_text({"a": [], "b": []}) == pd.DataFrame({"a": [], "b": []}).to_csv(index=False)
    frame = to_frame(joined)
    assert str(frame["lost_paths"].dtype) == "Int64" and frame["kind"].map(type).eq(str).all()


def _brute_force(cost: np.ndarray) -> float:
    n, m = cost.shape
    if n <= m:
        return min(cost[range(n), list(p)].sum() for p in itertools.permutations(range(m), n))
    return _brute_force(cost.T)


@pytest.mark.parametrize("shape", [(4, 4), (3, 5), (5, 3), (1, 1)])
def test_assignment_is_optimal(shape):
    from cotm_bertini.continuation.matching import hungarian

    rng = np.random.default_rng(sum(shape))
    for trial in range(40):
        cost = rng.random(shape)
        if trial % 2:  # near a continuation step: one cheap entry a row (the shortcut applies)
            k = min(shape)
            rows, cols = rng.permutation(shape[0])[:k], rng.permutation(shape[1])[:k]
            cost[rows, cols] *= 1e-3
        match = hungarian(cost)
        rows = np.flatnonzero(match >= 0)
        assert len(rows) == min(shape) and len(set(match[rows])) == len(rows)
        assert np.isclose(cost[rows, match[rows]].sum(), _brute_force(cost))


@pytest.fixture(scope="module")
def fold_sweep(tmp_path_factory):
    """The paper's fold (L01 = 11.0128 m) inside a 5-point sweep, through the public API."""
    import cotm_bertini as cb

    params = cb.Params.case("case3").replace(L02=0.0)
    out = tmp_path_factory.mktemp("fold")
    return cb.sweep(params, "L01", np.linspace(10.9, 11.1, 5), out=out)


def test_branches_and_events_from_columns_equal_those_from_a_dataframe(fold_sweep):
    from cotm_bertini.continuation.events import event_records, find_events
    from cotm_bertini.continuation.matching import assign_branches, branch_ids

    table = fold_sweep.table
    base, settings = fold_sweep.spec.base, fold_sweep.spec.settings
    columns = {c: table[c].to_numpy() for c in table.columns}
    assert (branch_ids(columns, "L01") == table["branch"].to_numpy()).all()
    bare = table.drop(columns="branch")
    assert (assign_branches(bare, "L01")["branch"] == table["branch"]).all()
    events = find_events(table, "L01", base, settings)
    assert list(events["kind"]) == ["fold", "stability_change"]
    frame = pd.DataFrame(event_records(columns, "L01", base, settings), columns=events.columns)
    pd.testing.assert_frame_equal(frame, events)
    # What the folder holds is what was found.
    on_disk = pd.read_csv(fold_sweep.folder / "events.csv")
    np.testing.assert_allclose(on_disk["L01"], events["L01"], rtol=0, atol=0)
    assert sorted(os.listdir(fold_sweep.folder)) == [  # .events.json: the refined events kept
        ".events.json", "columns.md", "events.csv", "points.bin", "run.json", "sweep.csv",
        "sweep.json",
    ]  # fmt: skip


def test_bifurcation_figure_fold_and_title(fold_sweep, monkeypatch, tmp_path):
    """Issue 16 item 16: the fixed parameters in the title; the two branches born at the fold
    start at the fold point; the fold's cross is drawn above the stability change's diamond."""
    import cotm_bertini.plot.bifurcation as bif

    figures = []
    monkeypatch.setattr(bif, "save", lambda fig, path: figures.append(fig) or [path])
    fold_sweep.plot(tmp_path / "b.png")
    (fig,) = figures
    title = fig._suptitle.get_text()
    assert "fixed: L02 = 0 m; the other parameters as in Table 1" in title
    fold = fold_sweep.events.iloc[0]
    born = [int(b) for b in fold["branches"].split("+")]
    for ax in fig.axes:
        if ax.get_gid() not in ("gamma1", "gamma2"):
            continue
        at = np.array([fold["L01"], fold[f"{ax.get_gid()}_deg"] % 360.0])
        starts = [
            np.asarray(seg)[0]
            for gid in ("stable-lines", "unstable-lines")
            for c in ax.collections
            if c.get_gid() == gid
            for seg in c.get_segments()
        ]
        hits = [s for s in starts if np.allclose(s, at, atol=1e-9)]
        assert len(hits) == len(born), (ax.get_gid(), at, starts)
        z = {c.get_gid(): c.get_zorder() for c in ax.collections}
        assert z["fold"] > z["stability_change"]


def test_workers_write_the_lines_pandas_would(tmp_path):
    """The sweep.csv lines written by the workers (under the columns foreseen from the grid's
    structures: here both free lengths reach 0) equal those written afterwards from the stored
    points, which equal pandas' own."""
    import cotm_bertini as cb
    from cotm_bertini.continuation.results import finish_columns
    from cotm_bertini.continuation.runner import assemble, sweep_names
    from cotm_bertini.continuation.store import PointStore
    from cotm_bertini.continuation.tables import union_names

    sw = cb.sweep(cb.Params.case("case3"), "L01", [0.0, 6.0], param2="L02", values2=[0.0, 7.0],
                  workers=2, out=tmp_path)  # fmt: skip
    store = PointStore(sw.folder)
    assert sweep_names(sw.spec) == union_names([store.points[i] for i in range(4)])
    by_workers = (sw.folder / "sweep.csv").read_text()
    finish_columns(sw.spec, sw.folder, sw.record["stats"])  # again, from the file: no worker lines
    assert (sw.folder / "sweep.csv").read_text() == by_workers
    assert by_workers == assemble(sw.spec, sw.folder).to_csv(index=False)
