"""Independent routes agree with Bertini: energy Newton on the torus, the Morse count."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import solve, solved

from cotm_bertini.analysis.critical_points import compare_physical, critical_points
from cotm_bertini.analysis.morse import morse_check, zero_length_configurations
from cotm_bertini.params import Params, make_params
from cotm_bertini.settings import Settings


def random_params(seed: int) -> Params:
    """A random but sane geometry: both springs with free length, points well apart."""
    rng = np.random.default_rng(seed)
    return make_params(
        None,
        {
            "L3": rng.uniform(6, 12),
            "k1": rng.uniform(1, 4),
            "k2": rng.uniform(1, 4),
            "p2x": rng.uniform(2, 5),
            "p3x": rng.uniform(-4, 0),
            "p3y": rng.uniform(2, 6),
            "p6x": rng.uniform(2, 6),
            "p5x": rng.uniform(-2, 1),
            "p5y": rng.uniform(-5, -2),
            "L01": rng.uniform(3, 14),
            "L02": rng.uniform(0, 14) if seed % 2 else 0.0,
        },
    )


@pytest.mark.parametrize("case", ["case1", "case2", "case3"])
def test_energy_route_finds_the_same_physical_equilibria(case):
    """Newton on grad V from a 48x48 grid finds exactly the physical rows, to 1e-6 deg."""
    result, params = solved(case)
    cmp = compare_physical(critical_points(params), result.table)
    assert cmp["only_energy_route"] == 0 and cmp["only_polynomial_route"] == 0, cmp
    assert cmp["worst_deg"] < 1e-6


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_energy_route_on_random_geometries(seed):
    """The same agreement on random geometries (one or two springs with free length)."""
    params = random_params(seed)
    table = solve(params, Settings(seed=seed, engine="cli"))
    cmp = compare_physical(critical_points(params), table)
    assert cmp["only_energy_route"] == 0 and cmp["only_polynomial_route"] == 0, cmp
    assert cmp["worst_deg"] < 1e-6
    assert morse_check(params, table)["ok"]


@pytest.mark.parametrize("case", ["case1", "case2", "case3"])
def test_morse_count_on_the_torus(case):
    """#min - #saddle + #max = 0, zero-length cusps of springs with L0 > 0 counted as maxima."""
    result, params = solved(case)
    check = morse_check(params, result.table)
    assert check["euler_characteristic"] == 0 and check["ok"], check
    if case == "case3":  # spring 2 can reach zero length: two cusps, both found as artefacts
        cusps = zero_length_configurations(params)
        assert len(cusps) == 2 and check["zero_length_maxima"] == 2
        art = result.table[
            (result.table["reason"] == "zero_length_spring") & result.table["is_real"]
        ]
        for c in cusps:
            d = np.hypot(
                ((art["gamma1_deg"] - c["gamma1_deg"] + 180) % 360 - 180),
                ((art["gamma2_deg"] - c["gamma2_deg"] + 180) % 360 - 180),
            )
            assert d.min() < 1e-4


def test_morse_check_detects_a_missing_equilibrium():
    """Dropping one physical row breaks the count: the check can fail."""
    result, params = solved("case3")
    s = result.table
    drop = s.index[s["kind"] == "saddle"][0]
    assert not morse_check(params, s.drop(index=drop))["ok"]
