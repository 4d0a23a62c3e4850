"""Solution branches of a one-parameter sweep, and the events between its points.

`assign_branches` joins the solutions of neighbouring sweep points into branches: a secant
predictor from each branch's last two points, then a one-to-one minimum-cost assignment (the
Hungarian algorithm) on the complex solver coordinates, so a branch goes on through a fold where
two real solutions become a complex-conjugate pair. `find_events` reads the branches for folds,
stability changes and physical changes, and refines each one's parameter value: a fold by Newton
on the augmented system F(x, p) = 0, J_x(x, p) v = 0, r.v = 1 in (x, v, p); the others by
bisection along the branch, Newton-correcting the branch point at each midpoint.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .equations import energy_hessian, parametric_system
from .geometry import Params
from .polynomial import ParametricSystem, PolySystem

ANGLE_VARS = ("c1", "s1", "c2", "s2")
MATCH_VARS = ANGLE_VARS + ("d1", "d2")
FOLD_TOL = 1e-10  # Newton on the augmented system stops when |dp| falls below this
BISECT_TOL = 1e-9  # bisection stops when the bracket is narrower than this
_CSTEP = 1e-20  # complex-step size: exact first derivatives of the real polynomial system


# --- branches -----------------------------------------------------------------------------


def _point_order(sweep: pd.DataFrame, param: str) -> list[tuple[object, float]]:
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
    out["branch"] = -1
    ls = _length_scale(sweep)
    key = "point" if "point" in sweep.columns else param
    history: dict[int, list[tuple[float, np.ndarray]]] = {}
    active: list[int] = []  # branches present at the previous point
    next_id = 0
    for pkey, value in _point_order(sweep, param):
        idx = sweep.index[(sweep[key] == pkey).to_numpy()]
        rows = sweep.loc[idx]
        if "solution_id" in rows.columns:
            rows = rows.sort_values("solution_id", kind="stable")
            idx = rows.index
        x = match_coordinates(rows, ls)
        good = np.isfinite(x[:, : len(ANGLE_VARS)]).all(axis=1)
        x, idx = x[good], idx[good]
        pred = np.array([_predict(history[b], value) for b in active]).reshape(-1, x.shape[1])
        cols = np.isfinite(x).all(axis=0) & np.isfinite(pred).all(axis=0)
        diff = np.abs(pred[:, None, cols] - x[None, :, cols])
        match = hungarian(np.sqrt((diff**2).sum(axis=2)))
        owner = -np.ones(len(x), dtype=int)
        for a, j in enumerate(match):
            if j >= 0:
                owner[j] = active[a]
        new_active = []
        for j in range(len(x)):
            b = int(owner[j])
            if b < 0:
                b, next_id = next_id, next_id + 1
                history[b] = []
            history[b].append((value, x[j]))
            new_active.append(b)
            out.loc[idx[j], "branch"] = b
        active = new_active
    out["branch"] = out["branch"].astype(int)
    return out


def _predict(hist: list[tuple[float, np.ndarray]], value: float) -> np.ndarray:
    """Secant extrapolation from a branch's last two points (constant from a single one)."""
    p1, x1 = hist[-1]
    if len(hist) < 2 or hist[-2][0] == p1:
        return x1
    p0, x0 = hist[-2]
    step = (x1 - x0) * ((value - p1) / (p1 - p0))
    return np.where(np.isfinite(step), x1 + step, x1)


# --- numerics on the polynomial system -----------------------------------------------------


@dataclass(frozen=True)
class _Structure:
    """The parametric system at a sweep point and how to instantiate it at a parameter value."""

    ps: ParametricSystem
    base: dict[str, float]
    param: str

    def system(self, value: complex) -> PolySystem:
        vals = {**self.base, self.param: value}
        return self.ps.instantiate([vals[n] for n in self.ps.parameters])

    def params(self, value: float) -> Params:
        return Params(**{**self.base, self.param: float(value)})


