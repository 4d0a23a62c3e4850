"""Solution branches of a one-parameter sweep: neighbouring points' solutions joined one-to-one.

A secant predictor from each branch's last two points, then a one-to-one minimum-cost assignment
(the Hungarian algorithm) on the complex solver coordinates, so a branch goes on through a fold
where two real solutions become a complex-conjugate pair.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

ANGLE_VARS = ("c1", "s1", "c2", "s2")
MATCH_VARS = ANGLE_VARS + ("d1", "d2")


def point_order(sweep: pd.DataFrame, param: str) -> list[tuple[object, float]]:
    """(point key, swept value) for every sweep point, sorted by value then key."""
    key = "point" if "point" in sweep.columns else param
    firsts = sweep.groupby(key, sort=True)[param].first()
    return sorted(((k, float(v)) for k, v in firsts.items()), key=lambda kv: (kv[1], kv[0]))


def _length_scale(sweep: pd.DataFrame) -> float:
    """A typical spring length, so d coordinates weigh like the unit-circle ones."""
    ds = [sweep[c].to_numpy(float) for c in ("d1", "d2") if c in sweep.columns]
    vals = np.abs(np.concatenate(ds)) if ds else np.array([])
    vals = vals[np.isfinite(vals)]
    return max(1.0, float(np.median(vals))) if len(vals) else 1.0


def match_coordinates(rows: pd.DataFrame, length_scale: float = 1.0) -> np.ndarray:
    """Complex coordinates (c1, s1, c2, s2, d1/L, d2/L) of each row; NaN where unknown.

    A spring with L0 > 0 contributes its solver variable d_i; a zero-free-length spring (no
    variable) its geometric length from the `d_i` column, so both structures are comparable.
    """
    out = np.full((len(rows), len(MATCH_VARS)), np.nan, dtype=complex)
    for j, v in enumerate(MATCH_VARS):
        scale = 1.0 if v in ANGLE_VARS else length_scale
        if f"{v}_re" in rows.columns:
            re = rows[f"{v}_re"].to_numpy(float)
            im = rows[f"{v}_im"].to_numpy(float)
            have = np.isfinite(re) & np.isfinite(im)
            out[have, j] = (re[have] + 1j * im[have]) / scale
        else:
            have = np.zeros(len(rows), dtype=bool)
        if v in rows.columns:
            fill = ~have & np.isfinite(rows[v].to_numpy(float))
            out[fill, j] = rows[v].to_numpy(float)[fill] / scale
    return out


def hungarian(cost: np.ndarray) -> np.ndarray:
    """Minimum-sum one-to-one assignment: for each row its column (-1 if rows outnumber columns)."""
    cost = np.asarray(cost, dtype=float)
    n, m = cost.shape
    if n == 0 or m == 0:
        return -np.ones(n, dtype=int)
    if n > m:
        cols = hungarian(cost.T)
        out = -np.ones(n, dtype=int)
        out[cols[cols >= 0]] = np.flatnonzero(cols >= 0)
        return out
    # Kuhn-Munkres with potentials (rows <= columns), 1-based with a virtual column 0.
    u, v = np.zeros(n + 1), np.zeros(m + 1)
    owner = np.zeros(m + 1, dtype=int)  # owner[j]: the row (1-based) assigned to column j
    way = np.zeros(m + 1, dtype=int)
    for i in range(1, n + 1):
        owner[0] = i
        j0 = 0
        minv = np.full(m + 1, np.inf)
        used = np.zeros(m + 1, dtype=bool)
        while True:
            used[j0] = True
            i0 = owner[j0]
            free = ~used[1:]
            cur = cost[i0 - 1] - u[i0] - v[1:]
            better = free & (cur < minv[1:])
            minv[1:][better] = cur[better]
            way[1:][better] = j0
            cand = np.where(free, minv[1:], np.inf)
            j1 = int(np.argmin(cand)) + 1
            delta = cand[j1 - 1]
            taken = np.flatnonzero(used)
            u[owner[taken]] += delta
            v[taken] -= delta
            minv[1:][free] -= delta
            j0 = j1
            if owner[j0] == 0:
                break
        while j0:
            j1 = way[j0]
            owner[j0] = owner[j1]
            j0 = j1
    out = -np.ones(n, dtype=int)
    for j in range(1, m + 1):
        if owner[j]:
            out[owner[j] - 1] = j - 1
    return out


def assign_branches(sweep: pd.DataFrame, param: str) -> pd.DataFrame:
    """A copy of `sweep` with an integer `branch` column joining solutions across its points."""
    out = sweep.copy()
    branch = np.full(len(sweep), -1, dtype=int)
    ls = _length_scale(sweep)
    keys = sweep["point" if "point" in sweep.columns else param].to_numpy()
    sid = sweep["solution_id"].to_numpy() if "solution_id" in sweep.columns else None
    history: dict[int, list[tuple[float, np.ndarray]]] = {}
    active: list[int] = []  # branches present at the previous point
    next_id = 0
    for pkey, value in point_order(sweep, param):
        pos = np.flatnonzero(keys == pkey)
        if sid is not None:
            pos = pos[np.argsort(sid[pos], kind="stable")]
        x = match_coordinates(sweep.iloc[pos], ls)
        good = np.isfinite(x[:, : len(ANGLE_VARS)]).all(axis=1)
        x, pos = x[good], pos[good]
        pred = np.array([_predict(history[b], value) for b in active]).reshape(-1, x.shape[1])
        cols = np.isfinite(x).all(axis=0) & np.isfinite(pred).all(axis=0)
        diff = np.abs(pred[:, None, cols] - x[None, :, cols])
        match = hungarian(np.sqrt((diff**2).sum(axis=2)))
        owner = -np.ones(len(x), dtype=int)
        for a, j in enumerate(match):
            if j >= 0:
                owner[j] = active[a]
        for j in np.flatnonzero(owner < 0):
            owner[j], next_id = next_id, next_id + 1
            history[int(owner[j])] = []
        for j, b in enumerate(owner):
            history[int(b)].append((value, x[j]))
        branch[pos] = owner
        active = [int(b) for b in owner]
    out["branch"] = branch
    return out


def _predict(hist: list[tuple[float, np.ndarray]], value: float) -> np.ndarray:
    """Secant extrapolation from a branch's last two points (constant from a single one)."""
    p1, x1 = hist[-1]
    if len(hist) < 2 or hist[-2][0] == p1:
        return x1
    p0, x0 = hist[-2]
    step = (x1 - x0) * ((value - p1) / (p1 - p0))
    return np.where(np.isfinite(step), x1 + step, x1)
