"""Pseudo-arclength continuation of a real curve F(z) = 0 (F: R^N -> R^(N-1)) through a window
of two of its coordinates, both ways from a point, to the window's edge or until it closes.

Steps are bounded in z (so the curve's shape in the other coordinates is followed) and in the
plane of the two window coordinates (so consecutive points are no further apart there than a
given fraction of the window's diagonal). A Newton corrector on F = 0 and the arclength equation
accepts a step only when it converges and the tangent turns by less than 60 deg; otherwise the
step is halved.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

# (z, zref) -> (F (N-1,), dF/dz (N-1, N)); zref: the last accepted point (a normalisation may
# depend on it).
Equations = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]

NEWTON_STEPS = 8
NEWTON_TOL = 1e-11
MIN_STEP = 1e-9
MAX_POINTS = 20000  # per direction


@dataclass(frozen=True)
class Window:
    """The window in the plane of coordinates (ix, iy) of z, in z's own units."""

    ix: int
    iy: int
    lo: tuple[float, float]
    hi: tuple[float, float]
    scale: tuple[float, float]  # user value = scale * coordinate (for the diagonal)

    @property
    def diagonal(self) -> float:
        """The window's diagonal in user units."""
        return float(np.hypot(*((h - lo) * s for lo, h, s in zip(self.lo, self.hi, self.scale,
                                                                    strict=True))))  # fmt: skip

    def xy_distance(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Distance in the plane (user units) between points (..., N)."""
        dx = (a[..., self.ix] - b[..., self.ix]) * self.scale[0]
        dy = (a[..., self.iy] - b[..., self.iy]) * self.scale[1]
        return np.hypot(dx, dy)

    def inside(self, z: np.ndarray, margin: float = 0.0) -> bool:
        """Whether z's plane coordinates lie in the window (grown by `margin` of each side)."""
        for i, k in enumerate((self.ix, self.iy)):
            w = (self.hi[i] - self.lo[i]) * margin
            if not (self.lo[i] - w <= z[k] <= self.hi[i] + w):
                return False
        return True


@dataclass(frozen=True)
class Traced:
    """One curve: its points in order, whether it closed, how each end stopped."""

    points: np.ndarray  # (m, N)
    closed: bool
    ends: tuple[str, str]  # "edge", "closed", "stalled" or "max_points"


def newton(eqs: Equations, z: np.ndarray, zref: np.ndarray, extra=None) -> np.ndarray | None:
    """Newton on F = 0 plus one more equation `extra(z) -> (value, gradient)`; None if it fails."""
    for _ in range(NEWTON_STEPS):
        F, J = eqs(z, zref)
        g, dg = extra(z)
        A = np.vstack([J, dg])
        b = np.append(F, g)
        try:
            dz = np.linalg.solve(A, b)
        except np.linalg.LinAlgError:
            return None
        if not np.isfinite(dz).all():
            return None
        z = z - dz
        if np.abs(dz).max() < NEWTON_TOL * (1.0 + np.abs(z).max()):
            F, _ = eqs(z, zref)
            return z if np.abs(F).max() < 1e-8 * (1.0 + np.abs(z).max()) else None
    return None


def tangent(eqs: Equations, z: np.ndarray, zref: np.ndarray) -> np.ndarray:
    """The unit tangent: the null vector of dF/dz."""
    _, J = eqs(z, zref)
    return np.linalg.svd(J)[2][-1]


def _passes(a: np.ndarray, b: np.ndarray, z0: np.ndarray, h: float) -> bool:
    """Whether the step from a to b passes z0 (the start: the curve has closed)."""
    ab = b - a
    s = float(np.clip((z0 - a) @ ab / max(ab @ ab, 1e-300), 0.0, 1.0))
    return bool(np.linalg.norm(a + s * ab - z0) < 0.1 * h)


def _step_size(t: np.ndarray, win: Window, spacing: float, hmax: float) -> float:
    """The largest step along t allowed by both bounds."""
    speed = np.hypot(t[win.ix] * win.scale[0], t[win.iy] * win.scale[1]) / win.diagonal
    return min(hmax, spacing / speed) if speed > 0 else hmax


def _clip(eqs: Equations, a: np.ndarray, b: np.ndarray, win: Window) -> np.ndarray | None:
    """The point where the curve between a (inside) and b (outside) crosses the window's edge."""
    best = None
    for i, k in enumerate((win.ix, win.iy)):
        for edge in (win.lo[i], win.hi[i]):
            if (a[k] - edge) * (b[k] - edge) < 0:
                s = (edge - a[k]) / (b[k] - a[k])
                unit = np.eye(len(a))[k]
                z = newton(eqs, a + s * (b - a), a, lambda z, k=k, e=edge, u=unit: (z[k] - e, u))
                if z is not None and win.inside(z, 1e-9) and (best is None or s < best[0]):
                    best = (s, z)
    return None if best is None else best[1]


def _one_way(eqs: Equations, z0: np.ndarray, t0: np.ndarray, win: Window, spacing: float,
             hmax: float) -> tuple[list[np.ndarray], str]:  # fmt: skip
    """Points from z0 (excluded) along +t0 until the edge, back at z0, or stuck."""
    out, z, t = [], z0, t0
    h = _step_size(t, win, spacing, hmax)
    travelled = 0.0
    while len(out) < MAX_POINTS:
        h = min(h * 1.5, _step_size(t, win, spacing, hmax))
        while True:
            pred = z + h * t
            new = newton(eqs, pred, z, lambda w, p=pred, t=t: (t @ (w - p), t))
            if new is not None:
                t_new = tangent(eqs, new, z)
                t_new = t_new if t_new @ t > 0 else -t_new
                close = win.xy_distance(new, z) <= spacing * win.diagonal
                if t_new @ t > 0.5 and np.linalg.norm(new - z) < 2 * h and close:
                    break
            h /= 2
            if h < MIN_STEP:
                return out, "stalled"
        if not win.inside(new):
            edge = _clip(eqs, z, new, win)
            return out + ([edge] if edge is not None else []), "edge"
        travelled += np.linalg.norm(new - z)
        if travelled > 3 * h and _passes(z, new, z0, h):
            return out, "closed"
        out.append(new)
        z, t = new, t_new
    return out, "max_points"


def trace(eqs: Equations, z0: np.ndarray, win: Window, spacing: float = 0.002,
          hmax: float = 0.05) -> Traced:  # fmt: skip
    """The curve through z0 (a point on it) both ways: `spacing` bounds consecutive points'
    distance in the window's plane as a fraction of its diagonal, `hmax` in z."""
    t0 = tangent(eqs, z0, z0)
    fwd, end_f = _one_way(eqs, z0, t0, win, spacing, hmax)
    if end_f == "closed":
        pts = [z0, *fwd, z0]
        return Traced(np.array(pts), True, ("closed", "closed"))
    back, end_b = _one_way(eqs, z0, -t0, win, spacing, hmax)
    pts = [*back[::-1], z0, *fwd]
    return Traced(np.array(pts), False, (end_b, end_f))
