"""Inverse design: the free lengths that hold a chosen pose in equilibrium, and whether it is
then physical and stable.

With a_i = (P_i . dP_i/dgamma1, P_i . dP_i/dgamma2) (P_i the spring vector, d_i = |P_i|) the
equilibrium equations are k_1 (1 - L01/d_1) a_1 + k_2 (1 - L02/d_2) a_2 = 0: linear in the free
lengths. Where a_1 and a_2 are independent (almost every pose) the only solution is
L0_i = d_i: both springs relaxed, V = 0, a global minimum. Only on the curve a_1 x a_2 = 0 of the
torus (the springs' generalised forces parallel) can a pose be held by tensioned springs, and
there the free lengths form a line: one of them is the designer's to choose.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from types import SimpleNamespace

import numpy as np

from ...errors import ParameterError
from ...model.kinematics import dot, spring_jacobian, spring_vectors
from ...params import Params
from ..energy_terms import gradient_hessian

PARALLEL = 1e-9  # |a_1 x a_2| / (|a_1| |a_2|) below this: the pose is on the parallel curve
ZERO_LENGTH = 1e-9  # a spring shorter than this (relative to L3) has no direction

# Unit and meaning of each field of a Design (docs/columns.md, the design CSV).
FIELDS = {
    "gamma1_deg": ("deg", "rod angle, in [0, 360)"),
    "gamma2_deg": ("deg", "top body angle, in [0, 360)"),
    "L01": ("m", "free length of spring 1 holding the pose"),
    "L02": ("m", "free length of spring 2 holding the pose"),
    "d1": ("m", "length of spring 1 at the pose"),
    "d2": ("m", "length of spring 2 at the pose"),
    "family": ("", "relaxed (L0 = d, V = 0) or parallel (on the parallel curve)"),
    "physical": ("", "both free lengths >= 0"),
    "stable": ("", "physical and the energy Hessian positive definite"),
    "hess_eig_min": ("J/rad^2", "smallest eigenvalue of the energy Hessian"),
    "hess_eig_max": ("J/rad^2", "largest eigenvalue of the energy Hessian"),
    "grad_residual": ("J/rad", "|grad V| at the design: 0 up to rounding"),
}


def wrap_deg(angle: float) -> float:
    """An angle in degrees as the tool reports angles, in [0, 360)."""
    w = angle % 360.0
    return 0.0 if w >= 360.0 else w


def _number(name: str, value: object) -> float:
    """A finite float, or ParameterError naming the argument and the value."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.floating | np.integer):
        raise ParameterError(f"{name} = {value!r}: must be a number")
    if not math.isfinite(value):
        raise ParameterError(f"{name} = {value!r}: must be finite")
    return float(value)


@dataclass(frozen=True)
class Design:
    """Free lengths (m) holding pose (gamma1, gamma2) in equilibrium, and what the pose is then."""

    gamma1_deg: float
    gamma2_deg: float
    L01: float
    L02: float
    d1: float
    d2: float
    family: str  # "relaxed" (L0 = d, V = 0) or "parallel" (on the curve a_1 x a_2 = 0)
    physical: bool
    stable: bool
    hess_eig_min: float
    hess_eig_max: float
    grad_residual: float  # the norm of grad V at the design, by the energy code

    def as_dict(self) -> dict:
        """The CSV row."""
        return asdict(self)

    def as_toml(self) -> str:
        """The design as TOML, each value with its unit and meaning in a comment."""
        lines = []
        for name, value in self.as_dict().items():
            unit, meaning = FIELDS[name]
            text = repr(value) if isinstance(value, float) else str(value)
            text = text.lower() if isinstance(value, bool) else text
            text = f'"{value}"' if isinstance(value, str) else text
            lines.append(f"{name} = {text}  # {unit + ', ' if unit else ''}{meaning}")
        return "\n".join(lines)


