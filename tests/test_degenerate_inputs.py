"""Degenerate values through a parameter, and what the refusals name (issue 39, items 2 and 7).

A body whose points coincide, an element whose ends meet in every pose, an expression that
divides by zero: refused in one line naming the parameter, its value and the file's element,
exit 2, nothing written, before any solving, whatever route sets the value (the file, --set,
Framework.replace, a point of a sweep or a map). The degeneracy each test expects is worked out
in the test from the file's numbers (plain arithmetic), not taken from the package."""

from __future__ import annotations

import dataclasses
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import cotm_bertini as cb
from cotm_bertini.continuation.spec import check_grid
from cotm_bertini.errors import ParameterError
from cotm_bertini.model.polynomial import PolySystem

ROOT = Path(__file__).resolve().parent.parent
XMODULE = ROOT / "examples" / "xmodule.toml"  # refused before any solve: never solved here
WHEEL = ROOT / "tests" / "fixtures" / "wheel_radius.toml"


def cli(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "cotm_bertini.cli", *args],
        capture_output=True, text=True, env=dict(os.environ), timeout=timeout,
    )  # fmt: skip


def _refused(args: list[str], out: Path) -> str:
    """The one line of a refusal: exit 2, nothing on stdout, no folder under `out`."""
    r = cli(*args, "--out", str(out), "--no-plots")
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    assert not out.exists() or not any(out.iterdir()), list(out.iterdir())
    return lines[0]


def _xmodule_tip(text: str) -> tuple[float, float]:
    """bar1's tip in its frame, read from the file with tomllib, not with the package."""
    import tomllib

    data = tomllib.loads(text)
    x, y = data["bodies"]["bar1"]["tip"]
    values = data["parameters"]
    return (values[x] if isinstance(x, str) else x), y


def test_set_L1_0_is_refused_in_one_line_before_any_solve(tmp_path):
    # bar1's tip is (L1, 0) in its frame and its other point o is (0, 0): with L1 = 0 they are
    # one point, and nothing fixes the bar's rotation.
    text = XMODULE.read_text().replace("L1 = 1.3 ", "L1 = 0.0 ")
    assert math.dist(_xmodule_tip(text), (0.0, 0.0)) == 0.0
    start = time.perf_counter()
    line = _refused(["solve", "--framework", str(XMODULE), "--set", "L1=0"], tmp_path / "out")
    assert time.perf_counter() - start < 15  # a refusal (the solve ran 25 s into a traceback)
    for word in ("L1 = 0", "bar1", "o and tip", "coincide"):
        assert word in line, line
    assert "Traceback" not in line and "zero-size" not in line


def test_L1_0_in_the_file_is_refused_alike(tmp_path):
    path = tmp_path / "x.toml"
    path.write_text(XMODULE.read_text().replace("L1 = 1.3 ", "L1 = 0.0 "))
    line = _refused(["solve", "--framework", str(path)], tmp_path / "out")
    assert "L1 = 0" in line and "body bar1's points o and tip coincide" in line, line


def test_replace_refuses_and_the_refusal_is_fast():
    fw = cb.Framework.from_toml(XMODULE)
    start = time.perf_counter()
    with pytest.raises(ParameterError) as err:
        fw.replace(L1=0)
    assert time.perf_counter() - start < 1.0
    message = str(err.value)
    assert "\n" not in message and message.startswith("L1 = 0: makes"), message
    assert "bar1" in message
    fw.replace(L1=-1.3)  # the tip on the other side: a bar all the same, accepted


def test_a_sweep_crossing_the_value_is_refused_naming_the_point(tmp_path):
    # r from -0.5 to 0.5 in 3 points: the middle one is r = 0, the rim on the centre.
    assert np.linspace(-0.5, 0.5, 3)[1] == 0.0
    args = ["sweep", "--framework", str(WHEEL), "--param", "r", "--from", "-0.5", "--to", "0.5"]
    line = _refused([*args, "--points", "3"], tmp_path / "out")
    for word in (
        "r = 0: makes body wheel's points centre and rim coincide",
        "at r = 0.0, point 2 of the 3",
    ):
        assert word in line, line
    fw = cb.Framework.from_toml(WHEEL)
    check_grid(fw, "r", tuple(np.linspace(-0.5, 0.5, 4)))  # 4 points miss r = 0: accepted
    with pytest.raises(ParameterError, match=r"r = 0: .*at r = 0\.0, L0s = 0\.2, point 4 of the 9"):
        cb.design_map(fw, "r", (-0.5, 0.5), "L0s", (0.2, 0.4), points=3)  # r major: 4th


