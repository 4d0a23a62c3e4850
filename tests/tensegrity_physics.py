"""Independent plain-numpy statics of spatial bar-and-cable frameworks (no package code): free
nodes, fixed anchors, bars of fixed length between any two points, tension-only cables of free
length L0 (energy k/2 max(|r| - L0, 0)^2). The checks of the spatial examples compare the
package's taut-set pruning (and, once it solves them, its equilibria) with the critical points
found here by Newton's method on the Lagrange conditions from thousands of random poses, per
taut set or on the piecewise energy."""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Spatial:
    """A framework: `anchors` (name -> xyz), `free` node names, bars (a, b, length), cables
    (name, a, b, k, L0) and loads (node, force: V = -force . x); a and b name an anchor or a
    free node."""

    anchors: dict
    free: tuple
    bars: tuple
    cables: tuple
    loads: tuple = ()

    def point(self, X: np.ndarray, name: str) -> np.ndarray:
        """The point's coordinates for every pose of X (s x 3m): (s, 3)."""
        if name in self.anchors:
            return np.broadcast_to(np.asarray(self.anchors[name], float), (len(X), 3))
        i = self.free.index(name)
        return X[:, 3 * i : 3 * i + 3]

    def lengths(self, X: np.ndarray) -> np.ndarray:
        """(s, cables) the cables' lengths."""
        ends = [(self.point(X, c[1]), self.point(X, c[2])) for c in self.cables]
        return np.stack([np.linalg.norm(a - b, axis=1) for a, b in ends], axis=1)

    def energy(self, X: np.ndarray) -> np.ndarray:
        """V of every pose: the taut cables' stretch energies."""
        stretch = np.maximum(self.lengths(X) - np.array([c[4] for c in self.cables]), 0.0)
        work = sum((self.point(X, n) @ np.asarray(f, float) for n, f in self.loads), 0.0)
        return 0.5 * stretch**2 @ np.array([c[3] for c in self.cables], float) - work


def _slot(fw: Spatial, name: str) -> int | None:
    return None if name in fw.anchors else fw.free.index(name)


def _add_link(G, H, fw, X, a, b, first, second):
    """Add a link's gradient and Hessian blocks for points a, b (r = a - b, d = |r|): the
    gradient first(d) r, the Hessian first(d) I + second(d) r r^T."""
    r = fw.point(X, a) - fw.point(X, b)
    d = np.linalg.norm(r, axis=1)
    f, s = first(d), second(d)
    block = f[:, None, None] * np.eye(3) + s[:, None, None] * r[:, :, None] * r[:, None, :]
    for p, sign in ((_slot(fw, a), 1.0), (_slot(fw, b), -1.0)):
        if p is None:
            continue
        G[:, 3 * p : 3 * p + 3] += sign * f[:, None] * r
        for q, sign2 in ((_slot(fw, a), 1.0), (_slot(fw, b), -1.0)):
            if q is not None:
                H[:, 3 * p : 3 * p + 3, 3 * q : 3 * q + 3] += sign * sign2 * block


