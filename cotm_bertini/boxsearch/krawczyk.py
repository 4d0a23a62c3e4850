"""The Krawczyk operator over batches of boxes, whatever the system: K(X) = m - Y g(m) +
(I - Y H(X)) (X - m), Y the inverse of the midpoint of H(X), a slope matrix of g over X. K(X)
inside the interior of X proves exactly one zero of g in X (it lies in K(X)); K(X) disjoint
from X proves none (Moore, Krawczyk). boxsearch.boxes tests grad V with it, boxsearch.cones the
Lagrange system of a spring at zero length."""

from __future__ import annotations

import numpy as np

from ..model.intervals import Interval


def krawczyk_step(lo: np.ndarray, hi: np.ndarray, g_mid: Interval, h: Interval,
                  fixed: np.ndarray | None = None) -> tuple:  # fmt: skip
    """(verdict, K lo, K hi) per box (B, n): 1 exactly one zero, -1 none, 0 unknown. `g_mid`
    encloses g at the boxes' middles, `h` a slope matrix over each box (B, n, n). Along a
    `fixed` coordinate ((B, n) bool) the box is its middle and g is 0 whatever it is (the test
    is that of the other components: see boxsearch.boxes.krawczyk)."""
    n = lo.shape[1]
    fixed = np.zeros(lo.shape, dtype=bool) if fixed is None else fixed
    mid = 0.5 * (lo + hi)
    box = Interval(np.where(fixed, mid, lo), np.where(fixed, mid, hi))
    h_mid = h.mid
    ok = np.isfinite(h_mid).all(axis=(1, 2)) & g_mid.finite().all(axis=1)
    ok &= np.abs(np.linalg.det(np.where(ok[:, None, None], h_mid, np.eye(n)))) > 1e-300
    y = np.linalg.inv(np.where(ok[:, None, None], h_mid, np.eye(n)))
    yg = (Interval(y) * Interval(g_mid.lo[:, None, :], g_mid.hi[:, None, :])).isum(axis=2)
    yh = (Interval(y[:, :, :, None]) * Interval(h.lo[:, None, :, :], h.hi[:, None, :, :])).isum(
        axis=2
    )
    spread = Interval(np.eye(n)) - yh  # (B, n, n)
    dx = box - mid
    tail = (spread * Interval(dx.lo[:, None, :], dx.hi[:, None, :])).isum(axis=2)
    k = (Interval(mid) - yg) + tail
    ok &= k.finite().all(axis=1)
    inside = ok & (((k.lo > lo) & (k.hi < hi)) | fixed).all(axis=1)
    apart = ok & (((k.hi < lo) | (k.lo > hi)) & ~fixed).any(axis=1)
    return np.where(inside, 1, np.where(apart, -1, 0)), k.lo, k.hi
