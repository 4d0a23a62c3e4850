"""Issue 27, items 1, 2 and 8: numbers Bertini's parser refused, extreme values that ended in a
traceback, and counts that could not be. Each checked where a user meets it (the command line,
or the API), against Bertini's own reading of the text or an energy written here."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import ROOT, run_cli

ZEEMAN = str(ROOT / "examples" / "zeeman.toml")
PENDULUM = str(ROOT / "examples" / "double_pendulum.toml")
# Python's shortest repr of each has no decimal point, or an exponent with "+": the forms
# Bertini 2's parser refused ("could not be interpreted as a valid integer").
AWKWARD = [1e-05, 5e-324, 1e16, -3e-100, 123456789012345678, 2e-5, 1.5e300, -7e22]


def _bertini_reads(text: str) -> complex:
    """What Bertini 2 parses `text` to: f = x - (text), evaluated at x = 0, negated."""
    import bertini

    system = bertini.parse.system(f"variable_group x;\nfunction f;\nf = x - ({text});\n")
    return -complex(system.eval(np.array([0.0 + 0j]))[0])


@pytest.mark.parametrize("value", AWKWARD)
def test_every_number_renders_in_a_form_bertini_reads_back_exactly(value):
    from cotm_bertini.backends.render import complex_number, polynomial_text
    from cotm_bertini.literals import bertini_number

    assert "e" in repr(float(value)) or "." not in repr(float(value))  # an awkward form indeed
    assert _bertini_reads(bertini_number(value)).real == float(value)
    z = complex(value, -value)
    assert _bertini_reads(complex_number(z)) == z
    # a polynomial's terms: x^2 * value - value (the constant term is the negated value)
    text = polynomial_text(("y",), np.array([[2], [0]]), np.array([value, -value]))
    assert "e+" not in text and _bertini_reads(text.replace("y^2", "0")).real == -float(value)


def test_sympy_texts_of_the_derivations_are_read_by_bertini():
    import sympy as sp

    from cotm_bertini.model.symbolic import bertini_text

    x = sp.Symbol("x")
    for value in AWKWARD:
        expr = sp.Float(value, 17) * x + sp.Float(value, 17)
        # at x = 0 the expression is its constant term: the value itself
        text = bertini_text(expr).replace("*x", "*0")
        assert _bertini_reads(text).real == float(value)
    assert "e+" not in bertini_text(sp.Float(1e16, 17) * x)


def test_settings_in_the_config_section_use_the_same_form():
    from cotm_bertini.settings import Settings

    cfg = Settings(final_tol=1e-07, max_norm=1e16).bertini_config()
    assert cfg["FinalTol"] == "1.0e-7" and cfg["MaxNorm"] == "1.0e16"


def _zeeman_angles(x: float, y: float) -> tuple[list[float], list[float]]:
    """Minima and maxima of Zeeman's energy on the wheel's circle by a dense scan (examples/
    zeeman.toml written out here: rim 0.5, bands k = 1, L0 = 0.25 to u = (x, y), p = (2, 0.25)
    from a wheel centred at c = (1, 0))."""
    t = np.linspace(0, 2 * np.pi, 200001)[:-1]
    rim = np.stack([1 + 0.5 * np.cos(t), 0.5 * np.sin(t)])
    d_u = np.hypot(rim[0] - x, rim[1] - y)
    d_p = np.hypot(rim[0] - 2.0, rim[1] - 0.25)
    v = 0.5 * (d_u - 0.25) ** 2 + 0.5 * (d_p - 0.25) ** 2
    lo = (v < np.roll(v, 1)) & (v < np.roll(v, -1))
    hi = (v > np.roll(v, 1)) & (v > np.roll(v, -1))
    return np.degrees(t[lo]).tolist(), np.degrees(t[hi]).tolist()


def _same_angles(found: list[float], expected: list[float]) -> None:
    """The same angles on the circle (degrees; 359.99999 is 0), to the scan's 2e-3 deg."""
    assert len(found) == len(expected)
    gap = (np.subtract.outer(found, expected) + 180) % 360 - 180
    assert np.abs(gap).min(axis=1).max() < 1e-2 and np.abs(gap).min(axis=0).max() < 1e-2


def _physical(folder) -> tuple[dict, list[dict]]:
    import pandas as pd

    rec = json.loads((folder / "latest" / "run.json").read_text())
    rows = pd.read_csv(folder / "latest" / "solutions.csv")
    return rec, rows[rows["physical"]].to_dict("records")


