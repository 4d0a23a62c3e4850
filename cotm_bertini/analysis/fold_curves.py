"""Fold curves in the (L01, L02) plane, from the structure of the equilibrium set.

Every equilibrium with a tensioned spring lies on the parallel curve a_1 x a_2 = 0 of the torus
(analysis.design), and there its free lengths lie on a line: with u the common direction of a_1,
a_2 and w_i = a_i . u, l_i = L0_i / d_i = 1 + t c_i with c = (k2 w2, -k1 w1). Along that line the
energy Hessian is affine in t,
    H(t) = sum_i k_i l_i w_i^2 / d_i^2 u u^T + sum_i k_i (1 - l_i) B_i,
so det H(t) is a quadratic: each pose on the parallel curve carries at most two fold points, and
the fold curves are the image of the parallel curve under those roots. The parallel curve does
not depend on the free lengths: it is sampled once (roots in gamma2 on a gamma1 grid and in
gamma1 on a gamma2 grid, each bisected to rounding), and every sample gives its fold points in
closed form.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..model.kinematics import dot, spring_jacobian, spring_second_derivatives, spring_vectors
from ..params import Params
from .design import generalised_forces, parallel_roots

FOLD_COLUMNS = [
    "L01", "L02", "gamma1_deg", "gamma2_deg", "d1", "d2", "physical", "family", "curve_id",
    "kind", "hess_eig_min",
]  # fmt: skip
LINK_DEG = 1.0  # fold points whose poses differ by less than this ...
LINK_LENGTH = 0.05  # ... and whose free lengths differ by less than this times L3 are linked


def parallel_samples(params: Params, points: int = 1500) -> np.ndarray:
    """Points (rad, shape (n, 2)) of the parallel curve: for `points` values of each angle, the
    other angle's roots."""
    grid = np.linspace(-np.pi, np.pi, points, endpoint=False)
    g1, r2 = parallel_roots(params, grid, axis=0)
    g2, r1 = parallel_roots(params, grid, axis=1)  # (the fixed gamma2, the gamma1 roots)
    return np.vstack([np.c_[g1, r2], np.c_[r1, g2]])


def _curvatures(params: Params, angles: tuple) -> np.ndarray:
    """B_i[j, l] = P_ij . P_il + P_i . P_ijl, shape (2, 2, 2, n)."""
    vec = spring_vectors(params, *angles)
    out = np.zeros((2, 2, 2, len(angles[0])))
    for i in (0, 1):
        pv, first = vec[f"spring{i + 1}"], spring_jacobian(params, i + 1, *angles)
        s11, s12, s22 = spring_second_derivatives(params, i + 1, *angles)
        curv = ((s11, s12), (s12, s22))
        for j in (0, 1):
            for m in (0, 1):
                out[i, j, m] = dot(first[j], first[m]) + dot(pv, curv[j][m])
    return out


def _det(x: np.ndarray) -> np.ndarray:
    return x[0, 0] * x[1, 1] - x[0, 1] * x[1, 0]


def fold_curves(params: Params, points: int = 1500) -> pd.DataFrame:
    """Every fold point carried by the samples of the parallel curve (free lengths of any sign;
    `physical`: both >= 0), in m and degrees; the geometry's own L01, L02 are not used."""
    pose = parallel_samples(params, points)
    g1, g2 = pose[:, 0], pose[:, 1]
    angles = (np.cos(g1), np.sin(g1), np.cos(g2), np.sin(g2))
    a, d = generalised_forces(params, g1, g2)
    norms = np.hypot(a[:, 0], a[:, 1])
    u = np.where(norms[0] >= norms[1], a[0] / norms[0], a[1] / norms[1])
    w = np.einsum("ijn,jn->in", a, u)
    k = np.array([params.k1, params.k2])[:, None]
    slope = np.stack([k[1] * w[1], -k[0] * w[0]])  # dl/dt
    b = _curvatures(params, angles)
    uu = np.einsum("in,jn->ijn", u, u)
    radial = k * w**2 / d**2
    h0 = radial.sum(axis=0) * uu
    h1 = (radial * slope).sum(axis=0) * uu - np.einsum("in,ijmn->jmn", k * slope, b)
    c0, c2 = _det(h0), _det(h1)
    c1 = _det(h0 + h1) - c0 - c2
    rows = []
    for n in range(len(g1)):
        for t in np.roots([c2[n], c1[n], c0[n]]):
            if abs(t.imag) <= 1e-12 * max(1.0, abs(t)):
                l0 = d[:, n] * (1 + t.real * slope[:, n])
                hess = h0[:, :, n] + t.real * h1[:, :, n]
                eig = np.linalg.eigvalsh(hess)
                rows.append(
                    (l0[0], l0[1], g1[n], g2[n], d[0, n], d[1, n], eig[np.argmin(abs(eig))])
                )
    table = _table(rows)
    return table.assign(curve_id=link_curves(table, params.L3))


def link_curves(folds: pd.DataFrame, length_scale: float) -> np.ndarray:
    """A curve id for each fold point: the connected pieces of the fold set, joining points of
    one family whose poses differ by under LINK_DEG and free lengths by under LINK_LENGTH L3."""
    pose = folds[["gamma1_deg", "gamma2_deg"]].to_numpy(float)
    l0 = folds[["L01", "L02"]].to_numpy(float)
    fam = folds.family.to_numpy()
    cells: dict[tuple, list[int]] = {}
    keys = np.floor(pose / LINK_DEG).astype(int)
    for n, key in enumerate(map(tuple, keys)):
        cells.setdefault(key, []).append(n)
    parent = np.arange(len(folds))

    def root(n: int) -> int:
        while parent[n] != n:
            parent[n] = parent[parent[n]]
            n = parent[n]
        return n

    wrap = int(round(360 / LINK_DEG))
    for n, (a, b) in enumerate(keys):
        for da in (-1, 0, 1):
            for db in (-1, 0, 1):
                for m in cells.get(((a + da) % wrap, (b + db) % wrap), ()):
                    gap = np.abs((pose[n] - pose[m] + 180) % 360 - 180).max()
                    near = np.abs(l0[n] - l0[m]).max() < LINK_LENGTH * length_scale
                    if m > n and fam[m] == fam[n] and gap < LINK_DEG and near:
                        parent[root(m)] = root(n)
    roots = np.array([root(n) for n in range(len(folds))])
    _, ids = np.unique(roots, return_inverse=True)
    return ids


def _table(rows: list[tuple]) -> pd.DataFrame:
    arr = np.array(rows, dtype=float).reshape(-1, 7)
    return pd.DataFrame(
        {
            "L01": arr[:, 0], "L02": arr[:, 1],
            "gamma1_deg": np.mod(np.degrees(arr[:, 2]), 360.0),
            "gamma2_deg": np.mod(np.degrees(arr[:, 3]), 360.0),
            "d1": arr[:, 4], "d2": arr[:, 5],
            "physical": (arr[:, 0] >= 0) & (arr[:, 1] >= 0),
            "family": np.where(
                np.abs(arr[:, :2] - arr[:, 4:6]).max(axis=1) <= 1e-9 * arr[:, 4:6].max(axis=1),
                "relaxed", "tensioned",
            ),
            "curve_id": -1, "kind": "fold", "hess_eig_min": arr[:, 6],
        },
        columns=FOLD_COLUMNS,
    )  # fmt: skip
