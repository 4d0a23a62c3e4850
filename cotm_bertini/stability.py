"""Turn solver endpoints into solutions: merge, refine, and classify real, physical, stable."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from .compiled import energy, energy_hessian, polynomial_system, tan_half_jacobian
from .geometry import Params, normalized, spring_vectors_cs, zero_length_points
from .polynomial import PolySystem


@dataclass(frozen=True)
class Tolerances:
    """Thresholds of the classification; each is documented in the README."""

    imag: float = 1e-8  # |Im| of every variable below this (relative to 1 + |x|): real
    # Condition number of the Jacobian at the refined point above this: a singular endpoint.
    # Ordinary roots with large |d| reach 1e9 (the variables are not scaled); exactly singular
    # ones (d = 0 artefacts) 1e14 and up.
    singular_condition: float = 1e12
    zero_length: float = 1e-5  # |d| below this times L3 at a singular endpoint: d = 0 artefact
    merge: float = 1e-8  # nonsingular endpoints closer than this (relative) are one solution
    hessian: float = 1e-9  # eigenvalues within this (relative to k L3^2) of 0: degenerate
    newton_steps: int = 3
    # An endpoint this close (units of L3) to a d = 0 artefact is that artefact. Small: a genuine
    # equilibrium can sit 1e-4 from one (a spring compressed to 2e-4 m, seen in a random geometry).
    snap: float = 2e-5


def newton_refine(system: PolySystem, x: np.ndarray, steps: int) -> tuple[np.ndarray, np.ndarray]:
    """A few complex Newton steps, each kept only where it lowers the residual."""
    x = np.array(x, dtype=complex)
    scale = system.scale()
    res = np.abs(system.evaluate(x) / scale).max(axis=1)
    for _ in range(steps):
        f = system.evaluate(x)
        jac = system.jacobian(x)
        step = np.zeros_like(x)
        ok = np.isfinite(jac).all(axis=(1, 2)) & (np.linalg.cond(jac) < 1e14)
        if ok.any():
            step[ok] = np.linalg.solve(jac[ok], f[ok][..., None])[..., 0]
        trial = x - step
        new = np.abs(system.evaluate(trial) / scale).max(axis=1)
        better = ok & (new < res)
        x[better] = trial[better]
        res[better] = new[better]
    return x, res


def cluster_endpoints(
    x: np.ndarray, singular: np.ndarray, accuracy: np.ndarray, tol: float
) -> np.ndarray:
    """Label endpoints that are one solution (several paths reaching it) with one group id."""
    n = len(x)
    labels = -np.ones(n, dtype=int)
    mag = 1.0 + np.abs(x).max(axis=1)
    # A singular root is only known to about the square root of the tracking accuracy.
    loose = np.where(singular, 10.0 * np.sqrt(np.maximum(accuracy, 1e-16)), tol)
    group = 0
    for i in range(n):
        if labels[i] >= 0:
            continue
        labels[i] = group
        for j in range(i + 1, n):
            if labels[j] >= 0:
                continue
            # Only two singular endpoints are merged loosely: a regular root is never swallowed.
            limit = max(loose[i], loose[j]) if (singular[i] and singular[j]) else tol
            if np.abs(x[i] - x[j]).max() <= limit * max(mag[i], mag[j]):
                labels[j] = group
        group += 1
    return labels


def _snap_zero_length(
    params: Params, variables: tuple[str, ...], x: np.ndarray, tol: Tolerances
) -> tuple[np.ndarray, np.ndarray]:
    """Put endpoints that sit on a d = 0 artefact exactly there (normalised units).

    An endgame only reaches such a double root to about the square root of its tolerance, and
    its two paths may end apart; the closed form knows the point exactly.
    """
    snapped = np.zeros(len(x), dtype=bool)
    exact = zero_length_points(normalized(params), variables)
    if not exact or not len(x):
        return x, snapped
    x = x.copy()
    for point in np.array(exact, dtype=complex):
        gap = np.abs(x - point).max(axis=1)
        near = gap < tol.snap
        x[near] = point
        snapped |= near
    return x, snapped


def complex_angles(c: np.ndarray, s: np.ndarray) -> np.ndarray:
    """gamma = -i log(c + i s), in degrees: real for points on the real circle."""
    return (-1j * np.log(c + 1j * s)) * (180.0 / np.pi)


def spring_vectors(params: Params, g1: np.ndarray, g2: np.ndarray) -> dict[str, np.ndarray]:
    """Points 2 -> 6 and 3 -> 5 and the rod 1 -> 4, in frame B, for real angles (radians)."""
    return spring_vectors_cs(params, np.cos(g1), np.sin(g1), np.cos(g2), np.sin(g2))


def classify(
    params: Params,
    endpoints: pd.DataFrame,
    variables: tuple[str, ...],
    tol: Tolerances = Tolerances(),
) -> pd.DataFrame:
    """One row per distinct finite solution with the solutions.csv columns (see README).

    The numerics (Newton refinement, condition numbers, merging, realness) run in units of L3
    and max(k1, k2), where every quantity is of order one whatever the user's units.
    """
    length = params.L3
    system = polynomial_system(normalized(params))
    is_d = np.array([v.startswith("d") for v in variables])
    x0 = endpoints[list(variables)].to_numpy(dtype=complex)
    x0 = np.where(is_d, x0 / length, x0)
    cond = endpoints["condition_number"].to_numpy(dtype=float)
    acc = endpoints["accuracy_estimate"].fillna(0.0).to_numpy(dtype=float)
    x0, snapped = _snap_zero_length(params, variables, x0, tol)
    x, res = newton_refine(system, x0, 0 if len(x0) == 0 else tol.newton_steps)
    # Our own condition number at the refined point: Bertini's estimate is taken wherever its
    # endgame stopped and varies by orders of magnitude between runs near a singular root.
    jac_cond = np.linalg.cond(system.jacobian(x)) if len(x) else np.zeros(0)
    jac_cond = np.where(np.isfinite(jac_cond), jac_cond, np.inf)
    singular = (
        (jac_cond > tol.singular_condition)
        | (endpoints["bertini_multiplicity"] > 1).to_numpy()
        | snapped
    )
    labels = cluster_endpoints(x, singular, acc, tol.merge)

    rows = []
    for g in range(labels.max() + 1 if len(labels) else 0):
        members = np.flatnonzero(labels == g)
        best = members[np.argmin(res[members])]
        rows.append(
            {
                "best": best,
                "multiplicity": len(members),
                "paths": " ".join(
                    str(int(p)) for p in endpoints["path_number"].to_numpy()[members]
                ),
                "condition_number": float(cond[members].max()),
                "jacobian_condition": float(jac_cond[members].min()),
                "singular": bool(singular[members].any() or len(members) > 1),
                "accuracy": float(acc[members].max()),
            }
        )
    if not rows:
        return _empty_frame(variables)
    best = np.array([r["best"] for r in rows])
    pts = x[best]
    absres = np.abs(system.evaluate(pts)).max(axis=1)
    pts = np.where(is_d, pts * length, pts)
    v = {name: pts[:, k] for k, name in enumerate(variables)}
    gam1 = complex_angles(v["c1"], v["s1"])
    gam2 = complex_angles(v["c2"], v["s2"])
    unit = np.where(is_d, length, 1.0)
    max_imag = (np.abs(pts.imag) / (unit + np.abs(pts.real))).max(axis=1)
    sing = np.array([r["singular"] for r in rows])
    # A singular root is known to about sqrt(accuracy) only: so is its imaginary part.
    loose = np.minimum(10.0 * np.sqrt([max(r["accuracy"], 1e-16) for r in rows]), 1e-4)
    is_real = max_imag < np.where(sing, np.maximum(loose, tol.imag), tol.imag)

    g1r, g2r = np.radians(gam1.real), np.radians(gam2.real)
    vec = spring_vectors(params, g1r, g2r)
    length = {i: np.hypot(*vec[f"spring{i}"].T) for i in (1, 2)}
    d = {}
    for i in (1, 2):
        name = f"d{i}"
        d[i] = v[name].real if name in v else length[i]
    frame = pd.DataFrame(
        {
            "solution_id": np.arange(1, len(rows) + 1),
            "gamma1_deg": np.mod(gam1.real, 360.0),
            "gamma2_deg": np.mod(gam2.real, 360.0),
            "gamma1_imag_deg": gam1.imag,
            "gamma2_imag_deg": gam2.imag,
            "d1": d[1],
            "d2": d[2],
            "is_real": is_real,
            "max_imag": max_imag,
        }
    )
    zero = np.zeros(len(rows), dtype=bool)
    for i in (1, 2):
        if f"d{i}" in v:
            # d = 0 with L0 > 0 is never an equilibrium (the force direction is undefined):
            # the double roots where one spring collapses, and the complex points where both do.
            zero |= np.abs(v[f"d{i}"]) < tol.zero_length * params.L3
    negative = is_real & ((d[1] <= 0) | (d[2] <= 0)) & ~zero
    frame["reason"] = np.select(
        [zero, ~is_real, negative], ["zero_length_spring", "complex", "negative_d"], default=""
    )
    physical = is_real & ~zero & ~negative
    frame["physical"] = physical
    frame["residual"] = absres
    frame["condition_number"] = [r["condition_number"] for r in rows]
    frame["jacobian_condition"] = [r["jacobian_condition"] for r in rows]
    frame["multiplicity"] = [r["multiplicity"] for r in rows]
    frame["singular"] = sing

    _mechanics(frame, params, g1r, g2r, vec, length, physical & ~sing, tol)
    frame["paper_stable"] = paper_criterion(params, frame)
    frame["paths"] = [r["paths"] for r in rows]
    for name in variables:
        frame[f"{name}_re"] = v[name].real
        frame[f"{name}_im"] = v[name].imag
    return _order(frame)


def _mechanics(
    frame: pd.DataFrame,
    params: Params,
    g1: np.ndarray,
    g2: np.ndarray,
    vec: dict[str, np.ndarray],
    length: dict[int, np.ndarray],
    can_be_stable: np.ndarray,
    tol: Tolerances,
) -> None:
    """Energy, Hessian, kind, forces; NaN where a row is not a physical equilibrium."""
    phys = frame["physical"].to_numpy()
    n = len(frame)
    nan = np.full(n, np.nan)
    e = nan.copy()
    lam = np.full((n, 2), np.nan)
    if phys.any():
        e[phys] = energy(params, g1[phys], g2[phys])
        hess = energy_hessian(params, g1[phys], g2[phys])
        lam[phys] = np.linalg.eigvalsh(hess)
    scale = max(params.k1, params.k2) * params.L3**2
    pos = lam > tol.hessian * scale
    negv = lam < -tol.hessian * scale
    kind = np.where(
        ~phys,
        "",
        np.where(
            pos.all(axis=1),
            "min",
            np.where(
                negv.all(axis=1),
                "max",
                np.where(pos.any(axis=1) & negv.any(axis=1), "saddle", "degenerate"),
            ),
        ),
    )
    frame["stable"] = phys & can_be_stable & (kind == "min")
    frame["kind"] = kind
    frame["energy"] = e
    frame["hess_eig1"] = lam[:, 0]
    frame["hess_eig2"] = lam[:, 1]
    f = {}
    for i, (k, L0) in enumerate(((params.k1, params.L01), (params.k2, params.L02)), start=1):
        f[i] = np.where(phys, k * (length[i] - L0), np.nan)
        frame[f"spring{i}_force"] = f[i]
    # Rod force from the force balance f1 u1 + f2 u2 + f3 u_rod = 0 (eq. (5)); tension > 0.
    with np.errstate(invalid="ignore", divide="ignore"):
        u_rod = vec["rod"] / params.L3
        pull = sum(f[i][:, None] * vec[f"spring{i}"] / length[i][:, None] for i in (1, 2))
        f3 = -(pull * u_rod).sum(axis=1)
    frame["rod_force"] = np.where(phys, f3, np.nan)
    frame["tensegrity"] = phys & (f[1] > 0) & (f[2] > 0) & (f3 < 0)


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


def _order(frame: pd.DataFrame) -> pd.DataFrame:
    # Physical first, then real, then complex; within each by angle, so ids are stable. Angles
    # are rounded to 1e-9 deg so that a conjugate pair (equal real parts up to rounding) is
    # always ordered by its imaginary part, whichever run produced it.
    key = np.where(frame["physical"], 0, np.where(frame["is_real"], 1, 2))
    sort = frame.assign(
        _k=key,
        _g1=np.round(frame["gamma1_deg"].to_numpy(), 9) % 360.0,
        _g2=np.round(frame["gamma2_deg"].to_numpy(), 9) % 360.0,
        _i1=np.round(frame["gamma1_imag_deg"].to_numpy(), 9),
        _i2=np.round(frame["gamma2_imag_deg"].to_numpy(), 9),
    )
    cols = ["_k", "_g1", "_g2", "_i1", "_i2"]
    frame = sort.sort_values(cols, kind="stable").drop(columns=cols).reset_index(drop=True)
    frame["solution_id"] = np.arange(1, len(frame) + 1)
    rest = [c for c in frame.columns if c not in COLUMNS]
    return frame[COLUMNS + rest]


def _empty_frame(variables: tuple[str, ...]) -> pd.DataFrame:
    cols = COLUMNS + [f"{n}_{p}" for n in variables for p in ("re", "im")]
    return pd.DataFrame({c: pd.Series(dtype=float) for c in cols})


def paper_criterion(params: Params, frame: pd.DataFrame) -> np.ndarray:
    """The paper's "stable": all eigenvalues of the Jacobian of its tan-half equations (F, tau,
    C1, C2 in x1, x2, d1, d2) have negative real parts. Evaluated on real rows, as the paper does;
    False for complex rows and where gamma = 180 deg (x = tan(gamma/2) is infinite there)."""
    out = np.zeros(len(frame), dtype=bool)
    for k, row in enumerate(frame.itertuples(index=False)):
        if not row.is_real:
            continue
        half = np.radians([row.gamma1_deg, row.gamma2_deg]) / 2
        if np.abs(np.cos(half)).min() < 1e-8:
            continue
        point = [*np.tan(half)]
        point += [getattr(row, f"d{i}") for i in (1, 2) if not params.zfl[i - 1]]
        eig = np.linalg.eigvals(tan_half_jacobian(params, tuple(point)))
        out[k] = bool(np.all(eig.real < 0))
    return out


def _anchor_jacobian(params: Params, spring: int, g1: float, g2: float) -> np.ndarray:
    """d(P_spring)/d(gamma1, gamma2): columns L3 u'(gamma1) and R'(gamma2) q."""
    q = (params.p6x, 0.0) if spring == 1 else (params.p5x, params.p5y)
    c1, s1, c2, s2 = np.cos(g1), np.sin(g1), np.cos(g2), np.sin(g2)
    return np.array(
        [[-params.L3 * s1, -s2 * q[0] - c2 * q[1]], [params.L3 * c1, c2 * q[0] - s2 * q[1]]]
    )


def zero_length_configurations(params: Params) -> list[dict]:
    """Real configurations where a spring with L0 > 0 has zero length (P6 = P2 or P5 = P3).

    V has a cone point there: V = 1/2 k L0^2 - k L0 |P| + (the other spring's energy). It is a
    local maximum (`is_max`) when the other spring's pull, carried to the coincident point
    (J^-T grad V_other), is weaker than the k L0 push of the collapsed spring; otherwise the cone
    is tilted over and the point is not critical at all. Closed form: P4 = L3 u(gamma1) lies on
    |P4| = L3 and on the circle of radius |q| around the bottom anchor (q: top anchor in T).
    """
    found = []
    springs = {
        1: ((params.p2x, 0.0), (params.p6x, 0.0), params.k1, params.L01),
        2: ((params.p3x, params.p3y), (params.p5x, params.p5y), params.k2, params.L02),
    }
    for spring, (anchor, q, k, free_length) in springs.items():
        if free_length == 0:
            continue
        a = np.array(anchor)
        r1, r2, dist = params.L3, float(np.hypot(*q)), float(np.hypot(*a))
        along = (dist**2 + r1**2 - r2**2) / (2 * dist)
        h2 = r1**2 - along**2
        if h2 < 0:
            continue
        ex = a / dist
        ey = np.array([-ex[1], ex[0]])
        for sign in (1.0, -1.0) if h2 > 0 else (1.0,):
            p4 = along * ex + sign * np.sqrt(h2) * ey
            g1 = float(np.arctan2(p4[1], p4[0]))
            w = a - p4  # = R(gamma2) q
            g2 = float(np.arctan2(w[1], w[0]) - np.arctan2(q[1], q[0]))
            other = 2 if spring == 1 else 1
            vec = spring_vectors(params, np.array([g1]), np.array([g2]))[f"spring{other}"][0]
            ko, L0o = (params.k2, params.L02) if other == 2 else (params.k1, params.L01)
            length = float(np.hypot(*vec))
            grad_other = (
                ko * (length - L0o) / length * (_anchor_jacobian(params, other, g1, g2).T @ vec)
            )
            jac = _anchor_jacobian(params, spring, g1, g2)
            pull = float(np.linalg.norm(np.linalg.solve(jac.T, grad_other)))
            found.append(
                {
                    "spring": spring,
                    "gamma1_deg": float(np.degrees(g1) % 360),
                    "gamma2_deg": float(np.degrees(g2) % 360),
                    "pull": pull,
                    "push": k * free_length,
                    "is_max": pull < k * free_length,
                }
            )
    return found


def morse_check(params: Params, frame: pd.DataFrame) -> dict:
    """#min - #saddle + #max over the physical equilibria, zero-length cusps counted as maxima.

    The torus has Euler characteristic 0, so a non-zero total means equilibria are missing (or a
    degenerate one makes the count inapplicable).
    """
    phys = frame[frame["physical"]]
    counts = {k: int((phys["kind"] == k).sum()) for k in ("min", "saddle", "max", "degenerate")}
    cusps = sum(c["is_max"] for c in zero_length_configurations(params))
    total = counts["min"] - counts["saddle"] + counts["max"] + cusps
    ok = total == 0 and counts["degenerate"] == 0
    return {**counts, "zero_length_maxima": cusps, "euler_characteristic": total, "ok": ok}
