"""Events between the points of a one-parameter sweep, refined.

`find_events` reads the branches for folds (and pitchforks: a pair meeting on a third branch),
stability changes and physical changes, and refines each one's parameter value: a fold by Newton
on the augmented system (folds.py); the others by bisection along the branch, Newton-correcting
the branch point at each midpoint. The table is screened as numpy arrays (point x branch) for
the intervals where a branch changes realness, a Hessian eigenvalue or a spring length changes
sign; only those intervals are read row by row.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..params import Params
from ..settings import Settings
from .folds import Structure, angles, fold_newton, hessian_eigs, newton, row_x, structure
from .matching import point_keys, point_order

Row = Mapping[str, object]  # one row of the sweep table: column -> value

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
    sweep_with_branches,
    param: str,
    base_params: Mapping[str, float] | Params,
    settings: Settings | Mapping | None = None,
):
    """Folds (and pitchforks), stability and physical changes between neighbouring points.

    Columns: kind, branches, the parameter (refined value), gamma1_deg, gamma2_deg at the event,
    refined, residual (fold: max |F|, |J v| relative to the coefficients; stability change:
    |eigenvalue| / max |eigenvalue| of the energy Hessian there; physical change: the larger of
    |d_i| and the relative |F| there), bracket (the accuracy of the value:
    last Newton step or bracket width), description, lo and hi (the sweep points around it), and
    the point itself: variables, x and (folds) the null vector v of J_x. `settings` are used only
    for a fresh solve where Newton cannot follow a branch during a bisection. Returns a DataFrame
    (`event_records` gives the same rows as dicts, without pandas).
    """
    import pandas as pd

    events = event_records(sweep_with_branches, param, base_params, settings)
    return pd.DataFrame(events, columns=event_columns(param))


def event_columns(param: str) -> list[str]:
    """The columns of events.csv for a sweep over `param`."""
    return EVENT_COLUMNS[:2] + [param] + EVENT_COLUMNS[2:]


def event_records(
    sweep_with_branches,
    param: str,
    base_params: Mapping[str, float] | Params,
    settings: Settings | Mapping | None = None,
) -> list[dict]:
    """The rows of `find_events` as dicts, sorted by the parameter, kind and branches.
    `sweep_with_branches`: a DataFrame or a mapping of numpy columns, with `branch`."""
    if settings is None:
        settings = Settings()
    elif not isinstance(settings, Settings):
        settings = Settings(**settings)
    sw = sweep_with_branches
    base = base_params.as_dict() if isinstance(base_params, Params) else dict(base_params)
    order = point_order(sw, param)
    grid = _Grid(sw, param, order)
    events: list[dict] = []
    for r in grid.candidates():
        (_, pa), (_, pb) = order[r], order[r + 1]
        st = structure(base, param, pa)
        if st.ps.variables != structure(base, param, pb).ps.variables:
            continue  # a change of structure (a free length reaching 0) is not an event
        A, B = grid.rows(r), grid.rows(r + 1)
        events.extend(_interval_events(_Ctx(base, param, settings, st, pa, pb, A, B)))
    nan_last = [(v[param] != v[param], v[param], v["kind"], v["branches"]) for v in events]
    return [events[k] for k in sorted(range(len(events)), key=nan_last.__getitem__)]


def _interval_events(ctx: _Ctx) -> list[dict]:
    """The events between two neighbouring points."""
    A, B = ctx.A, ctx.B
    common = [b for b in A if b in B and b >= 0]
    ra = {b: bool(A[b]["is_real"]) for b in common}
    rb = {b: bool(B[b]["is_real"]) for b in common}
    here: list[dict] = []
    for b in common:
        if ra[b] and rb[b]:
            here.extend(_along_branch_events(ctx, b))
    for real_side, group in (
        ("left", [b for b in common if ra[b] and not rb[b]]),
        ("right", [b for b in common if rb[b] and not ra[b]]),
    ):
        complex_side = B if real_side == "left" else A
        for pair in _conjugate_pairs(group, complex_side, ctx.st.ps.variables):
            third = [b for b in common if ra[b] and rb[b]]
            here.extend(_fold_events(ctx, pair, real_side, third, here))
    return here


class _Grid:
    """The sweep's rows indexed by (point in parameter order, branch), for the screening."""

    SCREENED = ("is_real", "hess_eig1", "hess_eig2", "d1", "d2")

    def __init__(self, sw, param: str, order: list[tuple[object, float]]):
        self.sw = sw
        self.columns = {n: np.asarray(sw[n]) for n in sw}
        keys, _ = point_keys(sw, param)
        rank = {k: r for r, (k, _) in enumerate(order)}
        row_rank = np.array([rank[k] for k in keys.tolist()], dtype=int)
        branch = np.asarray(sw["branch"], dtype=int)
        self.row_rank, self.branch = row_rank, branch
        width = int(branch.max()) + 1 if len(branch) else 0
        self.index = np.full((len(order), max(width, 1)), -1, dtype=int)
        rows = np.flatnonzero(branch >= 0)
        self.index[row_rank[rows], branch[rows]] = rows

    def _values(self, name: str) -> np.ndarray:
        col = np.asarray(self.sw[name], dtype=float)
        return np.where(self.index >= 0, col[self.index], np.nan)

    def candidates(self) -> list[int]:
        """The intervals (r, r + 1) where some branch present at both points changes realness,
        or, real at both, has a Hessian eigenvalue or a spring length change sign (or NaN)."""
        if len(self.index) < 2:
            return []
        have = self.index >= 0
        both = have[:-1] & have[1:]
        real = np.asarray(self.sw["is_real"], dtype=bool)[self.index] & have
        flips = both & (real[:-1] != real[1:])
        real_both = both & real[:-1] & real[1:]
        changes = np.zeros_like(flips)
        eig = [self._values(f"hess_eig{i}") for i in (1, 2)]
        finite = np.isfinite(eig[0]) & np.isfinite(eig[1])
        ok = finite[:-1] & finite[1:]
        for e in eig:
            changes |= ok & (np.sign(e[:-1]) != np.sign(e[1:]))
        for i in (1, 2):
            if f"d{i}" not in self.sw:
                continue
            d = self._values(f"d{i}")
            lo, hi = np.fmin(d[:-1], d[1:]), np.fmax(d[:-1], d[1:])
            changes |= np.isnan(d[:-1]) | np.isnan(d[1:]) | ((lo < 0) & (hi > 0))
        return np.flatnonzero((flips | (real_both & changes)).any(axis=1)).tolist()

    def rows(self, r: int) -> dict[int, Row]:
        """Point r's rows by branch (each a dict of its columns; branch -1 rows left out)."""
        rows = np.flatnonzero((self.row_rank == r) & (self.branch >= 0))
        return {int(self.branch[i]): {n: c[i] for n, c in self.columns.items()} for i in rows}