def test_framework_solve_at_a_value_whose_units_make_1e_05(tmp_path):
    """x = 2e-5 in units of the file's length (2.0) is 1e-05: the value of the bug report."""
    assert repr(2e-5 / 2.0) == "1e-05"
    r = run_cli("solve", "--framework", ZEEMAN, "--set", "x=0.00002", "--set", "y=-0.25",
                "--no-plots", "--out", str(tmp_path))  # fmt: skip
    assert r.returncode == 0, r.stderr
    rec, rows = _physical(tmp_path)
    lo, hi = _zeeman_angles(2e-5, -0.25)
    assert rec["status"] == "ok" and len(rows) == len(lo) + len(hi)
    _same_angles([row["wheel.angle_deg"] for row in rows], lo + hi)


def test_paper_solve_at_a_free_length_whose_units_make_1e_05(tmp_path):
    """L01 / L3 = 1e-05 exactly (L3 = 1 m): the paper's mechanism renders it too."""
    r = run_cli("solve", "--set", "L3=1", "--set", "L01=1e-05", "--no-plots",
                "--out", str(tmp_path))  # fmt: skip
    assert r.returncode == 0, r.stderr
    rec = json.loads((tmp_path / "latest" / "run.json").read_text())
    assert rec["status"] == "ok" and rec["counts"]["physical"] > 0


def test_sweeps_through_a_point_at_1e_05(tmp_path):
    """A sweep whose middle point is x = 2e-5 (1e-05 in the file's units), and a 3 x 3 grid
    (the map's 2-D sweep) through it; the paper's sweep through L01 / L3 = 1e-05."""
    r = run_cli("sweep", "--framework", ZEEMAN, "--set", "y=-0.25", "--param", "x",
                "--from", "0", "--to", "0.00004", "--points", "3", "--param2", "y",
                "--from2", "-0.26", "--to2", "-0.24", "--points2", "3", "--no-plots",
                "--out", str(tmp_path / "s"))  # fmt: skip
    assert r.returncode == 0, r.stderr
    r = run_cli("sweep", "--set", "L3=1", "--param", "L01", "--from", "0", "--to", "0.00002",
                "--points", "3", "--no-plots", "--out", str(tmp_path / "p"))  # fmt: skip
    assert r.returncode == 0, r.stderr


@pytest.mark.slow  # the Zeeman fold witness sets, solved cold: minutes (make stress)
def test_map_through_a_point_at_1e_05(tmp_path):
    """The map's fold systems rendered at x = 2e-5 (1e-05 in the file's units)."""
    r = run_cli("map", "--framework", ZEEMAN, "--param", "x", "--from", "0", "--to", "0.00004",
                "--param2", "y", "--from2", "-0.26", "--to2", "-0.24", "--points", "3",
                "--no-plots", "--out", str(tmp_path / "m"))  # fmt: skip
    assert r.returncode == 0, r.stderr


def _refused(r, *names: str) -> str:
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr, r.stderr
    assert all(n in lines[0] for n in names), lines[0]
    return lines[0]


@pytest.mark.parametrize(
    "args, names",
    [
        (["solve", "--framework", ZEEMAN, "--set", "x=1e200"], ["x = 1e+200", "length unit"]),
        (["solve", "--framework", ZEEMAN, "--set", "y=-1e15"], ["y = -1e+15"]),
        (["solve", "--framework", PENDULUM, "--set", "k=1e-200"], ["k = 1e-200", "stiffness"]),
        (["solve", "--framework", PENDULUM, "--set", "weight=1e200"], ["weight = 1e+200"]),
        (["solve", "--set", "L01=1e200"], ["L01 = 1e+200", "L3"]),
        (["solve", "--set", "k2=1e-200"], ["k1", "k2 = 1e-200"]),
        (["sweep", "--framework", ZEEMAN, "--param", "x", "--from", "0", "--to", "1e200",
          "--points", "3"], ["x = 1e+200"]),
        (["sweep", "--param", "L01", "--from", "0", "--to", "1e15", "--points", "3"], ["L01"]),
        (["map", "--framework", ZEEMAN, "--param", "x", "--from=-1e15", "--to", "0",
          "--param2", "y", "--from2", "-1", "--to2", "0", "--points", "3"], ["x = -"]),
    ],
)  # fmt: skip
def test_extreme_values_are_refused_in_one_line_and_nothing_is_written(tmp_path, args, names):
    out = tmp_path / "runs"
    line = _refused(run_cli(*args, "--no-plots", "--out", str(out)), *names)
    assert "double precision" in line
    assert not out.exists() or not any(out.rglob("*"))


