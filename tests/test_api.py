"""The public Python API: the documented snippet runs as written; settings honoured or refused."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import cotm_bertini as cb
from cotm_bertini.columns import SOLUTIONS


def test_the_documented_snippet_runs_as_written(tmp_path, monkeypatch):
    """The README / issue snippet, verbatim, in a fresh folder; the answers are the paper's."""
    monkeypatch.chdir(tmp_path)
    p = cb.Params.case("case3")  # also cb.Params(L3=9, k1=2.81, ...), cb.Params.from_toml(path)
    p2 = p.replace(
        L01=10.0
    )  # validated like the CLI: a bad value raises ValueError naming the field
    res = cb.solve(p, seed=1)  # -> cb.Solutions (engine="homotopy" default, or "cli")
    res.table  # pandas DataFrame: exactly the solutions.csv columns
    res.physical
    res.stable  # filtered DataFrames
    res.counts  # dict: paths_tracked, finite_endpoints, distinct_solutions, real, physical, stable
    res.morse  # the Morse check as a dict (ok, min, saddle, max, ...)
    res.save("runs/mine")  # the same run folder the CLI writes (CSV + run.json [+ figures])
    sw = cb.sweep(p, "L01", np.linspace(0, 12, 241), workers=2)  # -> cb.Sweep
    sw.table
    sw.events  # the sweep.csv / events.csv frames
    sw.plot("bifurcation.png")

    # Case 3 of the paper (Bertini 1.6 finds the same): 76 finite, 30 real, 14 physical.
    assert isinstance(res, cb.Solutions) and isinstance(sw, cb.Sweep)
    assert (len(res.table), len(res.physical), len(res.stable)) == (76, 14, 5)
    c = res.counts
    assert (c["distinct_solutions"], c["real"], c["physical"], c["stable"]) == (76, 30, 14, 5)
    assert res.morse["ok"] and res.status == "ok"
    assert p2.L01 == 10.0 and p2.L02 == 11.5
    documented = [name.strip() for key in SOLUTIONS for name in key.split(",")]
    assert all(col in documented for col in res.table.columns if col[-3:] not in ("_re", "_im"))
    folder = tmp_path / "runs" / "mine"
    for name in ("solutions.csv", "run.json", "columns.md", "input", "configurations.png"):
        assert (folder / name).is_file(), name
    rec = json.loads((folder / "run.json").read_text())
    assert rec["counts"] == res.counts and rec["parameters"] == p.as_dict()
    assert (tmp_path / "bifurcation.png").stat().st_size > 10_000
    assert sw.table["point"].nunique() == 241 and sw.table["L01"].nunique() == 241
    assert set(sw.events.columns) >= {"kind", "L01", "gamma1_deg", "gamma2_deg"}
    assert (sw.table.groupby("point")["lost_paths"].max() == 0).all()


def test_params_constructors_and_validation(tmp_path):
    """Params(...) defaults to Table 1; from_toml and replace validate like the command line."""
    assert cb.Params() == cb.Params.case("case1")
    assert cb.Params(L01=11.5, L02=11.5) == cb.Params.case("case3")
    toml = tmp_path / "p.toml"
    toml.write_text("k2 = 3.0\nL01 = 2\n")
    q = cb.Params.from_toml(toml)
    assert (q.k2, q.L01, q.k1) == (3.0, 2.0, 2.81)
    with pytest.raises(ValueError, match=r"k1 = -1\.0"):
        cb.Params().replace(k1=-1)
    with pytest.raises(ValueError, match=r"L02 = 'abc': must be a number"):
        cb.Params().replace(L02="abc")
    with pytest.raises(ValueError, match="q9: unknown parameter"):
        cb.Params().replace(q9=1.0)


