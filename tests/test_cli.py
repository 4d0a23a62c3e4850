"""The console script: a real solve, bad input, and solver faults (with stand-in binaries)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
from conftest import run_cli

REQUIRED = [
    "solution_id",
    "gamma1_deg",
    "gamma2_deg",
    "d1",
    "d2",
    "is_real",
    "max_imag",
    "physical",
    "stable",
    "residual",
    "condition_number",
    "multiplicity",
]


def cli(*args: str, env: dict | None = None, cwd: Path | None = None):
    """Run `cotm-bertini` as a user would, in a fresh process."""
    return run_cli(*args, env=env, cwd=cwd, timeout=300)


def test_solve_case1_writes_run_folder(tmp_path):
    """solve case1: exit 0, one run folder with solutions.csv, input, Bertini files, run.json."""
    r = cli("solve", "case1", "--out", str(tmp_path), "--seed", "11", "--engine", "cli")
    assert r.returncode == 0, r.stderr
    runs = [p for p in tmp_path.iterdir() if p.is_dir() and not p.is_symlink()]
    assert len(runs) == 1
    run = runs[0]
    assert str(run) in r.stdout
    for name in (
        "solutions.csv",
        "input",
        "run.json",
        "main_data",
        "finite_solutions",
        "configurations.png",
        "energy_map.svg",
    ):
        assert (run / name).is_file(), name
    table = pd.read_csv(run / "solutions.csv")
    assert list(table.columns[: len(REQUIRED)]) == REQUIRED
    assert len(table) == 6 and table["is_real"].sum() == 4
    assert table.loc[table["is_real"], "gamma1_deg"].between(0, 360).all()
    rec = json.loads((run / "run.json").read_text())
    assert rec["status"] == "ok"
    assert rec["seed"] == 11 and "RandomSeed: 11;" in (run / "input").read_text()
    assert rec["parameters"]["L01"] == 0.0 and rec["parameters"]["L3"] == 9.0
    for key in ("bertini2", "numpy", "sympy"):
        assert rec["versions"][key] not in ("", "not installed")
    for stage in ("derive", "render", "bertini", "solve", "parse", "classify", "write", "total"):
        assert rec["timings"][stage] >= 0
    assert rec["counts"]["distinct_solutions"] == 6
    assert rec["morse"]["ok"] and rec["morse"]["euler_characteristic"] == 0
    assert not list(tmp_path.glob(".partial-*"))


def test_default_engine_is_the_parameter_homotopy(tmp_path):
    """Without --engine: the in-process parameter homotopy, recorded in run.json."""
    r = cli("solve", "case2", "--out", str(tmp_path), "--no-plots", "--quiet")
    assert r.returncode == 0, r.stderr
    run = Path(r.stdout.strip())
    rec = json.loads((run / "run.json").read_text())
    assert rec["engine"]["flavour"] == "homotopy"
    assert rec["details"]["homotopy"]["lost"] == 0
    # By monodromy (the default route), proved by the trace test; its augmented fibre is at
    # most the Bezout number of case 2 (48: F + c M x + e has F's degrees).
    (route,) = rec["details"]["homotopy"]["generic_route"]["generic_sets"]
    assert route["route"] == "monodromy" and route["evidence"] == ["trace test"]
    assert rec["details"]["generic_set"]["paths"] <= 48
    assert "pathvariable t;" in (run / "input").read_text()
    table = pd.read_csv(run / "solutions.csv")
    assert (len(table), table["is_real"].sum(), table["physical"].sum()) == (22, 10, 6)


def test_params_file_and_set_override(tmp_path):
    """A TOML subset plus --set: the rest from Table 1, the case preset only sets L01/L02."""
    toml = tmp_path / "p.toml"
    toml.write_text("k2 = 3.0\nL3 = 9.5\n")
    r = cli(
        "solve",
        "case2",
        "--params",
        str(toml),
        "--set",
        "L01=10",
        "--out",
        str(tmp_path / "o"),
        "--quiet",
    )
    assert r.returncode == 0, r.stderr
    rec = json.loads((Path(r.stdout.strip()) / "run.json").read_text())
    p = rec["parameters"]
    assert (p["k2"], p["L3"], p["L01"], p["L02"], p["k1"]) == (3.0, 9.5, 10.0, 0.0, 2.81)


@pytest.mark.parametrize(
    ("toml", "sets", "needle"),
    [
        ("k1 = -1\n", [], "k1 = -1"),
        (None, [], "file not found"),
        ("q7 = 1\n", [], "q7: unknown parameter"),
        ('L3 = "nine"\n', [], "L3 = 'nine': must be a number"),
        (None, ["--set", "L01=abc"], "L01 = 'abc': must be a number"),
        (None, ["--set", "L02=-2"], "L02 = -2.0"),
        ("L3 = nan\n", [], "L3 = nan: must be finite"),
        ("p6x = 0\n", [], "p6x = 0.0"),
        ("k1 = [\n", [], "not valid TOML"),
    ],
)
def test_bad_input_is_one_line_exit_2_and_no_folder(tmp_path, toml, sets, needle):
    """Bad input: one clear line naming field and value, exit code 2, no run folder at all."""
    args = ["solve", "case1", "--out", str(tmp_path / "out")]
    if toml is not None:
        (tmp_path / "p.toml").write_text(toml)
        args += ["--params", str(tmp_path / "p.toml")]
    elif not sets:
        args += ["--params", str(tmp_path / "missing.toml")]
    r = cli(*args, *sets)
    assert r.returncode == 2
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    assert needle in lines[0]
    assert not (tmp_path / "out").exists()


def _fake_bertini(tmp_path: Path, body: str) -> Path:
    exe = tmp_path / "fake-bertini"
    exe.write_text("#!/bin/sh\n" + body + "\n")
    exe.chmod(0o755)
    return exe


@pytest.mark.parametrize(
    ("body", "needle"),
    [
        ('echo "ERROR: could not parse function f0" >&2; exit 1', "could not parse function f0"),
        ("sleep 30", "timed out after 1 s"),
        ('echo "finished"', "wrote no main_data"),
    ],
)
def test_solver_faults_are_reported_and_recorded(tmp_path, body, needle):
    """A crash, a timeout, missing output: exit 3, Bertini's words quoted, a -failed folder."""
    exe = _fake_bertini(tmp_path, body)
    r = cli("solve", "case1", "--bertini", str(exe), "--timeout", "1", "--out", str(tmp_path / "o"))
    assert r.returncode == 3
    assert needle in r.stderr
    failed = list((tmp_path / "o").glob("*-failed"))
    assert len(failed) == 1
    rec = json.loads((failed[0] / "run.json").read_text())
    assert rec["status"] == "failed" and needle in rec["error"]
    assert "retried with seed" in rec["error"] and "retried with seed" in r.stderr
    for n in (1, 2):  # both attempts kept, each with what Bertini said
        assert (failed[0] / f"failed-attempt-{n}" / "bertini.stderr").is_file()
    assert not list((tmp_path / "o").glob(".partial-*"))


