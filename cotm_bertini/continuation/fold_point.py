"""A fold of a framework's one-parameter family on the real route, located in its chart angles:
Newton on the fold system

    grad V(theta, p) = 0,   H(theta, p) v = 0,   v0 . v = 1

in (theta, p, v), started from the pair of equilibria that meet there (their mean pose, the
softest eigenvector of the Hessian there). At a generic fold the system is regular, so Newton
converges quadratically to the fold itself, where a bisection of the parameter by full solves
needs some thirty of them. Its third derivatives are one central difference: the derivative of
H along v is d/de H(theta + e v), whose (i, j) entry is sum_k V_ijk v_k, the Jacobian of H v.

What this proves: nothing by itself. The sweep's event refinement (framework_events.py) places
a full, proved solve on either side of the located value; only those two place the bracket.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .charts import FD, ChartPlane

STEPS = 40
TOL = 1e-13  # a converged Newton step (rad, and relative in the parameter)
RESIDUAL = 1e-9  # |grad V| and |H v| (normalised units) at an accepted fold
ALONG = 1e-5  # the central difference of H along v (rad)


@dataclass(frozen=True)
class Fold:
    """A located fold: the parameter value, the chart point, the null vector of H there."""

    value: float
    theta: np.ndarray
    null: np.ndarray


def locate_fold(fw, param: str, cols: dict, rows, p_from: float, p_to: float) -> Fold | None:
    """The fold where the pair of equilibria `rows` of a solve's columns `cols` at `p_from`
    meets (or the one equilibrium meets its partner, where only minima were looked for), if
    Newton on the fold system converges to one no farther from p_from than p_to is, twice over;
    else None."""
    plane = ChartPlane(fw, param, param)  # one parameter: both of the plane's axes
    theta = plane.land(_at(p_from)).chart_points(cols)[np.asarray(rows)]
    a, b = theta[[0, -1]]
    step = _wrapped(b - a) if not hasattr(plane.land(_at(p_from)), "positions") else b - a
    start = a + 0.5 * step if np.abs(step).max() < 1.0 else a  # two charts apart: one of them
    return fold_newton(plane, start, p_from, p_to)


def fold_newton(plane: ChartPlane, start: np.ndarray, p_from: float, p_to: float) -> Fold | None:
    """Newton on the fold system of `plane` (one parameter: both its axes) from chart point
    `start` at p_from, the null vector started at H's softest eigenvector there: the fold, if
    it converges no farther from p_from than p_to is, twice over; else None."""
    _, H = plane.derivatives(start[None], _at(p_from))
    eig, vec = np.linalg.eigh(H[0])
    v0 = vec[:, np.argmin(np.abs(eig))]
    z = np.concatenate([start, [p_from], v0])
    n = len(start)
    for _ in range(STEPS):
        F, J = _system(plane, z, v0, n)
        if not np.isfinite(J).all():
            return None
        try:
            move = np.linalg.solve(J, F)
        except np.linalg.LinAlgError:
            return None
        z = z - move
        if abs(z[n] - p_from) > 2 * abs(p_to - p_from) or np.abs(move[:n]).max() > 1.0:
            return None  # wandered off: another fold, or none
        if np.abs(move).max() < TOL * max(1.0, abs(z[n])):
            break
    F, _ = _system(plane, z, v0, n)
    if not np.abs(F).max() < RESIDUAL:
        return None
    return Fold(float(z[n]), z[:n], z[n + 1 :])


def _at(p: float) -> np.ndarray:
    return np.array([p, p], dtype=float)


def _wrapped(d: np.ndarray) -> np.ndarray:
    """Angle differences brought into [-pi, pi)."""
    return (d + np.pi) % (2 * np.pi) - np.pi


def _system(plane: ChartPlane, z: np.ndarray, v0: np.ndarray, n: int) -> tuple:
    """The fold system's residual and Jacobian at z = (theta, p, v)."""
    theta, p, v = z[:n], float(z[n]), z[n + 1 :]
    g, H = (m[0] for m in plane.derivatives(theta[None], _at(p)))
    h = FD * (1.0 + abs(p))
    H_up = plane.derivatives(theta[None], _at(p + h))[1][0]
    H_down = plane.derivatives(theta[None], _at(p - h))[1][0]
    g_p = plane.grad_along(theta[None], _at(p), np.ones(2))[0]
    pair = np.stack([theta + ALONG * v, theta - ALONG * v])
    Hs = plane.derivatives(pair, _at(p))[1]
    D = (Hs[0] - Hs[1]) / (2 * ALONG)  # d(H v)/d theta
    J = np.zeros((2 * n + 1, 2 * n + 1))
    J[:n, :n], J[:n, n] = H, g_p
    J[n : 2 * n, :n], J[n : 2 * n, n], J[n : 2 * n, n + 1 :] = D, (H_up - H_down) @ v / (2 * h), H
    J[2 * n, n + 1 :] = v0
    F = np.concatenate([g, H @ v, [v0 @ v - 1.0]])
    return F, J
