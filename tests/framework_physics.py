"""Independent plain-numpy energies of the example frameworks (no package code): the checks of
the framework route compare its equilibria with dense scans and local searches of these."""

from __future__ import annotations

import numpy as np


def zeeman_energy(theta, u, cables: bool, k=1.0, L0=0.25, centre=(1.0, 0.0), p=(2.0, 0.25),
                  radius=0.5):  # fmt: skip
    """V of Zeeman's machine at wheel angles theta (rad): two bands from the rim to u and p."""
    theta = np.asarray(theta, float)
    rim = np.stack([centre[0] + radius * np.cos(theta), centre[1] + radius * np.sin(theta)])
    V = 0.0
    for anchor in (u, p):
        d = np.hypot(rim[0] - anchor[0], rim[1] - anchor[1])
        stretch = np.maximum(d - L0, 0.0) if cables else d - L0
        V = V + k / 2 * stretch**2
    return V


def scan_critical_points(f, n: int = 200_000, period: float = 2 * np.pi) -> list[tuple]:
    """Critical points of a smooth periodic f(theta): sign changes of a central-difference
    derivative on a dense grid, bisected to 1e-13 rad; (theta, 'min' or 'max')."""
    h = 1e-7

    def df(t):
        return (f(t + h) - f(t - h)) / (2 * h)

    t = np.linspace(0.0, period, n, endpoint=False)
    g = df(t)
    out = []
    for i in np.flatnonzero(np.sign(g) != np.sign(np.roll(g, -1))):
        a, b = t[i], t[i] + period / n
        ga = df(a)
        for _ in range(60):
            m = (a + b) / 2
            if np.sign(df(m)) == np.sign(ga):
                a, ga = m, df(m)
            else:
                b = m
        out.append(((a + b) / 2 % period, "min" if g[i] < 0 else "max"))
    return out


def pendulum_energy(th1, th2, k=1.0, weight=0.3, L0=0.5):
    """V of examples/double_pendulum.toml at link angles th1, th2 (rad)."""
    e = np.stack([np.cos(th1), np.sin(th1)])
    tip = e + 0.8 * np.stack([np.cos(th2), np.sin(th2)])
    V = 0.0
    for point, anchor, kk, free in ((e, (-0.6, 1.2), k, L0), (tip, (1.5, -0.8), 2 * k, 0.4),
                                    (tip, (-1.2, -1.0), 1.5 * k, 0.0)):  # fmt: skip
        d = np.hypot(point[0] - anchor[0], point[1] - anchor[1])
        V = V + kk / 2 * (d - free) ** 2
    return V + weight * tip[1]


def grid_minima(f, n: int = 360) -> list[np.ndarray]:
    """Local minima of f on the torus: strict minima of an n x n grid, then Newton on a
    central-difference gradient and Hessian to convergence."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    T1, T2 = np.meshgrid(t, t, indexing="ij")
    V = f(T1, T2)
    lower = np.ones_like(V, dtype=bool)
    for s1 in (-1, 0, 1):
        for s2 in (-1, 0, 1):
            if s1 or s2:
                lower &= V < np.roll(np.roll(V, s1, 0), s2, 1)
    out = []
    for i, j in zip(*np.nonzero(lower), strict=True):
        x = np.array([t[i], t[j]])
        for _ in range(50):
            g, H = _grad_hess(f, x)
            step = np.linalg.solve(H, g)
            x = x - step
            if np.abs(step).max() < 1e-13:
                break
        out.append(np.mod(x, 2 * np.pi))
    return out


def _grad_hess(f, x, h=1e-5):
    e = np.eye(2) * h
    g = np.array([(f(*(x + e[k])) - f(*(x - e[k]))) / (2 * h) for k in range(2)])
    H = np.array(
        [[(f(*(x + e[a] + e[b])) - f(*(x + e[a] - e[b])) - f(*(x - e[a] + e[b]))
           + f(*(x - e[a] - e[b]))) / (4 * h * h) for b in range(2)] for a in range(2)]
    )  # fmt: skip
    return g, H


def hessian_eigenvalues(f, x) -> np.ndarray:
    """The eigenvalues of f's central-difference Hessian at x (ascending)."""
    return np.linalg.eigvalsh(_grad_hess(f, np.asarray(x, float))[1])


def gradient_norm(f, x) -> float:
    """|grad f| at x by central differences."""
    return float(np.linalg.norm(_grad_hess(f, np.asarray(x, float))[0]))


