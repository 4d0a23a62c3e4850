"""Forward kinematics of the CoTM, written once for numbers, numpy arrays and sympy symbols.

Points follow the reference notes (eq. (2) of the paper swaps labels): in the bottom frame B,
P1 = origin, P2 = [p2x, 0], P3 = [p3x, p3y]; the top frame T has its origin at
P4 = L3 [cos gamma1, sin gamma1] and is turned by gamma2; in it P6 = [p6x, 0], P5 = [p5x, p5y].
Spring 1 joins 2-6, spring 2 joins 3-5, the rod joins 1-4. Every function takes `p`, any object
with the parameter attributes (a Params, or a namespace of sympy symbols), and the cosines and
sines of the two angles; points are (x, y) pairs of whatever type the inputs are.
"""

from __future__ import annotations

import cmath
from typing import Any

Pair = tuple[Any, Any]


def rotate(c: Any, s: Any, q: Pair) -> Pair:
    """R(gamma) q for c = cos gamma, s = sin gamma."""
    return (c * q[0] - s * q[1], s * q[0] + c * q[1])


def cross(a: Pair, b: Pair) -> Any:
    """The z component of a x b."""
    return a[0] * b[1] - a[1] * b[0]


def dot(a: Pair, b: Pair) -> Any:
    """a . b."""
    return a[0] * b[0] + a[1] * b[1]


def anchors(p: Any) -> dict[int, tuple[Pair, Pair]]:
    """Spring i: (its anchor on the bottom body in B, its anchor on the top body in T)."""
    return {1: ((p.p2x, 0 * p.p2x), (p.p6x, 0 * p.p6x)), 2: ((p.p3x, p.p3y), (p.p5x, p.p5y))}


def points(p: Any, c1: Any, s1: Any, c2: Any, s2: Any) -> dict[int, Pair]:
    """Points 1-6 in frame B (eqs. (1)-(4))."""
    p4 = (p.L3 * c1, p.L3 * s1)
    (a1, q1), (a2, q2) = anchors(p)[1], anchors(p)[2]
    r6, r5 = rotate(c2, s2, q1), rotate(c2, s2, q2)
    zero = 0 * p.L3
    return {
        1: (zero, zero),
        2: a1,
        3: a2,
        4: p4,
        5: (p4[0] + r5[0], p4[1] + r5[1]),
        6: (p4[0] + r6[0], p4[1] + r6[1]),
    }


def spring_vectors(p: Any, c1: Any, s1: Any, c2: Any, s2: Any) -> dict[str, Pair]:
    """Spring vectors 2 -> 6 and 3 -> 5 and the rod 1 -> 4, in frame B."""
    pt = points(p, c1, s1, c2, s2)
    return {
        "spring1": (pt[6][0] - pt[2][0], pt[6][1] - pt[2][1]),
        "spring2": (pt[5][0] - pt[3][0], pt[5][1] - pt[3][1]),
        "rod": pt[4],
    }


def spring_jacobian(p: Any, spring: int, c1: Any, s1: Any, c2: Any, s2: Any) -> tuple[Pair, Pair]:
    """Columns d(P_spring)/d gamma1 = L3 u'(gamma1) and d(P_spring)/d gamma2 = R'(gamma2) q."""
    q = anchors(p)[spring][1]
    return (-p.L3 * s1, p.L3 * c1), rotate(-s2, c2, q)


def zero_length_poses(p: Any, spring: int) -> list[tuple[complex, complex, complex, complex]]:
    """(c1, s1, c2, s2) where spring `spring` has zero length: two poses, complex if unreachable.

    P4 = L3 u(gamma1) lies on the circle |P4| = L3 and on the circle of radius |q| around the
    bottom anchor a (q: the top anchor in T); then R(gamma2) q = a - P4 gives (c2, s2).
    """
    (ax, ay), (qx, qy) = ((complex(x), complex(y)) for x, y in anchors(p)[spring])
    norm_a = cmath.sqrt(ax * ax + ay * ay)
    ex, ey = ax / norm_a, ay / norm_a
    alpha = (ax * ax + ay * ay + p.L3**2 - qx * qx - qy * qy) / (2 * p.L3 * norm_a)
    out = []
    for beta in (cmath.sqrt(1 - alpha**2), -cmath.sqrt(1 - alpha**2)):
        u = (alpha * ex - beta * ey, alpha * ey + beta * ex)
        w = (ax - p.L3 * u[0], ay - p.L3 * u[1])
        qq = qx * qx + qy * qy
        out.append((u[0], u[1], (qx * w[0] + qy * w[1]) / qq, (qx * w[1] - qy * w[0]) / qq))
    return out


def spring_second_derivatives(
    p: Any, spring: int, c1: Any, s1: Any, c2: Any, s2: Any
) -> tuple[Pair, Pair, Pair]:
    """d2 P / d gamma1^2 = -L3 u(gamma1), d2 P / d gamma1 d gamma2 = 0, d2 P / d gamma2^2 =
    -R(gamma2) q (q: the spring's anchor on the top body, in T)."""
    q = anchors(p)[spring][1]
    zero = 0 * p.L3
    return (-p.L3 * c1, -p.L3 * s1), (zero, zero), rotate(-c2, -s2, q)