@dataclass(frozen=True)
class _Ctx:
    base: dict[str, float]
    param: str
    settings: Settings
    st: Structure
    pa: float
    pb: float
    A: dict[int, Row]  # the rows of the points on either side, by branch
    B: dict[int, Row]

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


def _conjugate_pairs(group: list[int], side: dict[int, Row], variables) -> list[tuple[int, int]]:
    """Pair the branches of `group` whose points on the complex `side` are conjugates."""
    left = sorted(group)
    pairs = []
    while len(left) >= 2:
        gaps = [
            (
                np.abs(row_x(side[a], variables) - np.conj(row_x(side[b], variables))).max(),
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


def _label(row: Row) -> str:
    if bool(row["physical"]):
        return str(row["kind"]) or "physical"
    return str(row["reason"]) if isinstance(row["reason"], str) and row["reason"] else "real"


def _refine_fold(
    ctx: _Ctx, R: dict[int, Row], C: dict[int, Row], pair: tuple[int, int], pr: float, pc: float
) -> tuple[np.ndarray, np.ndarray, float, float, bool, float]:
    """Newton on the augmented system from an interpolated start: (x, v, p, acc, ok, resid).

    When Newton fails or leaves the interval, the interpolated start is returned (not refined).
    """
    a, b = pair
    variables = ctx.st.ps.variables
    xa_r, xb_r = row_x(R[a], variables).real, row_x(R[b], variables).real
    xa_c, xb_c = row_x(C[a], variables), row_x(C[b], variables)
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
        step = row_x(ctx.B[c], variables).real - row_x(ctx.A[c], variables).real
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
    la, lb = _label(R[a]), _label(R[b])
    side, other = ("above", "below") if pr > pc else ("below", "above")
    kind, on = "fold", ""
    c = _pitchfork_branch(ctx, third, p, x)
    if c is not None:
        kind = "pitchfork"
        on = f" on branch {c} ({_label(ctx.A[c])} below, {_label(ctx.B[c])} above)"
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
    ra, rb = R[a], R[b]
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
    xa, xb = row_x(ctx.A[b], variables).real, row_x(ctx.B[b], variables).real
    t = (value - ctx.pa) / (ctx.pb - ctx.pa)
    return (1 - t) * xa + t * xb


def _along_branch_events(ctx: _Ctx, b: int) -> list[dict]:
    """Stability and physical changes along one branch that is real at both points."""
    ra, rb = ctx.A[b], ctx.B[b]
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
    xlo, xhi = row_x(ctx.A[b], variables).real, row_x(ctx.B[b], variables).real
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
