"""Newton refinement of endpoints, and snapping onto the closed-form d = 0 roots."""

from __future__ import annotations

import numpy as np

from ..model.artefacts import zero_length_points
from ..model.polynomial import PolySystem
from ..params import Params


def newton_refine(system: PolySystem, x: np.ndarray, steps: int) -> tuple[np.ndarray, np.ndarray]:
    """A few complex Newton steps, each kept only where it lowers the residual; a point whose
    step is at rounding level (or was not kept) is done: its next step would be the same."""
    x = np.array(x, dtype=complex)
    scale = system.scale()
    res = np.abs(system.evaluate(x) / scale).max(axis=1)
    active = np.arange(len(x))
    for _ in range(steps):
        xa = x[active]
        f, jac = system.value_and_jacobian(xa)
        step = np.zeros_like(xa)
        ok = np.isfinite(jac).all(axis=(1, 2))
        try:
            step[ok] = np.linalg.solve(jac[ok], f[ok][..., None])[..., 0]
        except np.linalg.LinAlgError:  # an exactly singular matrix: solve only the sound ones
            ok &= np.linalg.cond(jac) < 1e14
            step[ok] = np.linalg.solve(jac[ok], f[ok][..., None])[..., 0]
        # converged to rounding where no coordinate moves by more than 4e-14 relative
        ok &= np.isfinite(step).all(axis=1) & (np.abs(step) > 4e-14 * (1 + np.abs(xa))).any(axis=1)
        active, trial = active[ok], xa[ok] - step[ok]
        new = np.abs(system.evaluate(trial) / scale).max(axis=1) if len(trial) else res[:0]
        better = new < res[active]
        active = active[better]
        x[active], res[active] = trial[better], new[better]
        if not len(active):
            break
    return x, res


def snap_zero_length(
    params: Params, variables: tuple[str, ...], x: np.ndarray, radius: float
) -> tuple[np.ndarray, np.ndarray]:
    """Put endpoints within `radius` (normalised units) of a d = 0 artefact exactly there.

    An endgame only reaches such a double root to about the square root of its tolerance, and
    its two paths may end apart; the closed form knows the point exactly.
    """
    snapped = np.zeros(len(x), dtype=bool)
    exact = zero_length_points(params.normalized(), variables)
    if not len(exact) or not len(x):
        return x, snapped
    x = x.copy()
    for point in exact:
        near = np.abs(x - point).max(axis=1) < radius
        x[near] = point
        snapped |= near
    return x, snapped
