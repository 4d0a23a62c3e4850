"""The real route's branch and bound shared over worker processes (boxsearch/box_shares.py):
the same proof as in one process. chain3's rows, serial and on two local processes (and on a
Dask cluster), against the independent reference of tests/test_chain3.py (V, grad V and its
Hessian in plain numpy, Newton from a grid of starts); the shares' records merged box for box;
a share dropped is caught by the merge, and its roots are missed by the reference's check."""

from __future__ import annotations

import re

import numpy as np
import pytest
from conftest import ROOT, run_cli
from test_chain3 import FILE, _angles, _pairing, critical_points, read_chain

import cotm_bertini as cb
from cotm_bertini import progress
from cotm_bertini.boxsearch import box_shares
from cotm_bertini.boxsearch.boxes import MIN_WIDTH, SHORT, domain, merged, search
from cotm_bertini.boxsearch.real_route import landscape

SAME = 1e-8  # rad or table units: two runs of one proof agree to rounding


@pytest.fixture(scope="module")
def reference():
    """chain3's 22 critical points by the test's own Newton (tests/test_chain3.py)."""
    return critical_points(read_chain())


@pytest.fixture(scope="module")
def serial():
    """chain3 solved with its search in this process (no cache)."""
    return cb.solve(cb.Framework.from_toml(FILE), cache=False)


def _matches_reference(res, reference) -> None:
    """Every reference point a physical row (1e-6 deg), its Morse index the row's."""
    assert res.status == "ok", res.warnings
    pick = _pairing(_angles(res.physical), np.degrees(reference.theta))
    rows = res.physical.iloc[pick]
    np.testing.assert_array_equal(rows["index"].to_numpy(dtype=int), reference.index)


def _same_tables(a, b) -> None:
    """The same rows; `paths` apart: a root's number in the search's list, in the order one
    process found them or, shared, by angle."""
    assert list(a.columns) == list(b.columns) and len(a) == len(b) > 0
    for c in a.columns.drop("paths"):
        x, y = a[c].to_numpy(), b[c].to_numpy()
        if x.dtype.kind == "f":
            np.testing.assert_allclose(x, y, rtol=0, atol=SAME, equal_nan=True, err_msg=c)
        else:
            assert list(x) == list(y), c


def _sorted(roots: np.ndarray) -> np.ndarray:
    return roots[np.lexsort(roots.T[::-1])]


def test_two_workers_prove_what_one_does(reference, serial, monkeypatch, capfd):
    """Serial and on two local processes: the same rows (1e-8), both the reference's, the same
    boxes decided; the merged progress says the share decided, shares back, time left."""
    fw = cb.Framework.from_toml(FILE)
    monkeypatch.setenv(progress.ENV_DELAY, "0")
    monkeypatch.setenv(progress.ENV_SECONDS, "0")
    one, two = serial, cb.solve(fw, cache=False, workers=2)
    err = capfd.readouterr().err
    line = r"real search of chain3: \d+% of the poses decided, [\d,]+ boxes, \d/2 shares; "
    # (a search of a second or two ends before its first 10 s window: no time left known yet)
    assert re.search(line + r".* so far, (about .* left|time left not known yet)", err), err
    for res in (one, two):
        _matches_reference(res, reference)
    _same_tables(one.table, two.table)
    a, b = (r.record["details"]["real_search"] for r in (one, two))
    # chain3's 512 start boxes fill no 4,096-box batch step: one share a worker.
    assert (a["shares"], b["shares"], two.record["settings"]["workers"]) == (1, 2, 2)
    for key in ("boxes", "roots", "set_aside", "undecided", "found_by_newton"):
        assert a[key] == b[key], key
    assert b["cpu_seconds"] > 0 and b["seconds"] > 0


def test_shares_merge_box_for_box_and_a_lost_one_shows(reference, monkeypatch):
    """The start boxes dealt round-robin into shares, each searched alone: merged, the serial
    search's record (roots to 1e-8, every count); with one share left out the reference finds
    roots missing. split_search itself refuses a result with a share missing."""
    fw = cb.Framework.from_toml(FILE)
    land = landscape(fw)
    whole = search(land, SHORT, MIN_WIDTH)
    lo, hi = domain(land, 8)
    parts = [search(land, SHORT, MIN_WIDTH, boxes=(lo[k::5], hi[k::5])) for k in range(5)]
    volume = (2 * np.pi) ** 3
    joined = merged(parts, volume, 0.0)
    np.testing.assert_allclose(_sorted(joined.roots), _sorted(whole.roots), rtol=0, atol=SAME)
    assert (joined.boxes, joined.set_aside, len(joined.undecided), joined.shares) == (
        whole.boxes, whole.set_aside, len(whole.undecided), 5)  # fmt: skip
    assert joined.undecided_share == 0.0 and len(whole.roots) == len(reference.theta)
    _pairing(np.degrees(np.mod(joined.roots, 2 * np.pi)), np.degrees(reference.theta))
    short = merged(parts[:2] + parts[3:], volume, 0.0)
    assert 0 < len(short.roots) < len(reference.theta)
    with pytest.raises(AssertionError):
        _pairing(np.degrees(np.mod(short.roots, 2 * np.pi)), np.degrees(reference.theta))
    # Four shares a worker where the start boxes would fill the batch steps (here: smaller
    # steps asked for): the same record from two local processes.
    monkeypatch.setattr(box_shares, "BATCH", 128)
    eight = box_shares.split_search(landscape, fw, SHORT, MIN_WIDTH, workers=2)
    np.testing.assert_allclose(eight.roots, joined.roots, rtol=0, atol=SAME)
    assert (eight.boxes, eight.set_aside, eight.shares) == (whole.boxes, whole.set_aside, 8)
    # The pool's results with share 1 dropped: refused, not merged into a smaller proof.
    real = box_shares.as_done
    lossy = lambda *a: ((k, r) for k, r in real(*a) if k != 1)  # noqa: E731
    monkeypatch.setattr(box_shares, "as_done", lossy)
    gap = r"cover 0.875 of the domain, not all of it \(shares \[1\] of 8 never came back"
    with pytest.raises(cb.SolverError, match=gap):
        box_shares.split_search(landscape, fw, SHORT, MIN_WIDTH, workers=2)


