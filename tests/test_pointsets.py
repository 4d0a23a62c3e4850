"""model.pointsets.apart against the pairwise max-norm distance it stands in for."""

import numpy as np

from cotm_bertini.model.pointsets import apart


def _closest(x: np.ndarray) -> float:
    """The smallest complex max-norm distance between two rows (brute force)."""
    gaps = np.abs(x[:, None, :] - x[None, :, :]).max(axis=2)
    np.fill_diagonal(gaps, np.inf)
    return float(gaps.min())


def test_apart_is_never_wrong_and_usually_decides():
    """On 400 random sets (70 points in 6 complex coordinates, conjugate pairs among them, some
    with a planted near-duplicate): whenever `apart` says True, brute force agrees that every
    pair is more than the gap apart; a set with a pair closer than the gap is never apart;
    and most well-separated sets are recognised (else the quick route saves nothing)."""
    rng = np.random.default_rng(7)
    decided = separated = 0
    for trial in range(400):
        x = rng.normal(size=(70, 6)) + 1j * rng.normal(size=(70, 6))
        x[35:] = np.conj(x[:35])  # real parameters: roots come in conjugate pairs
        x[::9] = x[::9].real  # and some real roots
        if trial % 4 == 0:
            x[5] = x[40] + 1e-8 * rng.normal(size=6)
        gap = 1e-6
        says = apart(x, gap)
        truth = _closest(x) > gap
        assert not says or truth
        if truth:
            separated += 1
            decided += says
    assert separated > 250 and decided >= 0.95 * separated


def test_apart_refuses_nan_and_accepts_tiny_sets():
    """A NaN row cannot be proved apart; fewer than two rows are."""
    x = np.array([[1.0 + 1j, 2.0], [np.nan, 0.0]])
    assert not apart(x, 1e-6)
    assert apart(x[:1], 1e-6) and apart(x[:0], 1e-6)