def _structure(base: Mapping[str, float], param: str, value: float) -> _Structure:
    params = Params(**{**dict(base), param: float(value)})
    return _Structure(parametric_system(params.zfl), params.as_dict(), param)


def _newton(system: PolySystem, x: np.ndarray, steps: int = 30) -> tuple[np.ndarray, bool]:
    """Real Newton on F(x) = 0 from x; (x, converged)."""
    x = np.asarray(x, dtype=float).copy()
    for _ in range(steps):
        f = system.evaluate(x)[0].real
        jac = system.jacobian(x)[0].real
        try:
            dx = np.linalg.solve(jac, f)
        except np.linalg.LinAlgError:
            dx = np.linalg.lstsq(jac, f, rcond=None)[0]
        if not np.isfinite(dx).all():
            return x, False
        x -= dx
        if np.abs(dx).max() <= 1e-13 * (1.0 + np.abs(x).max()):
            return x, True
    return x, False


def _fold_newton(
    st: _Structure, x: np.ndarray, v: np.ndarray, p: float, steps: int = 40
) -> tuple[np.ndarray, np.ndarray, float, float, bool]:
    """Newton in (x, v, p) on F = 0, J v = 0, r.v = 1 (r: the initial null vector)."""
    n = len(x)
    r = v / (v @ v)
    x, v = x.astype(float).copy(), v.astype(float).copy()
    last = np.inf
    for _ in range(steps):
        sys0 = st.system(p)
        sysh = st.system(p + 1j * _CSTEP)
        f = sys0.evaluate(x)[0].real
        jac = sys0.jacobian(x)[0].real
        jv = jac @ v
        # d(J v)/dx by complex steps in x; dF/dp and d(J v)/dp by a complex step in p.
        xs = x[None, :] + 1j * _CSTEP * np.eye(n)
        hess_v = (sys0.jacobian(xs) @ v).imag.T / _CSTEP
        jac_h = sysh.jacobian(x)[0]
        f_p = sysh.evaluate(x)[0].imag / _CSTEP
        jv_p = (jac_h @ v).imag / _CSTEP
        big = np.zeros((2 * n + 1, 2 * n + 1))
        big[:n, :n], big[:n, 2 * n] = jac, f_p
        big[n : 2 * n, :n], big[n : 2 * n, n : 2 * n], big[n : 2 * n, 2 * n] = hess_v, jac, jv_p
        big[2 * n, n : 2 * n] = r
        rhs = np.concatenate([f, jv, [r @ v - 1.0]])
        try:
            step = np.linalg.solve(big, rhs)
        except np.linalg.LinAlgError:
            step = np.linalg.lstsq(big, rhs, rcond=None)[0]
        if not np.isfinite(step).all():
            return x, v, p, np.inf, False
        x, v, p = x - step[:n], v - step[n : 2 * n], p - step[2 * n]
        last = abs(step[2 * n])
        if last < FOLD_TOL and np.abs(step).max() < 1e-9 * (1 + np.abs(x).max()):
            return x, v, p, last, True
    return x, v, p, last, False


def _angles(variables: tuple[str, ...], x: np.ndarray) -> tuple[float, float]:
    """(gamma1, gamma2) in degrees, [0, 360), of a real point."""
    i = {n: k for k, n in enumerate(variables)}
    g1 = np.degrees(np.arctan2(x[i["s1"]], x[i["c1"]])) % 360.0
    g2 = np.degrees(np.arctan2(x[i["s2"]], x[i["c2"]])) % 360.0
    return float(g1), float(g2)


def _hessian_eigs(st: _Structure, value: float, variables, x: np.ndarray) -> np.ndarray:
    g1, g2 = np.radians(_angles(variables, x))
    return np.linalg.eigvalsh(energy_hessian(st.params(value), g1, g2))[0]


def _row_x(row: pd.Series, variables: tuple[str, ...]) -> np.ndarray:
    return np.array([row[f"{v}_re"] + 1j * row[f"{v}_im"] for v in variables])


