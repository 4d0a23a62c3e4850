"""Group path endpoints that are one solution (several paths reaching the same root)."""

from __future__ import annotations

import numpy as np


def cluster_endpoints(
    x: np.ndarray, singular: np.ndarray, accuracy: np.ndarray, tol: float
) -> np.ndarray:
    """Label endpoints that are one solution with one group id (0, 1, ... in first-seen order)."""
    n = len(x)
    labels = -np.ones(n, dtype=int)
    mag = 1.0 + np.abs(x).max(axis=1) if n else np.zeros(0)
    # A singular root is only known to about the square root of the tracking accuracy.
    loose = np.where(singular, 10.0 * np.sqrt(np.maximum(accuracy, 1e-16)), tol)
    group = 0
    for i in range(n):
        if labels[i] >= 0:
            continue
        labels[i] = group
        for j in range(i + 1, n):
            if labels[j] >= 0:
                continue
            # Only two singular endpoints are merged loosely: a regular root is never swallowed.
            limit = max(loose[i], loose[j]) if (singular[i] and singular[j]) else tol
            if np.abs(x[i] - x[j]).max() <= limit * max(mag[i], mag[j]):
                labels[j] = group
        group += 1
    return labels
