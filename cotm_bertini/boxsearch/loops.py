"""A planar framework whose bodies close one loop with one degree of freedom (a four-bar: three
bodies pinned in a tree, one pin closing it): its equilibria on the real route.

Its poses are the curve M = {h(theta) = 0} in the torus of the tree's body angles, h the
closing pin's two coordinates' mismatch. V's critical points on M are where V's gradient g is
normal to M, i.e. orthogonal to M's tangent t = J_1 x J_2 (the cross product of the rows of h's
Jacobian J, nonzero wherever M is smooth):

    F(theta) = (h_x, h_y, t . g) = 0,

three equations in the three angles, with no multiplier to bound. The branch and bound of
boxsearch.boxes runs on F as on a gradient: F's enclosure excludes boxes, and the Krawczyk test
on F's Jacobian proves each root unique. That Jacobian needs h's second derivatives, which a
chain of rotating bodies gives for free: along body k's angle, column k of J turns a quarter
turn (d/dtheta_k of R(theta_k) v is R(theta_k) v turned by pi/2; the other columns do not
depend on theta_k). The whole of M is searched, both assembly branches of a four-bar and
every crank angle. A singular pose of the loop (J of rank below 2, where M crosses itself)
makes F vanish with t, and its box stays undecided: reported, not hidden.

The pin's multipliers, which the endpoints of the polynomial system need, follow from
g + J^T mu = 0 at each root (least squares; exact there).
"""

from __future__ import annotations

import numpy as np

from ..model.framework.structure import layout
from ..model.intervals import Interval, stack


def single_loop(fw) -> str:
    """'' where `fw` is a planar framework of three bodies pinned in a tree with one pin
    closing a loop (one degree of freedom), else why not."""
    lay = layout(fw)
    if lay.translations or lay.free_nodes:
        return "a free body or a free node (not pinned to the ground)"
    if len(lay.closing_pins) != 1 or len(lay.rotations) != 3:
        pins = len(lay.closing_pins)
        return (f"{pins} closing pin{'s' * (pins != 1)} over {len(lay.rotations)} bodies (the "
                "real route takes one loop of three bodies, a four-bar)")  # fmt: skip
    return ""


def _cross(a: list, b: list) -> list:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _turned(J: list, k: int) -> tuple[list, list]:
    """d/dtheta_k of J's two rows: column k a quarter turn on (-J_1k, J_0k), the rest 0."""
    zero = J[0][k] * 0.0
    row0 = [-J[1][k] if j == k else zero for j in range(3)]
    row1 = [J[0][k] if j == k else zero for j in range(3)]
    return row0, row1


class ClosingPin:
    """F = (h, t . g) of a single-loop framework and its Jacobian, from the generated
    constraint_values and constraint_jacobian of its system (`fs`) and V's gradient and
    Hessian as the torus of its body angles gives them."""

    constraints = 2  # F's first components: the closing pin's mismatch

    def __init__(self, fs):
        self.fs = fs
        self.multipliers = [v for v in fs.ps.variables if v.startswith("mu_")]

    def parts(self, code, X, P) -> tuple[list, list]:
        """(h, J) from the generated `code` (ball or numeric module) at the pose X."""
        h = list(code.constraint_values(X, P))
        flat = list(code.constraint_jacobian(X, P))
        return h, [flat[:3], flat[3:6]]

    def system(self, h: list, J: list, g: list) -> list:
        """F's three components (intervals or arrays), g as a list of its components."""
        t = _cross(*J)
        return [h[0], h[1], t[0] * g[0] + t[1] * g[1] + t[2] * g[2]]

    def jacobian_rows(self, J: list, g: list, H) -> list:
        """F's Jacobian as three rows of three entries; H[i][k] V's Hessian's entries."""
        t = _cross(*J)
        last = []
        for k in range(3):
            d0, d1 = _turned(J, k)
            a, b = _cross(d0, J[1]), _cross(J[0], d1)
            last.append(sum(((a[i] + b[i]) * g[i] + t[i] * H[i][k] for i in range(3)),
                            start=J[0][k] * 0.0))  # fmt: skip
        return [J[0], J[1], last]

    def enclose(self, code, X, P, grad: Interval) -> Interval:
        """F's enclosure over the boxes (B, 3), grad V's enclosure given."""
        h, J = self.parts(code, X, P)
        g = [grad[:, i] for i in range(3)]
        return stack([_interval(v, len(grad.lo)) for v in self.system(h, J, g)], axis=1)

    def jacobian(self, code, X, P, grad: Interval, hess: Interval) -> Interval:
        """F's Jacobian's enclosure over the boxes (B, 3, 3)."""
        count = len(grad.lo)
        _, J = self.parts(code, X, P)
        J = [[_interval(v, count) for v in row] for row in J]
        g = [grad[:, i] for i in range(3)]
        H = [[hess[:, i, k] for k in range(3)] for i in range(3)]
        rows = self.jacobian_rows(J, g, H)
        return stack([stack(row, axis=1) for row in rows], axis=1)

    def numeric(self, X, P, g: np.ndarray, H: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """F and its Jacobian at points (R, 3), V's gradient and Hessian there given."""
        h, J = self.parts(self.fs.numeric, X, P)
        h, J = _arrays(h, len(g)), [_arrays(row, len(g)) for row in J]
        gl = [g[:, i] for i in range(3)]
        F = np.stack(self.system(h, J, gl), axis=1)
        rows = self.jacobian_rows(J, gl, [[H[:, i, k] for k in range(3)] for i in range(3)])
        return F, np.stack([np.stack(r, axis=1) for r in rows], axis=1)

    def pin_multipliers(self, X, P, g: np.ndarray) -> np.ndarray:
        """mu (R, 2) with g + J^T mu = 0 (least squares; exact at a critical point on M)."""
        _, J = self.parts(self.fs.numeric, X, P)
        A = np.stack([np.stack(_arrays(row, len(g)), axis=1) for row in J], axis=1)
        # (R, 2, 3): solve A^T mu = -g per point
        return np.stack(
            [np.linalg.lstsq(a.T, -b, rcond=None)[0] for a, b in zip(A, g, strict=True)]
        )


def _arrays(values: list, count: int) -> list[np.ndarray]:
    """Generated numeric outputs (arrays, or constants) as arrays of `count` points."""
    return [np.broadcast_to(np.asarray(v, dtype=float), (count,)) for v in values]


def _interval(v, count: int) -> Interval:
    """An enclosure (B,) of a generated entry (an interval, or a constant)."""
    return v if isinstance(v, Interval) else Interval.of(np.broadcast_to(float(v), (count,)))
