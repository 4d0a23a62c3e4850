"""The inertia of a symmetric matrix of balls, proved: how many eigenvalues are negative,
positive, for every matrix inside the balls, or None when a pivot may vanish.

B is first brought near diagonal by a congruence with a float matrix T (the eigenvectors of
B's midpoint; exact in ball arithmetic, and congruence keeps the inertia: Sylvester's law),
then factored as L D L^T without pivoting in ball arithmetic: when no pivot of D contains 0,
T^T B T is nonsingular (so is T) and its inertia is the signs of D. For the reduced Hessian of
a constrained equilibrium, B = [[H, G^T], [G, 0]] with G the constraint Jacobian (c rows):
a nonsingular B has G of full rank, and In(B) = In(Z^T H Z) + (c, c) (Z a basis of ker G).
"""

from __future__ import annotations

import numpy as np


def inertia(B: list[list]) -> tuple[int, int] | None:
    """(negative, positive) eigenvalue counts of every symmetric matrix in the arb balls B, or
    None if not decided."""
    from flint import arb, arb_mat

    n = len(B)
    if n == 0:
        return 0, 0
    mid = np.array([[float(b.mid()) for b in row] for row in B])
    if not np.isfinite(mid).all():
        return None
    _, vecs = np.linalg.eigh((mid + mid.T) / 2)
    T = arb_mat([[arb(float(vecs[i, j])) for j in range(n)] for i in range(n)])
    C = T.transpose() * arb_mat([list(row) for row in B]) * T
    a = [[C[i, j] for j in range(n)] for i in range(n)]
    pivots = []
    for k in range(n):
        d = a[k][k]
        if d.contains(0):
            return None
        pivots.append(d)
        for i in range(k + 1, n):
            factor = a[i][k] / d
            for j in range(k + 1, n):
                a[i][j] = a[i][j] - factor * a[k][j]
    negative = sum(1 for d in pivots if d < 0)
    return negative, n - negative


def reduced_kind(H: list[list], G: list[list]) -> str:
    """min, max or saddle from the Hessian H (m x m balls) reduced to the null space of the
    constraint Jacobian G (c x m), or 'undecided'."""
    from flint import arb

    m, c = len(H), len(G)
    zero = arb(0)
    B = [list(H[i]) + [G[r][i] for r in range(c)] for i in range(m)]
    B += [list(G[r]) + [zero] * c for r in range(c)]
    found = inertia(B)
    if found is None:
        return "undecided"
    index, size = found[0] - c, m - c
    if index == 0:
        return "min"
    return "max" if index == size else "saddle"
