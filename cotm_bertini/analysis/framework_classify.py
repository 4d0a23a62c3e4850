"""A framework's solutions classified: real, physical (lengths > 0, taut set consistent), and
stable by the Hessian of the Lagrangian reduced to the tangent space of the constraints."""

from __future__ import annotations

import numpy as np

from ..backends.endpoints import Endpoints
from ..model.framework.compiled import FrameworkSystem, slot_vector, variable_scale
from ..model.framework.spec import Framework
from ..model.framework.units import normalized_slots
from ..settings import Tolerances
from .classify import Merged, merge_endpoints, wrap_degrees
from .cluster import cluster_endpoints

_AXES = "xyz"
QUATERNION_ZERO = 1e-9  # a quaternion component below this is 0 for the sign shown (q or -q)


def framework_columns(
    fw: Framework,
    fs: FrameworkSystem,
    endpoints: Endpoints,
    unit: tuple[float, float],
    tol: Tolerances = Tolerances(),
) -> dict[str, np.ndarray]:
    """One row per distinct solution of one taut set (endpoints in normalised units)."""
    return framework_rows(fw, fs, endpoints, unit, tol)[0]


def framework_rows(fw, fs, endpoints: Endpoints, unit, tol: Tolerances = Tolerances()) -> tuple:
    """framework_columns and the refined solutions behind its rows (normalised units)."""
    slots_n = normalized_slots(fw)
    system = fs.ps.instantiate([slots_n[n] for n in fs.ps.parameters])
    merged = merge_endpoints(system, endpoints.points, endpoints, tol, scaled=True)
    merged = merge_sign_twins(fs, merged, tol)
    x = merged.x
    max_imag = (np.abs(x.imag) / (1.0 + np.abs(x.real))).max(axis=1) if len(x) else np.zeros(0)
    loose = np.minimum(10.0 * np.sqrt(np.maximum(merged.accuracy, 1e-16)), 1e-4)
    is_real = max_imag < np.where(merged.singular, np.maximum(loose, tol.imag), tol.imag)
    cols, reason, borderline = described(fw, fs, x, unit, tol)
    reason = np.where(is_real, reason, "complex").astype(object)
    physical = is_real & (reason == "")
    kind, index, eig = _stability(fs, x, slots_n, physical & ~merged.singular, tol)
    kind = np.where(physical & (merged.singular | borderline), "degenerate", kind)
    cols.update(
        is_real=is_real, max_imag=max_imag, singular=merged.singular, physical=physical,
        stable=physical & (kind == "min"), kind=kind.astype(object), index=index,
        hess_min_eig=eig, reason=reason,
        residual=np.abs(system.evaluate(x)).max(axis=1) if len(x) else np.zeros(0),
        jacobian_condition=merged.jacobian_condition, multiplicity=merged.multiplicity,
        taut_set=np.array([" ".join(fs.taut)] * len(x), dtype=object),
        paths=np.array(merged.paths, dtype=object),
    )  # fmt: skip
    return cols, x


def described(fw: Framework, fs: FrameworkSystem, x: np.ndarray, unit, tol) -> tuple:
    """The pose, link and energy columns of solutions `x` (normalised units), the first reason
    each is not an equilibrium of the real mechanism, and which have a cable at its free length."""
    X = x * variable_scale(fs, unit)
    var = {name: X[:, k] for k, name in enumerate(fs.ps.variables)}
    pos = positions(fs, x, slot_vector(normalized_slots(fw)), fw.dim, unit[0])
    cols: dict[str, np.ndarray] = {}
    cols.update(pose_columns(fw, fs, var, pos))
    links, reason, borderline = _link_columns(fw, fs, var, pos, unit, tol)
    cols.update(links)
    cols["energy"] = _energy(fw, pos, links)
    return cols, reason, borderline