# --- events ----------------------------------------------------------------------------------


def find_events(
    sweep_with_branches: pd.DataFrame,
    param: str,
    base_params: Mapping[str, float] | Params,
    seed: int = 1,
) -> pd.DataFrame:
    """Folds, stability changes and physical changes between neighbouring points, refined."""
    sw = sweep_with_branches
    base = base_params.as_dict() if isinstance(base_params, Params) else dict(base_params)
    order = _point_order(sw, param)
    key = "point" if "point" in sw.columns else param
    by_point = {k: sw[sw[key] == k].set_index("branch", drop=False) for k, _ in order}
    events: list[dict] = []
    for (ka, pa), (kb, pb) in zip(order[:-1], order[1:], strict=True):
        A, B = by_point[ka], by_point[kb]
        sa, sb = _structure(base, param, pa), _structure(base, param, pb)
        if sa.ps.variables != sb.ps.variables:
            continue  # a change of structure (a free length reaching 0) is not an event
        common = [b for b in A.index if b in B.index and b >= 0]
        ra = {b: bool(A.loc[b, "is_real"]) for b in common}
        rb = {b: bool(B.loc[b, "is_real"]) for b in common}
        ctx = _Ctx(base, param, seed, sa, pa, pb, A, B)
        to_complex = [b for b in common if ra[b] and not rb[b]]
        to_real = [b for b in common if not ra[b] and rb[b]]
        for real_side, group in (("left", to_complex), ("right", to_real)):
            for pair in _conjugate_pairs(group, B if real_side == "left" else A, sa.ps.variables):
                events.extend(_fold_events(ctx, pair, real_side))
        for b in common:
            if ra[b] and rb[b]:
                events.extend(_along_branch_events(ctx, b))
    cols = [
        "kind",
        "branches",
        param,
        "gamma1_deg",
        "gamma2_deg",
        "refined",
        "residual",
        "bracket",
        "description",
        "lo",
        "hi",
        "variables",
        "x",
        "null_vector",
    ]
    frame = pd.DataFrame(events, columns=cols)
    return frame.sort_values([param, "kind", "branches"], kind="stable").reset_index(drop=True)


@dataclass(frozen=True)
class _Ctx:
    base: dict[str, float]
    param: str
    seed: int
    st: _Structure
    pa: float
    pb: float
    A: pd.DataFrame
    B: pd.DataFrame


def _conjugate_pairs(group: list[int], side: pd.DataFrame, variables) -> list[tuple[int, int]]:
    """Pair the branches of `group` whose points on the complex `side` are conjugates."""
    left = sorted(group)
    pairs = []
    while len(left) >= 2:
        best = None
        for i, a in enumerate(left):
            for b in left[i + 1 :]:
                xa, xb = _row_x(side.loc[a], variables), _row_x(side.loc[b], variables)
                gap = np.abs(xa - np.conj(xb)).max()
                if best is None or gap < best[0]:
                    best = (gap, a, b)
        _, a, b = best
        pairs.append((a, b))
        left = [c for c in left if c not in (a, b)]
    return pairs


def _label(row: pd.Series) -> str:
    if bool(row["physical"]):
        return f"{row['kind'] or 'physical'}"
    return str(row["reason"]) or "real"


