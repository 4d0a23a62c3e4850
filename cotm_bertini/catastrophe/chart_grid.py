"""The grid of a design map on the real route, by continuation in chart angles (no sweep of
searches): what a map of a spatial framework can afford, where one proved search costs seconds.

1. Anchors: the real route's search (boxsearch.boxes) at ANCHORS x ANCHORS grid points (corners,
   middles), each proved or with its undecided volume.
2. Propagation: every equilibrium known at a grid point is followed along its grid row and its
   grid column to the neighbouring points (continuation.charts.advance), both ways, until no
   line gains a point. A step `advance` cannot take is taken by pseudo-arclength on the line's
   equilibrium curve (`through`): it reaches the neighbour, or turns back at a fold and brings
   the fold's partner back to the point it left (a new equilibrium there when it was not known).
   Each turning point is a fold seed; each cable whose state changes along a step gives a switch
   seed (located on the branch by the secant method). A branch neither reaching the neighbour
   nor turning back is lost, and listed.
3. What is not proved: a grid point other than an anchor has the equilibria connected to an
   anchor's along grid lines (through folds). A pair of equilibria born and dying away from
   every anchor's branches is not found; the Morse sum at every point (a single lost
   equilibrium breaks it, a lost pair does not) and the map's completeness test (every change
   of the stable count crossed by a traced fold or switch curve) are the checks.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..continuation.charts import ChartPlane, advance
from ..model.framework.spec import Framework
from ..progress import Progress
from .chart_curves import Seed
from .curve_trace import Window, one_way, tangent, turning_point

ANCHORS = 3  # searched grid points per axis (both ends and the middle)
SPACING = 0.2  # `through`: steps at most this fraction of the grid step's diagonal
HMAX = 0.1  # ... and this far in the chart angles (rad)
SWITCH_TOL = 1e-9  # a cable at its free length within this (normalised units) at a seed
SECANT_STEPS = 40
THROUGH_POINTS = 400  # `through` gives up after this many points ("too long")
TURN_HALVINGS = 24  # a turning point to 2^-24 of a step: a seed, refined by its curve's trace


@dataclass
class _State:
    """The propagation's working state: points by grid index, how many of each were followed
    along each line direction, lines to pass, seeds, lost branches."""

    known: dict
    pushed: dict = field(default_factory=dict)
    dirty: set = field(default_factory=set)  # (axis, index): rows (axis 0) and columns (1)
    seeds: list = field(default_factory=list)
    lost: list = field(default_factory=list)
    passes: int = 0
    throughs: int = 0


def anchor_indices(points: int, per_axis: int = ANCHORS) -> list[int]:
    """Grid indices of the anchors along one axis: evenly spread, both ends among them."""
    return sorted({int(round(v)) for v in np.linspace(0, points - 1, min(per_axis, points))})


PROPAGATION = "map: equilibria followed over the grid"


def propagate(plane: ChartPlane, xs: np.ndarray, ys: np.ndarray, known: dict) -> _State:
    """Followed to a fixed point: every equilibrium of `known` ({(i, j): (m, n) chart points})
    along its row and column (module docstring, 2); `known` grows in place."""
    state = _State(known)
    for i, j in known:
        state.dirty |= {(0, j), (1, i)}
    # Minutes on a spatial framework: reported as lines are passed, and every few seconds
    # (heartbeat) while one line's steps through folds run; no total (a line passed can make
    # crossing lines dirty again), so the note says how far the grid is filled.
    with Progress(PROPAGATION, None, "grid lines", heartbeat=True) as report:
        while state.dirty:
            axis, index = min(state.dirty)
            state.dirty.discard((axis, index))
            _line(plane, state, axis, index, xs, ys)
            state.passes += 1
            report.update(1, _followed(state, len(xs) * len(ys)))
    return state


def _followed(state: _State, points: int) -> str:
    """The propagation's progress note: grid points reached, equilibria, lines left, lost."""
    reached = sum(len(v) > 0 for v in state.known.values())
    found = sum(len(v) for v in state.known.values())
    return (f"{reached}/{points} grid points reached, {found} equilibria, "
            f"{state.throughs} steps through folds, {len(state.lost)} branches lost, "
            f"{len(state.dirty)} lines to pass")  # fmt: skip


def _params(axis: int, index: int, k: int, xs, ys) -> np.ndarray:
    """The parameters of point k of line (axis, index): a row (axis 0) moves x, a column y."""
    return np.array([xs[k], ys[index]]) if axis == 0 else np.array([xs[index], ys[k]])


def _key(axis: int, index: int, k: int) -> tuple[int, int]:
    return (k, index) if axis == 0 else (index, k)


def _line(plane: ChartPlane, state: _State, axis: int, index: int, xs, ys) -> None:
    """Passes forward and back along one line until it gains no point."""
    count = len(xs) if axis == 0 else len(ys)
    changed = True
    while changed:
        changed = False
        for sign in (1, -1):
            ks = range(count - 1) if sign > 0 else range(count - 1, 0, -1)
            for k in ks:
                changed |= _step(plane, state, axis, index, k, sign, xs, ys)


