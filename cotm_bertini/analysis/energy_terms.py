"""The energy's gradient and Hessian in the angles, written from the one kinematics module for
any arithmetic: floats, numpy arrays, or python-flint balls (for proofs over boxes of angles).

V = sum_i 1/2 k_i (d_i - L0_i)^2 with d_i = |P_i(gamma)|. With P_i' = dP_i/dgamma_j:
    dV/dgamma_j = sum_i k_i (1 - L0_i / d_i) (P_i . P_ij)
    d2V/dgamma_j dgamma_l = sum_i k_i [ (L0_i / d_i^3) (P_i . P_ij)(P_i . P_il)
                                        + (1 - L0_i / d_i) (P_ij . P_il + P_i . P_ijl) ]
A zero-free-length spring (L0_i = 0) has no 1/d_i: its terms are polynomial and smooth.
"""

from __future__ import annotations

from typing import Any

from ..model.kinematics import dot, spring_jacobian, spring_second_derivatives, spring_vectors


def _spring_terms(p: Any, angles: tuple, hessian: bool) -> list[tuple]:
    """Per spring: (k, L0, P, (P1, P2), (P11, P12, P22) or None, d^2)."""
    vec = spring_vectors(p, *angles)
    out = []
    for i, (k, free) in ((1, (p.k1, p.L01)), (2, (p.k2, p.L02))):
        pv = vec[f"spring{i}"]
        first = spring_jacobian(p, i, *angles)
        second = spring_second_derivatives(p, i, *angles) if hessian else None
        # Squares, not a product: the enclosure of a ball's square is non-negative and tight.
        out.append((k, free, pv, first, second, pv[0] ** 2 + pv[1] ** 2))
    return out


def curvature(pv, first, second, j: int, m: int) -> Any:
    """B_jm = P_j . P_m + P . P_jm of one spring (`second` = (P_11, P_12, P_22))."""
    curv = ((second[0], second[1]), (second[1], second[2]))
    return dot(first[j], first[m]) + dot(pv, curv[j][m])


def gradient_hessian(p: Any, angles: tuple, sqrt, hessian: bool = True, zero: Any = 0.0):
    """(grad, Hessian or None) of V at c1, s1, c2, s2 = `angles`; `sqrt` of the arithmetic used.

    `p` holds the parameters in that arithmetic; L0_i == 0 exactly means zero free length.
    """
    grad = [zero, zero]
    hess = [[zero, zero], [zero, zero]] if hessian else None
    for k, free, pv, first, second, dd in _spring_terms(p, angles, hessian):
        zfl = free == 0
        ratio = zero if zfl else free / sqrt(dd)  # L0 / d
        weight = k * (1 - ratio)
        proj = [dot(pv, first[j]) for j in (0, 1)]
        for j in (0, 1):
            grad[j] = grad[j] + weight * proj[j]
        if hessian:
            for j in (0, 1):
                for m in (0, 1):
                    term = weight * curvature(pv, first, second, j, m)
                    if not zfl:
                        term = term + k * ratio / dd * proj[j] * proj[m]
                    hess[j][m] = hess[j][m] + term
    return grad, hess