def test_the_api_refuses_them_too():
    import cotm_bertini as cb

    fw = cb.Framework.from_toml(ZEEMAN)
    with pytest.raises(cb.ParameterError, match=r"^x = 1e\+200: .*length unit"):
        fw.replace(x=1e200)
    fw.replace(x=1e-200)  # a coordinate of 1e-200 is just 0: it is solved, not refused
    with pytest.raises(cb.ParameterError, match="L02"):
        cb.Params(L02=1e15)


def test_a_bertini_failure_is_one_solver_error_naming_what_was_solved(monkeypatch):
    """A positive-dimensional system (f2 = 2 f1): the projective total-degree route ends every
    path at a singular point (no root kept, said in the record); and Bertini's own RuntimeError
    (raised here by the tracker, as Bertini raises it on a system it cannot parse or start)
    becomes a SolverError that names the generic solve, in one line."""
    import sympy as sp

    import cotm_bertini as cb
    from cotm_bertini.backends import homotopy
    from cotm_bertini.model.symbolic import parametric_from_sympy

    x, y, p = sp.symbols("x y p")
    f = x * y - p
    ps = parametric_from_sympy(("x", "y"), ("f1", "f2"), (f, 2 * f), ("p",))
    gs = homotopy.generic_set(ps, seed=3, use_cache=False, centre={"p": 1.0})
    assert gs.summary()["singular_endpoints"] == gs.summary()["paths"] == 4
    assert gs.summary()["tracked_points"] == 0

    def fails(*args, **kwargs):
        raise RuntimeError("Bertini stopped: the start system has no nonsingular point")

    monkeypatch.setattr(homotopy, "tracked_paths", fails)
    with pytest.raises(cb.SolverError) as err:
        homotopy.generic_set(ps, seed=3, use_cache=False, centre={"p": 1.0})
    text = str(err.value)
    assert "generic solution set" in text and "Bertini stopped" in text and "\n" not in text
    assert isinstance(err.value.__cause__, RuntimeError)


def test_ab_initio_counts_add_up():
    """Its report's paths are its own: finite + at infinity + lost + singular = tracked (the
    fallback used to report a total-degree solve's lost paths against the homotopy's count)."""
    from cotm_bertini.backends.homotopy import ab_initio
    from cotm_bertini.model.compiled import parametric_system
    from cotm_bertini.params import Params

    p = Params.case("case2")
    ps = parametric_system(p.zfl)
    ends, rep = ab_initio(ps, p.normalized())
    degree = ps.instantiate([1.0] * len(ps.parameters)).total_degree
    assert rep.tracked == degree == 48 and rep.finite == len(ends) == 20
    # the 2 double roots at d1 = 0 are reached by 4 paths, dropped as singular
    assert rep.finite + rep.infinite + rep.lost + 4 == rep.tracked and rep.lost == 0


def test_far_load_point_is_solved_not_reported_empty(tmp_path):
    """x = 1e5 (5e4 times the file's length unit): the solutions' lengths are 1e5 long, beyond
    Bertini's default max norm; every path was called infinite and the run said `ok` with no
    equilibrium. Now the max norm follows the parameters, and the counts agree with a scan."""
    r = run_cli("solve", "--framework", ZEEMAN, "--set", "x=1e5", "--set", "y=-0.25",
                "--no-plots", "--out", str(tmp_path))  # fmt: skip
    assert r.returncode == 0, r.stderr
    rec, rows = _physical(tmp_path)
    lo, hi = _zeeman_angles(1e5, -0.25)
    c = rec["counts"]
    assert rec["status"] == "ok" and (len(lo), len(hi)) == (1, 1)
    assert c["physical"] == 2 and c["stable"] == 1
    assert 0 <= c["lost_paths"] <= c["paths_tracked"]
    _same_angles([row["wheel.angle_deg"] for row in rows], lo + hi)


def test_an_empty_table_on_a_compact_space_is_incomplete():
    """V has a global minimum on the wheel's circle: a table without one misses equilibria,
    though an empty table's alternating sum is the circle's 0."""
    import cotm_bertini as cb
    from cotm_bertini.analysis.framework_checks import completeness

    fw = cb.Framework.from_toml(ZEEMAN)
    empty = {k: np.array([], dtype=object) for k in ("physical", "kind", "index")}
    out = completeness(fw, empty, {})
    assert out["morse"]["ok"] is False
    assert any("no minimum" in w for w in out["warnings"]), out["warnings"]