def _fold_events(ctx: _Ctx, pair: tuple[int, int], real_side: str) -> list[dict]:
    """The fold where branches `pair` meet, refined; plus a stability change if one is lost."""
    a, b = pair
    variables = ctx.st.ps.variables
    R, C = (ctx.A, ctx.B) if real_side == "left" else (ctx.B, ctx.A)
    pr, pc = (ctx.pa, ctx.pb) if real_side == "left" else (ctx.pb, ctx.pa)
    xa_r, xb_r = _row_x(R.loc[a], variables).real, _row_x(R.loc[b], variables).real
    xa_c, xb_c = _row_x(C.loc[a], variables), _row_x(C.loc[b], variables)
    # Near a fold |x_a - x_b|^2 grows like |p - p*| on both sides: interpolate it to zero.
    dr, dc = np.sum((xa_r - xb_r) ** 2), np.sum(np.abs(xa_c - xb_c) ** 2)
    p0 = (dr * pc + dc * pr) / (dr + dc) if dr + dc > 0 else 0.5 * (pr + pc)
    t = (p0 - pr) / (pc - pr)
    x0 = (1 - t) * 0.5 * (xa_r + xb_r) + t * 0.5 * (xa_c + xb_c).real
    v0 = xa_r - xb_r
    v0 = v0 / np.linalg.norm(v0) if np.linalg.norm(v0) > 0 else np.eye(len(x0))[0]
    x, v, p, last, ok = _fold_newton(ctx.st, x0, v0, p0)
    lo, hi = min(ctx.pa, ctx.pb), max(ctx.pa, ctx.pb)
    margin = 1e-9 * max(1.0, abs(hi))
    system = ctx.st.system(p) if np.isfinite(p) else None
    if system is not None and np.isfinite(x).all():
        resid = float(np.abs(system.evaluate(x)[0] / system.scale()).max())
        resid = max(resid, float(np.abs(system.jacobian(x)[0] @ v).max() / system.scale().max()))
    else:
        resid = np.inf
    ok = bool(ok and lo - margin <= p <= hi + margin and resid < 1e-9)
    if not ok:
        x, v, p = x0, v0, p0
    g1, g2 = _angles(variables, x)
    la, lb = _label(R.loc[a]), _label(R.loc[b])
    side = "above" if pr > pc else "below"
    desc = (
        f"branches {a} ({la}) and {b} ({lb}) meet: real {side} {ctx.param} = {p:.10g}, "
        f"a complex-conjugate pair on the other side"
    )
    event = {
        "kind": "fold",
        "branches": f"{a}+{b}",
        ctx.param: p,
        "gamma1_deg": g1,
        "gamma2_deg": g2,
        "refined": ok,
        "residual": resid,
        "bracket": last,
        "description": desc,
        "lo": lo,
        "hi": hi,
        "variables": tuple(variables),
        "x": tuple(float(c) for c in x),
        "null_vector": tuple(float(c) for c in v),
    }
    out = [event]
    ra, rb = R.loc[a], R.loc[b]
    if bool(ra["physical"]) and bool(rb["physical"]) and bool(ra["stable"]) != bool(rb["stable"]):
        (s, ls), (u, lu) = ((a, la), (b, lb)) if bool(ra["stable"]) else ((b, lb), (a, la))
        eig = _hessian_eigs(ctx.st, p, variables, x) if ok else np.array([np.nan, np.nan])
        small = float(np.abs(eig).min() / np.abs(eig).max())
        out.append(
            {
                **event,
                "kind": "stability_change",
                "residual": small,
                "description": f"at the fold: the stable {ls} {s} and the {lu} {u} merge "
                "(an energy-Hessian eigenvalue is 0 there)",
            }
        )
    return out


