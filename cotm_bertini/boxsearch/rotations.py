"""Rigid bodies turning in space on the real route: SO(3) covered by four gnomonic charts of the
unit quaternions (q and -q one rotation), as boxsearch.spheres covers a sphere by two charts.

Chart c (c = 0..3, the quaternion's w, x, y, z) holds the rotations whose component c is the
largest in magnitude: q = n / |n|, n = e_c + sum_j u_j e_{m_j}, m_0 < m_1 < m_2 the other three
components, with q_c > 0 (one of +-q). Where |q_c| is the largest, |u_j| = |q_{m_j} / q_c| <= 1,
so the four cubes [-1, 1]^3 cover SO(3); each chart's cube is taken a little larger (LO, HI;
not centred on 0, so that no symmetric pose lies on a halving face) and the charts overlap: a
critical point there is found in two charts and kept once (`fresh`). Each chart is a
diffeomorphism of R^3 onto the rotations with q_c != 0, so a critical point of V in chart
coordinates is one on SO(3). A box stores its chart in its first coordinate: u_0 + SHIFT c.

V's derivatives come from the generated code, in the local coordinates v of a rotation
q0 (sqrt(1 - |v|^2), v) (model.framework.derive). Near q0 = q(u), v(u') = vec(conj(q0) q(u')),
so with D_j = dv/du_j = vec(conj(q) e_{m_j}) / |n| (conj(q) q has no vector part) and
W_jk = d2v/du_j du_k = -(u_j D_k + u_k D_j) / |n|^2:

    grad_u V = D grad_v V,    Hess_u V = D Hess_v V D^T + sum_a (grad_v V)_a W_a.

Both hold on interval boxes (D and W enclosed from the box's u), so the Krawczyk test of
boxsearch.boxes applies in chart coordinates unchanged.
"""

from __future__ import annotations

import numpy as np

from ..model.framework.reach import length_bounds
from ..model.framework.spec import Framework
from ..model.framework.structure import layout
from ..model.intervals import Interval

SHIFT = 8.0  # chart c's first coordinate is stored as u_0 + SHIFT c
LO, HI = -1.0437, 1.0391  # each chart's cube (more than [-1, 1]: the charts overlap)
APART = 1e-8  # two rotations closer than this (quaternion components, up to sign) are one
_OTHERS = [tuple(m for m in range(4) if m != c) for c in range(4)]


def turning_bodies(fw: Framework) -> str:
    """'' where a spatial framework's poses are SO(3) per body (each body pinned at one point, to
    the ground or to a body placed before it: ball joints; no bars, free nodes or loops), else
    why not."""
    lay = layout(fw)
    if lay.translations:
        return f"body {lay.translations[0]} is pinned nowhere (bodies on ball joints only)"
    if lay.free_nodes or fw.bars:
        return "bodies with free nodes or bars (bodies on ball joints alone only)"
    if lay.closing_pins:
        return "a pin closes a loop or holds a body at a second point (bodies on ball joints only)"
    slots = fw.slots()
    for x in fw.springs:
        if slots[f"L0_{x.name}"] > 0 and length_bounds(fw, x.a, x.b)[0] <= 0:
            # Its cone (a curve or surface of poses) is not enclosed here: the search would run
            # down to its smallest boxes along it (a ball joint whose spring can: 0.875 of the
            # poses undecided after 120 s), where the complex route finishes.
            return (f"spring {x.name} of a body in space can reach zero length (its cone is not "
                    "enclosed by the real route's charts of rotations)")  # fmt: skip
    return ""


