"""The Morse count on the torus: a completeness check of the physical equilibria.

V(gamma1, gamma2) lives on a torus (Euler characteristic 0), so #min - #saddle + #max = 0 when no
equilibrium is missing. Where a spring with L0 > 0 can reach zero length, V has a cone point
(not smooth, not an equilibrium) that counts as a maximum when it is a local maximum.
"""

from __future__ import annotations

import numpy as np

from ..model.kinematics import spring_jacobian, spring_vectors, zero_length_poses
from ..params import Params


def _other_spring_pull(params: Params, spring: int, pose: tuple[float, ...]) -> float:
    """The other spring's pull carried to the coincident point: |J^-T grad V_other|."""
    other = 3 - spring
    k, L0 = (params.k2, params.L02) if other == 2 else (params.k1, params.L01)
    vec = np.array(spring_vectors(params, *pose)[f"spring{other}"], dtype=float)
    length = float(np.hypot(*vec))
    j_other = np.array(spring_jacobian(params, other, *pose), dtype=float)  # columns
    grad_other = k * (length - L0) / length * (j_other @ vec)
    jac = np.array(spring_jacobian(params, spring, *pose), dtype=float).T
    return float(np.linalg.norm(np.linalg.solve(jac.T, grad_other)))


def zero_length_configurations(params: Params) -> list[dict]:
    """Real configurations where a spring with L0 > 0 has zero length (P6 = P2 or P5 = P3).

    V has a cone point there: V = 1/2 k L0^2 - k L0 |P| + (the other spring's energy). It is a
    local maximum (`is_max`) when the other spring's pull, carried to the coincident point, is
    weaker than the k L0 push of the collapsed spring; otherwise the cone is tilted over and the
    point is not critical at all.
    """
    found = []
    for spring, k, free_length in ((1, params.k1, params.L01), (2, params.k2, params.L02)):
        if free_length == 0:
            continue
        poses = zero_length_poses(params, spring)
        if abs(poses[0][0].imag) > 1e-12 or abs(poses[0][1].imag) > 1e-12:
            continue  # out of reach: the spring never collapses
        real = [tuple(float(z.real) for z in pose) for pose in poses]
        if np.allclose(real[0], real[1], atol=1e-12):
            real = real[:1]  # a tangent pair: one pose
        for pose in real:
            pull = _other_spring_pull(params, spring, pose)
            found.append(
                {
                    "spring": spring,
                    "gamma1_deg": float(np.degrees(np.arctan2(pose[1], pose[0])) % 360),
                    "gamma2_deg": float(np.degrees(np.arctan2(pose[3], pose[2])) % 360),
                    "pull": pull,
                    "push": k * free_length,
                    "is_max": pull < k * free_length,
                }
            )
    return found


def morse_check(params: Params, table) -> dict:
    """#min - #saddle + #max over the physical equilibria, zero-length cusps counted as maxima.

    The torus has Euler characteristic 0, so a non-zero total means equilibria are missing (or a
    degenerate one makes the count inapplicable). `table`: a DataFrame or a dict of columns.
    """
    kinds = np.asarray(table["kind"], dtype=object)[np.asarray(table["physical"], dtype=bool)]
    counts = {k: int((kinds == k).sum()) for k in ("min", "saddle", "max", "degenerate")}
    cusps = sum(c["is_max"] for c in zero_length_configurations(params))
    total = counts["min"] - counts["saddle"] + counts["max"] + cusps
    # V is continuous on the compact torus: its global minimum is an equilibrium (never a cone
    # point, which is a maximum), so a table without one misses equilibria whatever the total.
    ok = total == 0 and counts["degenerate"] == 0 and counts["min"] > 0
    return {**counts, "zero_length_maxima": cusps, "euler_characteristic": total, "ok": ok}
