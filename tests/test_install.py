"""A non-editable install: the built wheel in a fresh venv solves case 1 from another folder."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _run(cmd: list[str], **kw) -> subprocess.CompletedProcess:
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=600, **kw)
    assert r.returncode == 0, f"{cmd}: {r.stdout}\n{r.stderr}"
    return r


def test_wheel_installs_and_solves_case1(tmp_path):
    """Build the wheel, install it (no editable install, no source tree on the path) into a new
    venv whose dependencies come from this environment, and solve case 1 from another folder."""
    src = tmp_path / "src"  # a copy, so the build leaves nothing in the checkout
    src.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(ROOT / name, src / name)
    for name in ("cotm_bertini", "templates"):
        shutil.copytree(ROOT / name, src / name, ignore=shutil.ignore_patterns("__pycache__"))
    wheels = tmp_path / "wheels"
    _run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", str(src), "-w", str(wheels)])
    (wheel,) = wheels.glob("cotm_bertini-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    assert "cotm_bertini/templates/zero_dim.input.j2" in names
    assert not any(n.startswith(("tests/", "templates/")) for n in names)

    venv = tmp_path / "venv"
    _run([sys.executable, "-m", "venv", "--without-pip", str(venv)])
    python = venv / "bin" / "python"
    site = Path(
        _run(
            [str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"]
        ).stdout.strip()
    )
    # numpy, pandas, bertini2, ... from this environment; the editable install of cotm_bertini
    # that lives there is not active (its .pth hook only runs in a site directory).
    (site / "deps.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    _run([sys.executable, "-m", "pip", "--python", str(python), "install", "-q", "--no-deps",
          str(wheel)])  # fmt: skip

    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["COTM_CACHE"] = str(tmp_path / "cache")
    code = (
        "import cotm_bertini as cb; print(cb.__file__); "
        "print(cb.solve(cb.Params.case('case1')).counts)"
    )
    r = _run([str(python), "-c", code], cwd=elsewhere, env=env)
    where, counts = r.stdout.strip().splitlines()[-2:]
    assert where.startswith(str(site)), where
    assert "'distinct_solutions': 6" in counts and "'physical': 4" in counts, counts
    cli = _run(
        [str(venv / "bin" / "cotm-bertini"), "solve", "case1", "--engine", "cli", "--no-plots",
         "--quiet", "--out", str(elsewhere / "runs")],
        cwd=elsewhere, env=env,
    )  # fmt: skip
    run = Path(cli.stdout.strip())
    assert "MPType: 2;" in (run / "input").read_text()
    assert (run / "solutions.csv").read_text().count("\n") == 7  # header + 6 solutions