def _add(plane: ChartPlane, state: _State, key, pts: np.ndarray, p, axis: int) -> int:
    """Fresh points of `pts` added at grid point `key`; the crossing line made dirty."""
    have = state.known.get(key, np.zeros((0, plane.n)))
    new = plane.fresh(pts, have, p)
    if len(new):
        state.known[key] = np.vstack([have, new])
        state.dirty.add((1 - axis, key[0] if axis == 0 else key[1]))
    return len(new)


def _step(plane: ChartPlane, state: _State, axis: int, index: int, k: int, sign: int,
          xs, ys) -> bool:  # fmt: skip
    """The points at line point k not yet followed towards k + sign, followed there."""
    here, there = _key(axis, index, k), _key(axis, index, k + sign)
    pts = state.known.get(here, np.zeros((0, plane.n)))
    done = state.pushed.get((here, axis, sign), 0)
    state.pushed[(here, axis, sign)] = len(pts)
    if done >= len(pts):
        return False
    p0, p1 = _params(axis, index, k, xs, ys), _params(axis, index, k + sign, xs, ys)
    moved = advance(plane, pts[done:], p0, p1)
    arrived = [moved.points[moved.ok]]
    partners = []
    _switches(plane, state, pts[done:][moved.ok], moved.points[moved.ok], p0, p1)
    for row in np.flatnonzero(~moved.ok):
        t_at = moved.reached[row]
        state.throughs += 1
        end, z, folds = through(plane, p0, p1, moved.points[row], t_at)
        state.seeds += folds
        if end == "far":
            arrived.append(z[None, :])
        elif end == "back":
            partners.append(z[None, :])
        else:
            state.lost.append({"x": float(p0[0]), "y": float(p0[1]), "towards": p1.tolist(),
                               "at": float(t_at), "why": end})  # fmt: skip
    added = _add(plane, state, there, np.vstack(arrived), p1, axis)
    back = _add(plane, state, here, np.vstack(partners), p0, axis) if partners else 0
    state.pushed[(here, axis, sign)] += back  # a partner came from there: not sent back to it
    return bool(added or back)


def _line_eqs(plane: ChartPlane, p0: np.ndarray, p1: np.ndarray):
    """curve_trace Equations of the equilibria on the segment p(t) = p0 + t (p1 - p0)."""
    n, d = plane.n, p1 - p0

    def eqs(z: np.ndarray, zref: np.ndarray):
        if not -0.5 <= z[n] <= 1.5:  # a Newton iterate far off the segment: a failed step
            return np.full(n, np.nan), np.full((n, n + 1), np.nan)
        p = p0 + z[n] * d
        g, H = plane.derivatives(z[:n], p)
        return g[0], np.hstack([H[0], plane.grad_along(z[:n], p, d)[0][:, None]])

    return eqs


def through(plane: ChartPlane, p0: np.ndarray, p1: np.ndarray, theta: np.ndarray,
            t_at: float) -> tuple[str, np.ndarray | None, list]:  # fmt: skip
    """The equilibrium at p0 + t_at (p1 - p0) followed by pseudo-arclength towards p1: ("far",
    its point at p1, seeds), ("back", the point where it came back to p0: the partner of the
    fold it turned at, seeds) or (why it stopped, None, seeds)."""
    n = plane.n
    eqs = _line_eqs(plane, p0, p1)
    win = Window(n, n, (0.0, 0.0), (1.0, 1.0), (1.0, 1.0))
    z0 = np.append(theta, t_at)
    t0 = tangent(eqs, z0, z0)
    t0 = t0 if t0[n] >= 0 else -t0
    pts, end = one_way(eqs, z0, t0, win, SPACING, HMAX, _counted(THROUGH_POINTS))
    end = "too long" if end == "left" else end
    seeds = _turns(plane, eqs, [z0, *pts], win, p0, p1)
    if not seeds and len(pts):
        seeds = _passed(plane, np.vstack([z0, pts]), p0, p1)
    if end != "edge" or not len(pts):
        return end if len(pts) else "stalled", None, seeds
    last = pts[-1]
    if abs(last[n] - 1.0) < 1e-9:
        return "far", plane.rechart(last[None, :n])[0], seeds
    if abs(last[n]) < 1e-9:
        return "back", plane.rechart(last[None, :n])[0], seeds
    return "edge", None, seeds


def _counted(most: int):
    """A curve_trace `keep` that stops a trace after `most` points (a branch that wanders
    without leaving its grid step: a continuum, or a loop)."""
    seen = [0]

    def keep(z: np.ndarray) -> bool:
        seen[0] += 1
        return seen[0] <= most

    return keep