def _lagrange(fw: Spatial, taut: tuple | None, X: np.ndarray, lam: np.ndarray):
    """(residual, its Jacobian, the Lagrangian's Hessian, the bars' Jacobian) of the Lagrange
    conditions grad V + sum lam_b grad g_b = 0, g_b = (|r|^2 - len^2) / 2 = 0. V: the cables of
    `taut` as springs of free length L0, the others absent; taut None: the piecewise V itself
    (each cable's force density k max(1 - L0/d, 0), its Hessian term only where it is taut)."""
    s, n, m = len(X), X.shape[1], len(fw.bars)
    G, H = np.zeros((s, n)), np.zeros((s, n, n))
    for name, a, b, k, L0 in fw.cables:
        if taut is None:
            _add_link(G, H, fw, X, a, b, lambda d, k=k, L0=L0: k * np.maximum(1 - L0 / d, 0),
                      lambda d, k=k, L0=L0: np.where(d > L0, k * L0 / d**3, 0.0))  # fmt: skip
        elif name in taut:
            _add_link(G, H, fw, X, a, b, lambda d, k=k, L0=L0: k * (1 - L0 / d),
                      lambda d, k=k, L0=L0: k * L0 / d**3)  # fmt: skip
    for node, f in fw.loads:
        p = fw.free.index(node)
        G[:, 3 * p : 3 * p + 3] -= np.asarray(f, float)
    A, g = np.zeros((s, m, n)), np.zeros((s, m))
    for j, (a, b, length) in enumerate(fw.bars):
        Gb, Hb = np.zeros((s, n)), np.zeros((s, n, n))
        _add_link(Gb, Hb, fw, X, a, b, np.ones_like, np.zeros_like)
        A[:, j], g[:, j] = Gb, 0.5 * (np.sum((fw.point(X, a) - fw.point(X, b)) ** 2, 1) - length**2)
        G += lam[:, j, None] * Gb
        H += lam[:, j, None, None] * Hb
    J = np.zeros((s, n + m, n + m))
    J[:, :n, :n], J[:, :n, n:], J[:, n:, :n] = H, np.transpose(A, (0, 2, 1)), A
    return np.concatenate([G, g], axis=1), J, H, A


def newton(fw: Spatial, X: np.ndarray, taut: tuple | None = None, steps: int = 60) -> tuple:
    """Newton's method on the Lagrange conditions (of V_taut, or of the piecewise V when taut
    is None) from every pose at once, multipliers first fitted by least squares, each step at
    most 0.5 long (a start far from a root wanders instead of jumping off), a pose left alone
    once its residual is below 1e-12: (poses, residuals, Hessians, bars' Jacobians)."""
    X, n = X.copy(), X.shape[1]
    F, _, _, A = _lagrange(fw, taut, X, np.zeros((len(X), len(fw.bars))))
    lam = np.stack([np.linalg.lstsq(a.T, -f[:n], rcond=None)[0] for a, f in zip(A, F, strict=True)])
    active = np.arange(len(X))
    for _ in range(steps):
        F, J, _, _ = _lagrange(fw, taut, X[active], lam[active])
        keep = np.linalg.norm(F, axis=1) >= 1e-12
        active, F, J = active[keep], F[keep], J[keep]
        if not len(active):
            break
        try:
            step = np.linalg.solve(J, F[:, :, None])[:, :, 0]
        except np.linalg.LinAlgError:  # a singular Jacobian somewhere: least squares for all
            pairs = zip(J, F, strict=True)
            step = np.stack([np.linalg.lstsq(j, f, rcond=None)[0] for j, f in pairs])
        step *= np.minimum(1.0, 0.5 / np.maximum(np.linalg.norm(step, axis=1), 1e-300))[:, None]
        X[active] -= step[:, :n]
        lam[active] -= step[:, n:]
    F, _, H, A = _lagrange(fw, taut, X, lam)
    return X, np.linalg.norm(F, axis=1), H, A


def morse_index(H: np.ndarray, A: np.ndarray) -> int:
    """Negative eigenvalues of the Lagrangian's Hessian H on the null space of the constraints'
    Jacobian A; -1 when an eigenvalue is too small to tell (a degenerate point)."""
    _, sv, vt = np.linalg.svd(A)
    null = vt[len(sv[sv > 1e-9]) :].T
    ev = np.linalg.eigvalsh(null.T @ H @ null)
    return -1 if np.min(np.abs(ev)) < 1e-7 else int(np.sum(ev < 0))


def _parent(fw: Spatial, node: str, placed) -> tuple[str, float] | None:
    """(point, length) of a bar that ties `node` to a point already in `placed`, or None."""
    return next(((b if a == node else a, length) for a, b, length in fw.bars
                 if node in (a, b) and (b if a == node else a) in placed), None)  # fmt: skip