def quaternion_columns(fs: FrameworkSystem) -> list[np.ndarray]:
    """The solver's columns (w, x, y, z) of each spatial body's quaternion."""
    index = {v: j for j, v in enumerate(fs.ps.variables)}
    bodies = dict.fromkeys(v.split("_", 1)[1] for v in index if v.startswith("qw_"))
    return [np.array([index[f"q{c}_{b}"] for c in "wxyz"]) for b in bodies]


def quaternion_products(q: np.ndarray) -> np.ndarray:
    """(n, 10) products q_i q_j (i <= j) of quaternions q (n, 4), real or complex: the same
    for q and -q, and equal only for q' = +-q (q q^T determines q up to its sign)."""
    i, j = np.triu_indices(4)
    return q[:, i] * q[:, j]


def sign_free(x: np.ndarray, quaternions: list[np.ndarray]) -> np.ndarray:
    """Solutions x (n, variables) with each body's quaternion replaced by its products
    (`quaternion_products`): rows of one pose are equal whatever the sign of each body's q."""
    body = np.zeros(x.shape[1], dtype=bool)
    for cols in quaternions:
        body[cols] = True
    return np.hstack([x[:, ~body], *(quaternion_products(x[:, c]) for c in quaternions)])


def merge_sign_twins(fs: FrameworkSystem, merged: Merged, tol: Tolerances) -> Merged:
    """One row per pose: q and -q of a spatial body are one rotation, reached by paths of their
    own, so the distinct roots come in sets of 2^bodies (each body's sign flips on its own).
    Roots equal but for those signs are merged, compared by `sign_free` (no sign convention,
    so no quaternion on a convention's boundary, e.g. qw = 0, is left doubled); the row keeps
    the root's own multiplicity and condition, and the paths to every sign."""
    quaternions = quaternion_columns(fs)
    if not quaternions or len(merged.x) < 2:
        return merged
    key = sign_free(merged.x, quaternions)
    labels = cluster_endpoints(key, merged.singular, merged.accuracy, tol.merge)
    if np.array_equal(labels, np.arange(len(labels))):
        return merged
    groups = [np.flatnonzero(labels == g) for g in range(labels.max() + 1)]
    first = np.array([m[0] for m in groups], dtype=int)
    return Merged(
        x=merged.x[first],
        multiplicity=np.array([merged.multiplicity[m].max() for m in groups], dtype=int),
        paths=[" ".join(merged.paths[i] for i in m) for m in groups],
        condition_number=np.array([merged.condition_number[m].max() for m in groups]),
        jacobian_condition=np.array([merged.jacobian_condition[m].min() for m in groups]),
        singular=np.array([bool(merged.singular[m].any()) for m in groups], dtype=bool),
        accuracy=np.array([merged.accuracy[m].max() for m in groups]),
    )


def shown_quaternions(q: np.ndarray) -> np.ndarray:
    """Real quaternions q (n, 4) with the sign shown in the table: of q and -q, the one whose
    first component larger than QUATERNION_ZERO in magnitude is positive (a component that is
    0 but for rounding, e.g. qw of a half turn, does not choose the sign)."""
    lead = (np.abs(q) > QUATERNION_ZERO).argmax(axis=1)
    sign = np.sign(np.take_along_axis(q, lead[:, None], axis=1))
    return q * np.where(sign < 0, -1.0, 1.0)


def column_names(fw: Framework) -> list[str]:
    """The solutions.csv columns of a framework, in order (docs/frameworks.md)."""
    names = ["solution_id"]
    for body, _ in fw.bodies:
        names += [f"{body}.{a}" for a in _AXES[: fw.dim]]
        names += [f"{body}.angle_deg"] if fw.dim == 2 else [f"{body}.q{c}" for c in "wxyz"]
    for body, pts in fw.bodies:
        names += [f"{body}.{p}.{a}" for p, _ in pts for a in _AXES[: fw.dim]]
    names += [f"{n}.{a}" for n in fw.nodes for a in _AXES[: fw.dim]]
    for x in fw.links:
        names += [f"{x.name}.length", f"{x.name}.tension"]
        names += [f"{x.name}.taut"] if x.kind == "cable" else []
    return names + [
        "energy", "is_real", "singular", "physical", "stable", "kind", "index", "reason",
        "hess_min_eig", "max_imag", "residual", "jacobian_condition", "multiplicity",
        "taut_set", "paths",
    ]  # fmt: skip


