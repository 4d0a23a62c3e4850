"""Boxes through the zero-length poses of a spring (the cone sets of V) decided, not set aside.

Where a spring with free length L0 > 0 may reach length 0 over a box, V is A's potential minus
k L0 d there, A smooth (the rest of V and k/2 d^2) and d = |r| not: grad V = A - k L0 J^T u,
u = r/d a unit vector, J = dr/dangle. A critical point, smooth (d > 0) or in Clarke's sense
(d = 0: A = J^T lambda, |lambda| <= k L0, the cone a maximum across the cone set), needs
A = k L0 J^T v with |v| <= 1 (v = u, |u| = 1, where d > 0). With P the pseudo-inverse of J's
midpoint transposed and N its null space, over a box:

- N A must meet k L0 (N J^T) v: where it misses, no critical point (the box is excluded);
- P A / (k L0) = (P J^T) v with P J^T = I + E: |v| lies within |P A| / (k L0) (1 -+ |E|);
  all above 1: none; all below 1: no smooth critical point, and every pose of the box at
  zero length where A is in the range of J^T is a Clarke critical point;
- those are the zeros of the Lagrange system G(angles, lambda) = (A - J^T lambda, r), with
  lambda within k L0 (P A / (k L0) +- |E| |v|): the Krawczyk test proves exactly one (a cone
  point) or none in the box.

A cone point's kind: V falls in every direction across the cone set (|lambda| < k L0), so its
index is dim plus that of the Lagrangian's Hessian along the cone set (A's minus lambda . d2r).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.intervals import Interval
from .krawczyk import krawczyk_step

CONE_RATIO = 2.0  # a box is tested at its spring's cone where d's least value < this x its spread
ROUND = 1e-12  # relative slack on norms computed in floating point


@dataclass(frozen=True)
class ConeParts:
    """A landscape's enclosures over boxes about one spring each at zero length."""

    A: Interval  # (B, n): grad V + k L0 J^T u, the gradient of all of V but -k L0 d
    J: Interval  # (B, dim, n): dr/dangle of the spring
    r: Interval  # (B, dim): the spring's vector
    kl0: np.ndarray  # (B,): k L0 of the spring
    H: Interval  # (B, n, n): a slope matrix of A
    R2: Interval  # (B, dim, n, n): d2r/dangle2


def near_cone(dd: Interval) -> tuple[np.ndarray, np.ndarray]:
    """(whether each box is tested at a spring's cone, which spring): the spring whose least
    length over the box is smallest against its spread there (the 1/d terms of the smooth
    test blow up), where that is below CONE_RATIO."""
    d = dd.sqrt()
    ratio = d.lo / np.maximum(d.hi - d.lo, 1e-300)
    spring = np.argmin(ratio, axis=1)
    return np.take_along_axis(ratio, spring[:, None], axis=1)[:, 0] < CONE_RATIO, spring


def _matvec(m: np.ndarray, v: Interval) -> Interval:
    """m (B, a, b) numbers times v (B, b): (B, a)."""
    return (Interval(m) * Interval(v.lo[:, None, :], v.hi[:, None, :])).isum(axis=2)


def _mag2(v: Interval, axis) -> np.ndarray:
    """The largest sum of squares over v along `axis`."""
    return np.square(np.maximum(np.abs(v.lo), np.abs(v.hi))).sum(axis=axis)


def _frames(J: Interval) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(ok, P, N) per box: P = pinv(mid J^T) (dim, n), N the null space of mid J (n - dim, n)."""
    Jm = J.mid
    dim = Jm.shape[1]
    ok = np.isfinite(Jm).all(axis=(1, 2))
    U, S, Vt = np.linalg.svd(np.where(ok[:, None, None], Jm, 1.0))
    ok &= S[:, -1] > 1e-9 * np.maximum(S[:, 0], 1e-300)
    S = np.where(ok[:, None], S, 1.0)
    return ok, U @ (Vt[:, :dim, :] / S[:, :, None]), Vt[:, dim:, :]


def cone_test(land, lo: np.ndarray, hi: np.ndarray, spring: np.ndarray) -> tuple:
    """(verdict, found) over boxes with each one spring at its cone (module docstring):
    verdict -1 no critical point of V in the box, 1 exactly one, a cone point, and no other,
    0 unknown; found the cone points (rows of the boxes with verdict 1): (angles (k, n),
    lambda (k, dim), index (k,))."""
    p = land.cone_parts(Interval(lo, hi), spring)
    count, dim, n = p.J.lo.shape
    ok, P, N = _frames(p.J)
    ok &= p.A.finite().all(axis=1) & (p.kl0 > 0)
    kl0 = np.where(p.kl0 > 0, p.kl0, 1.0)
    z = _matvec(P, p.A) * (1.0 / kl0)[:, None]
    E = (Interval(P[:, :, None, :]) * Interval(p.J.lo[:, None], p.J.hi[:, None])).isum(axis=3)
    E = E - np.eye(dim)
    e = np.sqrt(_mag2(E, (1, 2))) * (1 + ROUND)
    mig = np.where(z.contains_zero(), 0.0, np.minimum(np.abs(z.lo), np.abs(z.hi)))
    z_lo, z_hi = np.sqrt((mig**2).sum(axis=1)), np.sqrt(_mag2(z, 1))
    ok &= e < 1
    verdict = np.where(ok & (z_lo * (1 - ROUND) > 1 + e), -1, 0)
    if n > dim:  # across the cone set's tangent: A's part there against what J^T v can give
        NA = _matvec(N, p.A)
        S = (Interval(N[:, :, None, :]) * Interval(p.J.lo[:, None], p.J.hi[:, None])).isum(3)
        bound = kl0[:, None] * np.sqrt(_mag2(S, 2)) * (1 + ROUND)
        verdict[ok & ((NA.lo > bound) | (NA.hi < -bound)).any(axis=1)] = -1
    at = np.flatnonzero(ok & (verdict == 0) & (z_hi * (1 + ROUND) < 1 - e))
    empty = (np.zeros((0, n)), np.zeros((0, dim)), np.zeros(0, dtype=np.int64))
    if not len(at):
        return verdict, empty, at
    rho = z_hi[at] / (1 - e[at]) * (1 + ROUND)
    pad = (e[at] * rho * (1 + ROUND))[:, None]
    v = Interval(np.maximum(z.lo[at] - pad, -rho[:, None]), np.minimum(z.hi[at] + pad,
                                                                       rho[:, None]))  # fmt: skip
    lam = v * Interval(kl0[at, None])  # rounded outwards: it must hold every lambda
    y_lo, y_hi = np.hstack([lo[at], lam.lo]), np.hstack([hi[at], lam.hi])
    sub = sub_landscape(land, at)
    mid = 0.5 * (y_lo + y_hi)
    g_mid = _lagrange(sub.cone_parts(Interval(mid[:, :n]), spring[at]), mid, n)
    v, k_lo, k_hi = krawczyk_step(y_lo, y_hi, g_mid, _jacobian(_rows(p, at), lam))
    verdict[at] = v
    one = np.flatnonzero(v == 1)
    if not len(one):
        return verdict, empty, at[one]
    sub, which = sub_landscape(sub, one), spring[at[one]]
    y = _newton(sub, np.maximum(y_lo[one], k_lo[one]), np.minimum(y_hi[one], k_hi[one]), which, n)
    return verdict, (y[:, :n], y[:, n:], _index(sub, y, which, n)), at[one]


def sub_landscape(land, rows: np.ndarray):
    """The landscape over the batch's boxes `rows` (a family's view keeps each box's member)."""
    sub = getattr(land, "sub", None)
    return land if sub is None else sub(rows)