def random_poses(fw: Spatial, count: int, rng: np.random.Generator, scale: float) -> np.ndarray:
    """Random poses that meet the bars: each free node, in order, a bar's length from a point
    already placed in a random direction (Gaussian about the anchors' centroid if none)."""
    centre = np.mean(np.array(list(fw.anchors.values()), float), axis=0)
    placed = {n: np.broadcast_to(np.asarray(p, float), (count, 3)) for n, p in fw.anchors.items()}
    for node in fw.free:
        bar = _parent(fw, node, placed)
        if bar is None:
            placed[node] = centre + scale * rng.standard_normal((count, 3))
        else:
            u = rng.standard_normal((count, 3))
            placed[node] = placed[bar[0]] + bar[1] * u / np.linalg.norm(u, axis=1)[:, None]
    return np.concatenate([placed[n] for n in fw.free], axis=1)


def parents(fw: Spatial) -> list[tuple[str, float]]:
    """Each free node's parent: the point a bar ties it to, placed before it (a tree of bars
    rooted at the anchors; every free node must hang from one)."""
    seen, out = set(fw.anchors), []
    for node in fw.free:
        parent = _parent(fw, node, seen)
        if parent is None:
            raise ValueError(f"free node {node} hangs from no bar")
        out.append(parent)
        seen.add(node)
    return out


def _pose(fw: Spatial, U: np.ndarray) -> np.ndarray:
    """Poses from directions U (s x 3m, any length): each node its bar's length from its
    parent along its direction, so every bar holds exactly."""
    placed = {n: np.broadcast_to(np.asarray(p, float), (len(U), 3)) for n, p in fw.anchors.items()}
    for i, (node, (parent, length)) in enumerate(zip(fw.free, parents(fw), strict=True)):
        u = U[:, 3 * i : 3 * i + 3]
        placed[node] = placed[parent] + length * u / np.linalg.norm(u, axis=1)[:, None]
    return np.concatenate([placed[n] for n in fw.free], axis=1)


def descents(fw: Spatial, starts: int, seed: int, steps: int = 4000) -> tuple:
    """Local descents of V from random poses (directions of the bars as coordinates, central
    differences, a backtracking line search per pose): (final poses, their |grad V|)."""
    rng = np.random.default_rng(seed)
    U = rng.standard_normal((starts, 3 * len(fw.free)))

    def V(U):
        return fw.energy(_pose(fw, U))

    def grad(U, h=1e-7):
        E = np.eye(U.shape[1]) * h
        return np.stack([(V(U + E[k]) - V(U - E[k])) / (2 * h) for k in range(U.shape[1])], 1)

    for _ in range(steps):
        U /= np.linalg.norm(U.reshape(starts, -1, 3), axis=2).repeat(3, axis=1)
        g, v, step = grad(U), V(U), np.ones(starts)
        for _ in range(40):  # halve each pose's step until it decreases V enough
            bad = V(U - step[:, None] * g) > v - 0.5 * step * np.sum(g * g, axis=1)
            if not bad.any():
                break
            step[bad] /= 2
        U = U - step[:, None] * g
    return _pose(fw, U), np.linalg.norm(grad(U), axis=1)


def critical_points(fw: Spatial, starts: int = 2000, seed: int = 0, scale: float = 1.5) -> list:
    """Every critical point of V that Newton finds from `starts` random poses per taut set:
    dicts (X: 3m coordinates, taut: cable names, index: Morse index, energy), distinct to 1e-7,
    each with its cables taut (|r| > L0) or slack (|r| < L0) as its set says."""
    rng = np.random.default_rng(seed)
    names = [c[0] for c in fw.cables]
    L0 = np.array([c[4] for c in fw.cables])
    found: list[dict] = []
    for size in range(len(names) + 1):
        for taut in itertools.combinations(names, size):
            X0 = random_poses(fw, starts, rng, scale)
            X, res, H, A = newton(fw, X0, taut, steps=80)
            mask = np.isin(names, taut)
            for i in np.flatnonzero(res < 1e-11):
                d = fw.lengths(X[i : i + 1])[0]
                if not np.all(np.where(mask, d > L0 + 1e-9, d < L0 - 1e-9)):
                    continue
                if any(np.max(np.abs(p["X"] - X[i])) < 1e-7 for p in found):
                    continue
                found.append({"X": X[i].copy(), "taut": taut, "index": morse_index(H[i], A[i]),
                              "energy": float(fw.energy(X[i : i + 1])[0])})  # fmt: skip
    return found
