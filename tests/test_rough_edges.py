"""Rough edges a new user hits (issue 12): one test per item, the command line run as a user
runs it (a subprocess), checked on exit codes, one-line messages, what is written and what is
not."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest


def cli(*args: str, cwd: Path | None = None, timeout: float = 300):
    return subprocess.run(
        [sys.executable, "-m", "cotm_bertini.cli", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        env=dict(os.environ),
        timeout=timeout,
    )


def _one_line(r, code: int = 2) -> str:
    assert r.returncode == code, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    return lines[0]


@pytest.mark.parametrize(
    "command", [["solve", "case1", "--no-plots"], ["sweep", "--points", "2", "--no-plots"]]
)
def test_1_out_that_is_a_file_is_one_line_exit_2(tmp_path, command):
    x = tmp_path / "x"
    x.write_text("mine")
    line = _one_line(cli(*command, "--out", str(x)))
    assert str(x) in line and "not a directory" in line
    assert x.read_text() == "mine" and sorted(p.name for p in tmp_path.iterdir()) == ["x"]


def test_2_sweep_range_is_required_unless_documented(tmp_path):
    for param in ("p5y", "k1"):
        line = _one_line(cli("sweep", "--param", param, "--points", "3", "--out", str(tmp_path)))
        assert "--from" in line and param in line and "default range" in line
    assert not any(tmp_path.iterdir())


def test_3_failed_completeness_check_is_incomplete_exit_5(tmp_path):
    """At the fold of the paper's sweep (L01 = 11.012830665 m) two equilibria merge into one
    double root: the Morse count is off, so the run is `incomplete`, exit 5, warning stored."""
    r = cli("solve", "case2", "--set", "L01=11.012830665", "--no-plots", "--out", str(tmp_path))
    assert r.returncode == 5, r.stderr
    assert "equilibria may be missing" in r.stderr
    assert r.stdout.strip().splitlines()[-1].startswith("status incomplete (exit 5): a complete")
    rec = json.loads((tmp_path / "latest" / "run.json").read_text())
    assert rec["status"] == "incomplete" and rec["morse"]["ok"] is False
    assert any("equilibria may be missing" in w for w in rec["warnings"])


def test_4_path_accounting_has_no_negative_counts(tmp_path):
    """A custom geometry: closed-form d = 0 roots are counted apart from tracked endpoints."""
    r = cli("solve", "--set", "p6x=3.9", "--set", "L02=7", "--no-plots", "--out", str(tmp_path))
    assert r.returncode == 0, r.stderr
    c = json.loads((tmp_path / "latest" / "run.json").read_text())["counts"]
    assert all(v is None or v >= 0 for v in c.values() if isinstance(v, int)), c
    assert c["finite_endpoints"] + c["infinite_or_failed_paths"] == c["paths_tracked"]
    assert c["closed_form_endpoints"] > 0
    assert f"{c['finite_endpoints']} finite endpoints of {c['paths_tracked']} paths" in r.stdout
    # An ok run says so too, as its last line (issue 46): not only in run.json.
    last = r.stdout.strip().splitlines()[-1]
    assert last == "status ok (exit 0): every completeness check passed"


def test_5_a_params_file_labels_the_run(tmp_path):
    toml = tmp_path / "soft-springs.toml"
    toml.write_text("k1 = 1.5\nk2 = 1.4\n")
    r = cli("solve", "--params", str(toml), "--no-plots", "--quiet", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    run = tmp_path / r.stdout.strip()  # printed relative to where the command ran
    assert run.parent == tmp_path / "runs" / "soft-springs"
    assert json.loads((run / "run.json").read_text())["label"] == "soft-springs"
    only_set = cli("solve", "--set", "k1=1.5", "--no-plots", "--quiet", cwd=tmp_path)
    assert (tmp_path / only_set.stdout.strip()).parent == tmp_path / "runs" / "custom"
    # --quiet: stdout is the folder alone, the status line goes to stderr.
    assert only_set.stderr.strip().splitlines()[-1].startswith("status ok (exit 0)")


def test_5b_every_exit_code_of_a_solve_has_its_status_line():
    """ok, incomplete and contradiction, each named with its exit code and what it means."""
    from types import SimpleNamespace

    from cotm_bertini.cli.commands import _exit_code, _status_line

    cases = [
        ("ok", None, 0),
        ("incomplete", None, 5),
        ("ok", "proved", 0),
        ("ok", "rows proved", 0),
        ("ok", "undecided", 5),
        ("ok", "contradiction", 4),
        ("contradiction", None, 4),
    ]
    for status, cert, code in cases:
        got = _exit_code(status, None if cert is None else SimpleNamespace(status=cert))
        assert got == code, (status, cert)
    assert _status_line(4).startswith("status contradiction (exit 4): a proof and an "
                                      "independent check disagree")  # fmt: skip
    assert _status_line(5).startswith("status incomplete (exit 5): a completeness check failed")


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--workers", "0"], "--workers 0"),
        (["--workers", "-2"], "--workers -2"),
        (["--from", "2", "--to", "2", "--points", "3"], "--from 2 --to 2"),
    ],
)
def test_6_workers_and_empty_ranges_are_refused(tmp_path, args, needle):
    line = _one_line(cli("sweep", "--points", "3", *args, "--out", str(tmp_path)))
    assert needle in line
    assert not any(tmp_path.iterdir())


def test_7_progress_is_line_by_line_when_not_a_terminal(tmp_path):
    r = cli("sweep", "--from", "1", "--to", "2", "--points", "3", "--workers", "1",
            "--no-plots", "--out", str(tmp_path))  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "\r" not in r.stderr
    assert "sweep: 3/3 points, 0 paths lost" in r.stderr.splitlines()


def test_8_angles_wrap_after_rounding():
    """An angle of 359.99996 deg prints as 0.0000, never 360.0000."""
    import numpy as np

    from cotm_bertini.io.runfolder import summary_text

    record = {
        "counts": {
            "distinct_solutions": 1, "real": 1, "physical": 1, "stable": 0,
            "finite_endpoints": 1, "paths_tracked": 1, "closed_form_endpoints": 0,
        },
        "engine": {"flavour": "homotopy", "path": "in-process", "version": "4.0.0"},
        "timings": {"solve": 0.1},
    }  # fmt: skip
    table = {
        "solution_id": np.array([1]), "gamma1_deg": np.array([359.99996]),
        "gamma2_deg": np.array([180.0]), "d1": np.array([1.0]), "d2": np.array([2.0]),
        "is_real": np.array([True]), "physical": np.array([True]),
        "stable": np.array([False]), "kind": np.array(["saddle"], dtype=object),
        "reason": np.array([""], dtype=object),
    }  # fmt: skip
    text = summary_text(record, table)
    assert "360.0000" not in text and " 0.0000" in text


def test_9_bifurcation_plot_shows_physical_events_only():
    """A fold between two negative-d branches is not drawn on the physical-only diagram."""
    from cotm_bertini.plot.bifurcation import bifurcation_figure

    rows = []
    for k, (value, phys) in enumerate([(1.0, True), (2.0, True)]):
        for branch, g, physical in ((0, 10.0, True), (1, 200.0, False), (2, 210.0, False)):
            rows.append({"point": k, "L01": value, "branch": branch, "gamma1_deg": g + k,
                         "gamma2_deg": g, "is_real": True, "physical": physical and phys,
                         "stable": physical})  # fmt: skip
    sweep = pd.DataFrame(rows)
    events = pd.DataFrame(
        [{"kind": "fold", "branches": "1+2", "L01": 1.5, "gamma1_deg": 205.0,
          "gamma2_deg": 205.0, "lo": 1.0, "hi": 2.0}]
    )  # fmt: skip
    fig = bifurcation_figure(sweep, "L01", events=events)
    folds = [c for ax in fig.axes for c in ax.collections if c.get_gid() == "fold"]
    assert not folds
    shown = bifurcation_figure(sweep, "L01", events=events, show_all=True)
    assert [c for ax in shown.axes for c in ax.collections if c.get_gid() == "fold"]
    assert "1 physical equilibria a point" in fig.texts[0].get_text()


def test_10_paper_report_explains_and_prints_a_verdict():
    """The report explains 88 vs 76 and case 1 under k2/k1 = 0.98909, cites no file outside
    the repository, and ends with a one-line verdict."""
    from conftest import solved
    from paper_tables import K_RATIO

    from cotm_bertini.paper.report import Scenario, build_report

    scenarios = []
    for name, k2 in (("printed", None), ("ratio", 2.81 * K_RATIO)):
        tables, params = {}, {}
        for case in ("case1", "case3"):
            point, p = solved(case, k2)
            tables[case], params[case] = point.table, p
        scenarios.append(Scenario(name, params, tables, {}))
    text, _ = build_report(scenarios)
    assert "88 solutions in the paper, 76 here" in text
    assert "Case 1 and the ratio k2/k1" in text and "NOTES" not in text and "../" not in text
    verdict = text.strip().splitlines()[-1]
    assert verdict.startswith("paper: Table 2:") and "Table 4:" in verdict


def test_help_describes_every_option_of_sweep_and_verify():
    """Every option of every subcommand has help text, and `--help` prints it."""
    import argparse

    from cotm_bertini.cli.main import _parser

    sub = next(a for a in _parser()._actions if isinstance(a, argparse._SubParsersAction))
    for name, parser in sub.choices.items():
        for action in parser._actions:
            assert action.help, f"{name} {action.option_strings or action.dest}: no help"
    for command in ("sweep", "verify"):
        r = cli(command, "--help")
        assert r.returncode == 0 and "--seed" in r.stdout
        assert "random seed of the solver" in r.stdout


def test_params_command_prints_table1():
    r = cli("params")
    assert r.returncode == 0
    assert "L3 = 9.0  # m, rod length" in r.stdout and "k1 = 2.81  # N/m" in r.stdout
    assert "L01 = 0.0" in r.stdout  # Table 1 as printed
    assert "L01 = 11.5" in cli("params", "case2").stdout


def test_verify_out_writes_a_record(tmp_path):
    r = cli("verify", "case1", "--out", str(tmp_path))
    assert r.returncode == 0, r.stdout + r.stderr
    rec = json.loads((tmp_path / "verify.json").read_text())
    assert rec["ok"] is True and len(rec["routes"]) == 4


def test_every_run_folder_has_a_column_reference(tmp_path):
    solve = cli("solve", "case1", "--no-plots", "--quiet", "--out", str(tmp_path / "s"))
    assert "`physical`" in (Path(solve.stdout.strip()) / "columns.md").read_text()
    sweep = cli("sweep", "--from", "1", "--to", "2", "--points", "2", "--workers", "1",
                "--no-plots", "--quiet", "--out", str(tmp_path / "w"))  # fmt: skip
    assert sweep.returncode == 0, sweep.stderr
    (folder,) = (tmp_path / "w").glob("sweep-*")
    text = (folder / "columns.md").read_text()
    assert "## sweep.csv" in text and "## events.csv" in text
