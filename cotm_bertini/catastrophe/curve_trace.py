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
Keep = Callable[[np.ndarray], bool] | None

NEWTON_STEPS = 8
NEWTON_TOL = 1e-11
NEWTON_ACCEPT = 1e-7  # ... or below this and no longer halving (newton)
RESIDUAL = 1e-8  # |F_i| at a converged point, relative to row i's scale (newton)
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
    ends: tuple[str, str]  # "edge", "closed", "looped", "left", "stalled" or "max_points"


def remembered(eqs: Equations) -> Equations:
    """`eqs` keeping its last evaluation: Newton's closing residual and the tangent at the same
    point then cost one evaluation, not two."""
    last: dict = {}

    def cached(z: np.ndarray, zref: np.ndarray):
        key = (z.tobytes(), zref.tobytes())
        if last.get("key") != key:
            last.update(key=key, value=eqs(z, zref))
        return last["value"]

    return cached


def newton(eqs: Equations, z: np.ndarray, zref: np.ndarray, extra=None) -> np.ndarray | None:
    """Newton on F = 0 plus one more equation `extra(z) -> (value, gradient)`; None if it fails.

    Scale-invariant: each step solves the system with its columns scaled by 1 + |z_j| and its
    rows then by their largest entry, and converges when every component's step, relative to
    1 + |z_j|, is below NEWTON_TOL, or below NEWTON_ACCEPT and no longer halving (rounding);
    the residual is judged row by row against the same row scale. Near a zero-length end a
    force density grows like 1 / d while the angles stay of order one: unscaled, the Jacobian's
    condition grew past 1e10 there (6.5e4 scaled) and the steps stopped short.
    """
    before = np.inf
    for _ in range(NEWTON_STEPS):
        F, J = eqs(z, zref)
        g, dg = extra(z)
        cols = 1.0 + np.abs(z)
        A = np.vstack([J, dg]) * cols
        rows = np.abs(A).max(axis=1)
        rows[rows == 0] = 1.0
        try:
            dz = np.linalg.solve(A / rows[:, None], np.append(F, g) / rows) * cols
        except np.linalg.LinAlgError:
            return None
        if not np.isfinite(dz).all():
            return None
        z = z - dz
        size = (np.abs(dz) / (1.0 + np.abs(z))).max()
        if size < NEWTON_TOL or size < NEWTON_ACCEPT and size > before / 2:
            F, _ = eqs(z, zref)
            return z if (np.abs(F) <= RESIDUAL * rows[: len(F)]).all() else None
        before = size
    return None


def tangent(eqs: Equations, z: np.ndarray, zref: np.ndarray) -> np.ndarray:
    """The unit tangent: the null vector of dF/dz."""
    _, J = eqs(z, zref)
    return np.linalg.svd(J)[2][-1]


def _passes(a: np.ndarray, b: np.ndarray, z0: np.ndarray, h: float) -> bool:
    """Whether the step from a to b passes z0 (or any row of z0, (m, N))."""
    ab = b - a
    s = np.clip((z0 - a) @ ab / max(ab @ ab, 1e-300), 0.0, 1.0)
    near = np.linalg.norm(a + s[..., None] * ab - z0, axis=-1) < 0.1 * h
    return bool(np.any(near))


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
             hmax: float, keep: Keep, relative: bool) -> tuple[list[np.ndarray], str]:  # fmt: skip
    """Points from z0 (excluded) along +t0 until the edge, back at z0, back on itself elsewhere
    ("looped": it entered a loop through a junction, which it would go round for ever), out of
    `keep`, or stuck."""
    out, z, t = [], z0, t0
    seen = np.empty((MAX_POINTS, len(z0)))  # out as an array, for the loop test
    h = _step_size(t, win, spacing, hmax)
    travelled = 0.0
    while len(out) < MAX_POINTS:
        grow = 1.0 + np.abs(z).max() if relative else 1.0
        h = min(h * 1.5, _step_size(t, win, spacing, hmax * grow))
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
        if keep is not None and not keep(new):
            return out, "left"
        travelled += np.linalg.norm(new - z)
        if travelled > 3 * h and _passes(z, new, z0, h):
            return out, "closed"
        if len(out) > 3 and _passes(z, new, seen[: len(out) - 3], h):
            return out, "looped"
        seen[len(out)] = new
        out.append(new)
        z, t = new, t_new
    return out, "max_points"


def trace(eqs: Equations, z0: np.ndarray, win: Window, spacing: float = 0.002,
          hmax: float = 0.05, keep: Keep = None, relative: bool = False) -> Traced:  # fmt: skip
    """The curve through z0 (a point on it) both ways: `spacing` bounds consecutive points'
    distance in the window's plane as a fraction of its diagonal, `hmax` in z (times
    1 + max |z| if `relative`: a curve running off to infinity leaves in few steps); `keep`: the
    part of z-space to stay in (an end that leaves it stops there, "left")."""
    t0 = tangent(eqs, z0, z0)
    fwd, end_f = _one_way(eqs, z0, t0, win, spacing, hmax, keep, relative)
    if end_f == "closed":
        pts = [z0, *fwd, z0]
        return Traced(np.array(pts), True, ("closed", "closed"))
    back, end_b = _one_way(eqs, z0, -t0, win, spacing, hmax, keep, relative)
    pts = [*back[::-1], z0, *fwd]
    return Traced(np.array(pts), False, (end_b, end_f))


def one_way(eqs: Equations, z0: np.ndarray, t0: np.ndarray, win: Window, spacing: float = 0.002,
            hmax: float = 0.05, keep: Keep = None) -> tuple[np.ndarray, str]:  # fmt: skip
    """trace's one direction: the points from z0 (excluded) along +t0, (m, N), and how that end
    stopped (Traced.ends); for a caller that goes on from an end (a curve traced in pieces)."""
    pts, end = _one_way(eqs, z0, t0, win, spacing, hmax, keep, False)
    return np.array(pts).reshape(-1, len(z0)), end


def turning_point(eqs: Equations, za: np.ndarray, zb: np.ndarray, direction: np.ndarray,
                  win: Window, halvings: int = 50) -> np.ndarray | None:  # fmt: skip
    """The point of the curve between za and zb (near each other on it) where its image in the
    window's plane turns back along `direction` (a unit vector of the plane, user units): by
    `halvings` bisections on the sign of the image's velocity along it. None if that sign does
    not change or Newton fails."""
    t_a = zb - za
    t_a /= np.linalg.norm(t_a)

    def at(h: float):
        pred = za + h * t_a
        z = newton(eqs, pred, za, lambda w: (t_a @ (w - pred), t_a))
        if z is None:
            return None, 0.0
        t = tangent(eqs, z, za)
        t = t if t @ t_a > 0 else -t
        return z, t[win.ix] * win.scale[0] * direction[0] + t[win.iy] * win.scale[1] * direction[1]

    lo, hi = 0.0, float(np.linalg.norm(zb - za))
    z_lo, f_lo = at(lo)
    z_hi, f_hi = at(hi)
    if z_lo is None or z_hi is None or f_lo * f_hi > 0:
        return None
    for _ in range(halvings):
        mid = (lo + hi) / 2
        z, f = at(mid)
        if z is None:
            return None
        if f * f_lo > 0:
            lo, f_lo = mid, f
        else:
            hi = mid
    return at((lo + hi) / 2)[0]
