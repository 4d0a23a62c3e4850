"""Energy barriers (issue 10, part 2), checked with the independent energy code: each saddle is a
saddle, both descents end at minima, V never rises along a path, the barriers are energy
differences, and a path near a spring of zero length is flagged."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

import cotm_bertini as cb
from cotm_bertini.model.compiled import energy, energy_gradient, energy_hessian
from cotm_bertini.model.kinematics import spring_vectors


@pytest.fixture(scope="module", params=["case1", "case2", "case3"])
def found(request):
    return cb.barriers(cb.solve(cb.Params.case(request.param)))


def _eig(p, deg):
    g = np.radians(deg)
    return np.linalg.eigvalsh(energy_hessian(p, g[0], g[1])[0])


def test_saddles_are_saddles_and_descents_end_at_minima(found):
    p, sol = found.params, found.solutions.set_index("solution_id")
    minima = set(sol.index[(sol.physical.astype(bool)) & (sol.kind == "min")])
    saddles = set(sol.index[(sol.physical.astype(bool)) & (sol.kind == "saddle")])
    assert set(found.table.saddle_id) == saddles and found.warnings == []
    for _, row in found.table.iterrows():
        eig = _eig(p, np.array([row.saddle_gamma1_deg, row.saddle_gamma2_deg]))
        assert eig[0] < 0 < eig[1]
        v_saddle = float(energy(p, *np.radians([row.saddle_gamma1_deg, row.saddle_gamma2_deg])))
        for end_id, barrier, path in zip(
            (row.min_a, row.min_b),
            (row.barrier_a, row.barrier_b),
            found.paths[row.saddle_id],
            strict=True,
        ):
            end = path[-1]
            g = np.radians(end)
            assert np.abs(energy_gradient(p, g[0], g[1])[0]).max() < 1e-8 * p.k1 * p.L3**2
            assert _eig(p, end).min() > 0
            assert end_id in minima
            ref = sol.loc[end_id, ["gamma1_deg", "gamma2_deg"]].to_numpy(float)
            assert np.abs((end - ref + 180) % 360 - 180).max() < 1e-6
            values = energy(p, np.radians(path[:, 0]), np.radians(path[:, 1]))
            assert values.max() <= v_saddle + 1e-12 * max(1.0, abs(v_saddle))
            assert np.all(np.diff(values[1:]) <= 1e-12 * max(1.0, abs(v_saddle)))
            assert barrier == pytest.approx(v_saddle - float(energy(p, *g)), abs=1e-9)


def test_zero_length_flag_matches_the_paths(found):
    p = found.params
    for _, row in found.table.iterrows():
        shortest = np.inf
        for path in found.paths[row.saddle_id]:
            g = np.radians(path)
            vec = spring_vectors(
                p, np.cos(g[:, 0]), np.sin(g[:, 0]), np.cos(g[:, 1]), np.sin(g[:, 1])
            )
            lengths = [np.hypot(*vec[k]) for k in ("spring1", "spring2")]
            shortest = min(shortest, float(np.min(lengths)))
        assert row.min_spring_length == pytest.approx(shortest, rel=1e-9)
        assert bool(row.crosses_zero_length) == (shortest < 1e-3 * p.L3)


def test_the_barrier_of_a_pair_is_its_lowest_saddle(found):
    table = found.table
    for _, pair in found.pairs.iterrows():
        key = {pair.min_a, pair.min_b}
        joining = table[[{a, b} == key for a, b in zip(table.min_a, table.min_b, strict=True)]]
        assert pair.saddle_energy == joining.saddle_energy.min()
    assert found.pairs.apply(lambda r: r.min_a != r.min_b, axis=1).all()


def test_case1_has_one_minimum_and_no_barrier():
    res = cb.solve(cb.Params.case("case1"))
    found = cb.barriers(res)
    assert int((res.physical.kind == "min").sum()) == 1
    assert len(found.table) == 2 and found.pairs.empty


def test_cli_barriers_writes_a_run_folder(tmp_path):
    cmd = [sys.executable, "-m", "cotm_bertini.cli", "barriers", "case2", "--out", str(tmp_path)]
    run = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    folder = tmp_path / "latest"
    table = pd.read_csv(folder / "barriers.csv")
    assert {"min_a", "min_b", "saddle_id", "barrier_a", "barrier_b"} <= set(table.columns)
    assert (folder / "barriers.png").is_file() and (folder / "columns.md").is_file()
    assert not any(p.name.startswith(".partial") for p in tmp_path.iterdir())
    assert math.isfinite(table.barrier_a.max())
