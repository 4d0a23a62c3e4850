"""Events between the points of a one-parameter sweep, refined.

`find_events` reads the branches for folds (and pitchforks: a pair meeting on a third branch),
stability changes and physical changes, and refines each one's parameter value: a fold by Newton
on the augmented system (folds.py); the others by bisection along the branch, Newton-correcting
the branch point at each midpoint.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..params import Params
from ..settings import Settings
from .folds import Structure, angles, fold_newton, hessian_eigs, newton, row_x, structure
from .matching import point_order

BISECT_TOL = 1e-9  # bisection stops when the bracket is narrower than this


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
    settings: Settings | Mapping | None = None,
) -> pd.DataFrame:
    """Folds (and pitchforks), stability and physical changes between neighbouring points.

    Columns: kind, branches, the parameter (refined value), gamma1_deg, gamma2_deg at the event,
    refined, residual (fold: max |F|, |J v| relative to the coefficients; stability change:
    |eigenvalue| / max |eigenvalue| of the energy Hessian there; physical change: the larger of
    |d_i| and the relative |F| there), bracket (the accuracy of the value:
    last Newton step or bracket width), description, lo and hi (the sweep points around it), and
    the point itself: variables, x and (folds) the null vector v of J_x. `settings` are used only
    for a fresh solve where Newton cannot follow a branch during a bisection.
    """
    if settings is None:
        settings = Settings()
    elif not isinstance(settings, Settings):
        settings = Settings(**settings)
    sw = sweep_with_branches
    base = base_params.as_dict() if isinstance(base_params, Params) else dict(base_params)
    order = point_order(sw, param)
    key = "point" if "point" in sw.columns else param
    by_point = {k: sw[sw[key] == k].set_index("branch", drop=False) for k, _ in order}
    events: list[dict] = []
    for (ka, pa), (kb, pb) in zip(order[:-1], order[1:], strict=True):
        A, B = by_point[ka], by_point[kb]
        st = structure(base, param, pa)
        if st.ps.variables != structure(base, param, pb).ps.variables:
            continue  # a change of structure (a free length reaching 0) is not an event
        ctx = _Ctx(base, param, settings, st, pa, pb, A, B)
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
    settings: Settings
    st: Structure
    pa: float
    pb: float
    A: pd.DataFrame
    B: pd.DataFrame

    def event(self, kind: str, branches: str, value: float, x: np.ndarray, **info) -> dict:
        g1, g2 = angles(self.st.ps.variables, x)
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
                    row_x(side.loc[a], variables) - np.conj(row_x(side.loc[b], variables))
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


def _refine_fold(
    ctx: _Ctx, R: pd.DataFrame, C: pd.DataFrame, pair: tuple[int, int], pr: float, pc: float
) -> tuple[np.ndarray, np.ndarray, float, float, bool, float]:
    """Newton on the augmented system from an interpolated start: (x, v, p, acc, ok, resid).

    When Newton fails or leaves the interval, the interpolated start is returned (not refined).
    """
    a, b = pair
    variables = ctx.st.ps.variables
    xa_r, xb_r = row_x(R.loc[a], variables).real, row_x(R.loc[b], variables).real
    xa_c, xb_c = row_x(C.loc[a], variables), row_x(C.loc[b], variables)
    # Near a fold |x_a - x_b|^2 grows like |p - p*| on both sides: interpolate it to zero.
    dr, dc = np.sum((xa_r - xb_r) ** 2), np.sum(np.abs(xa_c - xb_c) ** 2)
    p0 = (dr * pc + dc * pr) / (dr + dc) if dr + dc > 0 else 0.5 * (pr + pc)
    t = (p0 - pr) / (pc - pr)
    x0 = (1 - t) * 0.5 * (xa_r + xb_r) + t * 0.5 * (xa_c + xb_c).real
    v0 = xa_r - xb_r
    v0 = v0 / np.linalg.norm(v0) if np.linalg.norm(v0) > 0 else np.eye(len(x0))[0]
    x, v, p, acc, ok = fold_newton(ctx.st, x0, v0, p0)
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
        return x0, v0, p0, acc, False, resid
    return x, v, p, acc, True, resid


def _pitchfork_branch(ctx: _Ctx, third: list[int], p: float, x: np.ndarray) -> int | None:
    """A third real branch through the meeting point (then the fold is a pitchfork), if any;
    e.g. where a branch passes through a configuration with both springs at their free lengths.
    """
    variables = ctx.st.ps.variables
    for c in third:
        xc = _interpolate(ctx, c, p)
        step = row_x(ctx.B.loc[c], variables).real - row_x(ctx.A.loc[c], variables).real
        if np.abs(xc - x).max() < max(1e-3, 0.1 * np.abs(step).max()):
            return c
    return None


def _fold_events(
    ctx: _Ctx, pair: tuple[int, int], real_side: str, third: list[int], along: list[dict]
) -> list[dict]:
    """The fold where branches `pair` meet, refined; a pitchfork if a third branch passes
    there; plus a stability change if the pair is a physical minimum and a saddle or maximum."""
    a, b = pair
    variables = ctx.st.ps.variables
    R, C = (ctx.A, ctx.B) if real_side == "left" else (ctx.B, ctx.A)
    pr, pc = (ctx.pa, ctx.pb) if real_side == "left" else (ctx.pb, ctx.pa)
    x, v, p, acc, ok, resid = _refine_fold(ctx, R, C, pair, pr, pc)
    la, lb = _label(R.loc[a]), _label(R.loc[b])
    side, other = ("above", "below") if pr > pc else ("below", "above")
    kind, on = "fold", ""
    c = _pitchfork_branch(ctx, third, p, x)
    if c is not None:
        kind = "pitchfork"
        on = f" on branch {c} ({_label(ctx.A.loc[c])} below, {_label(ctx.B.loc[c])} above)"
        for e in along:
            if e["kind"] == "stability_change" and e["branches"] == str(c) and ok:
                e[ctx.param], e["refined"], e["bracket"] = float(p), True, acc
                e["description"] += f", at the pitchfork {a}+{b}"
    desc = (
        f"branches {a} ({la}) and {b} ({lb}) meet{on}: real {side} {ctx.param} = {p:.10g}, "
        f"a complex-conjugate pair {other}"
    )
    event = ctx.event(
        kind, f"{a}+{b}", p, x, refined=ok, residual=resid, bracket=acc, description=desc,
        null_vector=tuple(float(c) for c in v),
    )  # fmt: skip
    out = [event]
    ra, rb = R.loc[a], R.loc[b]
    physical_pair = bool(ra["physical"]) and bool(rb["physical"])
    if kind == "fold" and physical_pair and bool(ra["stable"]) != bool(rb["stable"]):
        (s, ls), (u, lu) = ((a, la), (b, lb)) if bool(ra["stable"]) else ((b, lb), (a, la))
        eig = hessian_eigs(ctx.st, p, variables, x)
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
    xa, xb = row_x(ctx.A.loc[b], variables).real, row_x(ctx.B.loc[b], variables).real
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
            return float(hessian_eigs(ctx.st, value, variables, x)[j])

        p, x, width, ok, val = _bisect(ctx, b, eig)
        size = max(np.abs(hessian_eigs(ctx.st, p, variables, x)).max(), 1e-300)
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
    xlo, xhi = row_x(ctx.A.loc[b], variables).real, row_x(ctx.B.loc[b], variables).real
    flo = fn(lo, xlo)
    ok, resolves = True, 2
    while abs(hi - lo) > BISECT_TOL:
        mid = 0.5 * (lo + hi)
        guess = 0.5 * (xlo + xhi)
        reach = 10 * np.abs(xhi - xlo).max() + 1e-6
        x, conv = newton(ctx.st.system(mid), guess)
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
    """The real solution nearest `near` at `value`, from a full solve there."""
    from ..point import solve_point

    table = solve_point(Params(**{**ctx.base, ctx.param: value}), ctx.settings).table
    table = table[table["is_real"]]
    if table.empty:
        return near, False
    variables = ctx.st.ps.variables
    xs = table[[f"{v}_re" for v in variables]].to_numpy(float)
    return xs[int(np.argmin(np.abs(xs - near).max(axis=1)))], True
