"""The d = 0 artefacts of the model in closed form: roots where a spring with L0 > 0 collapses.

Multiplying the balance equations through by d_i adds roots with d_i = 0 (the spring's ends
coincide, its force direction is undefined: not equilibria). They are double roots, singular, and
known exactly, so the solvers need not track them.
"""

from __future__ import annotations

import numpy as np

from ..params import Params
from .kinematics import spring_vectors, zero_length_poses


def zero_length_points(params: Params, variables: tuple[str, ...]) -> np.ndarray:
    """Solver-variable points where a spring with L0 > 0 has zero length (the d = 0 artefacts).

    For spring i the two poses of `zero_length_poses` (complex ones included), d_i = 0, and the
    other spring's d_j = +-sqrt(|P_j|^2) (complex square root of the sum of squares). Each is a
    double root of the multiplied-through system.
    """
    out = []
    for i in (1, 2):
        if f"d{i}" not in variables:
            continue
        j = 3 - i
        for pose in zero_length_poses(params, i):
            point = dict(zip(("c1", "s1", "c2", "s2"), pose, strict=True)) | {f"d{i}": 0j}
            if f"d{j}" not in variables:
                out.append([point[v] for v in variables])
                continue
            vec = spring_vectors(params, *pose)[f"spring{j}"]
            dj = np.sqrt(complex(vec[0] ** 2 + vec[1] ** 2))
            out += [[(point | {f"d{j}": sign * dj})[v] for v in variables] for sign in (1, -1)]
    return np.array(out, dtype=complex).reshape(len(out), len(variables))
