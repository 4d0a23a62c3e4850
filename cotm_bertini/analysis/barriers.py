"""Energy barriers between stable states: from each saddle, gradient flow down both sides of its
unstable eigenvector to the minima it joins; the barrier of a pair of minima is the lowest
saddle joining them.

The flow is followed by steepest-descent steps of at most MAX_STEP rad (each accepted only if V
decreases), then Newton's method once the Hessian is positive definite and the Newton step is
short, to the minimum to rounding. A path that passes a spring within ZERO_LENGTH L3 of zero
length (where V has a cone point if that spring's L0 > 0: the flow is not smooth there) is
flagged, never hidden.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..model.compiled import energy, energy_gradient, energy_hessian
from ..params import Params
from .critical_points import deg_distance
from .design import generalised_forces

KICK = 1e-3  # rad: the first step off the saddle, along the unstable eigenvector
MAX_STEP = 0.02  # rad
MAX_STEPS = 20000
ZERO_LENGTH = 1e-3  # relative to L3
MATCH_DEG = 1e-5  # a descent end within this (deg, on the torus) of a minimum is that minimum


@dataclass(frozen=True)
class Descent:
    """One gradient-flow path from a saddle: angles (rad, unwrapped), its end, what it met."""

    path: np.ndarray  # (n, 2)
    converged: bool
    min_spring_length: float  # m, along the path


def _shortest_spring(params: Params, x: np.ndarray) -> float:
    return float(generalised_forces(params, x[0], x[1])[1].min())


def _newton_step(params: Params, x: np.ndarray, grad: np.ndarray) -> np.ndarray | None:
    """The Newton step where the Hessian is positive definite, else None."""
    hess = energy_hessian(params, x[0], x[1])[0]
    if np.linalg.eigvalsh(hess).min() <= 0:
        return None
    return -np.linalg.solve(hess, grad)


def descend(params: Params, start: np.ndarray) -> Descent:
    """Gradient flow of V from `start` (rad) to a minimum."""
    x = np.array(start, dtype=float)
    path, shortest = [x.copy()], _shortest_spring(params, x)
    v, step = float(energy(params, *x)), MAX_STEP
    for _ in range(MAX_STEPS):
        grad = energy_gradient(params, x[0], x[1])[0]
        newton = _newton_step(params, x, grad)
        if newton is not None and np.abs(newton).max() < 0.1:
            x = x + newton
            v = float(energy(params, *x))
            path.append(x.copy())
            shortest = min(shortest, _shortest_spring(params, x))
            if np.abs(newton).max() < 1e-13:
                return Descent(np.array(path), True, shortest)
            continue
        norm = float(np.hypot(*grad))
        if norm == 0:
            break
        while step > 1e-14:
            trial = x - step * grad / norm
            vt = float(energy(params, *trial))
            if vt < v:
                break
            step /= 2
        else:
            break
        x, v = trial, vt
        step = min(MAX_STEP, 2 * step)
        path.append(x.copy())
        shortest = min(shortest, _shortest_spring(params, x))
    return Descent(np.array(path), False, shortest)


def _match(end: np.ndarray, minima: pd.DataFrame) -> int | None:
    """The solution_id of the minimum the descent ended at (None: not a listed minimum)."""
    if minima.empty:
        return None
    angles = minima[["gamma1_deg", "gamma2_deg"]].to_numpy(float)
    dist = deg_distance(np.degrees(end), angles)
    k = int(np.argmin(dist))
    return int(minima.solution_id.iloc[k]) if dist[k] < MATCH_DEG else None


def saddle_connections(params: Params, solutions: pd.DataFrame) -> tuple[pd.DataFrame, dict]:
    """One row per physical saddle: the minima its two descents reach, the barriers from each
    side, whether a path passes a spring of (near) zero length, and `lowest` (the lowest saddle
    joining that pair of distinct minima). Also {saddle_id: (path_a, path_b)} in degrees."""
    phys = solutions[solutions.physical.astype(bool)]
    minima = phys[phys.kind == "min"]
    rows, paths = [], {}
    for _, s in phys[phys.kind == "saddle"].iterrows():
        x0 = np.radians([s.gamma1_deg, s.gamma2_deg])
        eigval, eigvec = np.linalg.eigh(energy_hessian(params, x0[0], x0[1])[0])
        v_s = float(energy(params, *x0))
        ends = [descend(params, x0 + sign * KICK * eigvec[:, 0]) for sign in (1, -1)]
        ids = [_match(e.path[-1], minima) if e.converged else None for e in ends]
        energies = [float(energy(params, *e.path[-1])) for e in ends]
        rows.append(
            {
                "saddle_id": int(s.solution_id),
                "min_a": ids[0], "min_b": ids[1],
                "barrier_a": v_s - energies[0], "barrier_b": v_s - energies[1],
                "saddle_gamma1_deg": float(s.gamma1_deg),
                "saddle_gamma2_deg": float(s.gamma2_deg),
                "saddle_energy": v_s,
                "saddle_eigenvalues": f"{eigval[0]:.6g} {eigval[1]:.6g}",
                "converged": all(e.converged for e in ends),
                "crosses_zero_length": min(e.min_spring_length for e in ends)
                < ZERO_LENGTH * params.L3,
                "min_spring_length": min(e.min_spring_length for e in ends),
            }
        )  # fmt: skip
        paths[int(s.solution_id)] = tuple(np.degrees(e.path) for e in ends)
    return _mark_lowest(pd.DataFrame(rows, columns=BARRIER_COLUMNS)), paths


BARRIER_COLUMNS = [
    "saddle_id", "min_a", "min_b", "barrier_a", "barrier_b", "saddle_gamma1_deg",
    "saddle_gamma2_deg", "saddle_energy", "saddle_eigenvalues", "converged",
    "crosses_zero_length", "min_spring_length",
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
