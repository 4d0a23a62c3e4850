"""Turn solver endpoints into solutions: merge, refine, and classify real, physical, stable."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..backends.endpoints import Endpoints
from ..model.compiled import polynomial_system
from ..model.kinematics import spring_vectors
from ..model.polynomial import PolySystem
from ..params import Params
from ..settings import Tolerances
from .cluster import cluster_endpoints
from .mechanics import mechanics, paper_criterion
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
class Merged:
    """The distinct solutions of a set of endpoints (normalised units)."""

    x: np.ndarray  # refined point of each solution
    multiplicity: np.ndarray
    paths: list[str]
    condition_number: np.ndarray
    jacobian_condition: np.ndarray
    singular: np.ndarray
    accuracy: np.ndarray


def _merge(params: Params, system: PolySystem, endpoints: Endpoints, tol: Tolerances) -> Merged:
    """Snap, Newton-refine and cluster the endpoints into distinct solutions."""
    is_d = np.array([v.startswith("d") for v in endpoints.variables])
    x0 = np.where(is_d, endpoints.points / params.L3, endpoints.points)
    x0, snapped = snap_zero_length(params, endpoints.variables, x0, tol.snap)
    return merge_endpoints(system, x0, endpoints, tol, snapped)


def merge_endpoints(
    system: PolySystem,
    x0: np.ndarray,
    endpoints: Endpoints,
    tol: Tolerances,
    snapped: np.ndarray | None = None,
    scaled: bool = False,
) -> Merged:
    """Newton-refine endpoints `x0` (normalised units) and cluster them into distinct solutions;
    `snapped` marks points put exactly on a known singular root (not refined, singular);
    `scaled`: judge singularity on the equilibrated Jacobian (frameworks, whose force densities
    range widely)."""
    snapped = np.zeros(len(x0), dtype=bool) if snapped is None else snapped
    acc = np.nan_to_num(endpoints.accuracy_estimate, nan=0.0)
    # The snapped points are exact (and exactly singular): Newton has nothing to do there.
    x, res = x0.copy(), np.zeros(len(x0))
    if (~snapped).any():
        x[~snapped], res[~snapped] = newton_refine(system, x0[~snapped], tol.newton_steps)
    # Our own condition number at the refined point: Bertini's estimate is taken wherever its
    # endgame stopped and varies by orders of magnitude between runs near a singular root.
    jac_cond = (
        np.linalg.cond(_equilibrated(system.jacobian(x), x, scaled)) if len(x) else np.zeros(0)
    )
    jac_cond = np.where(np.isfinite(jac_cond), jac_cond, np.inf)
    singular = (jac_cond > tol.singular_condition) | (endpoints.bertini_multiplicity > 1) | snapped
    labels = cluster_endpoints(x, singular, acc, tol.merge)
    if np.array_equal(labels, np.arange(len(labels))):  # every endpoint its own solution
        paths = [str(int(p)) for p in endpoints.path_number]
        return Merged(x, np.ones(len(x), dtype=int), paths, np.asarray(endpoints.condition_number,
                      dtype=float), jac_cond, singular.astype(bool), acc)  # fmt: skip
    groups = [np.flatnonzero(labels == g) for g in range(labels.max() + 1 if len(labels) else 0)]
    best = np.array([m[np.argmin(res[m])] for m in groups], dtype=int)
    return Merged(
        x=x[best] if len(best) else np.zeros((0, len(endpoints.variables)), complex),
        multiplicity=np.array([len(m) for m in groups], dtype=int),
        paths=[" ".join(str(int(p)) for p in endpoints.path_number[m]) for m in groups],
        condition_number=np.array([endpoints.condition_number[m].max() for m in groups]),
        jacobian_condition=np.array([jac_cond[m].min() for m in groups]),
        singular=np.array([bool(singular[m].any() or len(m) > 1) for m in groups], dtype=bool),
        accuracy=np.array([acc[m].max() for m in groups]),
    )


def _equilibrated(jac: np.ndarray, x: np.ndarray, scaled: bool) -> np.ndarray:
    """With `scaled`, the Jacobian in relative variables (columns times max(1, |x_j|)) with unit
    rows: a force density of 1e3 near a spring of almost zero length is not a singularity."""
    if not scaled:
        return jac
    jac = jac * np.maximum(1.0, np.abs(x))[:, None, :]
    norms = np.linalg.norm(jac, axis=2, keepdims=True)
    return jac / np.where(norms > 0, norms, 1.0)


def classify(params: Params, endpoints: Endpoints, tol: Tolerances = Tolerances()):
    """One row per distinct finite solution with the solutions.csv columns (a DataFrame)."""
    import pandas as pd  # only here: the solve path works on numpy columns

    return pd.DataFrame(classify_columns(params, endpoints, tol))


def classify_columns(
    params: Params, endpoints: Endpoints, tol: Tolerances = Tolerances()
) -> dict[str, np.ndarray]:
    """The solutions table as numpy columns (COLUMNS, then `<var>_re`, `<var>_im`), ordered.

    The numerics (Newton refinement, condition numbers, merging, realness) run in units of L3
    and max(k1, k2), where every quantity is of order one whatever the user's units.
    """
    variables = endpoints.variables
    system = polynomial_system(params.normalized())
    merged = _merge(params, system, endpoints, tol)
    if not len(merged.x):
        return empty_columns(variables)
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
    cols: dict[str, np.ndarray] = {
        "solution_id": np.arange(1, len(pts) + 1),
        "gamma1_deg": wrap_degrees(gam1.real),
        "gamma2_deg": wrap_degrees(gam2.real),
        "d1": d[1],
        "d2": d[2],
        "is_real": is_real,
        "max_imag": max_imag,
        "residual": np.abs(system.evaluate(merged.x)).max(axis=1),
        "condition_number": merged.condition_number,
        "multiplicity": merged.multiplicity,
        "singular": merged.singular,
        "jacobian_condition": merged.jacobian_condition,
        "gamma1_imag_deg": gam1.imag,
        "gamma2_imag_deg": gam2.imag,
        "paths": np.array(merged.paths, dtype=object),
    }
    cols.update(_physical_columns(params, v, d, is_real, merged.singular, tol))
    stable_ok = cols["physical"] & ~merged.singular
    cols.update(mechanics(params, cols["physical"], g1r, g2r, vec, stable_ok, tol.hessian))
    cols["paper_stable"] = paper_criterion(params, cols)
    for name in variables:
        cols[f"{name}_re"] = v[name].real
        cols[f"{name}_im"] = v[name].imag
    return _order(cols, variables)


def _physical_columns(params, v, d, is_real, singular, tol: Tolerances) -> dict[str, np.ndarray]:
    """`reason` and `physical`: real, both spring lengths > 0, not a d = 0 artefact."""
    # d = 0 with L0 > 0 is never an equilibrium (the force direction is undefined): the
    # double roots where one spring collapses (singular), and the complex points where both do
    # (nonsingular). A nonsingular root with one tiny d is a genuine equilibrium next to a cone
    # point (a saddle at d2 = 2.5e-5 m with L01 = 10.08, L02 = 0.42).
    short = [np.abs(v[f"d{i}"]) < tol.zero_length * params.L3 for i in (1, 2) if f"d{i}" in v]
    zero = np.zeros(len(is_real), dtype=bool)
    if short:
        zero = (singular & np.logical_or.reduce(short)) | np.logical_and.reduce(short)
    negative = is_real & ((d[1] <= 0) | (d[2] <= 0)) & ~zero
    reason = np.select(
        [zero, ~is_real, negative], ["zero_length_spring", "complex", "negative_d"], default=""
    )
    return {"reason": reason.astype(object), "physical": is_real & ~zero & ~negative}


def _order(cols: dict[str, np.ndarray], variables: tuple[str, ...]) -> dict[str, np.ndarray]:
    # Physical first, then real, then complex; within each by angle, so ids are stable. Angles
    # are rounded to 1e-9 deg so that a conjugate pair (equal real parts up to rounding) is
    # always ordered by its imaginary part, whichever run produced it.
    group = np.where(cols["physical"], 0, np.where(cols["is_real"], 1, 2))
    keys = (
        np.round(cols["gamma2_imag_deg"], 9),
        np.round(cols["gamma1_imag_deg"], 9),
        wrap_degrees(cols["gamma2_deg"], 9),
        wrap_degrees(cols["gamma1_deg"], 9),
        group,
    )
    order = np.lexsort(keys)  # the last key is the primary one
    names = COLUMNS + [f"{n}_{p}" for n in variables for p in ("re", "im")]
    out = {name: cols[name][order] for name in names}
    out["solution_id"] = np.arange(1, len(order) + 1)
    return out


def empty_columns(variables: tuple[str, ...]) -> dict[str, np.ndarray]:
    """A solutions table with no rows (every column present)."""
    cols = COLUMNS + [f"{n}_{p}" for n in variables for p in ("re", "im")]
    return {c: np.zeros(0, dtype=float) for c in cols}


def empty_solutions(variables: tuple[str, ...]):
    """A solutions table with no rows (every column present), as a DataFrame."""
    import pandas as pd

    return pd.DataFrame(empty_columns(variables))


def read_table(path):
    """A solutions (or sweep) table read back from CSV with the dtypes a fresh solve gives."""
    import pandas as pd

    table = pd.read_csv(path)
    for col in ("reason", "kind"):  # an all-empty column reads back as float NaN: made text
        table[col] = table[col].astype(object).fillna("").astype(str)
    table["paths"] = table["paths"].astype(str)
    if "lost_paths" in table:
        table["lost_paths"] = table["lost_paths"].astype("Int64")
    return table