@pytest.mark.parametrize(
    "tip, arm, words",
    [  # o = (0, 0, 0): with a = 0 the three points lie on the z axis
        ("[0.0, 0.0, 1.0]", '["a", 0.0, 0.5]', ["a = 0: makes", "o, tip and arm lie on one line"]),
        # on the z axis whatever h is: h is not named, the file's numbers are
        ('[0.0, 0.0, "h"]', "[0.0, 0.0, 0.5]", ["body mast's points o, tip and arm lie on"]),
    ],
)
def test_a_spatial_body_on_one_line_is_refused(tmp_path, tip, arm, words):
    text = f"""name = "mast"\ndim = 3\n[parameters]\na = 0.0\nh = 1.0
[ground]\ng = [0.0, 0.0, 0.0]\np = [1.0, 0.0, 0.5]\nq = [0.0, 1.0, 0.5]
[bodies.mast]\no = [0.0, 0.0, 0.0]\ntip = {tip}\narm = {arm}
[[pins]]\na = "mast.o"\nb = "ground.g"
[[springs]]\na = "mast.tip"\nb = "ground.p"\nk = 1.0\nL0 = 0.3
[[springs]]\na = "mast.arm"\nb = "ground.q"\nk = 1.0\nL0 = 0.3
"""
    path = tmp_path / "mast.toml"
    path.write_text(text)
    with pytest.raises(ParameterError) as err:
        cb.Framework.from_toml(path)
    message = str(err.value)
    for word in words:
        assert word in message, message
    if "h" in tip:
        assert "h = " not in message, message


def test_an_element_whose_ends_meet_in_every_pose_is_refused(tmp_path):
    # The wheel's centre is pinned at ground.c = (1, 0); a spring from the centre to ground.p
    # = (px, 0.25 * py) has zero length in every pose when px = 1 and py = 0.
    text = WHEEL.read_text().replace("r = 0.5", "r = 0.5\npx = 2.0\npy = 1.0")
    text = text.replace("p = [2.0, 0.25]", 'p = ["px", "0.25*py"]')
    text = text.replace('a = "wheel.rim"\nb = "ground.p"', 'a = "wheel.centre"\nb = "ground.p"')
    path = tmp_path / "w.toml"
    path.write_text(text)
    fw = cb.Framework.from_toml(path)
    with pytest.raises(ParameterError) as err:
        fw.replace(px=1.0, py=0.0)
    message = str(err.value)
    assert message.startswith("px = 1, py = 0: makes springs.spring's ends"), message
    assert "wheel.centre and ground.p meet in every pose" in message


def test_division_by_zero_names_the_field_and_the_expression(tmp_path):
    path = tmp_path / "x.toml"
    path.write_text(XMODULE.read_text().replace('L0 = "L0s"', 'L0 = "L0s/0"'))
    line = _refused(["solve", "--framework", str(path)], tmp_path / "out")
    assert "springs.top.L0 = 'L0s/0'" in line and "L0_top" not in line, line
    assert "division by zero" in line


@pytest.mark.parametrize("text", ["", "[parameters]\nx = 1.0\n"])
def test_a_file_with_no_elements_says_so(tmp_path, text):
    path = tmp_path / "f.toml"
    path.write_text(text)
    line = _refused(["solve", "--framework", str(path)], tmp_path / "out")
    assert "has no elements" in line and "can move freely" not in line, line
    assert "no bodies or nodes" in line and "no springs, cables, bars or loads" in line


def test_an_equation_left_with_no_terms_is_refused_not_a_traceback():
    """The safety nets behind the file's checks: at r = 0 (set past validation) the wheel's
    moment r x F is 0 for every pose and force; the solve refuses before tracking a path."""
    fw = cb.Framework.from_toml(WHEEL)
    bad = dataclasses.replace(fw, parameters=(("r", 0.0), ("L0s", 0.3)))
    with pytest.raises(
        ParameterError, match=r"r = 0, L0s = 0.3: .*body wheel: moment: every term is 0"
    ):
        cb.solve(bad)
    empty = PolySystem(("x",), ("f1", "f2"), (np.array([[1]]), np.zeros((0, 1), int)),
                       (np.array([2.0]), np.zeros(0)))  # fmt: skip
    with pytest.raises(ParameterError, match="equation f2 has no terms"):
        empty.scale()
