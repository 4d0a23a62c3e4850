"""Fold curves in the (L01, L02) plane, from the structure of the equilibrium set.

Every equilibrium with a tensioned spring lies on the parallel curve a_1 x a_2 = 0 of the torus
(analysis.design.free_lengths), and there its free lengths lie on a line: with u the common
direction of a_1, a_2 and w_i = a_i . u, l_i = L0_i / d_i = 1 + t c_i with c = (k2 w2,
-k1 w1). Along that line the energy Hessian is affine in t,
    H(t) = sum_i k_i l_i w_i^2 / d_i^2 u u^T + sum_i k_i (1 - l_i) B_i,
so det H(t) is a quadratic: each pose on the parallel curve carries at most two fold points, and
the fold curves are the image of the parallel curve under those roots. The parallel curve does
not depend on the free lengths: it is sampled once (roots in gamma2 on a gamma1 grid and in
gamma1 on a gamma2 grid, each bisected to rounding), and every sample gives its fold points in
closed form.
"""

from __future__ import annotations

from itertools import product

import numpy as np
import pandas as pd

from ..analysis.critical_points import deg_distance
from ..analysis.design.free_lengths import generalised_forces, parallel_cross, parallel_roots
from ..analysis.energy_terms import curvature
from ..model.kinematics import spring_jacobian, spring_second_derivatives, spring_vectors
from ..params import Params

FOLD_COLUMNS = [
    "L01", "L02", "gamma1_deg", "gamma2_deg", "d1", "d2", "physical", "family", "curve_id",
    "kind", "hess_eig_min",
]  # fmt: skip
LINK_DEG = 1.0  # fold points whose poses differ by less than this ...
LINK_LENGTH = 0.05  # ... and whose free lengths differ by less than this times L3 are linked


def _grid(points: int) -> np.ndarray:
    return np.linspace(-np.pi, np.pi, points, endpoint=False)


def parallel_samples(params: Params, points: int = 1500) -> list[tuple[np.ndarray, np.ndarray]]:
    """The parallel curve sampled: for axis 0, (gamma1 on a grid of `points`, the gamma2 roots);
    for axis 1, (gamma2 on the grid, the gamma1 roots), in rad."""
    return [parallel_roots(params, _grid(points), axis=axis) for axis in (0, 1)]


