"""Critical points found by Newton where the search could not prove them (undecided boxes, boxes
set aside) and minima reached by local descents: evidence beside the search, not proof."""

from __future__ import annotations

import numpy as np

from .boxes import domain


def critical_seeds(land, boxes: np.ndarray, most: int = 32) -> np.ndarray:
    """Critical points near undecided or set-aside boxes (lo_1..lo_n, hi_1..hi_n): Newton with
    a least-squares step (the Hessian may be singular there: a continuum) from the middles of
    at most `most` of them (`coarse_pick`); the ends where |grad V| < 1e-10. A landscape in
    charts moves each point to a chart regular there after every step (`rechart`: Newton
    stays away from a chart's poles, where a component of grad V vanishes by itself)."""
    n = land.n
    rechart = getattr(land, "rechart", lambda x: x)
    if not len(boxes):
        return np.zeros((0, n))
    pick = coarse_pick(boxes, most)
    x = 0.5 * (pick[:, :n] + pick[:, n:])
    live = np.arange(len(x))
    for _ in range(30):  # the points still moving only: most converge in a few steps
        g, h = land.derivatives(x[live])
        step = np.einsum("nij,nj->ni", np.linalg.pinv(h, rcond=1e-10), g)
        x[live] = rechart(x[live] - step)
        live = live[np.isfinite(step).all(axis=1) & (np.abs(step).max(axis=1) > 1e-13)]
        if not len(live):
            break
    g, _ = land.derivatives(x)
    return x[np.isfinite(g).all(axis=1) & (np.abs(g).max(axis=1) < 1e-10)]


def descent_minima(land, starts: int, seed: int, steps: int = 200) -> np.ndarray:
    """Local minima of V reached from `starts` random points of the domain (seeded): Newton
    steps where the Hessian is positive definite, else a gradient step of at most 0.2 rad,
    each shortened until V's first-order decrease is kept (no energy is evaluated: the step
    is damped instead); the ends with |grad V| < 1e-10 and a positive definite Hessian. Not a
    proof: evidence, for a search stopped by its budget, that its rows hold every minimum the
    descents find. None on a loop (its landscape's derivatives are F's, not V's)."""
    if getattr(land, "loop", None) is not None:
        return np.zeros((0, land.n))
    rng = np.random.default_rng(seed)
    lo, hi = domain(land, 8)
    pick = rng.integers(0, len(lo), starts)
    x = lo[pick] + rng.random((starts, land.n)) * (hi[pick] - lo[pick])
    rechart = getattr(land, "rechart", lambda y: y)
    for _ in range(steps):
        g, h = land.derivatives(x)
        with np.errstate(all="ignore"):
            eig = np.linalg.eigvalsh(h)
            newton = np.linalg.solve(np.where((eig > 0).all(axis=1)[:, None, None], h,
                                              np.eye(land.n)), g[..., None])[..., 0]  # fmt: skip
        step = np.where((eig > 0).all(axis=1)[:, None], newton, g)
        step *= np.minimum(1.0, 0.2 / np.maximum(np.abs(step).max(axis=1), 1e-300))[:, None]
        x = rechart(x - step)
        if np.abs(step).max(initial=0.0) < 1e-15:  # every descent has arrived (or is stuck)
            break
    g, h = land.derivatives(x)
    good = (np.abs(g).max(axis=1) < 1e-10) & (np.linalg.eigvalsh(h) > 0).all(axis=1)
    return x[good]


def coarse_pick(boxes: np.ndarray, most: int, cell: float = 0.02) -> np.ndarray:
    """At most `most` of the boxes (lo_1..lo_n, hi_1..hi_n), one a cell of `cell` rad of their
    middles, spread over the list: every cluster of boxes (one around each cone point or along
    a continuum) is seeded, not just the largest."""
    n = boxes.shape[1] // 2
    mid = 0.5 * (boxes[:, :n] + boxes[:, n:])
    _, first = np.unique(np.floor(mid / cell).astype(np.int64), axis=0, return_index=True)
    first = np.sort(first)
    return boxes[first[np.unique(np.linspace(0, len(first) - 1, min(most, len(first)))
                                 .astype(int))]]  # fmt: skip
