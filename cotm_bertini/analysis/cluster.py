"""Group path endpoints that are one solution (several paths reaching the same root)."""

from __future__ import annotations

import numpy as np

from ..model.pointsets import apart


def cluster_endpoints(
    x: np.ndarray, singular: np.ndarray, accuracy: np.ndarray, tol: float
) -> np.ndarray:
    """Label endpoints that are one solution with one group id (0, 1, ... in first-seen order).

    Two endpoints are one solution when every coordinate agrees within `tol` relative to the
    larger magnitude; two singular ones (known to about the square root of the tracking accuracy
    only) within the looser of their own accuracies. A regular root is never swallowed loosely.
    """
    n = len(x)
    labels = -np.ones(n, dtype=int)
    if n == 0:
        return labels
    mag = 1.0 + np.abs(x).max(axis=1)
    loose = np.where(singular, 10.0 * np.sqrt(np.maximum(accuracy, 1e-16)), tol)
    if apart(x, max(tol, loose.max()) * mag.max()):  # no pair within the loosest limit
        return np.arange(n)
    gap = np.abs(x[:, None, :] - x[None, :, :]).max(axis=2)
    both = singular[:, None] & singular[None, :]
    limit = np.where(both, np.maximum(loose[:, None], loose[None, :]), tol)
    same = gap <= limit * np.maximum(mag[:, None], mag[None, :])
    if np.count_nonzero(same) == n and same.diagonal().all():  # each only with itself
        return np.arange(n)
    group = 0
    for i in range(n):
        if labels[i] >= 0:
            continue
        labels[i] = group
        # Later endpoints join the first one they match (as a sequential scan would group them).
        joins = same[i] & (labels < 0)
        joins[: i + 1] = False
        labels[joins] = group
        group += 1
    return labels