def test_workers_honoured_or_refused(tmp_path):
    """workers below 1, with a scheduler, on the paper's mechanism, on the complex route, in a
    sweep's settings: one ParameterError naming the setting, before any work or folder."""
    with pytest.raises(cb.ParameterError, match=r"workers = 0: must be an integer >= 1"):
        cb.Settings(workers=0)
    with pytest.raises(cb.ParameterError, match=r"workers = 2 with scheduler = 'tcp://h:1'"):
        cb.Settings(workers=2, scheduler="tcp://h:1")
    with pytest.raises(cb.ParameterError, match=r"workers = 2: the paper's mechanism"):
        cb.solve(cb.Params(), workers=2, cache=False)
    fivebar = cb.Framework.from_toml(ROOT / "tests" / "fixtures" / "fivebar.toml")  # 2 DOF loop
    with pytest.raises(cb.ParameterError, match=r"workers = 2: .* complex route of"):
        cb.solve(fivebar, workers=2, cache=False)
    out = tmp_path / "sweeps"
    fw = cb.Framework.from_toml(FILE)
    with pytest.raises(cb.ParameterError, match=r"workers = 2 in the settings: a sweep or map"):
        cb.sweep(fw, "weight", [0.1, 0.2], cb.Settings(workers=2), out=out)
    assert not out.exists()
    res = run_cli("solve", "--framework", str(FILE), "--workers", "0", "--out", str(out))
    assert res.returncode == 2 and not out.exists(), res.stderr
    assert res.stderr.strip().splitlines() == [
        "cotm-bertini: error: workers = 0: must be an integer >= 1"
    ]


@pytest.fixture(scope="module")
def scheduler():
    """A two-process Dask cluster for this module (the workers import the package)."""
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
    ) as cluster:
        yield cluster.scheduler_address


def test_dask_cluster_proves_what_one_process_does(reference, serial, scheduler):
    """chain3 solved with its boxes on a two-process Dask cluster: the rows of the serial
    solve (1e-8) and the reference's, one share a worker."""
    fw = cb.Framework.from_toml(FILE)
    one, dask = serial, cb.solve(fw, cache=False, scheduler=scheduler)
    _matches_reference(dask, reference)
    _same_tables(one.table, dask.table)
    a, b = (r.record["details"]["real_search"] for r in (one, dask))
    assert b["shares"] == 2 and a["boxes"] == b["boxes"] and a["roots"] == b["roots"]
    assert dask.record["engine"]["flavour"] == "real"


def test_a_time_limit_stops_every_share_and_says_so():
    """timeout holds for the shared search as a whole: both shares stop at the common deadline,
    their boxes left are undecided, the status incomplete and the warning says how many
    shares stopped."""
    res = cb.solve(cb.Framework.from_toml(FILE), workers=2, timeout=0.05, cache=False)
    found = res.record["details"]["real_search"]
    assert res.status == "incomplete" and found["undecided"] > 0 and found["shares"] == 2
    assert re.search(r"left \d+ boxes undecided .*2 of 2 shares stopped at", res.warnings[0])


def test_by_default_a_search_probes_in_process_then_shares_what_is_left(monkeypatch):
    """workers=None (solve's default): the search runs here for PROBE_SECONDS; a search done by
    then is that plain search (no process started), one that is not goes on over one process
    a core from the boxes it left, and proves the same roots (chain3, probes of 60 s and of
    0.3 s, two cores)."""
    monkeypatch.setattr(box_shares, "default_workers", lambda: 2)
    fw = cb.Framework.from_toml(FILE)
    plain = search(landscape(fw), SHORT, MIN_WIDTH)
    monkeypatch.setattr(box_shares, "PROBE_SECONDS", 60.0)
    here = box_shares.split_search(landscape, fw, SHORT, MIN_WIDTH, workers=None)
    assert here.shares == 1 and here.boxes == plain.boxes
    monkeypatch.setattr(box_shares, "PROBE_SECONDS", 0.3)
    shared = box_shares.split_search(landscape, fw, SHORT, MIN_WIDTH, workers=None)
    assert shared.shares >= 2 and not shared.budget_hit and len(shared.undecided) == 0
    np.testing.assert_allclose(_sorted(shared.roots), _sorted(plain.roots), atol=SAME)
