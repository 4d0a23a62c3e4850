"""Solving a point from a neighbouring real point whose solutions are all known.

Two routes, tried in order by `backends.target`: Newton's method from the neighbour's solutions
(`newton_continue`: a short step, accepted only when it provably found every nonsingular
solution), then a parameter homotopy along the short segment between the two points with a
complex detour (`continue_from`, Bertini). Each is checked; a failed check is reported, and the
caller solves the point from the generic set instead.
"""

from __future__ import annotations

import time
from collections.abc import Iterator, Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import SolverError
from ..model.compiled import polynomial_system
from ..model.pointsets import apart
from ..model.polynomial import ParametricSystem
from ..params import Params
from ..settings import Settings
from .crossings import solve as quiet_solve
from .endpoints import Endpoints
from .homotopy import (
    _SUCCESS,
    GenericSet,
    TrackReport,
    _bertini,
    _code,
    _configure,
    _crossing,
    endpoint_record,
    is_singular,
    solver_errors,
)
from .render import parametric_texts, render_parameter_homotopy, render_system


@dataclass(frozen=True, eq=False)
class WarmStart:
    """A real parameter set with its complete set of nonsingular finite solutions (as many as
    the generic set has, in normalised units): a start for the next point of a sweep. `before`:
    the point it was continued from and its solutions in the same order (for a secant
    prediction along a straight line of points), if it was."""

    params: Params | Mapping[str, float]  # a framework's: its normalised slots by name
    points: np.ndarray
    generic_key: str
    before: tuple[Params | Mapping[str, float], np.ndarray] | None = None

    def next_to(
        self, params: Params | Mapping[str, float], points: np.ndarray, key: str
    ) -> WarmStart:
        """`params` solved by continuing this start (its `points` in this start's order)."""
        before = (self.params, self.points) if len(points) == len(self.points) else None
        return WarmStart(params, points, key, before)


# --- continuation from a neighbouring real point ---------------------------------------------

# Continuation steps: the segment between neighbouring sweep points is short, so the tracker may
# take large steps (the checks below catch a path that jumps).
_CONTINUATION_STEPS = {"max_step_size": "0.5", "initial_step_size": "0.5"}


def continue_from(
    ps: ParametricSystem,
    gs: GenericSet,
    warm: WarmStart,
    params: Params,
    settings: Settings,
    deadline: float | None,
) -> tuple[tuple | None, str]:
    """The solutions at `params` continued from a neighbouring real point's complete set.

    Only the parameters that differ (in normalised units) move, from the warm point (t = 1) to
    the target (t = 0), with a random complex detour * t (1 - t) so the path misses the real
    folds between the two points (the gamma trick of parameter homotopies). Checked: every path
    ends finite, nonsingular and in success, and no two at the same point (a path that jumped):
    then they are the generic count of distinct nonsingular roots, all there are (see
    `newton_continue`). Returns ((endpoints, info, input text), "") or (None, why not).
    """
    a, b = warm.params.normalized(), params.normalized()
    if warm.generic_key != gs.key:
        return None, "the previous point has another structure"
    if len(warm.points) != len(gs.points):
        return None, "the previous point's solution set is incomplete"
    free = [n for n in ps.parameters if getattr(a, n) != getattr(b, n)]
    if not free:
        free = ps.parameters[:1]  # the same point: a loop through the complex plane
    fixed = tuple((n, getattr(b, n)) for n in ps.parameters if n not in free)
    sub, texts = _fixed_system(ps, gs.key, fixed)
    # Reproducible: the detour depends on the seed and the target only (hash of floats is stable).
    rng = np.random.default_rng(abs(hash((settings.seed, *(getattr(b, n) for n in free)))))
    start = {n: getattr(a, n) for n in free}
    target = {n: getattr(b, n) for n in free}
    scale = {n: abs(target[n] - start[n]) or 1e-3 for n in free}
    detour = {
        n: scale[n] * complex(rng.uniform(-0.5, 0.5), rng.choice([-1, 1]) * rng.uniform(0.5, 1))
        for n in free
    }
    text = render_parameter_homotopy(sub, start, target, detour, texts)
    meta, pts = _run_homotopy(sub, text, warm.points, target, settings, deadline)
    # A path double precision cannot finish (one ending next to a spring of length ~1e-4, where
    # the root is ill-conditioned) is tracked again in adaptive precision, as `track` does.
    redo = [i for i, m in enumerate(meta) if _code(m) != _SUCCESS or not m.is_finite]
    if redo:
        again = _run_homotopy(sub, text, warm.points[redo], target, settings, deadline, "adaptive")
        meta, pts = list(meta), list(pts)
        for i, m, p in zip(redo, *again, strict=True):
            meta[i], pts[i] = m, p
    rows, failed = [], 0
    for i, (m, p) in enumerate(zip(meta, pts, strict=True)):
        if _code(m) == _SUCCESS and m.is_finite:
            rows.append(endpoint_record(i, m, p))
        else:
            failed += 1
    results = {i: (m, p) for i, (m, p) in enumerate(zip(meta, pts, strict=True))}
    if failed:
        return None, f"{failed} paths did not end in success"
    if any(is_singular(m) for m in meta):
        return None, "a path ended at a singular point"
    if _crossing(results, list(results)):
        return None, "two paths ended at the same point"
    rep = TrackReport(len(pts), len(rows), retracked_adaptive=len(redo), method="continued")
    method = "continued from the neighbouring point" + (" + adaptive retrack" if redo else "")
    info = {**rep.as_dict(), "method": method, "moved": free}
    return (Endpoints.from_records(ps.variables, rows), info, text), ""


