"""Solving a point from a neighbouring real point whose solutions are all known.

Two routes, tried in order by `backends.target`: Newton's method from the neighbour's solutions
(`newton_continue`: a short step, accepted only when it provably found every nonsingular
solution), then a parameter homotopy along the short segment between the two points with a
complex detour (`continue_from`, Bertini). Each is checked; a failed check is reported, and the
caller solves the point from the generic set instead.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..errors import SolverError
from ..model.compiled import polynomial_system
from ..model.polynomial import ParametricSystem
from ..params import Params
from ..settings import Settings
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
)
from .render import parametric_texts, render_parameter_homotopy, render_system


@dataclass(frozen=True, eq=False)
class WarmStart:
    """A real parameter set with its complete set of nonsingular finite solutions (as many as
    the generic set has, in normalised units): a start for the next point of a sweep."""

    params: Params
    points: np.ndarray
    generic_key: str


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
    rep = TrackReport(tracked=len(pts), finite=len(rows), method="continued")
    info = {**rep.as_dict(), "method": "continued from the neighbouring point", "moved": free}
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


def _run_homotopy(sub, text: str, points, target: dict, settings: Settings, deadline):
    """Track `points` along the homotopy `text` in double precision with large steps."""
    bertini = _bertini()
    from bertini import nag_algorithm as na

    system = sub.instantiate([target[n] for n in sub.parameters])
    hom = bertini.parse.system(text)
    tgt = bertini.parse.system(render_system(system))
    solver = na.HomotopySolver(hom, list(points), tgt, mptype="double")
    _configure(solver, settings, "double", deadline)
    solver.set(**{k: bertini.multiprec.real_mp(v) for k, v in _CONTINUATION_STEPS.items()})
    solver.solve(show_progress=False)
    if deadline is not None and time.perf_counter() > deadline:
        raise SolverError(f"the in-process solve timed out after {settings.timeout:g} s")
    return solver.solution_metadata(), solver.all_solutions()


# --- Newton from the neighbour's solutions ---------------------------------------------------

NEWTON_ITERATIONS = 8
_CONVERGED = 1e-13  # last Newton step, relative to 1 + |x|
_RESIDUAL = 1e-12  # |f| relative to the coefficients
_DISTINCT = 1e-6  # two endpoints closer than this (relative) are one: not a complete set
_CONDITION = 1e8  # a Jacobian worse conditioned than this: not provably nonsingular


def newton_continue(
    ps: ParametricSystem, gs: GenericSet, warm: WarmStart, params: Params
) -> tuple[tuple | None, str]:
    """The solutions at `params` by Newton's method from the neighbour's, when provably complete.

    The first Newton step on the target system from a neighbour's solution is the Euler
    predictor of the homotopy between them. Accepted only if every one of the generic count N of
    starts converges to a root with a well-conditioned Jacobian and the N roots are distinct.
    No parameter value has more than N isolated nonsingular roots (each persists to nearby
    generic parameters, where there are N: the parameter continuation theorem), so these are all
    of them, whichever start led to which; the d = 0 roots are singular and computed in closed
    form. Returns ((endpoints, info, text), "") or (None, why it was refused).
    """
    if warm.generic_key != gs.key or len(warm.points) != len(gs.points):
        return None, "the previous point has another structure or an incomplete set"
    system = polynomial_system(params.normalized())
    x, size = _newton(system, np.array(warm.points, dtype=complex))
    if x is None:
        return None, "a singular Jacobian on the way"
    why, residual, cond = _newton_refusal(system, x, size)
    if why:
        return None, why
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


def _newton(system, x: np.ndarray) -> tuple[np.ndarray | None, np.ndarray]:
    """Newton's method on every point until its step is below _CONVERGED (relative), at most
    NEWTON_ITERATIONS times; only the points not yet converged are iterated."""
    size = np.full(len(x), np.inf)
    active = np.arange(len(x))
    with np.errstate(all="ignore"):
        for _ in range(NEWTON_ITERATIONS):
            xa = x[active]
            try:
                step = np.linalg.solve(system.jacobian(xa), system.evaluate(xa)[..., None])
            except np.linalg.LinAlgError:
                return None, size
            xa = xa - step[..., 0]
            x[active] = xa
            size[active] = np.abs(step[..., 0]).max(axis=1) / (1 + np.abs(xa).max(axis=1))
            keep = ~(size[active] < _CONVERGED)  # NaN stays active, and then fails the check
            if not keep.any() or not np.isfinite(size[active]).all():
                break
            active = active[keep]
    return x, size


def _newton_refusal(system, x: np.ndarray, size: np.ndarray) -> tuple[str, np.ndarray, np.ndarray]:
    """Why the Newton endpoints are not a provably complete set ('' when they are), with each
    endpoint's relative residual and Jacobian condition number."""
    nothing = np.zeros(0)
    if not np.isfinite(x).all() or not (size < _CONVERGED).all():
        return "Newton did not converge on every start", nothing, nothing
    # |f_i| relative to its coefficients and to the size of the point (degree d_i).
    grow = (1 + np.abs(x).max(axis=1))[:, None] ** np.array(system.degrees)[None, :]
    residual = (np.abs(system.evaluate(x)) / (system.scale() * grow)).max(axis=1)
    if residual.max() > _RESIDUAL:
        return "a Newton endpoint is not a root", residual, nothing
    gaps = np.abs(x[:, None, :] - x[None, :, :]).max(axis=2) / (1 + np.abs(x).max())
    np.fill_diagonal(gaps, np.inf)
    if gaps.min() < _DISTINCT:
        return "two starts converged to one root", residual, nothing
    cond = np.linalg.cond(system.jacobian(x))
    if (cond > _CONDITION).any():
        return "a root is nearly singular", residual, cond
    return "", residual, cond