def fourbar_energy(theta, branch: int, ex=1.0, ey=2.0, L0=0.5):
    """V of examples/fourbar.toml at crank angle theta on one assembly branch (+1 or -1)."""
    scalar = np.ndim(theta) == 0
    B, p = fourbar_points(np.atleast_1d(np.asarray(theta, float)), branch)
    lift = np.hypot(p[0] - ex, p[1] - ey)
    tie = np.hypot(B[0] + 1.0, B[1] + 1.0)
    V = 1.0 / 2 * np.maximum(lift - L0, 0) ** 2 + 2.0 / 2 * tie**2
    return V[0] if scalar else V


def fourbar_points(theta: np.ndarray, branch: int) -> tuple[np.ndarray, np.ndarray]:
    """The crank's tip B and the coupler's cable point p (2 x n) at crank angles theta: the
    coupler's tip meets the rocker's where the circles |C - B| = 2.2, |C - D| = 1.5 cross."""
    B = np.stack([np.cos(theta), np.sin(theta)])
    D = np.array([2.0, 0.0])[:, None]
    gap = D - B
    dist = np.hypot(*gap)
    along = (2.2**2 - 1.5**2 + dist**2) / (2 * dist)
    across = np.sqrt(np.maximum(2.2**2 - along**2, 0.0))
    unit = gap / dist
    normal = np.stack([-unit[1], unit[0]])
    C = B + along * unit + branch * across * normal
    u = (C - B) / 2.2
    return B, B + 1.1 * u + 0.5 * np.stack([-u[1], u[0]])


def fourbar_branch(crank_deg, coupler_deg) -> int:
    """The assembly branch of a pose: the side of the line B -> D the joint C lies on."""
    t, f = np.radians(crank_deg), np.radians(coupler_deg)
    B = np.array([np.cos(t), np.sin(t)])
    C = B + 2.2 * np.array([np.cos(f), np.sin(f)])
    gap = np.array([2.0, 0.0]) - B
    return 1 if gap[0] * (C - B)[1] - gap[1] * (C - B)[0] > 0 else -1


PRISM_BASE = np.array(
    [[1.0, 0.0, 0.0], [-0.5, 0.8660254037844386, 0.0], [-0.5, -0.8660254037844386, 0.0]]
)


def prism_nodes(angles, h=1.2):
    """Top nodes A, B, C of examples/prism.toml: each on the sphere of radius h about its base
    corner, from (polar, azimuth) angles (6 numbers): the bars hold exactly."""
    a = np.asarray(angles, float).reshape(3, 2)
    dirs = np.stack(
        [np.sin(a[:, 0]) * np.cos(a[:, 1]), np.sin(a[:, 0]) * np.sin(a[:, 1]), np.cos(a[:, 0])],
        axis=1,
    )
    return PRISM_BASE + h * dirs


def prism_energy(angles, kt=1.0, kd=1.5):
    """V of the prism (zero-free-length cables): top triangle, and A-b, B-c, C-a diagonals."""
    n = prism_nodes(angles)
    top = sum(np.sum((n[i] - n[(i + 1) % 3]) ** 2) for i in range(3))
    diag = sum(np.sum((n[i] - PRISM_BASE[(i + 1) % 3]) ** 2) for i in range(3))
    return kt / 2 * top + kd / 2 * diag


def prism_minima(starts: int = 60, seed: int = 5) -> list[np.ndarray]:
    """Node positions (3 x 3) of the minima that local descents from random poses reach
    (gradient descent with a backtracking line search, then Newton, central differences)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(starts):
        x = np.concatenate([[rng.uniform(0.05, np.pi - 0.05), rng.uniform(0, 2 * np.pi)]
                            for _ in range(3)])  # fmt: skip
        for _ in range(3000):
            g = _gradient(prism_energy, x)
            if np.linalg.norm(g) < 1e-10:
                break
            step = 1.0
            while (
                prism_energy(x - step * g) > prism_energy(x) - 0.5 * step * g @ g and step > 1e-12
            ):
                step /= 2
            x = x - step * g
        out.append(prism_nodes(x))
    return out


def _gradient(f, x, h=1e-6):
    e = np.eye(len(x)) * h
    return np.array([(f(x + e[k]) - f(x - e[k])) / (2 * h) for k in range(len(x))])
