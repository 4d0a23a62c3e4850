"""README.md's examples run as written, so they cannot drift from the code.

Every fenced ```python block runs in a fresh interpreter, and every line of every ```sh block
as a command, each in a scratch folder that links in examples/ (so `runs/`, `bifurcation.png`
and the rest are written there, not in the repository), with the session's fresh cache
(conftest.py: COTM_CACHE, a new temporary folder) and the venv's `cotm-bertini` first on PATH.

Set-up lines are skipped by pattern, never silently: SETUP below names them (`make ...`: the
targets install packages and run whole suites, the test suite itself among them). Any other
line must be a `cotm-bertini` command, and must exit 0. The tests count what they ran: at least
one Python block and one command.

The pictures README shows are checked against `make figures`: each caption names the command
that made it, which must be the Makefile's (less the scratch `--out`), and a date.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT

README = ROOT / "README.md"
SETUP = re.compile(r"^make\s")  # set-up lines, skipped: `make case3`, `make test`, ...
FENCE = re.compile(r"^```(\w+)[^\n]*\n(.*?)^```", re.M | re.S)
PICTURE = re.compile(r"^!\[[^\]]*\]\((docs/img/[\w.-]+\.png)\)\s*$")
CAPTION = re.compile(r"`(cotm-bertini [^`]+)`, (\d{4}-\d{2}-\d{2})\.\*$")

pytestmark = pytest.mark.xdist_group("readme")


def blocks(language: str) -> list[str]:
    """The bodies of README's fenced blocks of one language, in order."""
    return [body for lang, body in FENCE.findall(README.read_text()) if lang == language]


def commands(block: str) -> list[str]:
    """A shell block's command lines: continuations joined, comments and blank lines dropped."""
    text = re.sub(r"\\\n\s*", " ", block)
    return [line for line in text.splitlines() if shlex.split(line, comments=True)]


def scratch(tmp_path: Path) -> tuple[Path, dict]:
    """A folder to run in (examples/ linked in) and the environment: the venv's bin first."""
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    venv_bin = str(Path(sys.executable).parent)
    env = {**os.environ, "PATH": venv_bin + os.pathsep + os.environ.get("PATH", "")}
    env.update(COTM_PROGRESS="0", MPLBACKEND="Agg")
    assert env.get("COTM_CACHE"), "conftest.py gives the session a fresh cache"
    return tmp_path, env


def test_the_python_examples_run(tmp_path):
    cwd, env = scratch(tmp_path)
    ran = 0
    for code in blocks("python"):
        done = subprocess.run(
            [sys.executable, "-c", code], cwd=cwd, env=env, capture_output=True, text=True,
            timeout=300,
        )  # fmt: skip
        assert done.returncode == 0, f"README's Python example failed:\n{code}\n{done.stderr}"
        ran += 1
    assert ran >= 1, "README has no ```python block"
    assert (cwd / "runs" / "mine" / "solutions.csv").is_file()  # the example's res.save(...)


def test_the_command_line_examples_run(tmp_path):
    cwd, env = scratch(tmp_path)
    ran, skipped = 0, []
    for block in blocks("sh"):
        for line in commands(block):
            argv = shlex.split(line, comments=True)
            if SETUP.match(line):
                skipped.append(line)
                continue
            assert argv[0] == "cotm-bertini", f"not a cotm-bertini command nor set-up: {line}"
            exe = Path(sys.executable).parent / "cotm-bertini"
            assert exe.is_file(), f"{exe}: the venv's command is missing"
            done = subprocess.run(
                argv, cwd=cwd, env=env, capture_output=True, text=True, timeout=300
            )
            assert done.returncode == 0, f"`{line}` exited {done.returncode}:\n{done.stderr}"
            ran += 1
    assert ran >= 1, "README has no cotm-bertini command in a ```sh block"
    assert any(s.startswith("make case3") for s in skipped)  # the set-up block is still there


def figures_commands() -> dict[str, str]:
    """`make figures`: each docs/img/<name>.png and the command that made it (as typed)."""
    makefile = (ROOT / "Makefile").read_text()
    recipe = re.search(r"^figures: \$\(STAMP\)\n((?:\t.*\n)+)", makefile, re.M)
    assert recipe, "the Makefile has no figures target"
    made, last = {}, None
    for line in recipe.group(1).splitlines():
        line = line.strip()
        if line.startswith("$(CLI) "):
            last = "cotm-bertini " + re.sub(r" --out \S+$", "", line.removeprefix("$(CLI) "))
        elif line.startswith("cp ") and last:
            made[line.split()[-1]] = last
    return made


def test_each_picture_names_the_command_that_made_it():
    made = figures_commands()
    lines = README.read_text().splitlines()
    shown = 0
    for i, line in enumerate(lines):
        picture = PICTURE.match(line)
        if not picture:
            continue
        path = picture.group(1)
        assert (ROOT / path).is_file(), path
        caption = next(x for x in lines[i + 1 :] if x.strip())
        named = CAPTION.search(caption)
        assert named, f"{path}: its caption names no command and date: {caption}"
        assert path in made, f"{path} is not made by `make figures`"
        assert named.group(1) == made[path], f"{path}: the Makefile runs `{made[path]}`"
        shown += 1
    assert shown >= 5
