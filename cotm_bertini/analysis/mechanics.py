"""Mechanics of physical equilibria: energy, Hessian and kind, forces; the paper's criterion."""

from __future__ import annotations

import numpy as np

from ..model.compiled import energy, energy_hessian, tan_half_jacobian
from ..params import Params


def hessian_kind(eigenvalues: np.ndarray, tol: float) -> np.ndarray:
    """'min', 'max', 'saddle' or 'degenerate' per row of ascending Hessian eigenvalues."""
    pos = eigenvalues > tol
    neg = eigenvalues < -tol
    return np.where(
        pos.all(axis=1),
        "min",
        np.where(
            neg.all(axis=1),
            "max",
            np.where(pos.any(axis=1) & neg.any(axis=1), "saddle", "degenerate"),
        ),
    )


def mechanics(
    params: Params,
    phys: np.ndarray,
    g1: np.ndarray,
    g2: np.ndarray,
    vec: dict[str, tuple[np.ndarray, np.ndarray]],
    can_be_stable: np.ndarray,
    hessian_tol: float,
) -> dict[str, np.ndarray]:
    """Energy, Hessian, kind, stable, forces, tensegrity; NaN where a row is not physical."""
    n = len(phys)
    e = np.full(n, np.nan)
    lam = np.full((n, 2), np.nan)
    if phys.any():
        e[phys] = energy(params, g1[phys], g2[phys])
        lam[phys] = np.linalg.eigvalsh(energy_hessian(params, g1[phys], g2[phys]))
    scale = max(params.k1, params.k2) * params.L3**2
    kind = np.where(phys, hessian_kind(lam, hessian_tol * scale), "").astype(object)
    length = {i: np.hypot(*vec[f"spring{i}"]) for i in (1, 2)}
    f = {}
    for i, (k, L0) in enumerate(((params.k1, params.L01), (params.k2, params.L02)), start=1):
        f[i] = np.where(phys, k * (length[i] - L0), np.nan)
    # Rod force from the force balance f1 u1 + f2 u2 + f3 u_rod = 0 (eq. (5)); tension > 0.
    with np.errstate(invalid="ignore", divide="ignore"):
        rod = np.stack(vec["rod"], axis=-1) / params.L3
        pull = sum(
            f[i][:, None] * np.stack(vec[f"spring{i}"], axis=-1) / length[i][:, None]
            for i in (1, 2)
        )
        f3 = -(pull * rod).sum(axis=1)
    return {
        "stable": phys & can_be_stable & (kind == "min"),
        "kind": kind,
        "energy": e,
        "hess_eig1": lam[:, 0],
        "hess_eig2": lam[:, 1],
        "spring1_force": f[1],
        "spring2_force": f[2],
        "rod_force": np.where(phys, f3, np.nan),
        "tensegrity": phys & (f[1] > 0) & (f[2] > 0) & (f3 < 0),
    }


def paper_criterion(params: Params, cols) -> np.ndarray:
    """The paper's "stable": all eigenvalues of the Jacobian of its tan-half equations (F, tau,
    C1, C2 in x1, x2, d1, d2) have negative real parts. Evaluated on real rows, as the paper does;
    False for complex rows and where gamma = 180 deg (x = tan(gamma/2) is infinite there).
    `cols`: a solutions table (DataFrame or dict of columns)."""
    is_real = np.asarray(cols["is_real"], dtype=bool)
    out = np.zeros(len(is_real), dtype=bool)
    half = np.radians(np.stack([cols["gamma1_deg"], cols["gamma2_deg"]], axis=1).astype(float)) / 2
    rows = np.flatnonzero(is_real & (np.abs(np.cos(half)).min(axis=1) >= 1e-8))
    if not len(rows):
        return out
    point = [np.tan(half[rows, 0]), np.tan(half[rows, 1])]
    point += [np.asarray(cols[f"d{i}"], float)[rows] for i in (1, 2) if not params.zfl[i - 1]]
    jac = tan_half_jacobian(params, tuple(point))
    out[rows] = (np.linalg.eigvals(jac).real < 0).all(axis=1)
    return out