def positions(fs: FrameworkSystem, x: np.ndarray, P: np.ndarray, dim: int, length: float) -> dict:
    """Every point's (n, dim) world coordinates in user units (complex where the solution is),
    from solutions `x` and slots `P` in the framework's units."""
    vals = fs.numeric.positions(x, P)
    flat = [np.broadcast_to(np.asarray(v) * length, (len(x),)) for v in vals]
    return {p: np.stack(flat[k * dim : (k + 1) * dim], axis=1) for k, p in enumerate(fs.points)}


def pose_columns(fw: Framework, fs: FrameworkSystem, var: dict, pos: dict) -> dict:
    cols = {}
    for body, _ in fw.bodies:
        for a in range(fw.dim):
            cols[f"{body}.{_AXES[a]}"] = pos[body][:, a].real
        if fw.dim == 2:
            angle = np.degrees(np.arctan2(var[f"s_{body}"].real, var[f"c_{body}"].real))
            cols[f"{body}.angle_deg"] = wrap_degrees(angle)
        else:
            q = shown_quaternions(np.stack([var[f"q{c}_{body}"].real for c in "wxyz"], axis=1))
            for k, c in enumerate("wxyz"):
                cols[f"{body}.q{c}"] = q[:, k]
    for body, pts in fw.bodies:
        for name, _ in pts:
            for a in range(fw.dim):
                cols[f"{body}.{name}.{_AXES[a]}"] = pos[f"{body}.{name}"][:, a].real
    for node in fw.nodes:
        for a in range(fw.dim):
            cols[f"{node}.{_AXES[a]}"] = pos[node][:, a].real
    return cols


def _link_columns(fw, fs, var, pos, unit, tol) -> tuple[dict, np.ndarray, np.ndarray]:
    """Length and tension of every spring and cable (bars: tension), the first reason a row is
    not an equilibrium of the real mechanism, and rows with a cable exactly at its free length."""
    n = len(next(iter(pos.values()))) if pos else 0
    slots, cols = fw.slots(), {}
    reason = np.full(n, "", dtype=object)
    borderline = np.zeros(n, dtype=bool)
    near = tol.zero_length * unit[0]
    for x in fw.links:
        r = pos[x.a] - pos[x.b]
        length = np.sqrt((r.real**2).sum(axis=1))
        if x.kind == "bar":
            mu = var[f"mu_{x.name}"].real
            cols[f"{x.name}.length"], cols[f"{x.name}.tension"] = length, mu * length
            continue
        k, L0 = slots[f"k_{x.name}"], slots[f"L0_{x.name}"]
        d = var.get(f"d_{x.name}")
        signed = length if d is None else d.real
        stretch = signed - L0
        taut = x.kind == "spring" or x.name in fs.taut
        cols[f"{x.name}.length"] = signed
        cols[f"{x.name}.tension"] = k * stretch if taut else np.zeros(n)
        if x.kind == "cable":
            cols[f"{x.name}.taut"] = np.full(n, taut)
            borderline |= np.abs(stretch) <= near
            bad = (stretch < -near) if taut else (stretch > near)
            label = "cable_pushes" if taut else "slack_cable_stretched"
            reason = np.where((reason == "") & bad, f"{label}:{x.name}", reason)
        if d is not None:
            reason = np.where(
                (reason == "") & (signed <= near), f"negative_length:{x.name}", reason
            )
    return cols, reason, borderline


