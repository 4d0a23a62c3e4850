"""Sets of complex points: a quick proof that no two are close."""

from __future__ import annotations

from functools import cache

import numpy as np

_SEED = 20261126  # the projection is fixed: the same points always take the same route


@cache
def _line(size: int) -> np.ndarray:
    return np.random.default_rng(_SEED).uniform(0.5, 1.0, size)


def apart(x: np.ndarray, gap: float) -> bool:
    """True only if every two rows of x differ by more than `gap` in some coordinate's real or
    imaginary part (so by more than `gap` in the complex max norm); False does not say they
    are close. One projection onto a random line w and a sort, O(n log n) where the pairwise
    test is O(n^2 m): |w . (a - b)| <= |w|_1 max|a - b|, so projections more than gap |w|_1
    apart are of points more than gap apart."""
    if len(x) < 2:
        return True
    parts = np.hstack([np.real(x), np.imag(x)])
    w = _line(parts.shape[1])
    line = np.sort((parts * w).sum(axis=1))
    return bool((np.diff(line) > gap * w.sum()).all())