def _poses(samples: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """(gamma1, gamma2) of every sample."""
    (g1, r2), (g2, r1) = samples
    return np.concatenate([g1, r1]), np.concatenate([r2, g2])


def _curvatures(params: Params, angles: tuple) -> np.ndarray:
    """B_i[j, l] = P_ij . P_il + P_i . P_ijl, shape (2, 2, 2, n)."""
    vec = spring_vectors(params, *angles)
    out = np.zeros((2, 2, 2, len(angles[0])))
    for i in (0, 1):
        pv, first = vec[f"spring{i + 1}"], spring_jacobian(params, i + 1, *angles)
        second = spring_second_derivatives(params, i + 1, *angles)
        for j, m in product((0, 1), repeat=2):
            out[i, j, m] = curvature(pv, first, second, j, m)
    return out


def _det(x: np.ndarray) -> np.ndarray:
    return x[0, 0] * x[1, 1] - x[0, 1] * x[1, 0]


def _line_terms(params: Params, g1: np.ndarray, g2: np.ndarray) -> tuple:
    """At poses on the parallel curve: d, the line's slope dl/dt, H(0), dH/dt and the
    coefficients c1, c2 of det H(t) = c1 t + c2 t^2 (its constant term, det of a rank-one
    matrix, is zero: t = 0, the relaxed equilibrium, is always a fold)."""
    angles = (np.cos(g1), np.sin(g1), np.cos(g2), np.sin(g2))
    a, d = generalised_forces(params, g1, g2)
    norms = np.hypot(a[:, 0], a[:, 1])
    u = np.where(norms[0] >= norms[1], a[0] / norms[0], a[1] / norms[1])
    w = np.einsum("ijn,jn->in", a, u)
    k = np.array([params.k1, params.k2])[:, None]
    slope = np.stack([k[1] * w[1], -k[0] * w[0]])
    b = _curvatures(params, angles)
    uu = np.einsum("in,jn->ijn", u, u)
    radial = k * w**2 / d**2
    h0 = radial.sum(axis=0) * uu
    h1 = (radial * slope).sum(axis=0) * uu - np.einsum("in,ijmn->jmn", k * slope, b)
    c2 = _det(h1)
    c1 = _det(h0 + h1) - _det(h0) - c2
    return d, slope, h0, h1, c1, c2


def tensioned_free_lengths(params: Params, g1, g2) -> np.ndarray:
    """L0 (shape (2, n)) of the tensioned fold at poses on the parallel curve (NaN if none)."""
    g1, g2 = np.atleast_1d(np.asarray(g1, float)), np.atleast_1d(np.asarray(g2, float))
    d, slope, _, _, c1, c2 = _line_terms(params, g1, g2)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(c2 != 0, -c1 / c2, np.nan)
    return d * (1 + t * slope)


def _fold_row(terms: tuple, n: int, t: float, g1: float, g2: float) -> tuple:
    """(L01, L02, gamma1, gamma2, d1, d2, Hessian eigenvalue nearest 0) at root t of pose n."""
    d, slope, h0, h1, _, _ = terms
    l0 = d[:, n] * (1 + t * slope[:, n])
    eig = np.linalg.eigvalsh(h0[:, :, n] + t * h1[:, :, n])
    return (l0[0], l0[1], g1, g2, d[0, n], d[1, n], eig[np.argmin(abs(eig))])


def fold_curves(params: Params, points: int = 1500) -> pd.DataFrame:
    """Every fold point carried by the samples of the parallel curve (free lengths of any sign;
    `physical`: both >= 0), in m and degrees, and the cusps found along it; the geometry's own
    L01, L02 are not used."""
    return _folds(params, parallel_samples(params, points), points)


def fold_curves_proved(params: Params, points: int = 1500) -> tuple[pd.DataFrame, dict]:
    """`fold_curves` from samples proved to leave no part of the parallel curve out
    (`certify/curve.certify_samples`: crossings the sampler missed are added), and the
    certificate (the run.json `certificate` record of the map)."""
    from ..analysis.certify.curve import certify_samples

    record, samples = certify_samples(params, parallel_samples(params, points), _grid(points))
    return _folds(params, samples, points), record


def _folds(params: Params, samples: list, points: int) -> pd.DataFrame:
    """The fold and cusp table of the parallel curve's samples."""
    g1, g2 = _poses(samples)
    terms = _line_terms(params, g1, g2)
    c1, c2 = terms[4], terms[5]
    rows = []
    for n in range(len(g1)):
        for t in [0.0] + ([-c1[n] / c2[n]] if c2[n] != 0 else []):
            rows.append(_fold_row(terms, n, t, g1[n], g2[n]))
    table = _table(rows)
    table = table.assign(curve_id=link_curves(table, params.L3))
    table = pd.concat([table, _cusps(params, samples, _grid(points))], ignore_index=True)
    return zero_length_ends(table, params.L3)


def zero_length_ends(table: pd.DataFrame, length_unit: float) -> pd.DataFrame:
    """Rows where a spring is shorter than the solutions' zero-length rule (Tolerances
    .zero_length times L3) get kind `zero_length` and are not physical: V is not smooth there
    (a spring with a free length at zero length), so a fold curve running into that point ends
    there; it neither folds nor turns back in a cusp."""
    from ..settings import Tolerances

    lengths = table[["d1", "d2"]].to_numpy(float)
    short = (lengths < Tolerances().zero_length * length_unit).any(axis=1)
    return table.assign(
        kind=np.where(short, "zero_length", table.kind),
        physical=table.physical.to_numpy(bool) & ~short,
    )


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
        near = [m for da, db in product((-1, 0, 1), repeat=2)
                for m in cells.get(((a + da) % wrap, (b + db) % wrap), ()) if m > n]  # fmt: skip
        near = np.array(near, dtype=int)
        if near.size == 0:
            continue
        linked = (
            (fam[near] == fam[n])
            & (deg_distance(pose[n], pose[near]) < LINK_DEG)
            & (np.abs(l0[near] - l0[n]).max(axis=1) < LINK_LENGTH * length_scale)
        )
        for m in near[linked]:
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


def _on_curve(params: Params, fixed: float, guess: float, axis: int) -> float:
    """The root of a_1 x a_2 in the free angle nearest `guess`, by Newton (rad)."""

    def cross(x):
        return float(
            parallel_cross(params, fixed, x) if axis == 0 else parallel_cross(params, x, fixed)
        )

    x = guess
    for _ in range(30):
        h = 1e-7
        slope = (cross(x + h) - cross(x - h)) / (2 * h)
        if slope == 0:
            break
        step = cross(x) / slope
        x -= step
        if abs(step) < 1e-15:
            break
    return x


def _image(params: Params, g1, g2, family: str) -> np.ndarray:
    """The fold's free lengths (2, n) at poses on the parallel curve, for one family."""
    if family == "relaxed":
        return generalised_forces(params, np.atleast_1d(g1), np.atleast_1d(g2))[1]
    return tensioned_free_lengths(params, g1, g2)


def _image_speed(params, fixed: float, guess: float, axis: int, e: np.ndarray, family: str):
    """(d L0 / d fixed) . e along the family's fold curve, and the pose's free angle."""
    h = 1e-6
    ends = []
    for f in (fixed - h, fixed + h):
        x = _on_curve(params, f, guess, axis)
        g = (f, x) if axis == 0 else (x, f)
        ends.append(_image(params, *g, family)[:, 0])
    return float(np.dot(ends[1] - ends[0], e) / (2 * h)), _on_curve(params, fixed, guess, axis)


def _cusps(params: Params, samples: list, grid: np.ndarray) -> pd.DataFrame:
    """Cusps of the fold curves: where the fold point stops and turns back as its pose moves
    along the parallel curve (d L0 / ds = 0), found where consecutive samples turn by more than
    120 deg and refined by bisection on the speed along the incoming direction."""
    found = []
    for axis, (fixed, free) in enumerate(samples):
        for branch in _branches(fixed, free, grid):
            g = (fixed[branch], free[branch]) if axis == 0 else (free[branch], fixed[branch])
            for family in ("relaxed", "tensioned"):
                step = np.diff(_image(params, *g, family), axis=1)
                norm = np.hypot(*step)
                dots = np.einsum("in,in->n", step[:, :-1], step[:, 1:])
                for k in np.flatnonzero(dots < -0.5 * norm[:-1] * norm[1:]):
                    pose = _refine_cusp(params, fixed[branch], free[branch], k, step, axis, family)
                    if pose is not None:
                        found.append((*pose, family))
    return _cusp_table(params, found)


def _branches(fixed: np.ndarray, free: np.ndarray, grid: np.ndarray) -> list[np.ndarray]:
    """Indices of the roots chained from one grid value to the next (nearest root within
    2 deg), so each chain follows one smooth branch of the curve as a graph over `fixed`."""
    by_value = {v: np.flatnonzero(fixed == v) for v in grid}
    chains, open_chains = [], {}
    for v in grid:
        nxt = {}
        for idx in by_value[v]:
            prev = min(open_chains, key=lambda j: abs(free[j] - free[idx]), default=None)
            if prev is not None and abs(free[prev] - free[idx]) < np.radians(2.0):
                chain = open_chains.pop(prev)
            else:
                chain = []
                chains.append(chain)
            chain.append(idx)
            nxt[idx] = chain
        open_chains = nxt
    return [np.array(c) for c in chains if len(c) >= 3]


def _refine_cusp(params, fixed, free, k: int, step: np.ndarray, axis: int, family: str):
    """Bisection between samples k and k + 2 on the image speed along the incoming direction."""
    e = step[:, k] / np.hypot(*step[:, k])
    lo, hi = fixed[k], fixed[k + 2]
    s_lo, _ = _image_speed(params, lo, free[k], axis, e, family)
    s_hi, _ = _image_speed(params, hi, free[k + 2], axis, e, family)
    if np.sign(s_lo) == np.sign(s_hi):
        return None
    guess = free[k + 1]
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        s_mid, guess = _image_speed(params, mid, guess, axis, e, family)
        lo, hi, s_lo = (mid, hi, s_mid) if np.sign(s_mid) == np.sign(s_lo) else (lo, mid, s_lo)
    x = _on_curve(params, 0.5 * (lo + hi), guess, axis)
    return (0.5 * (lo + hi), x) if axis == 0 else (x, 0.5 * (lo + hi))


def _cusp_table(params: Params, poses: list[tuple]) -> pd.DataFrame:
    """Cusp rows (kind `cusp`), one per distinct pose (the two samplings find some twice)."""
    rows, seen, families = [], [], []
    for g1, g2, family in poses:
        key = np.degrees([g1, g2]) % 360.0
        if seen and deg_distance(key, np.array(seen)).min() < 0.05:
            continue  # the same cusp, found from both samplings
        seen.append(key)
        families.append(family)
        terms = _line_terms(params, np.array([g1]), np.array([g2]))
        t = 0.0 if family == "relaxed" else -terms[4][0] / terms[5][0]
        rows.append(_fold_row(terms, 0, t, g1, g2))
    return _table(rows).assign(kind="cusp", family=families, curve_id=-1)
