"""Turn solver endpoints into solutions: merge, refine, and classify real, physical, stable."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..backends.endpoints import Endpoints
from ..model.compiled import polynomial_system
from ..model.kinematics import spring_vectors
from ..params import Params
from ..settings import Tolerances
from .cluster import cluster_endpoints
from .mechanics import add_mechanics, paper_criterion
from .refine import newton_refine, snap_zero_length

COLUMNS = [
    "solution_id",
    "gamma1_deg",
    "gamma2_deg",
    "d1",
    "d2",
    "is_real",
    "max_imag",
    "physical",
    "stable",
    "residual",
    "condition_number",
    "multiplicity",
    "reason",
    "singular",
    "jacobian_condition",
    "kind",
    "energy",
    "hess_eig1",
    "hess_eig2",
    "spring1_force",
    "spring2_force",
    "rod_force",
    "tensegrity",
    "paper_stable",
    "gamma1_imag_deg",
    "gamma2_imag_deg",
    "paths",
]


def complex_angles(c: np.ndarray, s: np.ndarray) -> np.ndarray:
    """gamma = -i log(c + i s), in degrees: real for points on the real circle."""
    return (-1j * np.log(c + 1j * s)) * (180.0 / np.pi)


def wrap_degrees(angle: np.ndarray, digits: int | None = None) -> np.ndarray:
    """Angles in [0, 360); with `digits`, rounded first, so 359.99999 never prints as 360.0."""
    a = np.mod(np.asarray(angle, dtype=float), 360.0)
    if digits is not None:
        a = np.mod(np.round(a, digits), 360.0)
    return np.where(a >= 360.0, 0.0, a)


@dataclass(frozen=True)
class _Merged:
    """The distinct solutions of a set of endpoints (normalised units)."""

    x: np.ndarray  # refined point of each solution
    multiplicity: np.ndarray
    paths: list[str]
    condition_number: np.ndarray
    jacobian_condition: np.ndarray
    singular: np.ndarray
    accuracy: np.ndarray


def _merge(params: Params, endpoints: Endpoints, tol: Tolerances) -> _Merged:
    """Snap, Newton-refine and cluster the endpoints into distinct solutions."""
    system = polynomial_system(params.normalized())
    is_d = np.array([v.startswith("d") for v in endpoints.variables])
    x0 = np.where(is_d, endpoints.points / params.L3, endpoints.points)
    acc = np.nan_to_num(endpoints.accuracy_estimate, nan=0.0)
    x0, snapped = snap_zero_length(params, endpoints.variables, x0, tol.snap)
    x, res = newton_refine(system, x0, tol.newton_steps if len(x0) else 0)
    # Our own condition number at the refined point: Bertini's estimate is taken wherever its
    # endgame stopped and varies by orders of magnitude between runs near a singular root.
    jac_cond = np.linalg.cond(system.jacobian(x)) if len(x) else np.zeros(0)
    jac_cond = np.where(np.isfinite(jac_cond), jac_cond, np.inf)
    singular = (jac_cond > tol.singular_condition) | (endpoints.bertini_multiplicity > 1) | snapped
    labels = cluster_endpoints(x, singular, acc, tol.merge)
    groups = [np.flatnonzero(labels == g) for g in range(labels.max() + 1 if len(labels) else 0)]
    best = np.array([m[np.argmin(res[m])] for m in groups], dtype=int)
    return _Merged(
        x=x[best] if len(best) else np.zeros((0, len(endpoints.variables)), complex),
        multiplicity=np.array([len(m) for m in groups], dtype=int),
        paths=[" ".join(str(int(p)) for p in endpoints.path_number[m]) for m in groups],
        condition_number=np.array([endpoints.condition_number[m].max() for m in groups]),
        jacobian_condition=np.array([jac_cond[m].min() for m in groups]),
        singular=np.array([bool(singular[m].any() or len(m) > 1) for m in groups], dtype=bool),
        accuracy=np.array([acc[m].max() for m in groups]),
    )


def classify(params: Params, endpoints: Endpoints, tol: Tolerances = Tolerances()) -> pd.DataFrame:
    """One row per distinct finite solution with the solutions.csv columns (docs/columns.md).

    The numerics (Newton refinement, condition numbers, merging, realness) run in units of L3
    and max(k1, k2), where every quantity is of order one whatever the user's units.
    """
    variables = endpoints.variables
    merged = _merge(params, endpoints, tol)
    if not len(merged.x):
        return empty_solutions(variables)
    system = polynomial_system(params.normalized())
    absres = np.abs(system.evaluate(merged.x)).max(axis=1)
    is_d = np.array([v.startswith("d") for v in variables])
    pts = np.where(is_d, merged.x * params.L3, merged.x)
    v = {name: pts[:, k] for k, name in enumerate(variables)}
    gam1, gam2 = complex_angles(v["c1"], v["s1"]), complex_angles(v["c2"], v["s2"])
    unit = np.where(is_d, params.L3, 1.0)
    max_imag = (np.abs(pts.imag) / (unit + np.abs(pts.real))).max(axis=1)
    # A singular root is known to about sqrt(accuracy) only: so is its imaginary part.
    loose = np.minimum(10.0 * np.sqrt(np.maximum(merged.accuracy, 1e-16)), 1e-4)
    is_real = max_imag < np.where(merged.singular, np.maximum(loose, tol.imag), tol.imag)
    g1r, g2r = np.radians(gam1.real), np.radians(gam2.real)
    vec = spring_vectors(params, np.cos(g1r), np.sin(g1r), np.cos(g2r), np.sin(g2r))
    d = {i: v[f"d{i}"].real if f"d{i}" in v else np.hypot(*vec[f"spring{i}"]) for i in (1, 2)}
    frame = pd.DataFrame(
        {
            "solution_id": np.arange(1, len(pts) + 1),
            "gamma1_deg": wrap_degrees(gam1.real),
            "gamma2_deg": wrap_degrees(gam2.real),
            "gamma1_imag_deg": gam1.imag,
            "gamma2_imag_deg": gam2.imag,
            "d1": d[1],
            "d2": d[2],
            "is_real": is_real,
            "max_imag": max_imag,
        }
    )
    _physical_columns(frame, params, v, d, is_real, tol)
    frame["residual"] = absres
    frame["condition_number"] = merged.condition_number
    frame["jacobian_condition"] = merged.jacobian_condition
    frame["multiplicity"] = merged.multiplicity
    frame["singular"] = merged.singular
    physical = frame["physical"].to_numpy()
    add_mechanics(frame, params, g1r, g2r, vec, physical & ~merged.singular, tol.hessian)
    frame["paper_stable"] = paper_criterion(params, frame)
    frame["paths"] = merged.paths
    for name in variables:
        frame[f"{name}_re"] = v[name].real
        frame[f"{name}_im"] = v[name].imag
    return _order(frame)


def _physical_columns(frame, params, v, d, is_real, tol: Tolerances) -> None:
    """`reason` and `physical`: real, both spring lengths > 0, not a d = 0 artefact."""
    zero = np.zeros(len(frame), dtype=bool)
    for i in (1, 2):
        if f"d{i}" in v:
            # d = 0 with L0 > 0 is never an equilibrium (the force direction is undefined):
            # the double roots where one spring collapses, and the complex points where both do.
            zero |= np.abs(v[f"d{i}"]) < tol.zero_length * params.L3
    negative = is_real & ((d[1] <= 0) | (d[2] <= 0)) & ~zero
    frame["reason"] = np.select(
        [zero, ~is_real, negative], ["zero_length_spring", "complex", "negative_d"], default=""
    )
    frame["physical"] = is_real & ~zero & ~negative


def _order(frame: pd.DataFrame) -> pd.DataFrame:
    # Physical first, then real, then complex; within each by angle, so ids are stable. Angles
    # are rounded to 1e-9 deg so that a conjugate pair (equal real parts up to rounding) is
    # always ordered by its imaginary part, whichever run produced it.
    key = np.where(frame["physical"], 0, np.where(frame["is_real"], 1, 2))
    sort = frame.assign(
        _k=key,
        _g1=wrap_degrees(frame["gamma1_deg"].to_numpy(), 9),
        _g2=wrap_degrees(frame["gamma2_deg"].to_numpy(), 9),
        _i1=np.round(frame["gamma1_imag_deg"].to_numpy(), 9),
        _i2=np.round(frame["gamma2_imag_deg"].to_numpy(), 9),
    )
    cols = ["_k", "_g1", "_g2", "_i1", "_i2"]
    frame = sort.sort_values(cols, kind="stable").drop(columns=cols).reset_index(drop=True)
    frame["solution_id"] = np.arange(1, len(frame) + 1)
    rest = [c for c in frame.columns if c not in COLUMNS]
    return frame[COLUMNS + rest]


def empty_solutions(variables: tuple[str, ...]) -> pd.DataFrame:
    """A solutions table with no rows (every column present)."""
    cols = COLUMNS + [f"{n}_{p}" for n in variables for p in ("re", "im")]
    return pd.DataFrame({c: pd.Series(dtype=float) for c in cols})


def read_table(path) -> pd.DataFrame:
    """A solutions (or sweep) table read back from CSV with the dtypes a fresh solve gives."""
    table = pd.read_csv(path)
    for col in ("reason", "kind"):
        table[col] = table[col].fillna("").astype(str)
    table["paths"] = table["paths"].astype(str)
    if "lost_paths" in table:
        table["lost_paths"] = table["lost_paths"].astype("Int64")
    return table
