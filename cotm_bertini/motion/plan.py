"""A plan between two stable states: an actuator path over a map's grid that takes the
mechanism from one state to the other and returns the actuators to where they started.

The graph's nodes are (grid point, stable state there), the state named by the map's 2-D sweep
row it is (its pose within MATCH of that row's), so a region's states are the sweep's. An edge
is one grid step to a 4-neighbour, and what happens on it is not guessed from the map's curves
but simulated: the follower (follow.py) moves the state along the step, through any fold or
cable switch, to the state it is in at the neighbour. The path is the shortest by number of
snaps, then by actuator travel (each axis in units of its window), found by Dijkstra's
algorithm from the start state (carried from the start values to the nearest grid point) to
any state at that grid point that the step back to the start values leaves in the goal. Its
staircases are then cut short: a straight move replaces a run of grid steps wherever the
follower shows it ends in the same state with the same snaps.
"""

from __future__ import annotations

import heapq
import itertools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..analysis.barriers import Flow
from ..errors import ParameterError
from ..progress import Progress
from .follow import follow
from .path import ActuatorPath

MATCH = 1e-6  # a pose within this (deg, or length units) of a sweep row's is that row's state


@dataclass(frozen=True)
class Grid:
    """The map's grid: axes names and values, and its 2-D sweep's stable rows by grid index
    (`point`: the first axis slowest)."""

    names: tuple[str, str]
    xs: np.ndarray
    ys: np.ndarray
    stable: dict[int, pd.DataFrame]
    pose: list[str]  # the columns that place the mechanism
    length: float  # the model's length unit

    def values(self, i: int, j: int) -> dict[str, float]:
        """The parameter values at grid point (i, j)."""
        return {self.names[0]: float(self.xs[i]), self.names[1]: float(self.ys[j])}

    def nearest(self, values: dict[str, float]) -> tuple[int, int]:
        """The grid point nearest the values (in window units)."""
        x, y = values[self.names[0]], values[self.names[1]]
        return int(np.argmin(np.abs(self.xs - x))), int(np.argmin(np.abs(self.ys - y)))


@dataclass(frozen=True)
class Planned:
    """The grid path found (empty: none), its snaps and travel, and the search's work."""

    waypoints: list[dict[str, float]]
    snaps: int
    travel: float
    expanded: int
    steps_simulated: int
    unlisted: int  # states the follower reached that the map's sweep does not list


def plan_path(
    flow_at: Callable[[dict[str, float]], Flow],
    grid: Grid,
    start: dict[str, float],
    x0: np.ndarray,
    is_goal: Callable[[np.ndarray], bool],
    progress: bool = False,
) -> Planned:
    """The fewest-snaps, then shortest, grid path from the state x0 at `start` that ends back
    at `start` in a state `is_goal` accepts (see the module docstring)."""
    search = _Search(flow_at, grid)
    g0 = grid.nearest(start)
    first = search.step(start, grid.values(*g0), x0)
    if first is None:
        return Planned([], 0, 0.0, 0, search.simulated, search.unlisted)
    x, snaps = first
    key0 = (*g0, search.identify(g0, x))
    best, states = {key0: (snaps, 0.0)}, {key0: x}
    came: dict[tuple, tuple | None] = {key0: None}
    counter = itertools.count()
    heap = [(snaps, 0.0, next(counter), key0, x)]
    with Progress("plan", None, "states", force=progress) as report:
        while heap:
            snaps, travel, _, key, x = heapq.heappop(heap)
            if best.get(key, (np.inf, np.inf)) < (snaps, travel):
                continue
            report.update(1)
            if key[:2] == g0:
                back = search.step(grid.values(*g0), start, x)
                if back is not None and is_goal(back[0]):
                    kept = search.shortcut(_chain(came, key), states, best)
                    path = _distinct([start, *(grid.values(*k[:2]) for k in kept), start])
                    return Planned(path, snaps + back[1], _travel(path, grid), report.done,
                                   search.simulated, search.unlisted)  # fmt: skip
            for nxt in _neighbours(key[:2], grid):
                moved = search.step(grid.values(*key[:2]), grid.values(*nxt), x)
                if moved is None:
                    continue
                y, n = moved
                cost = (snaps + n, travel + _length(key[:2], nxt, grid))
                nkey = (*nxt, search.identify(nxt, y))
                if cost < best.get(nkey, (np.inf, np.inf)):
                    best[nkey], came[nkey], states[nkey] = cost, key, y
                    heapq.heappush(heap, (*cost, next(counter), nkey, y))
    return Planned([], 0, 0.0, report.done, search.simulated, search.unlisted)


