"""Inverse design (issue 10, part 3): the free lengths holding a pose, checked with the
independent energy code (sympy-derived gradient and Hessian) and against the solver's equilibria."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

import cotm_bertini as cb
from cotm_bertini.analysis.design.free_lengths import parallel_curve, parallel_sine
from cotm_bertini.model.compiled import energy_gradient, energy_hessian
from cotm_bertini.model.kinematics import zero_length_poses

P = cb.Params.case("case3")


def _energy_check(dsg: cb.Design) -> tuple[float, np.ndarray]:
    """|grad V| relative to k L3 max(d, L0), and the Hessian eigenvalues, by the energy code."""
    p = P.replace(L01=dsg.L01, L02=dsg.L02)
    g1, g2 = math.radians(dsg.gamma1_deg), math.radians(dsg.gamma2_deg)
    scale = max(P.k1, P.k2) * P.L3 * max(dsg.d1, dsg.d2, dsg.L01, dsg.L02)
    grad = energy_gradient(p, g1, g2)[0]
    return float(np.abs(grad).max()) / scale, np.linalg.eigvalsh(energy_hessian(p, g1, g2)[0])


def test_random_poses_are_held_by_the_designed_free_lengths():
    rng = np.random.default_rng(10)
    for g1, g2 in rng.uniform(-180, 180, size=(100, 2)):
        dsg = cb.design(P, float(g1), float(g2))
        assert dsg.family == "relaxed"  # a random pose is off the parallel curve
        rel, eig = _energy_check(dsg)
        assert rel < 1e-10
        assert dsg.stable == bool(eig.min() > 0)
        assert np.allclose([dsg.hess_eig_min, dsg.hess_eig_max], eig, rtol=1e-9, atol=1e-12)


def test_poses_on_the_parallel_curve_take_a_chosen_free_length():
    rng = np.random.default_rng(11)
    checked = 0
    for g1 in rng.uniform(-180, 180, size=60):
        for g2 in parallel_curve(P, float(g1)):
            assert abs(parallel_sine(P, math.radians(g1), math.radians(g2))) < 1e-12
            dsg = cb.design(P, float(g1), g2, L01=float(rng.uniform(0.5, 14)))
            assert dsg.family == "parallel"
            if dsg.L02 < 0:
                assert not dsg.physical and not dsg.stable
                continue
            rel, eig = _energy_check(dsg)
            assert rel < 1e-10
            assert dsg.stable == bool(eig.min() > 1e-9 * np.abs(eig).max())
            checked += 1
    assert checked >= 50


def test_the_solver_equilibria_are_recovered_by_inverse_design():
    res = cb.solve(P)
    for _, row in res.physical.iterrows():
        g1, g2 = math.radians(row.gamma1_deg), math.radians(row.gamma2_deg)
        on_curve = abs(float(parallel_sine(P, g1, g2))) < 1e-9
        dsg = cb.design(P, row.gamma1_deg, row.gamma2_deg, L01=P.L01 if on_curve else None)
        assert dsg.L01 == pytest.approx(P.L01, rel=1e-8)
        assert dsg.L02 == pytest.approx(P.L02, rel=1e-8)
        assert dsg.stable == bool(row.stable)


def test_bad_poses_and_free_lengths_are_refused():
    with pytest.raises(cb.ParameterError, match="L01=5 cannot hold this pose"):
        cb.design(P, 10.0, 20.0, L01=5.0)
    g1 = 30.0
    g2 = parallel_curve(P, g1)[0]
    with pytest.raises(cb.ParameterError, match="pass exactly one of L01, L02"):
        cb.design(P, g1, g2)
    pose = zero_length_poses(P, 2)[0]  # spring 2 reaches zero length in case 3 (spring 1 not)
    assert max(abs(z.imag) for z in pose) == 0
    c1, s1, c2, s2 = (z.real for z in pose)
    with pytest.raises(cb.ParameterError, match="spring 2 has zero length"):
        cb.design(P, math.degrees(math.atan2(s1, c1)), math.degrees(math.atan2(s2, c2)))
    with pytest.raises(cb.ParameterError, match="gamma2_deg = inf: must be finite"):
        cb.design(P, 1.0, float("inf"))


def _cli(*args: str) -> subprocess.CompletedProcess:
    cmd = [sys.executable, "-m", "cotm_bertini.cli", "design", *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120)


def test_cli_design_prints_and_writes_one_row(tmp_path):
    out = tmp_path / "design.csv"
    run = _cli("--gamma1", "10", "--gamma2", "20", "--out", str(out))
    assert run.returncode == 0, run.stderr
    row = pd.read_csv(out)
    assert len(row) == 1 and row.family[0] == "relaxed" and bool(row.stable[0])
    assert row.L01[0] == pytest.approx(cb.design(P, 10, 20).d1, rel=1e-12)
    bad = _cli("--gamma1", "10", "--gamma2", "20", "--L01", "5", "--out", str(tmp_path / "b.csv"))
    assert bad.returncode == 2
    assert bad.stderr.count("\n") == 1 and "L01=5" in bad.stderr
    assert not (tmp_path / "b.csv").exists()