def test_a_failed_attempt_is_retried_with_a_new_seed(tmp_path, fixtures_dir):
    """First Bertini run crashes, the retry (new seed, tighter tolerances) succeeds: exit 0,
    run.json lists both attempts, the retry's input has the new seed."""
    src = fixtures_dir / "case1"
    marker = tmp_path / "crashed-once"
    exe = _fake_bertini(
        tmp_path,
        f'if [ ! -e {marker} ]; then touch {marker}; echo "Segmentation fault" >&2; exit 139; fi\n'
        f'for f in {src}/*; do n=$(basename "$f"); [ "$n" = input ] || cp "$f" .; done\n'
        f"chmod u+w *; cat {src}/stdout.txt",
    )
    r = cli(
        "solve",
        "case1",
        "--bertini",
        str(exe),
        "--seed",
        "5",
        "--out",
        str(tmp_path / "o"),
        "--quiet",
        "--no-plots",
    )
    assert r.returncode == 0, r.stderr
    assert "attempt 1 failed" in r.stderr and "Segmentation fault" in r.stderr
    run = Path(r.stdout.strip())
    rec = json.loads((run / "run.json").read_text())
    attempts = rec["details"]["attempts"]
    assert [a["ok"] for a in attempts] == [False, True]
    assert attempts[1]["settings"]["RandomSeed"] != "5"
    assert "TrackTolBeforeEG: 1.0e-7;" in (run / "input").read_text()
    assert (run / "failed-attempt-1" / "input").is_file()


@pytest.mark.parametrize("case", ["case1", "case2", "case3"])
def test_user_bertini1_binary(tmp_path, fixtures_dir, case):
    """COTM_BERTINI: a Bertini 1.x binary (replaying the real 1.6 files) runs the pipeline."""
    src = fixtures_dir / case
    exe = _fake_bertini(
        tmp_path,
        f'for f in {src}/*; do n=$(basename "$f"); [ "$n" = input ] || cp "$f" .; done\n'
        f"chmod u+w *; cat {src}/stdout.txt",
    )
    r = cli("solve", case, "--out", str(tmp_path / "o"), "--quiet", env={"COTM_BERTINI": str(exe)})
    assert r.returncode == 0, r.stderr
    run = Path(r.stdout.strip())
    rec = json.loads((run / "run.json").read_text())
    assert rec["engine"]["flavour"] == "bertini1" and rec["engine"]["version"] == "1.6"
    assert rec["details"]["output_layout"] == "bertini1"
    expected = {"case1": (8, 6, 4), "case2": (48, 22, 10), "case3": (192, 76, 30)}[case]
    c = rec["counts"]
    assert (c["paths_tracked"], c["distinct_solutions"], c["real"]) == expected