def _along_branch_events(ctx: _Ctx, b: int) -> list[dict]:
    """Stability and physical changes along one branch that is real at both points."""
    ra, rb = ctx.A.loc[b], ctx.B.loc[b]
    variables = ctx.st.ps.variables
    out = []
    if bool(ra["physical"]) and bool(rb["physical"]) and not ra["singular"] and not rb["singular"]:
        ea = np.array([ra["hess_eig1"], ra["hess_eig2"]], float)
        eb = np.array([rb["hess_eig1"], rb["hess_eig2"]], float)
        if np.isfinite(ea).all() and np.isfinite(eb).all() and (np.sign(ea) != np.sign(eb)).any():
            j = int(np.flatnonzero(np.sign(ea) != np.sign(eb))[0])

            def eig(value: float, x: np.ndarray, j: int = j) -> float:
                return float(_hessian_eigs(ctx.st, value, variables, x)[j])

            p, x, width, ok, val = _bisect(ctx, ra, rb, eig)
            g1, g2 = _angles(variables, x)
            out.append(
                {
                    "kind": "stability_change",
                    "branches": str(b),
                    ctx.param: p,
                    "gamma1_deg": g1,
                    "gamma2_deg": g2,
                    "refined": ok,
                    "residual": abs(val),
                    "bracket": width,
                    "description": f"branch {b}: {ra['kind']} -> {rb['kind']} (Hessian "
                    f"eigenvalue {j + 1} changes sign)",
                    "lo": min(ctx.pa, ctx.pb),
                    "hi": max(ctx.pa, ctx.pb),
                    "variables": tuple(variables),
                    "x": tuple(float(c) for c in x),
                    "null_vector": None,
                }
            )
    for i in (1, 2):
        da, db = float(ra[f"d{i}"]), float(rb[f"d{i}"])
        if not (np.isfinite(da) and np.isfinite(db)) or np.sign(da) == np.sign(db):
            continue
        if f"d{i}" not in variables:
            continue
        k = variables.index(f"d{i}")

        def dval(value: float, x: np.ndarray, k: int = k) -> float:
            return float(x[k])

        p, x, width, ok, val = _bisect(ctx, ra, rb, dval)
        g1, g2 = _angles(variables, x)
        now = "becomes" if da < 0 else "stops being"
        out.append(
            {
                "kind": "physical_change",
                "branches": str(b),
                ctx.param: p,
                "gamma1_deg": g1,
                "gamma2_deg": g2,
                "refined": ok,
                "residual": abs(val),
                "bracket": width,
                "description": f"branch {b}: d{i} crosses 0, {now} physical",
                "lo": min(ctx.pa, ctx.pb),
                "hi": max(ctx.pa, ctx.pb),
                "variables": tuple(variables),
                "x": tuple(float(c) for c in x),
                "null_vector": None,
            }
        )
    return out


def _bisect(
    ctx: _Ctx, ra: pd.Series, rb: pd.Series, fn
) -> tuple[float, np.ndarray, float, bool, float]:
    """Bisection on fn(value, x) along a branch; the branch point at each midpoint is the
    Newton-corrected interpolation of the bracket's ends (a fresh solve if Newton fails)."""
    variables = ctx.st.ps.variables
    lo, hi = ctx.pa, ctx.pb
    xlo, xhi = _row_x(ra, variables).real, _row_x(rb, variables).real
    flo = fn(lo, xlo)
    ok = True
    while abs(hi - lo) > BISECT_TOL:
        mid = 0.5 * (lo + hi)
        x, conv = _newton(ctx.st.system(mid), 0.5 * (xlo + xhi))
        if not conv or np.abs(x - 0.5 * (xlo + xhi)).max() > 10 * np.abs(xhi - xlo).max() + 1e-6:
            x, conv = _resolve(ctx, mid, 0.5 * (xlo + xhi))
            if not conv:
                ok = False
                break
        fm = fn(mid, x)
        if np.sign(fm) == np.sign(flo):
            lo, xlo, flo = mid, x, fm
        else:
            hi, xhi = mid, x
    mid = 0.5 * (lo + hi)
    x, conv = _newton(ctx.st.system(mid), 0.5 * (xlo + xhi))
    return mid, x, abs(hi - lo), bool(ok and conv), fn(mid, x)


def _resolve(ctx: _Ctx, value: float, near: np.ndarray) -> tuple[np.ndarray, bool]:
    """The real solution nearest `near` at `value`, from a full parameter-homotopy solve."""
    from .sweep import solve_point

    table = solve_point(ctx.base, {ctx.param: value}, ctx.seed)
    table = table[table["is_real"]]
    if table.empty:
        return near, False
    variables = ctx.st.ps.variables
    xs = np.array([[r[f"{v}_re"] for v in variables] for _, r in table.iterrows()])
    j = int(np.argmin(np.abs(xs - near).max(axis=1)))
    return xs[j], True