def generalised_forces(params: Params, g1, g2) -> tuple[np.ndarray, np.ndarray]:
    """(a, d): a[i] = (P_i . dP_i/dgamma1, P_i . dP_i/dgamma2) and d[i] = |P_i|, for angles in
    radians (arrays broadcast; a has shape (2, 2, ...))."""
    g1, g2 = np.broadcast_arrays(np.asarray(g1, dtype=float), np.asarray(g2, dtype=float))
    angles = (np.cos(g1), np.sin(g1), np.cos(g2), np.sin(g2))
    vec = spring_vectors(params, *angles)
    a = np.zeros((2, 2, *g1.shape))
    d = np.zeros((2, *g1.shape))
    for i in (0, 1):
        pv = vec[f"spring{i + 1}"]
        jac = spring_jacobian(params, i + 1, *angles)
        d[i] = np.sqrt(dot(pv, pv))
        a[i] = np.stack([np.asarray(dot(pv, jac[j]), dtype=float) for j in (0, 1)])
    return a, d


def _sine(a: np.ndarray) -> np.ndarray:
    """a_1 x a_2 / (|a_1| |a_2|) of generalised forces `a`."""
    cross = a[0, 0] * a[1, 1] - a[0, 1] * a[1, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        return cross / (np.hypot(*a[0]) * np.hypot(*a[1]))


def parallel_sine(params: Params, g1, g2) -> np.ndarray:
    """a_1 x a_2 / (|a_1| |a_2|): zero on the curve where tensioned springs can hold the pose."""
    return _sine(generalised_forces(params, g1, g2)[0])


def parallel_cross(params: Params, g1, g2) -> np.ndarray:
    """a_1 x a_2: its zero set is the parallel curve."""
    a, _ = generalised_forces(params, g1, g2)
    return a[0, 0] * a[1, 1] - a[0, 1] * a[1, 0]


def design(
    params: Params,
    gamma1_deg: float,
    gamma2_deg: float,
    L01: float | None = None,
    L02: float | None = None,
) -> Design:
    """The free lengths holding the pose of `params`' geometry (its own L01, L02 unused) in
    equilibrium; on the parallel curve pass one of L01, L02. ParameterError where none exists.
    The angles are reported in [0, 360)."""
    if not isinstance(params, Params):
        raise ParameterError(f"params = {params!r}: expected a cb.Params")
    gamma1_deg = wrap_deg(_number("gamma1_deg", gamma1_deg))
    gamma2_deg = wrap_deg(_number("gamma2_deg", gamma2_deg))
    L01 = None if L01 is None else _number("L01", L01)
    L02 = None if L02 is None else _number("L02", L02)
    where = f"gamma1 = {gamma1_deg:.12g} deg, gamma2 = {gamma2_deg:.12g} deg"
    g1, g2 = math.radians(gamma1_deg), math.radians(gamma2_deg)
    a, d = generalised_forces(params, g1, g2)
    for i in (0, 1):
        if d[i] < ZERO_LENGTH * params.L3:
            raise ParameterError(
                f"{where}: spring {i + 1} has zero length there, so its pull has no direction"
            )
    if abs(float(_sine(a))) > PARALLEL:
        curve = parallel_curve(params, gamma1_deg) if (L01, L02) != (None, None) else []
        l0 = _relaxed(d, L01, L02, where, curve)
        family = "relaxed"
    else:
        l0 = _on_parallel_curve(params, a, d, L01, L02, where)
        family = "parallel"
    return _assess(params, gamma1_deg, gamma2_deg, l0, d, family)


def _relaxed(d: np.ndarray, L01, L02, where: str, curve: list[float]) -> np.ndarray:
    """L0 = d, refusing a given free length that differs (pointing to the parallel curve)."""
    hint = ""
    if curve:
        hint = "; at this gamma1 the curve passes gamma2 = " + ", ".join(f"{g:.9f}" for g in curve)
        hint += " deg"
    for i, given in enumerate((L01, L02)):
        if given is not None and abs(given - d[i]) > 1e-12 * max(1.0, d[i]):
            raise ParameterError(
                f"{where}: L0{i + 1}={given:.12g} cannot hold this pose: off the curve where the "
                f"springs' generalised forces are parallel, only relaxed springs can "
                f"(L01={d[0]:.12g} m, L02={d[1]:.12g} m){hint}"
            )
    return d.copy()


def _on_parallel_curve(params: Params, a, d, L01, L02, where: str) -> np.ndarray:
    """k1 (1 - l1) a1 + k2 (1 - l2) a2 = 0 with a2 = mu a1 (or a1 = 0): l_other from l_given."""
    if (L01 is None) == (L02 is None):
        raise ParameterError(
            f"{where}: the pose lies on the curve where the springs' generalised forces are "
            "parallel; its free lengths form a line, so pass exactly one of L01, L02"
        )
    k = (params.k1, params.k2)
    n1, n2 = np.hypot(*a[0]), np.hypot(*a[1])
    given = 0 if L01 is not None else 1
    value = L01 if L01 is not None else L02
    other = 1 - given
    ell = np.ones(2)
    ell[given] = value / d[given]
    # Weight of spring i's (1 - l_i) along the common direction of a_1 and a_2.
    u = a[0] / n1 if n1 >= n2 else a[1] / n2
    w = [k[i] * float(np.dot(a[i], u)) for i in (0, 1)]
    if abs(w[other]) <= PARALLEL * max(abs(w[0]), abs(w[1])):
        if abs(w[given] * (1 - ell[given])) > PARALLEL * max(abs(w[0]), abs(w[1])):
            raise ParameterError(
                f"{where}: spring {other + 1} exerts no generalised force here, so spring "
                f"{given + 1} must be relaxed (L0{given + 1}={d[given]:.12g} m)"
            )
        raise ParameterError(
            f"{where}: spring {other + 1} exerts no generalised force here: any L0{other + 1} "
            "holds the pose, so no unique design exists"
        )
    ell[other] = 1 + w[given] * (1 - ell[given]) / w[other]
    return ell * d


def _assess(params: Params, g1_deg: float, g2_deg: float, l0, d, family: str) -> Design:
    """Hessian eigenvalues and gradient at the design (the free lengths may be negative: a
    namespace, not a validated Params)."""
    p = SimpleNamespace(**{**params.as_dict(), "L01": float(l0[0]), "L02": float(l0[1])})
    g1, g2 = math.radians(g1_deg), math.radians(g2_deg)
    angles = (math.cos(g1), math.sin(g1), math.cos(g2), math.sin(g2))
    grad, hess = gradient_hessian(p, angles, math.sqrt)
    eig = np.linalg.eigvalsh(np.array(hess, dtype=float))
    physical = bool((np.asarray(l0) >= 0).all())
    tol = 1e-9 * float(np.abs(eig).max())
    return Design(
        g1_deg, g2_deg, float(l0[0]), float(l0[1]), float(d[0]), float(d[1]), family,
        physical, physical and bool(eig.min() > tol), float(eig.min()), float(eig.max()),
        float(np.hypot(*grad)),
    )  # fmt: skip


def parallel_roots(
    params: Params, fixed: np.ndarray, axis: int = 0, samples: int = 1440
) -> tuple[np.ndarray, np.ndarray]:
    """Points of the parallel curve: for each angle in `fixed` (rad; gamma1 if axis is 0, else
    gamma2) every root of a_1 x a_2 in the other angle, from sign changes on `samples` steps,
    bisected to rounding. Returns (fixed angle, root) arrays, one entry a root."""
    fixed = np.asarray(fixed, dtype=float)
    grid = np.linspace(-np.pi, np.pi, samples + 1)
    F, G = np.meshgrid(fixed, grid, indexing="ij")

    def cross(f, g):
        return parallel_cross(params, f, g) if axis == 0 else parallel_cross(params, g, f)

    vals = cross(F, G)
    i, j = np.nonzero(np.sign(vals[:, :-1]) != np.sign(vals[:, 1:]))
    lo, hi, flo, fix = grid[j], grid[j + 1], vals[i, j], fixed[i]
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        fm = cross(fix, mid)
        same = np.sign(fm) == np.sign(flo)
        lo, flo, hi = np.where(same, mid, lo), np.where(same, fm, flo), np.where(same, hi, mid)
    return fix, 0.5 * (lo + hi)


def parallel_curve(params: Params, gamma1_deg: float, samples: int = 1440) -> list[float]:
    """The gamma2 (degrees, in [0, 360), ascending) where the pose (gamma1, gamma2) is on the
    parallel curve."""
    _, roots = parallel_roots(params, np.array([math.radians(gamma1_deg)]), 0, samples)
    return sorted(wrap_deg(math.degrees(float(r))) for r in roots)