@pytest.mark.parametrize(
    ("options", "needle"),
    [
        ({"mptype": 1}, "mptype = 1"),
        ({"variable_groups": "multihomogeneous"}, "variable_groups"),
        ({"extra_config": {"MaxNorm": "1e6"}}, "extra_config"),
        ({"engine": "homotopy", "bertini": "/bin/true"}, "bertini"),
        ({"seed": -1}, "seed = -1"),
        ({"timeout": 0}, "timeout = 0"),
        ({"colour": "red"}, "colour: unknown setting"),
    ],
)
def test_settings_the_homotopy_engine_cannot_honour_are_refused(options, needle):
    """An option only a Bertini input file can express is refused, never silently ignored."""
    with pytest.raises(cb.ParameterError, match=needle):
        cb.solve(cb.Params.case("case1"), cache=False, **options)


def test_tracking_settings_reach_the_in_process_solver():
    """final_tol, the Newton tolerances, the security level, max_norm, the condition-number
    threshold, threads and the time limit are set on Bertini's own configuration objects."""
    import time

    import bertini
    from bertini import nag_algorithm as na

    from cotm_bertini.backends.homotopy import _configure

    text = "INPUT\nvariable_group x;\nfunction f;\nf = x^2 - 2;\nEND;"
    hom = "INPUT\nvariable_group x;\npathvariable t;\nparameter a;\na = 2*(1-t) + 3*t;\n"
    hom += "function f;\nf = x^2 - a;\nEND;"
    pts = [[3**0.5], [-(3**0.5)]]
    solver = na.HomotopySolver(
        bertini.parse.system(hom), pts, bertini.parse.system(text), mptype="adaptive"
    )
    settings = cb.Settings(
        final_tol=1e-9,
        tracktol_before_eg=1e-6,
        tracktol_during_eg=1e-7,
        security_level=1,
        max_norm=1e6,
        condnum_threshold=1e9,
        threads=1,
        timeout=30.0,
    )
    _configure(solver, settings, "adaptive", time.perf_counter() + 30.0)
    assert solver.get_config("endgame").final_tolerance == pytest.approx(1e-9)
    tol = solver.get_config("tolerances")
    assert (tol.newton_before_endgame, tol.newton_during_endgame) == pytest.approx((1e-6, 1e-7))
    assert solver.get_config("security").level == 1
    assert solver.get_config("security").max_norm == pytest.approx(1e6)
    assert solver.get_config("post_processing").condition_number_threshold == pytest.approx(1e9)
    zd = solver.get_config("zero_dim")
    assert zd.num_threads == 1 and 0 < zd.max_solve_wall_clock_duration <= 30.0


def test_a_time_limit_is_honoured_in_process():
    """timeout under the homotopy engine stops the solve with a clear SolverError."""
    with pytest.raises(cb.SolverError, match="timed out"):
        cb.solve(cb.Params.case("case3"), cache=False, timeout=1e-6)


def test_double_precision_only_is_honoured():
    """mptype=0 tracks in double precision only and still finds case 2's solutions."""
    res = cb.solve(cb.Params.case("case2"), cache=False, mptype=0)
    assert res.record["settings"]["mptype"] == 0
    assert res.record["details"]["homotopy"]["retracked_adaptive"] == 0
    assert (res.counts["distinct_solutions"], res.counts["physical"]) == (22, 6)


def test_cache_hit_needs_no_numpy_or_pandas(tmp_path):
    """A repeated request is answered from the cache without loading numpy, pandas or Bertini."""
    code = (
        "import sys, cotm_bertini as cb\n"
        "r = cb.solve(cb.Params.case('case1'), label='x')\n"
        "print(r.cache_hit, r.counts['distinct_solutions'], "
        "any(m in sys.modules for m in ('numpy', 'pandas', 'bertini')))\n"
    )
    env = {**os.environ}
    first = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    second = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert first.returncode == 0, first.stderr
    assert second.stdout.split() == ["True", "6", "False"], second.stdout + second.stderr


def test_version_prints_package_and_bertini():
    r = subprocess.run(
        [sys.executable, "-m", "cotm_bertini.cli", "--version"], capture_output=True, text=True
    )
    assert r.returncode == 0
    assert f"cotm-bertini {cb.__version__}" in r.stdout and "bertini2 4.0.0" in r.stdout