def _energy(fw: Framework, pos: dict, links: dict) -> np.ndarray:
    """V = sum k/2 (d - L0)^2 over springs and taut cables - sum F . x (user units)."""
    slots = fw.slots()
    n = len(next(iter(pos.values()))) if pos else 0
    V = np.zeros(n)
    for x in fw.links:
        if x.kind != "bar":
            stretch = links[f"{x.name}.length"] - slots[f"L0_{x.name}"]
            if x.kind == "cable":
                stretch = np.maximum(stretch, 0.0)
            V += slots[f"k_{x.name}"] / 2 * stretch**2
    for load in fw.loads:
        f = np.array([slots[f"f_{load.name}_{a}"] for a in _AXES[: fw.dim]])
        V -= pos[load.point].real @ f
    return V


def _stability(fs: FrameworkSystem, x: np.ndarray, slots_n: dict, mask: np.ndarray, tol):
    """kind, index and smallest eigenvalue of the reduced Hessian (normalised units), per row."""
    n = len(x)
    kind = np.full(n, "", dtype=object)
    index = np.full(n, -1, dtype=int)
    eig_min = np.full(n, np.nan)
    if not mask.any():
        return kind, index, eig_min
    P = np.array([slots_n[s] for s in slots_n])
    H, G = local_hessian(fs, x[mask].real, P)
    for k, row in enumerate(np.flatnonzero(mask)):
        eig = _reduced_eigenvalues(H[k], G[k])
        limit = tol.hessian * max(1.0, float(np.abs(H[k]).max()))
        index[row] = int((eig < -limit).sum())
        eig_min[row] = eig.min() if len(eig) else np.nan
        if (np.abs(eig) <= limit).any():
            kind[row] = "degenerate"
        elif index[row] == 0:
            kind[row] = "min"
        elif index[row] == len(eig):
            kind[row] = "max"
        else:
            kind[row] = "saddle"
    return kind, index, eig_min


def local_hessian(fs: FrameworkSystem, X: np.ndarray, P: np.ndarray) -> tuple:
    """The Lagrangian's Hessian (n, m, m) and the constraint Jacobian (n, c, m) in local
    coordinates at real solutions X (n, variables) of the structure, slots P (normalised)."""
    n, m = len(X), fs.local_size
    H = _stack(fs.numeric.hessian(X, P), n).reshape(n, m, m)
    G = np.zeros((n, 0, m))
    if fs.constraints:
        G = _stack(fs.numeric.constraint_jacobian(X, P), n).reshape(n, -1, m)
    return H, G


def _stack(values: list, n: int) -> np.ndarray:
    out = np.empty((n, len(values)))
    for k, v in enumerate(values):
        out[:, k] = v  # a constant entry of the generated code is a float: broadcast
    return out


def tangent_basis(G: np.ndarray, m: int) -> np.ndarray:
    """An orthonormal basis (m, m - rank) of the null space of the constraint Jacobian G (c, m):
    the directions the constraints allow."""
    if not len(G):
        return np.eye(m)
    _, s, vt = np.linalg.svd(G)
    rank = int((s > 1e-10 * max(1.0, s.max(initial=0.0))).sum())
    return vt[rank:].T


def reduced_eigh(H: np.ndarray, G: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues (ascending) of H on the null space of G, and their eigenvectors in local
    coordinates (columns)."""
    N = tangent_basis(G, len(H))
    eig, vec = np.linalg.eigh(_reduce(H, G, N))
    return eig, N @ vec


def _reduce(H: np.ndarray, G: np.ndarray, N: np.ndarray) -> np.ndarray:
    H = (H + H.T) / 2
    return N.T @ H @ N if len(G) else H


def _reduced_eigenvalues(H: np.ndarray, G: np.ndarray) -> np.ndarray:
    """Eigenvalues of H on the null space of the constraint Jacobian G."""
    R = _reduce(H, G, tangent_basis(G, len(H)))
    return np.linalg.eigvalsh(R) if R.size else np.zeros(0)
