"""Numerics on the polynomial system along a sweep: Newton on a branch, and on a fold.

A fold is solved as the augmented system F(x, p) = 0, J_x(x, p) v = 0, r.v = 1 in (x, v, p);
first derivatives in p and of J v in x come from complex steps (exact for a real polynomial).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..model.compiled import energy_hessian, parametric_system
from ..model.polynomial import ParametricSystem, PolySystem
from ..params import Params

FOLD_TOL = 1e-10  # Newton on the augmented system stops when |dp| falls below this
_CSTEP = 1e-20  # complex-step size: exact first derivatives of the real polynomial system


@dataclass(frozen=True)
class Structure:
    """The parametric system at a sweep point and how to instantiate it at a parameter value."""

    ps: ParametricSystem
    base: dict[str, float]
    param: str

    def system(self, value: complex) -> PolySystem:
        vals = {**self.base, self.param: value}
        return self.ps.instantiate([vals[n] for n in self.ps.parameters])

    def params(self, value: float) -> Params:
        return Params(**{**self.base, self.param: float(value)})


def structure(base: Mapping[str, float], param: str, value: float) -> Structure:
    params = Params(**{**dict(base), param: float(value)})
    return Structure(parametric_system(params.zfl), params.as_dict(), param)


def newton(system: PolySystem, x: np.ndarray, steps: int = 12) -> tuple[np.ndarray, bool]:
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


def fold_newton(
    st: Structure, x: np.ndarray, v: np.ndarray, p: float, steps: int = 60
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


def angles(variables: tuple[str, ...], x: np.ndarray) -> tuple[float, float]:
    """(gamma1, gamma2) in degrees, [0, 360), of a real point."""
    i = {n: k for k, n in enumerate(variables)}
    g1 = np.degrees(np.arctan2(x[i["s1"]], x[i["c1"]])) % 360.0
    g2 = np.degrees(np.arctan2(x[i["s2"]], x[i["c2"]])) % 360.0
    return float(g1), float(g2)


def hessian_eigs(st: Structure, value: float, variables, x: np.ndarray) -> np.ndarray:
    g1, g2 = np.radians(angles(variables, x))
    return np.linalg.eigvalsh(energy_hessian(st.params(value), g1, g2))[0]


def row_x(row: Mapping[str, float], variables: tuple[str, ...]) -> np.ndarray:
    """A row's solver coordinates (the `<var>_re`, `<var>_im` columns) as a complex vector."""
    return np.array([row[f"{v}_re"] + 1j * row[f"{v}_im"] for v in variables])
