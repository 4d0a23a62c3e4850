"""Equilibria of a framework on the real route followed in its chart angles (boxsearch.real_route,
boxsearch.spheres) as two of its parameters change: no polynomial system, no sympy expansion.

`ChartPlane` gives grad V, its Hessian and its parameter derivatives at any chart point and any
(x, y) of the two parameters (a landscape for each parameter value visited, copied from the
first with its numbers replaced: real_route.moved_landscape). `advance` moves many equilibria at
once from one parameter value to the next (an Euler predictor on dX/dp = -H^-1 dg/dp, Newton at
the new value), halving a step that jumps: the Morse index must stay and the corrector stay
close to the predictor. What `advance` cannot follow (a turning point, a kink at a cable
switch, a pitchfork) catastrophe/chart_grid.py follows by pseudo-arclength, and the fold and
switch curves are traced by catastrophe/chart_curves.py.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..boxsearch.real_route import moved_landscape, new_landscape
from ..model.framework.spec import Framework, scale_of, slot_kind
from ..model.framework.units import units

FD = 1e-6  # central differences in a parameter: step FD * (1 + |p|)
FD_ANGLE = 1e-5  # ... in a chart angle (rad), for the fold function's gradient
NEWTON_STEPS = 12
NEWTON_TOL = 1e-12  # rad: a converged step
GRAD_TOL = 1e-9  # |grad V| (normalised units) at an accepted equilibrium
HALVINGS = 6  # advance: a step halved at most this many times before `through` takes it
KEEP = 20000  # landscapes kept (one per parameter value visited)


class ChartPlane:
    """V of framework `fw` as a function of chart angles and of its parameters `x`, `y`."""

    def __init__(self, fw: Framework, x: str, y: str):
        self.fw, self.x, self.y = fw, x, y
        self._lands: dict[tuple[float, float], object] = {}
        self._base = None
        first = self._base = self.land((fw.values[x], fw.values[y]))
        self._exprs = fw.slot_expressions()
        length, stiffness = units(fw)
        self._scale = {n: scale_of(slot_kind(n), length, stiffness) for n in self._exprs}
        self.n = first.n
        self.cables = tuple(c.name for c in fw.cables)
        self.rechart: Callable = getattr(first, "rechart", lambda t: t)

    def land(self, p) -> object:
        """The landscape at parameter values p = (x, y), made once (from the first one)."""
        key = (float(p[0]), float(p[1]))
        got = self._lands.get(key)
        if got is None:
            if len(self._lands) >= KEEP:
                self._lands.clear()
            # Unvalidated values: the map's grid was validated, and what continuation visits
            # between grid points (Newton's iterates, difference steps) need not be. The slots
            # in the first landscape's units (a unit that moved with the parameters would put
            # its own derivative into the differences).
            values = {**self.fw.values, self.x: key[0], self.y: key[1]}
            fw = dataclasses.replace(self.fw, parameters=tuple(values.items()))
            got = None
            if self._base is not None:
                slots = {n: e.evaluate(values) / self._scale[n] for n, e in self._exprs.items()}
                got = moved_landscape(self._base, fw, slots)
            got = new_landscape(fw) if got is None else got
            self._lands[key] = got
        return got

    def derivatives(self, theta: np.ndarray, p) -> tuple[np.ndarray, np.ndarray]:
        """grad V (R, n) and its Hessian (R, n, n) at chart points theta (R, n), parameters p."""
        return self.land(p).derivatives(np.atleast_2d(theta))

    def grad_along(self, theta: np.ndarray, p, d: np.ndarray) -> np.ndarray:
        """d grad V / dt along p + t d at chart points theta (R, n): central differences."""
        h = FD * (1.0 + float(np.abs(p).max()))
        up, down = np.asarray(p) + h * d, np.asarray(p) - h * d
        return (self.derivatives(theta, up)[0] - self.derivatives(theta, down)[0]) / (2 * h)

    def grad_p(self, theta: np.ndarray, p) -> np.ndarray:
        """d grad V / d(x, y) at chart points theta (R, n): (R, n, 2), central differences."""
        return np.stack([self.grad_along(theta, p, e) for e in np.eye(2)], axis=-1)

    def index(self, theta: np.ndarray, p) -> tuple[np.ndarray, np.ndarray]:
        """Each point's Morse index (negative eigenvalues of the chart Hessian) and its
        eigenvalue nearest 0."""
        _, H = self.derivatives(theta, p)
        eig = np.linalg.eigvalsh(H)
        near = eig[np.arange(len(eig)), np.abs(eig).argmin(axis=1)] if len(eig) else eig[:, 0]
        return (eig < 0).sum(axis=1), near

    def margins(self, theta: np.ndarray, p) -> np.ndarray:
        """(R, cables): each cable's length minus its free length (normalised units; +inf for
        a cable without one): taut where > 0."""
        theta = np.atleast_2d(theta)
        if not self.cables:  # springs alone (np.stack takes no empty list)
            return np.zeros((len(theta), 0))
        land = self.land(p)
        d = land.cable_lengths(theta)
        free = {x.name: x.L0 for x in land.links}
        return np.stack(
            [d[c] - free[c] if free.get(c) is not None else np.full(len(theta), np.inf)
             for c in self.cables], axis=1,
        ).reshape(len(theta), len(self.cables))  # fmt: skip

    def fresh(self, points: np.ndarray, known: np.ndarray, p) -> np.ndarray:
        """`points` not at the pose of a `known` one nor of an earlier one (the landscape's)."""
        return self.land(p).fresh(np.atleast_2d(points).reshape(-1, self.n),
                                  np.atleast_2d(known).reshape(-1, self.n))  # fmt: skip


def newton(plane: ChartPlane, theta: np.ndarray, p) -> tuple[np.ndarray, np.ndarray]:
    """Newton on grad V = 0 at parameters p from points theta (R, n), recharted after every
    step: (points, converged mask)."""
    x = np.array(theta, dtype=float, copy=True)
    ok = np.zeros(len(x), dtype=bool)
    live = np.arange(len(x))
    for _ in range(NEWTON_STEPS):
        if not len(live):
            break
        g, H = plane.derivatives(x[live], p)
        with np.errstate(all="ignore"):
            try:
                step = np.linalg.solve(H, g[..., None])[..., 0]
            except np.linalg.LinAlgError:
                step = np.einsum("nij,nj->ni", np.linalg.pinv(H), g)
        bad = ~np.isfinite(step).all(axis=1) | (np.abs(step).max(axis=1) > 1.0)
        x[live[~bad]] = plane.rechart(x[live[~bad]] - step[~bad])
        done = ~bad & (np.abs(step).max(axis=1) < NEWTON_TOL)
        ok[live[done]] = True
        live = live[~bad & ~done]
    if ok.any():  # a small step is not enough: the gradient itself must vanish
        g, _ = plane.derivatives(x[ok], p)
        ok[np.flatnonzero(ok)[np.abs(g).max(axis=1) > GRAD_TOL]] = False
    return x, ok


def _one_step(plane: ChartPlane, theta, p0, p1) -> tuple[np.ndarray, np.ndarray]:
    """Predictor-corrector from parameters p0 to p1 (both (x, y)); ok where Newton converged,
    the index is kept and the corrector stayed within half the predictor's move (no jump)."""
    dp = np.asarray(p1, float) - np.asarray(p0, float)
    _, H = plane.derivatives(theta, p0)
    gp = plane.grad_along(theta, p0, dp)
    with np.errstate(all="ignore"):
        try:
            move = -np.linalg.solve(H, gp[..., None])[..., 0]
        except np.linalg.LinAlgError:
            move = -np.einsum("nij,nj->ni", np.linalg.pinv(H), gp)
    move = np.where(np.isfinite(move), move, 0.0)
    pred = theta + move
    x, ok = newton(plane, pred, p1)
    i0, _ = plane.index(theta, p0)
    i1, _ = plane.index(x, p1)
    # The corrector's move, measured on the poses (x is recharted, pred is not).
    near = _distance(plane, x, pred, p1) <= 0.5 * _distance(plane, pred, theta, p1) + 1e-7
    return x, ok & (i0 == i1) & near


def _distance(plane: ChartPlane, a: np.ndarray, b: np.ndarray, p) -> np.ndarray:
    """Row by row, the largest coordinate difference of the poses of chart points a and b
    (node positions for spheres, angles mod 2 pi for tori): chart-independent."""
    land = plane.land(p)
    if not len(a):
        return np.zeros(0)
    if hasattr(land, "positions"):
        return np.abs(land.positions(a) - land.positions(b)).max(axis=1)
    return np.abs((a - b + np.pi) % (2 * np.pi) - np.pi).max(axis=1)


@dataclass(frozen=True)
class Advanced:
    """Where `advance` took each point: `points` at the far value where `ok`, else the last
    point it reached, at fraction `reached` of the way (0 to 1)."""

    points: np.ndarray
    ok: np.ndarray
    reached: np.ndarray


def advance(plane: ChartPlane, theta: np.ndarray, p0, p1) -> Advanced:
    """Equilibria theta (R, n) at parameters p0 followed to p1; a step that fails is halved
    up to HALVINGS times, point by point, and grows again after a success."""
    theta = np.atleast_2d(np.asarray(theta, float))
    out = np.array(theta, copy=True)
    ok = np.zeros(len(theta), dtype=bool)
    reached = np.zeros(len(theta))
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    todo = [(i, theta[i], 0.0, 1.0) for i in range(len(theta))]  # (row, point, at, step)
    while todo:
        groups: dict[tuple[float, float], list] = {}  # one call for a batch at one (at, step)
        for item in todo:
            groups.setdefault((item[2], item[3]), []).append(item)
        todo = []
        for (f, h), items in groups.items():
            to = min(f + h, 1.0)
            x, good = _one_step(plane, np.array([it[1] for it in items]),
                                p0 + f * (p1 - p0), p0 + to * (p1 - p0))  # fmt: skip
            for (i, xi0, _, _), xi, gi in zip(items, x, good, strict=True):
                if gi and to >= 1.0:
                    out[i], ok[i], reached[i] = xi, True, 1.0
                elif gi:
                    todo.append((i, xi, to, min(2 * h, 1.0 - to)))
                elif h > 0.5**HALVINGS:
                    todo.append((i, xi0, f, h / 2))
                else:
                    out[i], reached[i] = xi0, f
    return Advanced(out, ok, reached)
