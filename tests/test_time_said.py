"""Time said, and no silent minutes (issue 39, item 6): the cost statement by monodromy,
a finished sweep run again (to draw its page) that solves nothing, and the events' refinement
reporting its progress on stderr (a plan reusing the identical map: tests/test_motion.py, which
has that map made already).

Path counts are the Bezout number computed independently (tests/test_progress.bezout);
"nothing solved again" is checked by making every solve and every refinement raise.
"""

from __future__ import annotations

import re

import pytest
from conftest import ROOT
from test_progress import zeeman_paths

import cotm_bertini as cb
from cotm_bertini import progress

ZEEMAN = ROOT / "examples" / "zeeman.toml"


def test_params_framework_by_monodromy_says_why_no_time_and_times_the_fallback(
    tmp_path, monkeypatch
):
    """`params --framework`'s statement (cb.cost's lines) for a taut set found by monodromy by
    default (zeeman's, under a route rule lowered to 0 paths: at its 24 paths it would take
    total degree), empty cache: it says plainly that the search has no time estimate and why,
    and gives the total-degree fallback's paths (two seeds x the Bezout number) and its time at
    the rate it measured (paths x rate). With monodromy asked for there is no fallback to time."""
    from cotm_bertini.backends import generic

    monkeypatch.setenv("COTM_CACHE", str(tmp_path))
    monkeypatch.setattr(generic, "TOTAL_DEGREE_PATHS", 0)
    fw = cb.Framework.from_toml(ZEEMAN)
    text = "\n".join(cb.cost(fw, cb.Settings(route="complex")).lines())
    assert "no time estimate: a monodromy search tracks paths until its trace test passes" in text
    m = re.search(
        r"the total-degree fallback tracks (\d+) paths \(two seeds\), an estimated ([\d.]+) s "
        r"at ([\d.]+) s a path \(measured on the first (\d+) paths",
        text,
    )
    assert m, text
    assert int(m[1]) == 2 * zeeman_paths()
    assert float(m[2]) == pytest.approx(int(m[1]) * float(m[3]), rel=0.06, abs=0.06)
    asked = cb.cost(fw, cb.Settings(generic="monodromy")).headline()
    assert "fallback" not in asked
    assert f"the total-degree route would track {zeeman_paths()} paths per set" in asked


def test_a_finished_sweep_run_again_with_html_solves_nothing(tmp_path, monkeypatch, capfd):
    """A framework sweep across Zeeman's bistable region: its events are refined (each probe a
    solve) with progress lines on stderr; run again with --html, every point is resumed and the
    events are read back (a solve or a refinement would raise), events.csv is unchanged and
    the page is written."""
    from cotm_bertini import point
    from cotm_bertini.cli.main import main
    from cotm_bertini.continuation import framework_events

    monkeypatch.setenv(progress.ENV_DELAY, "0")
    monkeypatch.setenv(progress.ENV_SECONDS, "0")
    args = ["sweep", "--framework", str(ZEEMAN), "--set", "x=0.1", "--param", "y", "--from", "-1",
            "--to", "0.5", "--points", "16", "--no-plots", "--out", str(tmp_path)]  # fmt: skip
    assert main(args) == 0
    err = capfd.readouterr().err
    folder = next(tmp_path.glob("sweep-*"))
    events = (folder / "events.csv").read_text()
    changes = len(events.splitlines()) - 1
    assert changes >= 2  # the two folds of the bistable region
    lines = [ln for ln in err.splitlines() if ln.startswith("sweep: events refined")]
    assert lines and re.search(r"(\d+)/\1 intervals", lines[-1]), err

    def no(*args, **kwargs):
        raise AssertionError("solved again")

    monkeypatch.setattr(point, "solve_framework_point", no)
    monkeypatch.setattr(framework_events, "framework_event_records", no)
    assert main([*args, "--html"]) == 0
    assert (folder / "events.csv").read_text() == events
    assert (folder / "explore.html").is_file()
    assert not [ln for ln in capfd.readouterr().err.splitlines() if "events refined" in ln]
