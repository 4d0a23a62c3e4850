"""Where V can have a local minimum, over boxes: the tests of a search for the stable
equilibria alone (`only="stable"`), from an enclosure [H] of V's Hessian over each box (every
taut set's Hessian the box allows: boxsearch.real_route, boxsearch.spheres).

- No minimum in a box: at a local minimum the Hessian is positive semidefinite, so for every
  direction v, v^T H v >= 0 there (where V is only once differentiable, at a cable reaching its
  free length, each one-sided second derivative along v is one taut set's v^T H v, held by the
  enclosure too). A direction along which v^T [H] v < 0 over the whole box leaves none in it.
  The directions tried are the axes (the diagonal of [H]) and the eigenvector of the smallest
  eigenvalue of [H]'s middle (the direction along which the box is most likely concave): the
  non-convexity test of interval global optimisation, with the most telling direction added.
- A proved minimum: a critical point proved alone in a box where [H] is positive definite
  (the smallest eigenvalue of [H]'s middle above the spectral norm of its radius, which bounds
  how far any matrix in [H] moves it: Weyl).
"""

from __future__ import annotations

import numpy as np

from ..model.intervals import Interval

EPS = np.finfo(float).eps


def no_minimum(H: Interval) -> np.ndarray:
    """(B,) True where no point of the box is a local minimum of V: some diagonal entry of the
    Hessian's enclosure [H] (B, n, n), or its quadratic form along the middle's softest
    eigenvector, is negative over the whole box."""
    if not len(H.lo):
        return np.zeros(0, dtype=bool)
    diagonal = (np.diagonal(H.hi, axis1=1, axis2=2) < 0).any(axis=1)
    with np.errstate(invalid="ignore", over="ignore"):
        mid = 0.5 * (H.lo + H.hi)
    ok = np.isfinite(mid).all(axis=(1, 2))
    v = np.zeros(mid.shape[:2])
    if ok.any():
        v[ok] = np.linalg.eigh(mid[ok])[1][:, :, 0]
    return diagonal | (ok & (_form_upper(H, v) < 0))


def _form_upper(H: Interval, v: np.ndarray) -> np.ndarray:
    """An upper bound of v^T H v over every H in [H], rounding included (each product v_i v_j
    and every sum a relative EPS off: bounded by (n^2 + 2) EPS sum |v_i v_j| max|H_ij|)."""
    c = v[:, :, None] * v[:, None, :]
    size = np.maximum(np.abs(H.lo), np.abs(H.hi))
    n = v.shape[1]
    with np.errstate(invalid="ignore", over="ignore"):
        top = np.maximum(c * H.lo, c * H.hi).sum(axis=(1, 2))
        pad = 4 * (n * n + 2) * EPS * (np.abs(c) * size).sum(axis=(1, 2))
    return np.where(np.isfinite(top + pad), top + pad, np.inf)


def positive_definite(H: Interval) -> np.ndarray:
    """(B,) True where every matrix in [H] (B, n, n) is positive definite: the middle's smallest
    eigenvalue (less its rounding) above the Frobenius norm of the radius (>= its spectral
    norm, by which any matrix in [H] moves the eigenvalues: Weyl)."""
    if not len(H.lo):
        return np.zeros(0, dtype=bool)
    mid, rad = 0.5 * (H.lo + H.hi), 0.5 * (H.hi - H.lo)
    ok = np.isfinite(mid).all(axis=(1, 2)) & np.isfinite(rad).all(axis=(1, 2))
    out = np.zeros(len(mid), dtype=bool)
    if ok.any():
        m = mid[ok]
        low = np.linalg.eigvalsh(m)[:, 0]
        size = np.linalg.norm(m, axis=(1, 2))
        # The middle and the eigenvalues are rounded: a few n EPS |M| more.
        slack = np.linalg.norm(rad[ok], axis=(1, 2)) + 8 * m.shape[1] * EPS * size
        out[ok] = low > slack
    return out