def _turns(plane: ChartPlane, eqs, pts: list, win: Window, p0, p1) -> list[Seed]:
    """The turning points of the traced line curve `pts` (where t turns back), refined, as
    fold seeds (switch seeds when a cable is at its free length there: a nonsmooth fold)."""
    n = plane.n
    t = np.array([z[n] for z in pts])
    dt = np.diff(t)
    seeds = []
    for k in np.flatnonzero(dt[1:] * dt[:-1] < 0) + 1:
        z = turning_point(eqs, pts[k - 1], pts[k + 1], np.array([1.0, 0.0]), win, TURN_HALVINGS)
        if z is None:
            z = pts[k]
        p = p0 + z[n] * (p1 - p0)
        theta = plane.rechart(z[None, :n])[0]
        margin = plane.margins(theta[None], p)[0]
        at = int(np.argmin(np.abs(margin))) if len(margin) else -1
        if at >= 0 and abs(margin[at]) < 1e-6:
            seeds.append(Seed("cable_switch", np.concatenate([theta, p]), plane.cables[at]))
        else:
            seeds.append(Seed("fold", np.concatenate([theta, p])))
    return seeds


def _passed(plane: ChartPlane, pts: np.ndarray, p0, p1) -> list[Seed]:
    """Where a traced line curve `pts` that did not turn changes its Morse index: H singular
    with the branch passing (a pitchfork, where a symmetric branch meets the pair its symmetry
    breaks into, e.g. the prism's flat poses and their mirror images), as a fold seed (the
    point of the curve nearest singular; the fold system holds there too)."""
    n = plane.n
    ps = [p0 + z[n] * (p1 - p0) for z in pts]
    got = [plane.index(z[None, :n], p) for z, p in zip(pts, ps, strict=True)]
    index = np.concatenate([i for i, _ in got])
    near = np.abs(np.concatenate([e for _, e in got]))
    seeds = []
    for k in np.flatnonzero(index[1:] != index[:-1]):
        j = k if near[k] < near[k + 1] else k + 1
        theta = plane.rechart(pts[j][None, :n])[0]
        seeds.append(Seed("fold", np.concatenate([theta, ps[j]])))
    return seeds


def _switches(plane: ChartPlane, state: _State, a: np.ndarray, b: np.ndarray, p0, p1) -> None:
    """Switch seeds where a cable's state differs between the ends of followed steps a -> b."""
    if not len(a):
        return
    m0, m1 = plane.margins(a, p0), plane.margins(b, p1)
    for row, col in zip(*np.nonzero((m0 > 0) != (m1 > 0)), strict=True):
        seed = _switch_point(plane, a[row], p0, p1, col, (m0[row, col], m1[row, col]))
        if seed is not None:
            state.seeds.append(seed)


def _switch_point(plane: ChartPlane, theta, p0, p1, col: int, ends) -> Seed | None:
    """Where the branch from theta (at p0) has cable `col` at its free length: regula falsi
    (Illinois) on the fraction of the step, each value reached by `advance` from p0."""
    lo, hi, f_lo, f_hi = 0.0, 1.0, float(ends[0]), float(ends[1])
    best = None
    for _ in range(SECANT_STEPS):
        s = (lo * f_hi - hi * f_lo) / (f_hi - f_lo) if f_hi != f_lo else 0.5 * (lo + hi)
        p = p0 + s * (p1 - p0)
        moved = advance(plane, theta[None], p0, p)
        if not moved.ok[0]:
            return None
        f = float(plane.margins(moved.points, p)[0, col])
        best = (moved.points[0], p)
        if abs(f) < SWITCH_TOL:
            break
        if (f > 0) == (f_lo > 0):
            lo, f_lo, f_hi = s, f, f_hi / 2
        else:
            hi, f_hi, f_lo = s, f, f_lo / 2
    if best is None:
        return None
    return Seed("cable_switch", np.concatenate(best), plane.cables[col])


def anchor_task(task: tuple) -> dict:
    """One anchor's search (a worker's task: framework, grid index, budget in seconds): its
    chart roots (and, as the solve does, critical points Newton finds next to cone points or in
    boxes left undecided) and what the search decided."""
    from ..boxsearch.box_shares import split_search
    from ..boxsearch.boxes import MIN_WIDTH, SHORT
    from ..boxsearch.real_route import landscape
    from ..boxsearch.seeds import critical_seeds

    fw, key, seconds = task
    t0 = time.perf_counter()
    found = split_search(landscape, fw, SHORT, MIN_WIDTH, max_seconds=seconds,
                         label=f"anchor search of {fw.name}")  # fmt: skip
    land = landscape(fw)
    near = [critical_seeds(land, found.undecided), critical_seeds(land, found.set_aside_boxes)]
    seeds = land.fresh(np.vstack(near), found.roots)
    proved = not len(found.undecided) and not found.budget_hit
    return {"key": key, "roots": np.vstack([found.roots, seeds]), "proved": proved,
            "boxes": int(found.boxes), "seconds": time.perf_counter() - t0,
            "undecided": found.undecided_share, "set_aside": int(found.set_aside)}  # fmt: skip


def anchor_jobs(fw: Framework, x: str, xs, y: str, ys, per_axis: int,
                seconds: float | None) -> list[tuple]:  # fmt: skip
    """The anchors' tasks: (framework at the grid point, (i, j), budget)."""
    return [(fw.replace(**{x: float(xs[i]), y: float(ys[j])}), (i, j), seconds)
            for i in anchor_indices(len(xs), per_axis)
            for j in anchor_indices(len(ys), per_axis)]  # fmt: skip