def _rows(p: ConeParts, rows: np.ndarray) -> ConeParts:
    return ConeParts(p.A[rows], p.J[rows], p.r[rows], p.kl0[rows], p.H[rows], p.R2[rows])


def _lagrange(p: ConeParts, y: np.ndarray, n: int) -> Interval:
    """G = (A - J^T lambda, r) at points y = (angles, lambda) (B, n + dim), rounded outwards
    (`p`: the parts at those angles)."""
    lam = Interval(y[:, n:])
    top = p.A - (p.J * Interval(lam.lo[:, :, None], lam.hi[:, :, None])).isum(axis=1)
    return Interval(np.hstack([top.lo, p.r.lo]), np.hstack([top.hi, p.r.hi]))


def _jacobian(p: ConeParts, lam: Interval) -> Interval:
    """A slope matrix of G over boxes of (angles, lambda): [[H - lambda . R2, -J^T], [J, 0]]."""
    count, dim, n = p.J.lo.shape
    L = Interval(lam.lo[:, :, None, None], lam.hi[:, :, None, None])
    top = p.H - (L * p.R2).isum(axis=1)
    lo, hi = np.zeros((count, n + dim, n + dim)), np.zeros((count, n + dim, n + dim))
    lo[:, :n, :n], hi[:, :n, :n] = top.lo, top.hi
    jt = np.swapaxes
    lo[:, :n, n:], hi[:, :n, n:] = -jt(p.J.hi, 1, 2), -jt(p.J.lo, 1, 2)
    lo[:, n:, :n], hi[:, n:, :n] = p.J.lo, p.J.hi
    return Interval(lo, hi)


def _newton(land, lo: np.ndarray, hi: np.ndarray, spring: np.ndarray, n: int) -> np.ndarray:
    """The zero of G each box (angles, lambda) holds alone, by Newton from its middle (points
    evaluated as degenerate boxes; kept inside the box)."""
    y = 0.5 * (lo + hi)
    for _ in range(30):
        p = land.cone_parts(Interval(y[:, :n]), spring)
        g, jac = _lagrange(p, y, n).mid, _jacobian(p, Interval(y[:, n:])).mid
        with np.errstate(all="ignore"):
            try:
                step = np.linalg.solve(jac, g[..., None])[..., 0]
            except np.linalg.LinAlgError:
                break
        new = y - np.nan_to_num(step)
        y = np.where(((new >= lo) & (new <= hi)).all(axis=1)[:, None], new, y)
        if np.abs(step).max() < 1e-15:
            break
    return y


def _index(land, y: np.ndarray, spring: np.ndarray, n: int) -> np.ndarray:
    """Each cone point's index: dim (V falls across the cone set) plus the negative
    eigenvalues of the Lagrangian's Hessian H - lambda . R2 along the cone set (null J)."""
    p = land.cone_parts(Interval(y[:, :n]), spring)
    dim = p.J.lo.shape[1]
    hl = (p.H - (Interval(y[:, n:, None, None]) * p.R2).isum(axis=1)).mid
    _, _, Vt = np.linalg.svd(p.J.mid)
    N = Vt[:, dim:, :]
    if N.shape[1] == 0:  # the cone set is points: a maximum
        return np.full(len(y), dim)
    tangent = N @ hl @ np.swapaxes(N, 1, 2)
    return dim + (np.linalg.eigvalsh(0.5 * (tangent + np.swapaxes(tangent, 1, 2))) < 0).sum(1)
