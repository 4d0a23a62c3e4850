"""Fold curves (issue 10, part 1, closed-form route): every fold point is an equilibrium with a
singular Hessian by the independent energy code, direct solves either side differ by two
physical equilibria, and the paper's 1-D fold (L01 = 11.0128 m at L02 = 0) lies on the curve."""

from __future__ import annotations

import math

import numpy as np
import pytest

import cotm_bertini as cb
from cotm_bertini.model.compiled import energy_gradient, energy_hessian

P = cb.Params.case("case3")


@pytest.fixture(scope="module")
def folds():
    return cb.fold_curves(P)


def test_fold_points_are_degenerate_equilibria(folds):
    phys = folds[folds.physical]
    assert len(phys) > 1000
    for _, r in phys.iloc[::40].iterrows():
        q = P.replace(L01=r.L01, L02=r.L02)
        g1, g2 = math.radians(r.gamma1_deg), math.radians(r.gamma2_deg)
        scale = max(P.k1, P.k2) * P.L3 * max(r.L01, r.L02, r.d1, r.d2)
        assert np.abs(energy_gradient(q, g1, g2)[0]).max() < 1e-8 * scale
        hess = energy_hessian(q, g1, g2)[0]
        assert abs(np.linalg.det(hess)) < 1e-8 * np.linalg.norm(hess) ** 2
        assert abs(r.hess_eig_min) < 1e-8 * np.linalg.norm(hess)


def _crossings(folds, l02: float) -> np.ndarray:
    """L01 where the sampled fold curve crosses L02 = l02: linear interpolation between fold
    points within 0.1 m of the line on either side, whose poses differ by at most 1 deg but are
    not the same pose (neighbouring samples of one curve, not the two roots of one pose) and
    whose L01 differ by under 0.1 m."""
    pts = folds[["L01", "L02", "gamma1_deg", "gamma2_deg"]].to_numpy(float)
    pts = pts[np.abs(pts[:, 1] - l02) < 0.1]
    below, above = pts[pts[:, 1] < l02], pts[pts[:, 1] >= l02]
    gap = below[:, None, 2:] - above[None, :, 2:]
    gap = np.abs((gap + 180) % 360 - 180).max(axis=2)
    close = np.abs(below[:, None, 0] - above[None, :, 0]) < 0.1
    i, j = np.nonzero((gap < 1.0) & (gap > 1e-9) & close)
    a, b = below[i], above[j]
    return a[:, 0] + (l02 - a[:, 1]) / (b[:, 1] - a[:, 1]) * (b[:, 0] - a[:, 0])


def test_the_paper_fold_lies_on_the_curve(folds):
    # The 1-D sweep of the paper (Fig. 5, L02 = 0) has its fold at L01 = 11.0128 m.
    crossings = _crossings(folds, 0.0)
    assert np.abs(crossings - 11.0128).min() < 2e-3


@pytest.mark.parametrize("index", [0, 1, 2])
def test_direct_solves_either_side_differ_by_two(folds, index):
    rng = np.random.default_rng(100 + index)
    phys = folds[folds.physical & folds.L01.between(1, 13) & folds.L02.between(1, 13)]
    r = phys.iloc[int(rng.integers(len(phys)))]
    counts = []
    for step in (-1e-4, 1e-4):
        res = cb.solve(P.replace(L01=r.L01 + step, L02=r.L02), cache=False)
        counts.append(len(res.physical))
    assert abs(counts[0] - counts[1]) == 2