def test_verify_case1_all_routes_agree():
    """verify: Morse count, energy route, resultant and PHCpack all agree with Bertini."""
    r = cli("verify", "case1")
    assert r.returncode == 0, r.stdout + r.stderr
    for route in ("Morse count", "energy Newton", "Sylvester resultant", "PHCpack"):
        line = next(ln for ln in r.stdout.splitlines() if route in ln)
        assert " agrees " in line, line
    assert "all routes agree" in r.stdout


def test_second_identical_request_is_answered_from_the_cache(tmp_path):
    """Same request twice: the second run says it used the cache and has the same table;
    --no-cache solves again; a changed parameter is a different request."""
    # A parameter set no other test asks for, so the session cache has not seen it.
    args = ["solve", "case2", "--set", "k2=2.7123", "--out", str(tmp_path), "--no-plots", "--quiet"]
    first = cli(*args)
    second = cli(*args)
    assert first.returncode == 0 and second.returncode == 0, second.stderr
    assert "cache: answered" not in first.stderr and "cache: answered" in second.stderr
    a, b = Path(first.stdout.strip()), Path(second.stdout.strip())
    assert a != b
    assert (a / "solutions.csv").read_text() == (b / "solutions.csv").read_text()
    rec = json.loads((b / "run.json").read_text())
    assert rec["cache"]["hit"] is True
    third = cli(*args, "--no-cache")
    assert "cache: answered" not in third.stderr
    changed = cli(*args, "--set", "L01=11.4")
    assert "cache: answered" not in changed.stderr


def test_a_cold_solve_from_a_warm_cache_imports_no_sympy(tmp_path):
    """`solve case3 --no-cache` in a fresh process, once the derived equations and the generic
    set are cached: the compiled system serves, so sympy (~0.3 s to import) is never loaded."""
    code = (
        "import sys\n"
        "from cotm_bertini.cli import main\n"
        f"rc = main(['solve', 'case3', '--no-cache', '--no-plots', '--quiet', '--out', "
        f"{str(tmp_path)!r}])\n"
        "print(rc, 'sympy' in sys.modules)\n"
    )
    warm = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert warm.returncode == 0, warm.stderr
    cold = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert cold.stdout.split()[-2:] == ["0", "False"], cold.stdout + cold.stderr


@pytest.mark.parametrize(
    ("args", "line"),
    [
        (["solve", "--framwork", "f"], "unknown option --framwork (did you mean --framework?)"),
        (["solve", "case3", "--no-cahce"], "unknown option --no-cahce (did you mean --no-cache?)"),
        (["map", "--param", "x", "--fro2=1"], "unknown option --fro2 (did you mean --from2?)"),
        (["solve", "--xyzzy"], "unknown option --xyzzy (`cotm-bertini solve --help` lists them)"),
        (["solv", "case3"], "unknown command 'solv' (did you mean solve?)"),
        (["--verison"], "unknown option --verison (did you mean --version?)"),
    ],
)
def test_an_unknown_option_is_named_with_the_nearest_known_one(tmp_path, capsys, args, line):
    """A typo in an option is named (not taken for the case's value), exit 2, nothing written."""
    from cotm_bertini.cli.main import main

    with pytest.raises(SystemExit) as exc:
        main([*args, "--out", str(tmp_path / "out")])
    assert exc.value.code == 2
    assert capsys.readouterr().err == f"cotm-bertini: error: {line}\n"
    assert not (tmp_path / "out").exists()


def test_an_option_abbreviated_unambiguously_is_still_accepted(capsys):
    from cotm_bertini.cli.main import main

    assert main(["params", "case3", "--set=k2=3", "--rou", "complex"]) == 0
    assert "k2 = 3.0" in capsys.readouterr().out


def test_a_library_warning_reaches_the_console_as_one_line():
    """A warning not yet fixed where it arises is one line like the package's own, its source
    named, not Python's two lines with the source quoted."""
    import importlib

    cli_main = importlib.import_module("cotm_bertini.cli.main")
    text = cli_main._warning_line(RuntimeWarning("invalid value encountered in add"),
                                  RuntimeWarning, "/x/model/intervals.py", 76)  # fmt: skip
    assert text == ("cotm-bertini: warning: invalid value encountered in add "
                    "(RuntimeWarning, intervals.py:76)\n")  # fmt: skip