_FIXED: dict[tuple, tuple[ParametricSystem, tuple[str, ...]]] = {}


def _fixed_system(ps: ParametricSystem, key: str, fixed: tuple) -> tuple:
    """`ps` with the `fixed` parameters folded in, and its texts (kept: a sweep reuses them)."""
    if (key, fixed) not in _FIXED:
        if len(_FIXED) > 32:
            _FIXED.clear()
        sub = ps.fix(dict(fixed))
        _FIXED[key, fixed] = (sub, parametric_texts(sub))
    return _FIXED[key, fixed]


def _run_homotopy(
    sub, text: str, points, target: dict, settings: Settings, deadline, mptype: str = "double"
):
    """Track `points` along the homotopy `text` with large steps (in double precision, or
    `mptype`)."""
    bertini = _bertini()
    from bertini import nag_algorithm as na

    system = sub.instantiate([target[n] for n in sub.parameters])
    with solver_errors(f"the continuation from the neighbouring point ({len(points)} paths)"):
        hom = bertini.parse.system(text)
        tgt = bertini.parse.system(render_system(system))
        solver = na.HomotopySolver(hom, list(points), tgt, mptype=mptype)
        _configure(solver, settings, mptype, deadline, max([1.0, *map(abs, target.values())]))
        solver.set(**{k: bertini.multiprec.real_mp(v) for k, v in _CONTINUATION_STEPS.items()})
        quiet_solve(solver)
    if deadline is not None and time.perf_counter() > deadline:
        raise SolverError(f"the in-process solve timed out after {settings.timeout:g} s")
    return solver.solution_metadata(), solver.all_solutions()


# --- Newton from the neighbour's solutions ---------------------------------------------------

NEWTON_ITERATIONS = 20
_CONVERGED = 1e-13  # a point stops iterating when its last Newton step (relative) is below this
_ACCEPTED = 1e-10  # ... and is a root when its last step is below this (1e-4 of _DISTINCT: a
# root whose Jacobian is conditioned 1e4 cannot be located to 1e-13, yet it is one root)
_RESIDUAL = 1e-12  # |f| relative to the coefficients
_DISTINCT = 1e-6  # two endpoints closer than this (relative) are one: not a complete set
_CONDITION = 1e8  # a Jacobian worse conditioned than this: not provably nonsingular
_NEARLY_SINGULAR = "a root is nearly singular"
_SUBSTEPS = (2, 4)  # when one step fails: Newton along this many equal steps to the target,
_DETOUR_STEPS = 8  # then along this many steps of an arc into complex parameters (past folds)
_DETOUR = 0.5 + 0.5j  # the arc's largest excursion, relative to the step between the points


def newton_continue(
    ps: ParametricSystem, gs: GenericSet, warm: WarmStart, params: Params | Mapping[str, float]
) -> tuple[tuple | None, str]:
    """The solutions at `params` by Newton's method from the neighbour's, when provably complete.

    The first Newton step on the target system from a neighbour's solution is the Euler
    predictor of the homotopy between them. Accepted only if every one of the generic count N of
    starts converges to a root with a well-conditioned Jacobian and the N roots are distinct.
    No parameter value has more than N isolated nonsingular roots (each persists to nearby
    generic parameters, where there are N: the parameter continuation theorem), so these are all
    of them, whichever start led to which (or however the starts were chosen); the d = 0 roots
    are singular and computed in closed form. The starts: the neighbour's solutions, or, when
    the neighbour was itself continued from a point on the same line, their secant
    extrapolation; if those fail, Newton along 2, then 4, equal steps to the target. Returns
    ((endpoints, info, text), "") or (None, why the first attempt was refused).
    """
    if warm.generic_key != gs.key or len(warm.points) != len(gs.points):
        return None, "the previous point has another structure or an incomplete set"
    system = (
        polynomial_system(params.normalized())
        if isinstance(params, Params)
        else ps.instantiate(_normalised(ps, params))
    )
    first = ""
    for stages, start in _attempts(ps, warm, params):
        x, size = np.array(start, dtype=complex), None
        for stage in stages:
            x, size = _newton(system if stage is None else ps.instantiate(stage), x)
            if x is None:
                break
        why, residual, cond = (
            ("a singular Jacobian on the way", None, None)
            if x is None
            else _newton_refusal(system, x, size)
        )
        if not why:
            break
        first = first or why
        if why == _NEARLY_SINGULAR:  # N distinct roots, so every root: no attempt does better
            return None, first
    else:
        return None, first
    records = [
        {
            "path_number": i, "condition_number": cond[i], "function_residual": residual[i],
            "newton_residual": size[i], "final_t": 0.0, "accuracy_estimate": size[i],
            "cycle_number": 1, "bertini_multiplicity": 1, "coords": x[i],
        }
        for i in range(len(x))
    ]  # fmt: skip
    rep = TrackReport(tracked=len(x), finite=len(x), method="newton")
    info = {**rep.as_dict(), "method": "Newton from the neighbouring point (complete)"}
    return (Endpoints.from_records(ps.variables, records), info, ""), ""