class _Search:
    """The follower over one grid step, and the names of the states it ends in."""

    def __init__(self, flow_at, grid: Grid):
        self.flow_at, self.grid = flow_at, grid
        self.simulated = self.unlisted = 0
        self._extra: dict[tuple[int, int], list[np.ndarray]] = {}

    def step(self, a: dict, b: dict, x: np.ndarray) -> tuple[np.ndarray, int] | None:
        """The state after moving the parameters from a to b, and the snaps on the way (None:
        x is no minimum at a, or the follower warned: a snap fell nowhere, or an end it could
        not name or a degenerate one, which a plan does not pass)."""
        if a == b:
            return x, 0
        names = tuple(a)
        path = ActuatorPath(names, np.array([[a[n] for n in names], [b[n] for n in names]]))
        self.simulated += 1
        try:
            f = follow(self.flow_at, path, x, 1)
        except ParameterError:  # x is no minimum at a (a fold's ghost on the grid)
            return None
        if f.warnings:
            return None
        return f.states[-1], len(f.snaps)

    def shortcut(self, chain: list[tuple], states: dict, best: dict) -> list[tuple]:
        """The chain's nodes kept where a straight move from one kept node to a later one ends
        in that node's state with the snaps the chain has between them (greedy, farthest
        first): the grid's staircases become straight lines, the outcome unchanged."""
        kept, i = [chain[0]], 0
        while i < len(chain) - 1:
            j = len(chain) - 1
            while j > i + 1 and not self._same(chain[i], chain[j], states, best):
                j -= 1
            kept.append(chain[j])
            i = j
        return kept

    def _same(self, a: tuple, b: tuple, states: dict, best: dict) -> bool:
        grid = self.grid
        moved = self.step(grid.values(*a[:2]), grid.values(*b[:2]), states[a])
        if moved is None:
            return False
        return moved[1] == best[b][0] - best[a][0] and self.identify(b[:2], moved[0]) == b[2]

    def identify(self, point: tuple[int, int], x: np.ndarray) -> int:
        """The solution_id of the sweep's stable row at the point that x is; a state it does not
        list gets a negative id of its own (and is counted)."""
        i, j = point
        grid = self.grid
        here = self.flow_at(grid.values(i, j))
        cols = here.columns(x[None, :])
        pose = np.array([cols[name][0] for name in grid.pose], dtype=float)
        rows = grid.stable.get(i * len(grid.ys) + j)
        if rows is not None and len(rows):
            gap = _pose_gap(rows[grid.pose].to_numpy(float), pose, grid)
            k = int(np.argmin(gap))
            if gap[k] < MATCH:
                return int(rows.solution_id.iloc[k])
        extra = self._extra.setdefault(point, [])
        for k, other in enumerate(extra):
            if _pose_gap(other[None, :], pose, grid)[0] < MATCH:
                return -(k + 1)
        extra.append(pose)
        self.unlisted += 1
        return -len(extra)


def _pose_gap(rows: np.ndarray, pose: np.ndarray, grid: Grid) -> np.ndarray:
    """The largest difference of each row's pose from `pose`: degrees for angles (modulo 360),
    the model's length unit for the rest."""
    diff = np.abs(rows - pose)
    deg = np.array([c.endswith("_deg") for c in grid.pose])
    diff[:, deg] = np.abs((diff[:, deg] + 180.0) % 360.0 - 180.0)
    diff[:, ~deg] /= grid.length
    return diff.max(axis=1)


def _neighbours(point: tuple[int, int], grid: Grid) -> list[tuple[int, int]]:
    i, j = point
    out = [(i + di, j + dj) for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1))]
    return [(a, b) for a, b in out if 0 <= a < len(grid.xs) and 0 <= b < len(grid.ys)]


def _length(a: tuple[int, int], b: tuple[int, int], grid: Grid) -> float:
    """One grid step's travel in window units."""
    if a[0] != b[0]:
        return abs(grid.xs[b[0]] - grid.xs[a[0]]) / np.ptp(grid.xs)
    return abs(grid.ys[b[1]] - grid.ys[a[1]]) / np.ptp(grid.ys)


def _distinct(points: list[dict[str, float]]) -> list[dict[str, float]]:
    """The waypoints without repeats in a row (the start may be a grid point)."""
    return [p for k, p in enumerate(points) if k == 0 or p != points[k - 1]]


def _chain(came: dict, key: tuple) -> list[tuple]:
    """The nodes from the first to `key`."""
    out = []
    while key is not None:
        out.append(key)
        key = came[key]
    return out[::-1]


def _travel(path: list[dict[str, float]], grid: Grid) -> float:
    """The path's length in window units (each axis over its window's width)."""
    pts = np.array([[p[n] for n in grid.names] for p in path])
    scale = np.array([np.ptp(grid.xs), np.ptp(grid.ys)])
    return float(np.linalg.norm(np.diff(pts, axis=0) / scale, axis=1).sum())
