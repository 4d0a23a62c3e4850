"""Energy route: every critical point of V(gamma1, gamma2) by Newton from a grid on the torus.

Independent of the polynomial model: it works on V = sum 1/2 k_i (|P_i| - L0i)^2 directly (its
sympy gradient and Hessian), so it finds physical equilibria only, never negative-d roots or
d = 0 artefacts. Used as a cross-check of the Bertini route.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..model.compiled import energy, energy_gradient, energy_hessian
from ..model.kinematics import spring_vectors
from ..params import Params


def newton_on_gradient(
    params: Params, g: np.ndarray, iterations: int = 60, max_step: float = 0.3
) -> np.ndarray:
    """Damped Newton on grad V = 0 from many starts at once (angles in radians, shape (n, 2))."""
    g = np.array(g, dtype=float)
    for _ in range(iterations):
        grad = energy_gradient(params, g[:, 0], g[:, 1])
        hess = energy_hessian(params, g[:, 0], g[:, 1])
        ok = np.isfinite(hess).all(axis=(1, 2)) & (np.abs(np.linalg.det(hess)) > 1e-300)
        step = np.zeros_like(g)
        step[ok] = np.linalg.solve(hess[ok], grad[ok][..., None])[..., 0]
        norm = np.linalg.norm(step, axis=1, keepdims=True)
        step *= np.minimum(1.0, max_step / np.maximum(norm, 1e-300))
        g = g - step
    return np.mod(g, 2 * np.pi)


def critical_points(params: Params, grid: int = 48, tol: float = 1e-10) -> pd.DataFrame:
    """Distinct critical points of V with |grad V| < tol min(k) L3^2, classified by the Hessian.

    Damped Newton from every grid point, then undamped Newton steps to polish: the tolerance is
    relative to the weaker spring, so a very stiff spring cannot hide an unconverged point.
    """
    axis = (np.arange(grid) + 0.5) * 2 * np.pi / grid
    starts = np.stack(np.meshgrid(axis, axis, indexing="ij"), axis=-1).reshape(-1, 2)
    g = newton_on_gradient(params, starts)
    g = newton_on_gradient(params, g, iterations=8, max_step=np.inf)
    scale = min(params.k1, params.k2) * params.L3**2
    grad = energy_gradient(params, g[:, 0], g[:, 1])
    good = np.isfinite(grad).all(axis=1) & (np.abs(grad).max(axis=1) < tol * scale)
    # Exclude the cusps where a spring with L0 > 0 has zero length: V is not smooth there.
    vec = spring_vectors(params, np.cos(g[:, 0]), np.sin(g[:, 0]), np.cos(g[:, 1]), np.sin(g[:, 1]))
    for i, L0 in ((1, params.L01), (2, params.L02)):
        if L0 > 0:
            good &= np.hypot(*vec[f"spring{i}"]) > 1e-6 * params.L3
    g = g[good]
    distinct: list[np.ndarray] = []
    for point in g:
        if not any(_torus_distance(point, q) < 1e-7 for q in distinct):
            distinct.append(point)
    if not distinct:
        return pd.DataFrame(columns=["gamma1_deg", "gamma2_deg", "energy", "kind"])
    pts = np.array(distinct)
    hess = energy_hessian(params, pts[:, 0], pts[:, 1])
    lam = np.linalg.eigvalsh(hess)
    kind = np.where((lam > 0).all(axis=1), "min", np.where((lam < 0).all(axis=1), "max", "saddle"))
    frame = pd.DataFrame(
        {
            "gamma1_deg": np.degrees(pts[:, 0]),
            "gamma2_deg": np.degrees(pts[:, 1]),
            "energy": energy(params, pts[:, 0], pts[:, 1]),
            "kind": kind,
        }
    )
    return frame.sort_values(["gamma1_deg", "gamma2_deg"]).reset_index(drop=True)


def _torus_distance(a: np.ndarray, b: np.ndarray) -> float:
    d = np.abs(a - b) % (2 * np.pi)
    return float(np.minimum(d, 2 * np.pi - d).max())


def compare_physical(found: pd.DataFrame, solutions: pd.DataFrame) -> dict:
    """Match energy-route points to the physical rows of a solutions table (degrees)."""
    phys = solutions[solutions["physical"]]
    a = found[["gamma1_deg", "gamma2_deg"]].to_numpy()
    b = phys[["gamma1_deg", "gamma2_deg"]].to_numpy()
    worst, missing_in_b, missing_in_a = 0.0, 0, 0
    for p in a:
        d = deg_distance(p, b)
        if d.size == 0 or d.min() > 1e-4:
            missing_in_b += 1
        else:
            worst = max(worst, float(d.min()))
    for q in b:
        d = deg_distance(q, a)
        if d.size == 0 or d.min() > 1e-4:
            missing_in_a += 1
    return {
        "energy_route": len(a),
        "polynomial_route": len(b),
        "worst_deg": worst,
        "only_energy_route": missing_in_b,
        "only_polynomial_route": missing_in_a,
    }


def deg_distance(p: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """The largest angle difference (deg, on the torus) between point p and each row."""
    if rows.size == 0:
        return np.array([])
    d = np.abs(rows - p) % 360.0
    return np.minimum(d, 360.0 - d).max(axis=1)