def _attempts(ps: ParametricSystem, warm: WarmStart, params: Params) -> Iterator[tuple]:
    """The Newton attempts in order, made as they are asked for: (the parameter values,
    normalised, Newton is run at in turn, None for the target itself; the starts)."""
    secant = _secant(warm, params)
    yield [None], (warm.points if secant is None else secant)
    a, b = (_normalised(ps, q) for q in (warm.params, params))
    t = np.arange(1, _DETOUR_STEPS) / _DETOUR_STEPS
    yield [a + (b - a) * (s + 4 * _DETOUR * s * (1 - s)) for s in t] + [None], warm.points
    for k in _SUBSTEPS:
        yield [a + (b - a) * j / k for j in range(1, k)] + [None], warm.points


def _normalised(ps: ParametricSystem, params: Params | Mapping[str, float]) -> np.ndarray:
    """The values of `ps`'s parameters in normalised units: a Params (the paper's model), or a
    mapping of normalised values by name (a framework's slots)."""
    if isinstance(params, Params):
        params = params.normalized().as_dict()
    return np.array([params[n] for n in ps.parameters], dtype=float)


def _vector(params: Params | Mapping[str, float]) -> np.ndarray:
    """Every value of a parameter set, for the secant's line test."""
    values = params.as_dict() if isinstance(params, Params) else params
    return np.array(list(values.values()), dtype=float)


def _secant(warm: WarmStart, params: Params) -> np.ndarray | None:
    """The neighbour's solutions extrapolated along the line from the point before it, when the
    target lies on that line (a row of a grid, a 1-D sweep), else None."""
    if warm.before is None:
        return None
    before, points = warm.before
    p0, p1, p2 = (_vector(q) for q in (before, warm.params, params))
    back, ahead = p1 - p0, p2 - p1
    t = float(ahead @ back) / float(back @ back) if back.any() else 0.0
    if t <= 0 or not np.allclose(ahead, t * back, rtol=0, atol=1e-12 * (1 + np.abs(p2).max())):
        return None
    return warm.points + t * (warm.points - points)


def _newton(system, x: np.ndarray) -> tuple[np.ndarray | None, np.ndarray]:
    """Newton's method on every point until its step is below _CONVERGED (relative), or below
    _ACCEPTED and no longer halving (rounding: a root whose Jacobian is conditioned 1e4 never
    reaches _CONVERGED), at most NEWTON_ITERATIONS times; only the points not yet done are
    iterated."""
    size = np.full(len(x), np.inf)
    active = np.arange(len(x))
    with np.errstate(all="ignore"):
        for _ in range(NEWTON_ITERATIONS):
            xa = x[active]
            try:
                f, jac = system.value_and_jacobian(xa)
                step = np.linalg.solve(jac, f[..., None])
            except np.linalg.LinAlgError:
                return None, size
            xa = xa - step[..., 0]
            x[active] = xa
            before = size[active]
            size[active] = np.abs(step[..., 0]).max(axis=1) / (1 + np.abs(xa).max(axis=1))
            now = size[active]
            done = (now < _CONVERGED) | ((now < _ACCEPTED) & (now > before / 2))
            keep = ~done  # NaN stays active, and then fails the check
            if not keep.any() or not np.isfinite(size[active]).all():
                break
            active = active[keep]
    return x, size


def _newton_refusal(system, x: np.ndarray, size: np.ndarray) -> tuple[str, np.ndarray, np.ndarray]:
    """Why the Newton endpoints are not a provably complete set ('' when they are), with each
    endpoint's relative residual and Jacobian condition number."""
    nothing = np.zeros(0)
    if not np.isfinite(x).all() or not (size < _ACCEPTED).all():
        return "Newton did not converge on every start", nothing, nothing
    values, jac = system.value_and_jacobian(x)  # one pass: the Jacobian is asked for below
    # |f_i| relative to its coefficients and to the size of the point (degree d_i).
    grow = (1 + np.abs(x).max(axis=1))[:, None] ** np.array(system.degrees)[None, :]
    residual = (np.abs(values) / (system.scale() * grow)).max(axis=1)
    if residual.max() > _RESIDUAL:
        return "a Newton endpoint is not a root", residual, nothing
    if not apart(x, _DISTINCT * (1 + np.abs(x).max())):  # then compare every pair
        gaps = np.abs(x[:, None, :] - x[None, :, :]).max(axis=2) / (1 + np.abs(x).max())
        np.fill_diagonal(gaps, np.inf)
        if gaps.min() < _DISTINCT:
            return "two starts converged to one root", residual, nothing
    cond = np.linalg.cond(jac)
    if (cond > _CONDITION).any():
        return _NEARLY_SINGULAR, residual, cond
    return "", residual, cond
