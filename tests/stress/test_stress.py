"""Stress tests of numerical stability. `make test` runs a fast subset; `make stress` (with
COTM_STRESS=full) the full set: 200 random geometries, 20 seeds.

Every comparison is with an independent route: Newton on grad V from a grid on the torus
(critical_points), or a symmetry of the mechanics (scaling all lengths leaves the angles alone).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from conftest import solve  # noqa: E402
from physics import mp_refine  # noqa: E402

from cotm_bertini.analysis.critical_points import critical_points  # noqa: E402
from cotm_bertini.params import TABLE1, Params, make_params  # noqa: E402
from cotm_bertini.settings import Settings  # noqa: E402

FULL = os.environ.get("COTM_STRESS") == "full"
N_GEOMETRIES = 200 if FULL else 8
SEEDS = list(range(1, 21)) if FULL else [1, 2]
UNTRUSTED_CONDITION = 1e8  # rows whose Jacobian condition exceeds this are flagged


def random_params(seed: int) -> Params:
    """A random geometry; each spring zero-free-length with probability 1/4."""
    rng = np.random.default_rng(1000 + seed)
    values = {
        "L3": rng.uniform(4, 14),
        "k1": rng.uniform(0.5, 5),
        "k2": rng.uniform(0.5, 5),
        "p2x": rng.uniform(1, 6) * rng.choice([-1, 1]),
        "p3x": rng.uniform(-5, 5),
        "p3y": rng.uniform(1, 6) * rng.choice([-1, 1]),
        "p6x": rng.uniform(1, 6),
        "p5x": rng.uniform(-4, 4),
        "p5y": rng.uniform(1, 6) * rng.choice([-1, 1]),
        "L01": 0.0 if rng.random() < 0.25 else rng.uniform(1, 16),
        "L02": 0.0 if rng.random() < 0.25 else rng.uniform(1, 16),
    }
    return make_params(None, values)


def _gap(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Pairwise angle distances (deg, modulo 360) between rows of a and b."""
    d = np.abs((a[:, None, :] - b[None, :, :] + 180.0) % 360.0 - 180.0)
    return d.max(axis=2)


def audit(params: Params, table: pd.DataFrame, tol: float = 1e-6) -> dict:
    """Physical rows against the energy route: misses, extras, and whether each is flagged."""
    phys = table[table["physical"]]
    ours = phys[["gamma1_deg", "gamma2_deg"]].to_numpy()
    flagged = (phys["singular"] | (phys["jacobian_condition"] > UNTRUSTED_CONDITION)).to_numpy()
    ref = critical_points(params)[["gamma1_deg", "gamma2_deg"]].to_numpy()
    if len(ours) and len(ref):
        g = _gap(ours, ref)
        extra = g.min(axis=1) > tol
        miss = g.min(axis=0) > tol
        # A miss is explained when a flagged row of ours sits near it (a near-double root).
        near_flagged = (g[flagged] < 1.0).any(axis=0) if flagged.any() else np.zeros_like(miss)
    else:
        extra, miss = np.ones(len(ours), bool), np.ones(len(ref), bool)
        near_flagged = np.zeros(len(ref), bool)
    # A row of ours the grid search did not reach (a narrow basin next to a cusp) is confirmed
    # if 40-digit Newton on eqs (7)-(8), started there, stays there.
    for k in np.flatnonzero(extra & ~flagged):
        ref1, ref2 = mp_refine(params, *ours[k])
        if _gap(np.array([[ref1, ref2]]), ours[k : k + 1]).max() < 1e-7:
            extra[k] = False
    return {
        "silent_extras": int((extra & ~flagged).sum()),
        "silent_misses": int((miss & ~near_flagged).sum()),
        "flagged_rows": int(flagged.sum()),
        "physical": len(ours),
        "energy_route": len(ref),
    }


@pytest.mark.parametrize("seed", range(N_GEOMETRIES))
def test_random_geometry(seed):
    """Random geometries: every physical equilibrium the energy route finds, and nothing else
    (or the rows that differ are flagged as untrustworthy)."""
    params = random_params(seed)
    table = solve(params, Settings(seed=1))
    result = audit(params, table)
    assert result["silent_extras"] == 0 and result["silent_misses"] == 0, (params, result)


@pytest.mark.parametrize("seed", SEEDS)
def test_seeds_give_the_same_physical_equilibria(seed):
    """Case 3 from independent generic start sets (seeds): the same physical equilibria."""
    params = make_params("case3")
    ref = solve(params, Settings(seed=1))
    other = solve(params, Settings(seed=seed))
    a = ref.loc[ref["physical"], ["gamma1_deg", "gamma2_deg"]].to_numpy()
    b = other.loc[other["physical"], ["gamma1_deg", "gamma2_deg"]].to_numpy()
    assert len(a) == len(b) == 14
    assert _gap(a, b).min(axis=1).max() < 1e-9
    assert len(ref) == len(other) == 76


@pytest.mark.parametrize("factor", [1e-3, 1e3])
def test_scaled_geometry_gives_the_same_angles(factor):
    """All lengths times 1e-3 or 1e3 (k unchanged): V scales by factor^2, the equilibria do not
    move, and their kinds and stability stay."""
    base = make_params("case3")
    lengths = ("L3", "p2x", "p3x", "p3y", "p6x", "p5x", "p5y", "L01", "L02")
    scaled = base.replace(**{n: getattr(base, n) * factor for n in lengths})
    a, b = solve(base), solve(scaled)
    pa, pb = a[a["physical"]], b[b["physical"]]
    assert len(pa) == len(pb)
    g = _gap(
        pa[["gamma1_deg", "gamma2_deg"]].to_numpy(), pb[["gamma1_deg", "gamma2_deg"]].to_numpy()
    )
    assert g.min(axis=1).max() < 1e-8
    assert list(pa["kind"]) == list(pb["kind"])
    assert np.allclose(pb["d1"].to_numpy(), factor * pa["d1"].to_numpy(), rtol=1e-9)


@pytest.mark.parametrize(
    "overrides",
    [
        {"k2": 2.81e-4},  # k2/k1 = 1e-4
        {"k2": 2.81e4},  # k2/k1 = 1e4
        {"p5x": 4.25, "p5y": 1e-6},  # P5 almost on P6
        {"L01": 11.5, "L02": 11.5 + 1e-9},  # springs slack at the zero-energy equilibria
        {"p3x": 3.1875 + 1e-6, "p3y": 1e-6},  # P3 almost on P2
    ],
)
def test_near_degenerate_parameters_are_right_or_flagged(overrides):
    """Near-degenerate inputs: the table agrees with the energy route, or says which rows it
    cannot trust (singular / large condition number) — never a silent wrong table."""
    params = make_params("case3", overrides)
    table = solve(params)
    result = audit(params, table)
    assert result["silent_extras"] == 0 and result["silent_misses"] == 0, result


def test_near_a_fold():
    """Just past a fold of the paper sweep two equilibria are about to merge: both are found
    (or flagged), with the condition number saying how close they are."""
    for l01 in (11.0131, 11.01305, 11.013):
        params = make_params(None, {**TABLE1, "L01": l01})
        table = solve(params)
        result = audit(params, table)
        assert result["silent_extras"] == 0 and result["silent_misses"] == 0, (l01, result)