def domain(bodies: int, per: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """The boxes (lo, hi) that cover SO(3)^bodies: each body's four chart cubes, each cut in
    `per` along each coordinate."""
    edges = LO + (HI - LO) * np.arange(per + 1) / per
    cells = np.indices((per,) * 3).reshape(3, -1).T
    lo = np.vstack([edges[cells] + [SHIFT * c, 0, 0] for c in range(4)])
    hi = np.vstack([edges[cells + 1] + [SHIFT * c, 0, 0] for c in range(4)])
    idx = np.indices((len(lo),) * bodies).reshape(bodies, -1).T
    return lo[idx].reshape(len(idx), -1), hi[idx].reshape(len(idx), -1)


def chart(first) -> np.ndarray:
    """The chart (0..3) of each box or point from its first coordinate (lo bounds, or values)."""
    lo = first.lo if isinstance(first, Interval) else np.asarray(first)
    return np.clip(np.floor((lo + SHIFT / 2) / SHIFT), 0, 3).astype(np.int64)


def _coords(x, j: int):
    """Coordinate j (0..2) of a body's chart coordinates `x` (B, 3), the chart's shift taken off."""
    col = x[:, j]
    if j:
        return col
    return col - SHIFT * chart(col)


def _pick(c: np.ndarray, values: list):
    """values[c] per row: Intervals or arrays."""
    out = values[0]
    for k in range(1, len(values)):
        mask = c == k
        if mask.any():
            out = Interval.where(mask, values[k], out) if isinstance(out, Interval) else (
                np.where(mask, values[k], out))  # fmt: skip
    return out


def frame(x) -> dict:
    """A body's unnormalised quaternion n (4 components), 1/|n|^2, its chart and u, over boxes
    (an Interval (B, 3)) or at points (an array (R, 3))."""
    c = chart(x[:, 0])
    u = [_coords(x, j) for j in range(3)]
    boxes = isinstance(x, Interval)
    one = Interval.of(np.ones(len(c))) if boxes else np.ones(len(c))
    square = (lambda a: a.square()) if boxes else (lambda a: a * a)
    inv2 = one + square(u[0]) + square(u[1]) + square(u[2])
    inv2 = inv2.reciprocal() if boxes else 1.0 / inv2
    n = []
    for m in range(4):  # component m is 1 in chart m, else u_j of the chart's j with m_j = m
        options = [one if m == k else u[_OTHERS[k].index(m)] for k in range(4)]
        n.append(_pick(c, options))
    return {"n": n, "inv2": inv2, "chart": c, "u": u}


def quaternion(f: dict) -> list:
    """The unit quaternion (w, x, y, z) of a frame (`frame`): n / |n|."""
    s = f["inv2"].sqrt() if isinstance(f["inv2"], Interval) else np.sqrt(f["inv2"])
    return [a * s for a in f["n"]]


def _vec_conj_times(n: list, m: int) -> list:
    """vec(conj(n) e_m), e_m the quaternion basis element m (linear in n)."""
    w, x, y, z = n
    return [[-x, -y, -z], [w, -z, y], [z, w, -x], [-y, x, w]][m]


def jacobian(f: dict) -> list:
    """D (3 x 3 nested lists, D[j][a] = dv_a/du_j) of a frame (module docstring)."""
    c, n, inv2 = f["chart"], f["n"], f["inv2"]
    rows = []
    for j in range(3):
        per_chart = [_vec_conj_times(n, _OTHERS[k][j]) for k in range(4)]
        rows.append([_pick(c, [per_chart[k][a] for k in range(4)]) * inv2 for a in range(3)])
    return rows


def gradient(D: list, g: list) -> list:
    """grad_u V = D grad_v V of one body (`g`: its three grad_v components)."""
    return [D[j][0] * g[0] + D[j][1] * g[1] + D[j][2] * g[2] for j in range(3)]


def curvature(f: dict, Dg: list) -> list:
    """sum_a g_a W_a (3 x 3 nested lists): the chart's own term of Hess_u V, from the body's
    chart gradient Dg = D grad_v V (`gradient`; W_jk = -(u_j D_k + u_k D_j) / |n|^2)."""
    u, inv2 = f["u"], f["inv2"]
    return [[-(u[j] * Dg[k] + u[k] * Dg[j]) * inv2 for k in range(3)] for j in range(3)]


def chart_points(q: np.ndarray) -> np.ndarray:
    """Chart coordinates (R, 3) of unit quaternions (R, 4): each in the chart of its largest
    component."""
    c = np.abs(q).argmax(axis=1)
    lead = q[np.arange(len(q)), c]
    others = np.array(_OTHERS)[c]
    u = np.take_along_axis(q, others, axis=1) / lead[:, None]
    u[:, 0] += SHIFT * c
    return u


def same(a: np.ndarray, b: np.ndarray, apart: float = APART) -> bool:
    """Whether quaternions a and b (bodies x 4) are one pose: each body's q = +-q' within
    `apart`."""
    gap = np.minimum(np.abs(a - b).max(axis=1), np.abs(a + b).max(axis=1))
    return bool(gap.max() <= apart)
