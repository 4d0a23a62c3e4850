"""Solution branches of a one-parameter sweep: neighbouring points' solutions joined one-to-one.

A secant predictor from each branch's last two points, then a one-to-one minimum-cost assignment
(the Hungarian algorithm) on the complex solver coordinates, so a branch goes on through a fold
where two real solutions become a complex-conjugate pair. The table is read as numpy columns (a
DataFrame or a dict of arrays), the coordinates of all rows at once; only the assignment is
done point by point.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

ANGLE_VARS = ("c1", "s1", "c2", "s2")
MATCH_VARS = ANGLE_VARS + ("d1", "d2")


def _column(table, name: str, dtype=float) -> np.ndarray:
    return np.asarray(table[name], dtype=dtype)


def point_order(sweep, param: str) -> list[tuple[object, float]]:
    """(point key, swept value) for every sweep point, sorted by value then key."""
    keys, values = point_keys(sweep, param)
    uniq, first = np.unique(keys, return_index=True)
    vals = values[first].astype(float)
    return sorted(zip(uniq.tolist(), vals.tolist(), strict=True), key=lambda kv: (kv[1], kv[0]))


def point_keys(sweep, param: str) -> tuple[np.ndarray, np.ndarray]:
    """Each row's point key (`point`, or the swept value when there is no `point` column) and
    its swept value."""
    values = np.asarray(sweep[param])
    return (np.asarray(sweep["point"]) if "point" in sweep else values), values


def _length_scale(sweep) -> float:
    """A typical spring length, so d coordinates weigh like the unit-circle ones."""
    ds = [_column(sweep, c) for c in ("d1", "d2") if c in sweep]
    vals = np.abs(np.concatenate(ds)) if ds else np.array([])
    vals = vals[np.isfinite(vals)]
    return max(1.0, float(np.median(vals))) if len(vals) else 1.0


def match_coordinates(rows, length_scale: float = 1.0) -> np.ndarray:
    """Complex coordinates (c1, s1, c2, s2, d1/L, d2/L) of each row; NaN where unknown.

    A spring with L0 > 0 contributes its solver variable d_i; a zero-free-length spring (no
    variable) its geometric length from the `d_i` column, so both structures are comparable.
    `rows`: a DataFrame or a mapping of columns.
    """
    n = len(rows[next(iter(rows))]) if isinstance(rows, Mapping) else len(rows)
    out = np.full((n, len(MATCH_VARS)), np.nan, dtype=complex)
    for j, v in enumerate(MATCH_VARS):
        scale = 1.0 if v in ANGLE_VARS else length_scale
        if f"{v}_re" in rows:
            re = _column(rows, f"{v}_re")
            im = _column(rows, f"{v}_im")
            have = np.isfinite(re) & np.isfinite(im)
            out[have, j] = (re[have] + 1j * im[have]) / scale
        else:
            have = np.zeros(n, dtype=bool)
        if v in rows:
            col = _column(rows, v)
            fill = ~have & np.isfinite(col)
            out[fill, j] = col[fill] / scale
    return out


def hungarian(cost: np.ndarray) -> np.ndarray:
    """Minimum-sum one-to-one assignment: for each row its column (-1 if rows outnumber columns)."""
    cost = np.asarray(cost, dtype=float)
    n, m = cost.shape
    if n == 0 or m == 0:
        return -np.ones(n, dtype=int)
    if n <= m:
        # Every row's cheapest column, when no two rows share one, is the optimum (each row
        # pays its own minimum): the rule along a sweep, away from folds.
        best = np.argmin(cost, axis=1)
        if len(np.unique(best)) == n and np.isfinite(cost[np.arange(n), best]).all():
            return best
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


def assign_branches(sweep, param: str):
    """A copy of the DataFrame `sweep` with an integer `branch` column joining solutions across
    its points."""
    out = sweep.copy()
    out["branch"] = branch_ids(sweep, param)
    return out


def branch_ids(sweep, param: str, coords: np.ndarray | None = None) -> np.ndarray:
    """The branch of every row of `sweep` (a DataFrame or a mapping of columns), -1 for rows
    without finite angles: rows of each point (by solution_id) matched to the branches present
    at the point before (in parameter order). `coords`: each row's matching coordinates
    (default: the paper's model's, `match_coordinates`; rows with any NaN get -1)."""
    keys, _ = point_keys(sweep, param)
    branch = np.full(len(keys), -1, dtype=int)
    if coords is None:
        coords = match_coordinates(sweep, _length_scale(sweep))
        good = np.isfinite(coords[:, : len(ANGLE_VARS)]).all(axis=1)
    else:
        good = np.isfinite(coords).all(axis=1)
    rank = {k: r for r, (k, _) in enumerate(point_order(sweep, param))}
    values = [v for _, v in point_order(sweep, param)]
    sid = _column(sweep, "solution_id") if "solution_id" in sweep else np.zeros(len(keys))
    row_rank = np.array([rank[k] for k in keys.tolist()], dtype=int)
    order = np.lexsort((sid, row_rank))  # by point, then solution_id (stable)
    order = order[good[order]]
    bounds = np.searchsorted(row_rank[order], np.arange(len(values) + 1))
    hist = _History(coords.shape[1])
    active = np.zeros(0, dtype=int)  # branches present at the previous point
    for r, value in enumerate(values):
        pos = order[bounds[r] : bounds[r + 1]]
        x = coords[pos]
        pred = hist.predict(active, value)
        cols = np.isfinite(x).all(axis=0) & np.isfinite(pred).all(axis=0)
        diff = np.abs(pred[:, None, cols] - x[None, :, cols])
        match = hungarian(np.sqrt((diff**2).sum(axis=2)))
        owner = -np.ones(len(x), dtype=int)
        owner[match[match >= 0]] = active[match >= 0]
        new = owner < 0
        owner[new] = hist.new(int(new.sum()))
        hist.push(owner, value, x)
        branch[pos] = owner
        active = owner
    return branch


class _History:
    """The last two (value, coordinates) of every branch, for the secant predictor."""

    def __init__(self, width: int):
        self.x = np.zeros((0, 2, width), dtype=complex)  # [branch, last / one before, coord]
        self.p = np.zeros((0, 2))
        self.count = np.zeros(0, dtype=int)

    def new(self, k: int) -> np.ndarray:
        start = len(self.count)
        self.x = np.concatenate([self.x, np.zeros((k, 2, self.x.shape[2]), complex)])
        self.p = np.concatenate([self.p, np.zeros((k, 2))])
        self.count = np.concatenate([self.count, np.zeros(k, dtype=int)])
        return np.arange(start, start + k)

    def push(self, branches: np.ndarray, value: float, x: np.ndarray) -> None:
        self.x[branches, 1], self.p[branches, 1] = self.x[branches, 0], self.p[branches, 0]
        self.x[branches, 0], self.p[branches, 0] = x, value
        self.count[branches] += 1

    def predict(self, branches: np.ndarray, value: float) -> np.ndarray:
        """Secant extrapolation from each branch's last two points (constant from one)."""
        x1, p1 = self.x[branches, 0], self.p[branches, 0]
        x0, p0 = self.x[branches, 1], self.p[branches, 1]
        secant = (self.count[branches] >= 2) & (p0 != p1)
        with np.errstate(all="ignore"):
            factor = np.where(secant, (value - p1) / np.where(secant, p1 - p0, 1.0), 0.0)
            step = (x1 - x0) * factor[:, None]
        step = np.where(np.isfinite(step), step, 0.0)
        return np.where(secant[:, None], x1 + step, x1)
