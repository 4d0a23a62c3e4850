"""Solution branches of a one-parameter sweep, and the events between its points.

`assign_branches` joins the solutions of neighbouring sweep points into branches: a secant
predictor from each branch's last two points, then a one-to-one minimum-cost assignment (the
Hungarian algorithm) on the complex solver coordinates, so a branch goes on through a fold where
two real solutions become a complex-conjugate pair. `find_events` reads the branches for folds
(and pitchforks: a pair meeting on a third branch), stability changes and physical changes, and
refines each one's parameter value: a fold by Newton on the augmented system F(x, p) = 0,
J_x(x, p) v = 0, r.v = 1 in (x, v, p); the others by bisection along the branch,
Newton-correcting the branch point at each midpoint.
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
    branch = np.full(len(sweep), -1, dtype=int)
    ls = _length_scale(sweep)
    keys = sweep["point" if "point" in sweep.columns else param].to_numpy()
    sid = sweep["solution_id"].to_numpy() if "solution_id" in sweep.columns else None
    history: dict[int, list[tuple[float, np.ndarray]]] = {}
    active: list[int] = []  # branches present at the previous point
    next_id = 0
    for pkey, value in _point_order(sweep, param):
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


def _newton(system: PolySystem, x: np.ndarray, steps: int = 12) -> tuple[np.ndarray, bool]:
    """Real Newton on F(x) = 0 from x; (x, converged: relative residual below 1e-11)."""
    x = np.asarray(x, dtype=float).copy()
    scale = system.scale()
    for _ in range(steps):
        f = system.evaluate(x)[0].real
        if np.abs(f / scale).max() < 1e-14:
            break
        jac = system.jacobian(x)[0].real
        try:
            dx = np.linalg.solve(jac, f)
        except np.linalg.LinAlgError:
            dx = np.linalg.lstsq(jac, f, rcond=None)[0]
        if not np.isfinite(dx).all():
            return x, False
        x -= dx
    return x, bool(np.abs(system.evaluate(x)[0] / scale).max() < 1e-11)


def _fold_newton(
    st: _Structure, x: np.ndarray, v: np.ndarray, p: float, steps: int = 60
) -> tuple[np.ndarray, np.ndarray, float, float, bool]:
    """Newton in (x, v, p) on F = 0, J v = 0, r.v = 1 (r: the initial null vector).

    Returns (x, v, p, accuracy in p, converged). At a regular fold Newton converges
    quadratically and the accuracy is the last |dp|; where the augmented system is itself
    singular (a pitchfork) it stalls at a noise floor, and the accuracy is the spread of p over
    the last iterations.
    """
    n = len(x)
    r = v / (v @ v)
    x, v = x.astype(float).copy(), v.astype(float).copy()
    ps: list[float] = []
    for _ in range(steps):
        sys0 = st.system(p)
        sysh = st.system(p + 1j * _CSTEP)
        f = sys0.evaluate(x)[0].real
        jac = sys0.jacobian(x)[0].real
        # d(J v)/dx by complex steps in x; dF/dp and d(J v)/dp by a complex step in p.
        xs = x[None, :] + 1j * _CSTEP * np.eye(n)
        hess_v = (sys0.jacobian(xs) @ v).imag.T / _CSTEP
        jac_h = sysh.jacobian(x)[0]
        big = np.zeros((2 * n + 1, 2 * n + 1))
        big[:n, :n] = jac
        big[:n, 2 * n] = sysh.evaluate(x)[0].imag / _CSTEP
        big[n : 2 * n, :n] = hess_v
        big[n : 2 * n, n : 2 * n] = jac
        big[n : 2 * n, 2 * n] = (jac_h @ v).imag / _CSTEP
        big[2 * n, n : 2 * n] = r
        rhs = np.concatenate([f, jac @ v, [r @ v - 1.0]])
        try:
            step = np.linalg.solve(big, rhs)
        except np.linalg.LinAlgError:
            step = np.linalg.lstsq(big, rhs, rcond=None)[0]
        if not np.isfinite(step).all():
            return x, v, p, np.inf, False
        x, v, p = x - step[:n], v - step[n : 2 * n], p - step[2 * n]
        ps.append(p)
        if abs(step[2 * n]) < FOLD_TOL and np.abs(step).max() < 1e-9 * (1 + np.abs(x).max()):
            return x, v, p, abs(step[2 * n]), True
    spread = float(np.ptp(ps[-10:]))
    return x, v, p, spread, spread < 1e-8


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

EVENT_COLUMNS = [
    "kind",
    "branches",
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


def find_events(
    sweep_with_branches: pd.DataFrame,
    param: str,
    base_params: Mapping[str, float] | Params,
    seed: int = 1,
) -> pd.DataFrame:
    """Folds (and pitchforks), stability and physical changes between neighbouring points.

    Columns: kind, branches, the parameter (refined value), gamma1_deg, gamma2_deg at the event,
    refined, residual (fold: max |F|, |J v| relative to the coefficients; stability change:
    |eigenvalue| / max |eigenvalue| of the energy Hessian there; physical change: the larger of
    |d_i| and the relative |F| there), bracket (the accuracy of the value:
    last Newton step or bracket width), description, lo and hi (the sweep points around it), and
    the point itself: variables, x and (folds) the null vector v of J_x. `seed` is used only
    for a fresh solve where Newton cannot follow a branch during a bisection.
    """
    sw = sweep_with_branches
    base = base_params.as_dict() if isinstance(base_params, Params) else dict(base_params)
    order = _point_order(sw, param)
    key = "point" if "point" in sw.columns else param
    by_point = {k: sw[sw[key] == k].set_index("branch", drop=False) for k, _ in order}
    events: list[dict] = []
    for (ka, pa), (kb, pb) in zip(order[:-1], order[1:], strict=True):
        A, B = by_point[ka], by_point[kb]
        st = _structure(base, param, pa)
        if st.ps.variables != _structure(base, param, pb).ps.variables:
            continue  # a change of structure (a free length reaching 0) is not an event
        ctx = _Ctx(base, param, seed, st, pa, pb, A, B)
        common = [b for b in A.index if b in B.index and b >= 0]
        ra = {b: bool(A.loc[b, "is_real"]) for b in common}
        rb = {b: bool(B.loc[b, "is_real"]) for b in common}
        here: list[dict] = []
        for b in common:
            if ra[b] and rb[b]:
                here.extend(_along_branch_events(ctx, b))
        for real_side, group in (
            ("left", [b for b in common if ra[b] and not rb[b]]),
            ("right", [b for b in common if rb[b] and not ra[b]]),
        ):
            complex_side = B if real_side == "left" else A
            for pair in _conjugate_pairs(group, complex_side, st.ps.variables):
                third = [b for b in common if ra[b] and rb[b]]
                here.extend(_fold_events(ctx, pair, real_side, third, here))
        events.extend(here)
    frame = pd.DataFrame(events, columns=EVENT_COLUMNS[:2] + [param] + EVENT_COLUMNS[2:])
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

    def event(self, kind: str, branches: str, value: float, x: np.ndarray, **info) -> dict:
        g1, g2 = _angles(self.st.ps.variables, x)
        return {
            "kind": kind,
            "branches": branches,
            self.param: float(value),
            "gamma1_deg": g1,
            "gamma2_deg": g2,
            "lo": min(self.pa, self.pb),
            "hi": max(self.pa, self.pb),
            "variables": tuple(self.st.ps.variables),
            "x": tuple(float(c) for c in x),
            "null_vector": None,
            **info,
        }


def _conjugate_pairs(group: list[int], side: pd.DataFrame, variables) -> list[tuple[int, int]]:
    """Pair the branches of `group` whose points on the complex `side` are conjugates."""
    left = sorted(group)
    pairs = []
    while len(left) >= 2:
        gaps = [
            (
                np.abs(
                    _row_x(side.loc[a], variables) - np.conj(_row_x(side.loc[b], variables))
                ).max(),
                a,
                b,
            )
            for i, a in enumerate(left)
            for b in left[i + 1 :]
        ]
        _, a, b = min(gaps)
        pairs.append((a, b))
        left = [c for c in left if c not in (a, b)]
    return pairs


def _label(row: pd.Series) -> str:
    if bool(row["physical"]):
        return str(row["kind"]) or "physical"
    return str(row["reason"]) if isinstance(row["reason"], str) and row["reason"] else "real"


def _fold_events(
    ctx: _Ctx, pair: tuple[int, int], real_side: str, third: list[int], along: list[dict]
) -> list[dict]:
    """The fold where branches `pair` meet, refined; a pitchfork if a third branch passes
    there; plus a stability change if the pair is a physical minimum and a saddle or maximum."""
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
    x, v, p, acc, ok = _fold_newton(ctx.st, x0, v0, p0)
    lo, hi = min(ctx.pa, ctx.pb), max(ctx.pa, ctx.pb)
    margin = 1e-9 * max(1.0, abs(hi))
    resid = np.inf
    if np.isfinite(p) and np.isfinite(x).all() and np.isfinite(v).all():
        system = ctx.st.system(p)
        scale = system.scale()
        resid = float(
            max(
                np.abs(system.evaluate(x)[0] / scale).max(),
                np.abs(system.jacobian(x)[0] @ v).max() / scale.max(),
            )
        )
    ok = bool(ok and lo - margin <= p <= hi + margin and resid < 1e-9)
    if not ok:
        x, v, p = x0, v0, p0
    la, lb = _label(R.loc[a]), _label(R.loc[b])
    side, other = ("above", "below") if pr > pc else ("below", "above")
    kind, on = "fold", ""
    # A third real branch through the meeting point makes it a pitchfork (e.g. where a branch
    # passes through a configuration with both springs at their free lengths).
    for c in third:
        xc = _interpolate(ctx, c, p)
        near = max(
            1e-3,
            0.1
            * np.abs(
                _row_x(ctx.B.loc[c], variables).real - _row_x(ctx.A.loc[c], variables).real
            ).max(),
        )
        if np.abs(xc - x).max() < near:
            kind = "pitchfork"
            on = f" on branch {c} ({_label(ctx.A.loc[c])} below, {_label(ctx.B.loc[c])} above)"
            for e in along:
                if e["kind"] == "stability_change" and e["branches"] == str(c) and ok:
                    e.update(
                        {
                            ctx.param: float(p),
                            "refined": True,
                            "bracket": acc,
                            "description": e["description"] + f", at the pitchfork {a}+{b}",
                        }
                    )
            break
    desc = (
        f"branches {a} ({la}) and {b} ({lb}) meet{on}: real {side} {ctx.param} = {p:.10g}, "
        f"a complex-conjugate pair {other}"
    )
    event = ctx.event(
        kind,
        f"{a}+{b}",
        p,
        x,
        refined=ok,
        residual=resid,
        bracket=acc,
        description=desc,
        null_vector=tuple(float(c) for c in v),
    )
    out = [event]
    ra, rb = R.loc[a], R.loc[b]
    if (
        kind == "fold"
        and bool(ra["physical"])
        and bool(rb["physical"])
        and (bool(ra["stable"]) != bool(rb["stable"]))
    ):
        (s, ls), (u, lu) = ((a, la), (b, lb)) if bool(ra["stable"]) else ((b, lb), (a, la))
        eig = _hessian_eigs(ctx.st, p, variables, x)
        out.append(
            {
                **event,
                "kind": "stability_change",
                "residual": float(np.abs(eig).min() / np.abs(eig).max()),
                "description": f"at the fold: the stable {ls} {s} and the {lu} {u} merge "
                "(an energy-Hessian eigenvalue is 0 there; residual: |eig| / max |eig|)",
            }
        )
    return out


def _interpolate(ctx: _Ctx, b: int, value: float) -> np.ndarray:
    """Branch b's real point at `value`, linear between the interval's ends."""
    variables = ctx.st.ps.variables
    xa, xb = _row_x(ctx.A.loc[b], variables).real, _row_x(ctx.B.loc[b], variables).real
    t = (value - ctx.pa) / (ctx.pb - ctx.pa)
    return (1 - t) * xa + t * xb


def _along_branch_events(ctx: _Ctx, b: int) -> list[dict]:
    """Stability and physical changes along one branch that is real at both points."""
    ra, rb = ctx.A.loc[b], ctx.B.loc[b]
    variables = ctx.st.ps.variables
    out = []
    ea = np.array([ra["hess_eig1"], ra["hess_eig2"]], float)
    eb = np.array([rb["hess_eig1"], rb["hess_eig2"]], float)
    if np.isfinite(ea).all() and np.isfinite(eb).all() and (np.sign(ea) != np.sign(eb)).any():
        j = int(np.flatnonzero(np.sign(ea) != np.sign(eb))[0])

        def eig(value: float, x: np.ndarray) -> float:
            return float(_hessian_eigs(ctx.st, value, variables, x)[j])

        p, x, width, ok, val = _bisect(ctx, b, eig)
        size = max(np.abs(_hessian_eigs(ctx.st, p, variables, x)).max(), 1e-300)
        out.append(
            ctx.event(
                "stability_change",
                str(b),
                p,
                x,
                refined=ok,
                residual=abs(val) / size,
                bracket=width,
                description=f"branch {b}: {ra['kind']} -> {rb['kind']} (energy-Hessian eigenvalue "
                f"{j + 1} changes sign)",
            )
        )
    for i in (1, 2):
        da, db = float(ra[f"d{i}"]), float(rb[f"d{i}"])
        if f"d{i}" not in variables or not (min(da, db) < 0 < max(da, db)):
            continue
        k = variables.index(f"d{i}")

        def dval(value: float, x: np.ndarray, k: int = k) -> float:
            return float(x[k])

        p, x, width, ok, val = _bisect(ctx, b, dval)
        system = ctx.st.system(p)
        resid = max(
            abs(val) / (1 + np.abs(x).max()), np.abs(system.evaluate(x)[0] / system.scale()).max()
        )
        now = "becomes" if da < db else "stops being"
        out.append(
            ctx.event(
                "physical_change",
                str(b),
                p,
                x,
                refined=ok,
                residual=resid,
                bracket=width,
                description=f"branch {b}: d{i} crosses 0 ({now} physical as {ctx.param} grows; "
                "the spring's ends coincide there)",
            )
        )
    return out


def _bisect(ctx: _Ctx, b: int, fn) -> tuple[float, np.ndarray, float, bool, float]:
    """Bisection on the sign of fn(value, x) along branch b between the interval's ends.

    The branch point at each midpoint is the Newton-corrected interpolation of the bracket's
    ends; if Newton fails or jumps to another branch, a fresh parameter-homotopy solve there
    (at most twice), else the bisection stops (not refined). Returns (value, x, bracket width,
    refined, fn there).
    """
    variables = ctx.st.ps.variables
    lo, hi = ctx.pa, ctx.pb
    xlo, xhi = _row_x(ctx.A.loc[b], variables).real, _row_x(ctx.B.loc[b], variables).real
    flo = fn(lo, xlo)
    ok, resolves = True, 2
    while abs(hi - lo) > BISECT_TOL:
        mid = 0.5 * (lo + hi)
        guess = 0.5 * (xlo + xhi)
        reach = 10 * np.abs(xhi - xlo).max() + 1e-6
        x, conv = _newton(ctx.st.system(mid), guess)
        if not conv or np.abs(x - guess).max() > reach:
            conv = False
            if resolves:
                resolves -= 1
                x, conv = _resolve(ctx, mid, guess)
                conv = conv and np.abs(x - guess).max() <= reach
        if not conv:
            ok = False
            break
        fm = fn(mid, x)
        if np.sign(fm) == np.sign(flo):
            lo, xlo, flo = mid, x, fm
        else:
            hi, xhi = mid, x
    # The value: the midpoint of the final bracket, or (when the bisection had to stop early,
    # e.g. where the branch runs into a singular root) the secant estimate inside it.
    fhi = fn(hi, xhi)
    t = 0.5 if ok or not np.isfinite([flo, fhi]).all() or flo == fhi else flo / (flo - fhi)
    t = min(max(t, 0.0), 1.0)
    x = (1 - t) * xlo + t * xhi
    value = lo + t * (hi - lo)
    return value, x, abs(hi - lo), ok, fn(value, x)


def _resolve(ctx: _Ctx, value: float, near: np.ndarray) -> tuple[np.ndarray, bool]:
    """The real solution nearest `near` at `value`, from a full parameter-homotopy solve."""
    from .sweep import solve_point

    table = solve_point(ctx.base, {ctx.param: value}, ctx.seed)
    table = table[table["is_real"]]
    if table.empty:
        return near, False
    variables = ctx.st.ps.variables
    xs = table[[f"{v}_re" for v in variables]].to_numpy(float)
    return xs[int(np.argmin(np.abs(xs - near).max(axis=1)))], True
