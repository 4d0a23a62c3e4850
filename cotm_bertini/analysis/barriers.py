"""Energy barriers between stable states: from each saddle of index 1, gradient flow down both
sides of its unstable eigenvector to the minima it joins; the barrier of a pair of minima is the
lowest saddle joining them.

One driver for every model: a `Flow` gives the energy, its gradient in local coordinates, a
step (`move`: a retraction, back onto the constraint set for a framework), Newton's step where
the Hessian is positive definite, the shortest spring or cable, and which listed minimum a
descent ended at. The paper's mechanism has `PaperFlow` (angles on the torus); a framework has
analysis/framework_flow.FrameworkFlow (its reduced coordinates on the constraint set).

The flow is followed by steepest-descent steps of at most MAX_STEP (rad, or framework length
units), each accepted only if V decreases, then Newton's method once the Hessian is positive
definite and the Newton step is short, to the minimum to rounding. A path that passes a spring
or cable within ZERO_LENGTH (relative to the model's length) of zero length (where V has a cone
point if its L0 > 0: the flow is not smooth there) is flagged, never hidden.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import pandas as pd

from ..model.compiled import energy, energy_gradient, energy_hessian
from ..params import Params
from .classify import wrap_degrees
from .critical_points import deg_distance
from .design.free_lengths import generalised_forces

KICK = 1e-3  # rad: the first step off the saddle, along the unstable eigenvector
MAX_STEP = 0.02  # rad
MAX_STEPS = 20000
ZERO_LENGTH = 1e-3  # relative to L3 (a framework: its length unit)
MATCH_DEG = 1e-5  # a descent end within this (deg, on the torus) of a minimum is that minimum
NEWTON_RANGE = 0.1  # Newton's step is taken once it is shorter than this
STALLED = 1e-6  # a Newton step below this that no longer shrinks is rounding: converged


class Flow(Protocol):
    """What the driver needs of a model (states are numpy vectors; steps in local coordinates)."""

    newton_tol: float  # converged once Newton's step is shorter than this
    zero_length: float  # a spring shorter than this is flagged (user units)
    length_unit: float  # the model's length unit (user units)
    hessian_unit: float  # eigh's eigenvalues over this are in normalised units
    pose_names: list[str]  # the barriers.csv columns that place the saddle

    def saddles(self, solutions: pd.DataFrame) -> pd.DataFrame: ...
    def saddle(self, row) -> tuple[np.ndarray, np.ndarray, np.ndarray]: ...
    def state(self, row) -> np.ndarray: ...
    def at(self, model) -> Flow: ...
    def pose(self, row) -> dict: ...
    def energy(self, x: np.ndarray) -> float: ...
    def gradient(self, x: np.ndarray) -> np.ndarray: ...
    def newton(self, x: np.ndarray, grad: np.ndarray) -> np.ndarray | None: ...
    def eigh(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...
    def move(self, x: np.ndarray, step: np.ndarray) -> np.ndarray: ...
    def shortest(self, x: np.ndarray) -> float: ...
    def cable_gap(self, x: np.ndarray) -> float: ...
    def rows(self, path: np.ndarray) -> pd.DataFrame: ...
    def columns(self, path: np.ndarray) -> dict[str, np.ndarray]: ...
    def match(self, end: np.ndarray) -> int | None: ...
    def record(self, path: np.ndarray) -> object: ...


@dataclass(frozen=True)
class Descent:
    """One gradient-flow path from a saddle: the states, whether it converged, what it met."""

    path: np.ndarray  # (n, state size)
    converged: bool
    min_spring_length: float  # user units, along the path


def newton_done(size: float, last: float, tol: float) -> bool:
    """Newton's method has converged: its step is below `tol`, or below STALLED and no longer
    shrinking (the rounding floor of an ill-conditioned minimum, 1e-8 where the Hessian's
    condition is 1e9; a degenerate minimum's steps still shrink, by 2/3, and go on)."""
    return size < tol or (size < STALLED and size > 0.9 * last)


def descend(flow: Flow, start: np.ndarray, max_steps: int = MAX_STEPS) -> Descent:
    """Gradient flow of V from `start` to a minimum (at most `max_steps` steps)."""
    x = np.array(start, dtype=float)
    path, shortest = [x.copy()], flow.shortest(x)
    v, step, last = flow.energy(x), MAX_STEP, np.inf
    for _ in range(max_steps):
        grad = flow.gradient(x)
        newton = flow.newton(x, grad)
        if newton is not None and np.abs(newton).max() < NEWTON_RANGE:
            x = flow.move(x, newton)
            v = flow.energy(x)
            path.append(x.copy())
            shortest = min(shortest, flow.shortest(x))
            size = float(np.abs(newton).max())
            if newton_done(size, last, flow.newton_tol):
                return Descent(np.array(path), True, shortest)
            last = size
            continue
        last = np.inf
        norm = float(np.hypot.reduce(np.abs(grad)))
        if norm == 0:
            break
        while step > 1e-14:
            trial = flow.move(x, -(step * grad / norm))
            vt = flow.energy(trial)
            if vt < v:
                break
            step /= 2
        else:
            break
        x, v = trial, vt
        step = min(MAX_STEP, 2 * step)
        path.append(x.copy())
        shortest = min(shortest, flow.shortest(x))
    return Descent(np.array(path), False, shortest)


def saddle_connections(flow: Flow, solutions: pd.DataFrame,
                       max_steps: int = MAX_STEPS) -> tuple[pd.DataFrame, dict]:  # fmt: skip
    """One row per physical saddle of index 1: the minima its two descents reach, the barriers
    from each side, whether a path passes a spring of (near) zero length, and `lowest` (the
    lowest saddle joining that pair of distinct minima). Also {saddle_id: (path_a, path_b)} as
    `flow.record` gives them."""
    rows, paths = [], {}
    for _, s in flow.saddles(solutions).iterrows():
        x0, eigval, unstable = flow.saddle(s)
        v_s = flow.energy(x0)
        starts = [flow.move(x0, sign * KICK * unstable) for sign in (1, -1)]
        ends = [descend(flow, start, max_steps) for start in starts]
        ids = [flow.match(e.path[-1]) if e.converged else None for e in ends]
        energies = [flow.energy(e.path[-1]) for e in ends]
        shortest = min(e.min_spring_length for e in ends)
        rows.append(
            {
                "saddle_id": int(s.solution_id),
                "min_a": ids[0], "min_b": ids[1],
                "barrier_a": v_s - energies[0], "barrier_b": v_s - energies[1],
                **flow.pose(s),
                "saddle_energy": v_s,
                "saddle_eigenvalues": " ".join(f"{e:.6g}" for e in eigval),
                "converged": all(e.converged for e in ends),
                "crosses_zero_length": shortest < flow.zero_length,
                "min_spring_length": shortest,
            }
        )  # fmt: skip
        paths[int(s.solution_id)] = tuple(flow.record(e.path) for e in ends)
    columns = HEAD_COLUMNS + flow.pose_names + TAIL_COLUMNS
    return _mark_lowest(pd.DataFrame(rows, columns=columns)), paths


HEAD_COLUMNS = ["saddle_id", "min_a", "min_b", "barrier_a", "barrier_b"]
TAIL_COLUMNS = [
    "saddle_energy", "saddle_eigenvalues", "converged", "crosses_zero_length",
    "min_spring_length",
]  # fmt: skip


def _mark_lowest(table: pd.DataFrame) -> pd.DataFrame:
    table = table.astype({"min_a": "Int64", "min_b": "Int64"})
    pair = [
        tuple(sorted((int(a), int(b)))) if pd.notna(a) and pd.notna(b) and a != b else None
        for a, b in zip(table.min_a, table.min_b, strict=True)
    ]
    lowest = np.zeros(len(table), dtype=bool)
    for key in {p for p in pair if p is not None}:
        idx = [i for i, p in enumerate(pair) if p == key]
        lowest[min(idx, key=lambda i: table.saddle_energy.iloc[i])] = True
    return table.assign(lowest=lowest)


class PaperFlow:
    """The paper's mechanism: states are (gamma1, gamma2) in rad, unwrapped on the torus."""

    newton_tol = 1e-13
    pose_names = ["saddle_gamma1_deg", "saddle_gamma2_deg"]

    def __init__(self, params: Params, solutions: pd.DataFrame):
        self._values(params)
        phys = solutions[solutions.physical.astype(bool)]
        self.minima = phys[phys.kind == "min"]

    def _values(self, params: Params) -> None:
        self.params = params
        self.length_unit = params.L3
        self.zero_length = ZERO_LENGTH * params.L3
        self.hessian_unit = max(params.k1, params.k2) * params.L3**2  # J/rad^2

    def at(self, params: Params) -> PaperFlow:
        """The same flow at other parameter values (states carry over: angles)."""
        out = copy.copy(self)
        out._values(params)
        return out

    def saddles(self, solutions: pd.DataFrame) -> pd.DataFrame:
        """The physical saddles (on the torus every saddle has index 1)."""
        phys = solutions[solutions.physical.astype(bool)]
        return phys[phys.kind == "saddle"]

    def saddle(self, row) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The saddle's angles (rad), Hessian eigenvalues and unstable eigenvector."""
        x0 = self.state(row)
        eigval, eigvec = self.eigh(x0)
        return x0, eigval, eigvec[:, 0]

    def state(self, row) -> np.ndarray:
        """A solutions row's angles (rad)."""
        return np.radians([float(row.gamma1_deg), float(row.gamma2_deg)])

    def eigh(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Eigenvalues (ascending, J/rad^2) and eigenvectors of the Hessian of V."""
        return np.linalg.eigh(energy_hessian(self.params, x[0], x[1])[0])

    def pose(self, row) -> dict:
        """The saddle's barriers.csv pose columns."""
        return {"saddle_gamma1_deg": float(row.gamma1_deg),
                "saddle_gamma2_deg": float(row.gamma2_deg)}  # fmt: skip

    def energy(self, x: np.ndarray) -> float:
        """V (J)."""
        return float(energy(self.params, *x))

    def gradient(self, x: np.ndarray) -> np.ndarray:
        """dV/dgamma (J/rad)."""
        return energy_gradient(self.params, x[0], x[1])[0]

    def newton(self, x: np.ndarray, grad: np.ndarray) -> np.ndarray | None:
        """The Newton step where the Hessian is positive definite, else None."""
        eig, vec = self.eigh(x)
        if eig.min() <= 0:
            return None
        return -vec @ ((vec.T @ grad) / eig)

    def move(self, x: np.ndarray, step: np.ndarray) -> np.ndarray:
        """Angles are their own coordinates."""
        return x + step

    def shortest(self, x: np.ndarray) -> float:
        """The shorter spring (m)."""
        return float(generalised_forces(self.params, x[0], x[1])[1].min())

    def cable_gap(self, x: np.ndarray) -> float:
        """No cables: nothing switches."""
        return np.inf

    def rows(self, path: np.ndarray) -> pd.DataFrame:
        """States as solutions.csv-style rows: the angles (deg, wrapped), d1, d2 (m), V (J)."""
        return pd.DataFrame(self.columns(path))

    def columns(self, path: np.ndarray) -> dict[str, np.ndarray]:
        """The columns of `rows`, as numpy arrays."""
        path = np.atleast_2d(path)
        d = generalised_forces(self.params, path[:, 0], path[:, 1])[1]
        deg = wrap_degrees(np.degrees(path))
        return {"gamma1_deg": deg[:, 0], "gamma2_deg": deg[:, 1], "d1": d[0], "d2": d[1],
                "energy": np.array([self.energy(x) for x in path])}  # fmt: skip

    def match(self, end: np.ndarray) -> int | None:
        """The solution_id of the minimum the descent ended at (None: not a listed minimum)."""
        if self.minima.empty:
            return None
        angles = self.minima[["gamma1_deg", "gamma2_deg"]].to_numpy(float)
        dist = deg_distance(np.degrees(end), angles)
        k = int(np.argmin(dist))
        return int(self.minima.solution_id.iloc[k]) if dist[k] < MATCH_DEG else None

    def record(self, path: np.ndarray) -> np.ndarray:
        """A path in degrees (unwrapped)."""
        return np.degrees(path)
