"""Issue 16, items 1, 2, 8, 9, 10 and 12: one set of defaults, honest messages, readable help
and design output; each checked where a user meets it (the command line, or the Python API)."""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

import cotm_bertini as cb
from cotm_bertini.cli.main import _parser, main

ROOT = Path(__file__).resolve().parent.parent
P3 = cb.Params.case("case3")


def cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """`cotm-bertini ARGS` in a fresh process, as a user runs it."""
    return subprocess.run(
        [sys.executable, "-m", "cotm_bertini.cli", *args],
        capture_output=True, text=True, cwd=cwd, env=dict(os.environ), timeout=300,
    )  # fmt: skip


def _one_line(r: subprocess.CompletedProcess, code: int = 2) -> str:
    assert r.returncode == code, r.stdout + r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    return lines[0]


def _commands() -> dict[str, argparse.ArgumentParser]:
    sub = next(a for a in _parser()._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


# Item 1: one rule for the defaults, `params` prints what `solve` solves.


@pytest.mark.parametrize("case", [[], ["case3"]])
def test_1_params_solve_and_sweep_use_the_same_parameters(tmp_path, monkeypatch, capsys, case):
    """A file holding only k2 = 5: `params`, `solve`, `sweep` and cb.Params agree on the set."""
    toml = tmp_path / "mine.toml"
    toml.write_text("k2 = 5\n")
    monkeypatch.chdir(tmp_path)
    expected = cb.Params.from_toml(toml, case=case[0] if case else None).as_dict()
    assert main(["params", *case, "--params", str(toml)]) == 0
    printed = tomllib.loads(capsys.readouterr().out)
    assert printed == expected
    assert main(["solve", *case, "--params", str(toml), "--no-plots", "--out", "s"]) == 0
    first = capsys.readouterr().out.splitlines()[0]
    free = "L01 = 11.5 m, L02 = 11.5 m" if case else "L01 = 0 m, L02 = 0 m"
    label = case[0] if case else "mine"
    assert first.startswith(f"{label} ({free}; k2 = 5 N/m): "), first
    solved = json.loads((tmp_path / "s" / "latest" / "run.json").read_text())["parameters"]
    assert solved == expected
    if case:
        return  # `sweep` takes no case
    argv = ["sweep", "--param", "k1", "--from", "2", "--to", "3", "--points", "2"]
    assert main([*argv, "--params", str(toml), "--no-plots", "--quiet", "--out", "w"]) == 0
    (spec,) = (tmp_path / "w").glob("sweep-*/sweep.json")
    base = json.loads(spec.read_text())["spec"]["base"]
    assert {**base, "k1": expected["k1"]} == expected


def test_1_no_case_is_table1_everywhere(tmp_path, monkeypatch, capsys):
    """No case, no file, no --set: Table 1 as printed (cb.Params()), labelled table1."""
    monkeypatch.chdir(tmp_path)
    assert main(["params"]) == 0
    assert tomllib.loads(capsys.readouterr().out) == cb.Params().as_dict()
    assert main(["solve", "--no-plots", "--quiet"]) == 0
    folder = Path(capsys.readouterr().out.strip())
    assert folder.parent == Path("runs") / "table1"
    assert json.loads((folder / "run.json").read_text())["parameters"] == cb.Params().as_dict()


# Item 2: a range needs two points; one point needs --from equal to --to.


@pytest.mark.parametrize(
    ("args", "needles"),
    [
        (["--param", "L01", "--from", "0", "--to", "12", "--points", "1"], ["--points 1", "12"]),
        (["--param", "L01", "--points", "1"], ["--points 1", "from 0 to 12"]),
        (["--param", "L01", "--points", "0"], ["--points 0"]),
        (["--points", "2", "--param2", "L02", "--from2", "1", "--to2", "3", "--points2", "1"],
         ["--points2 1", "--from2 V --to2 V"]),
        (["--param", "zz", "--from", "0", "--to", "1", "--points", "2"], ["--param 'zz'"]),
        (["--points", "2", "--param2", "L01", "--from2", "1", "--to2", "2", "--points2", "2"],
         ["--param2 'L01'", "same as --param"]),
    ],
)  # fmt: skip
def test_2_a_range_with_fewer_than_two_points_is_refused(tmp_path, args, needles):
    line = _one_line(cli("sweep", *args, "--no-plots", "--out", str(tmp_path / "o")))
    assert all(n in line for n in needles), line
    assert not any(tmp_path.iterdir())


def test_2_one_point_is_one_value(tmp_path, capsys):
    """--points 1 with --from equal to --to solves that one value, named by it."""
    argv = ["sweep", "--param", "L01", "--from", "5", "--to", "5", "--points", "1"]
    assert main([*argv, "--no-plots", "--quiet", "--workers", "1", "--out", str(tmp_path)]) == 0
    (folder,) = tmp_path.glob("sweep-*")
    assert folder.name.startswith("sweep-L01-5-5-1-")
    spec = json.loads((folder / "sweep.json").read_text())["spec"]
    assert spec["values"] == [5.0]


def test_2_python_linspace_refuses_a_one_point_range():
    from cotm_bertini.continuation.spec import SweepSpec

    with pytest.raises(cb.ParameterError, match=r"points = 1 for L01 from start = 0 to stop = 12"):
        SweepSpec.linspace(cb.Params(), "L01", 0.0, 12.0, 1)
    assert SweepSpec.linspace(cb.Params(), "L01", 4.0, 4.0, 1).values == (4.0,)


# Item 8: Python errors are ParameterError naming the Python argument, never a CLI flag.


def _api_calls(tmp_path: Path) -> list[tuple[str, object]]:
    """(expected text, a call) for each bad Python input."""
    from cotm_bertini.continuation.spec import SweepSpec

    a_file = tmp_path / "a-file"
    a_file.write_text("x")
    p = cb.Params()
    return [
        ("foo: unknown parameter", lambda: cb.Params(foo=1)),
        ("L3 = 1: given twice", lambda: cb.Params(9.0, L3=1)),
        ("bar: unknown parameter", lambda: p.replace(bar=1)),
        ("colour: unknown setting", lambda: cb.Settings(colour="red")),
        ("gamma1_deg = 'abc': must be a number", lambda: cb.design(P3, "abc", 3)),
        ("gamma2_deg = inf: must be finite", lambda: cb.design(P3, 1.0, math.inf)),
        ("L02 = 'x': must be a number", lambda: cb.design(P3, 1.0, 2.0, L02="x")),
        ("params = 'case3': expected a cb.Params", lambda: cb.design("case3", 1.0, 2.0)),
        ("param = 'zz': unknown parameter", lambda: cb.sweep(p, "zz", [0, 1])),
        ("workers = 0: must be an integer >= 1", lambda: cb.sweep(p, "L01", [0, 1], workers=0)),
        ("param2 = 'L01': same as param",
         lambda: cb.sweep(p, "L01", [0, 1], param2="L01", values2=[1, 2])),
        ("param2 = 'L02': needs values2", lambda: cb.sweep(p, "L01", [0, 1], param2="L02")),
        (f"out {str(a_file)!r}", lambda: cb.sweep(p, "L01", [0, 1], out=a_file)),
        ("points = 0 for L01", lambda: SweepSpec.linspace(p, "L01", 0.0, 1.0, 0)),
        ("points = 1: a map needs", lambda: cb.design_map(p, points=1)),
        ("workers = 0", lambda: cb.resume_sweep(tmp_path, workers=0)),
        (f"folder {str(tmp_path / 'nope')!r}", lambda: cb.resume_sweep(tmp_path / "nope")),
        (f"folder {str(tmp_path)!r}: no sweep.json", lambda: cb.resume_sweep(tmp_path)),
        (f"path {str(tmp_path / 'n.toml')!r}", lambda: cb.Params.from_toml(tmp_path / "n.toml")),
    ]  # fmt: skip


def test_8_python_errors_name_the_python_argument(tmp_path):
    for needle, call in _api_calls(tmp_path):
        with pytest.raises(cb.ParameterError) as info:
            call()
        text = str(info.value)
        assert needle in text, (needle, text)
        assert not re.search(r"--\w", text), text  # no command-line flag from Python
        assert "\n" not in text
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a-file"]  # nothing half-written


def test_8_the_command_line_still_names_its_flags(tmp_path):
    assert "--workers 0" in _one_line(cli("sweep", "--points", "2", "--workers", "0"))
    assert "--params" in _one_line(cli("params", "--params", str(tmp_path / "no.toml")))
    assert "--gamma2 nan" in _one_line(cli("design", "--gamma1", "1", "--gamma2", "nan"))
    assert "--points 1" in _one_line(cli("map", "--points", "1", "--out", str(tmp_path / "m")))
    assert "--resume" in _one_line(cli("sweep", "--resume", str(tmp_path)))
    assert not (tmp_path / "m").exists()


# Item 9: every output file that --help or docs/cli.md names is written.


def _named_files(text: str) -> set[str]:
    """File names a text promises: `x.json`, `x.csv`, and `x.png/svg` as both."""
    names = set(re.findall(r"\b([\w-]+\.(?:json|csv|md|png|svg))\b", text))
    for stem, a, b in re.findall(r"\b([\w-]+)\.(png|svg)/(png|svg)\b", text):
        names |= {f"{stem}.{a}", f"{stem}.{b}"}
    return names - {p.name for p in (ROOT / "docs").glob("*.md")}  # links to the docs


def _doc_bullet(command: str) -> str:
    text = (ROOT / "docs" / "cli.md").read_text()
    match = re.search(rf"^- `{command}`.*?(?=^- `|^#|\Z)", text, re.S | re.M)
    assert match, command
    return match.group(0)


@pytest.mark.parametrize(
    ("command", "folder"), [(["verify", "case1"], "."), (["barriers", "case1"], "latest")]
)
def test_9_help_and_docs_name_only_files_that_are_written(tmp_path, command, folder):
    out_help = next(a.help for a in _commands()[command[0]]._actions if "--out" in a.option_strings)
    promised = _named_files(out_help) | _named_files(_doc_bullet(command[0]))
    assert promised, command
    r = cli(*command, "--out", str(tmp_path))
    assert r.returncode == 0, r.stdout + r.stderr
    written = {p.name for p in (tmp_path / folder).iterdir()}
    assert promised <= written, promised - written


# Item 10: the top-level help says what the tool does and lists every command.


def test_10_top_level_help_has_a_purpose_and_every_command():
    r = cli("--help")
    assert r.returncode == 0
    assert "Every equilibrium of the planar compliant tensegrity mechanism" in r.stdout
    docs = (ROOT / "docs" / "cli.md").read_text()
    for name in _commands():
        assert re.search(rf"^\s+{name}\s+\w", r.stdout, re.M), f"{name} missing from --help"
        assert f"cotm-bertini {name}" in docs, f"{name} missing from docs/cli.md"


# Item 12: design speaks degrees in [0, 360), echoes what was asked, prints units.


def test_12_design_prints_units_and_angles_in_0_360(tmp_path):
    r = cli(
        "design", "case3", "--gamma1", "-30", "--gamma2", "400", "--out", str(tmp_path / "d.csv")
    )
    assert r.returncode == 0, r.stderr
    printed = tomllib.loads(r.stdout.split("-> ")[0])
    assert printed["gamma1_deg"] == pytest.approx(330.0) and printed["gamma2_deg"] == 40.0
    units = dict(re.findall(r"^(\w+) = .*#\s*([^,\s]+),", r.stdout, re.M))
    assert units["gamma1_deg"] == "deg" and units["L01"] == "m" and units["d2"] == "m"
    assert units["hess_eig_min"] == "J/rad^2"
    assert cb.design(P3, -30, 400).gamma1_deg == pytest.approx(330.0)


def test_12_design_refusal_echoes_the_pose_and_suggests_angles_in_0_360():
    line = _one_line(
        cli("design", "case3", "--gamma1", "56.0999", "--gamma2", "108.8997", "--L01", "3")
    )
    assert "gamma1 = 56.0999 deg, gamma2 = 108.8997 deg" in line
    suggested = re.search(r"the curve passes gamma2 = ([-\d., ]+) deg", line).group(1)
    values = [float(v) for v in suggested.split(",")]
    assert values and all(0 <= v < 360 for v in values), values
    assert values == sorted(values)
