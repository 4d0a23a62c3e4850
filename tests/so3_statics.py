"""The statics of one rigid body on a ball joint, written here in numpy with no package code: V
of springs, cables and loads on the body as a function of its rotation R, its gradient and
Hessian in the body-frame rotation vector w (R exp([w]x), at w = 0), and Newton on SO(3) from
random rotations. Test helper for tests/test_rotations.py."""

from __future__ import annotations

import numpy as np


def _hat(v: np.ndarray) -> np.ndarray:
    """[v]x for vectors (..., 3): (..., 3, 3)."""
    z = np.zeros(v.shape[:-1])
    return np.stack([np.stack([z, -v[..., 2], v[..., 1]], -1),
                     np.stack([v[..., 2], z, -v[..., 0]], -1),
                     np.stack([-v[..., 1], v[..., 0], z], -1)], -2)  # fmt: skip


def expm(w: np.ndarray) -> np.ndarray:
    """exp([w]x) by Rodrigues' formula, (R, 3) -> (R, 3, 3)."""
    t = np.linalg.norm(w, axis=1)[:, None, None]
    K = _hat(w)
    with np.errstate(invalid="ignore", divide="ignore"):
        a = np.where(t > 1e-12, np.sin(t) / t, 1.0)
        b = np.where(t > 1e-12, (1 - np.cos(t)) / t**2, 0.5)
    return np.eye(3) + a * K + b * K @ K


def rotation(q: np.ndarray) -> np.ndarray:
    """The rotation matrices (R, 3, 3) of quaternions (R, 4), w first."""
    q = q / np.linalg.norm(q, axis=1)[:, None]
    w, x, y, z = q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], -2)  # fmt: skip


def derivatives(body: dict, R: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(V, grad V, Hess V) at rotations R (N, 3, 3), in the body-frame rotation vector. `body`:
    pivot (3,), links [(kind, body point, ground point, k, L0)], loads [(body point, force)],
    body points relative to the pivot in the body's frame."""
    E = np.eye(3)
    V, g, H = np.zeros(len(R)), np.zeros((len(R), 3)), np.zeros((len(R), 3, 3))

    def jets(c):
        p = body["pivot"] + R @ c
        dp = np.stack([R @ np.cross(E[a], c) for a in range(3)], 1)  # (N, a, 3)
        ddp = np.empty((len(R), 3, 3, 3))
        for a in range(3):
            for b in range(3):
                m = 0.5 * (_hat(E[a]) @ _hat(E[b]) + _hat(E[b]) @ _hat(E[a])) @ c
                ddp[:, a, b] = R @ m
        return p, dp, ddp

    for kind, c, ground, k, L0 in body["links"]:
        p, dp, ddp = jets(np.asarray(c, float))
        r = p - ground
        d = np.linalg.norm(r, axis=1)
        on = np.ones(len(R), bool) if kind == "spring" else d > L0
        ra = np.einsum("nc,nac->na", r, dp)
        w = np.where(on, k * (1 - L0 / d), 0.0)
        V += np.where(on, 0.5 * k * (d - L0) ** 2, 0.0)
        g += w[:, None] * ra
        A = np.einsum("nac,nbc->nab", dp, dp) + np.einsum("nc,nabc->nab", r, ddp)
        H += w[:, None, None] * A + np.where(on, k * L0 / d**3, 0.0)[:, None, None] * (
            ra[:, :, None] * ra[:, None, :]
        )
    for c, force in body["loads"]:
        p, dp, ddp = jets(np.asarray(c, float))
        V -= p @ force
        g -= dp @ force
        H -= ddp @ force
    return V, g, H


def critical_points(body: dict, starts: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(rotations (K, 3, 3), Hessian indices (K,)) of the distinct critical points Newton on
    SO(3) reaches from `starts` random rotations (steps of at most 0.5 rad)."""
    rng = np.random.default_rng(seed)
    R = rotation(rng.normal(size=(starts, 4)))
    for _ in range(80):
        _, g, H = derivatives(body, R)
        with np.errstate(all="ignore"):
            step = -np.linalg.solve(H + 1e-14 * np.eye(3), g[..., None])[..., 0]
        big = np.linalg.norm(step, axis=1)
        step *= np.minimum(1.0, 0.5 / np.maximum(big, 1e-300))[:, None]
        step[~np.isfinite(step).all(axis=1)] = 0.0
        R = R @ expm(step)
    _, g, H = derivatives(body, R)
    good = np.linalg.norm(g, axis=1) < 1e-10
    found, index = [], []
    for Ri, Hi in zip(R[good], H[good], strict=True):
        if all(np.abs(Ri - F).max() > 1e-6 for F in found):
            found.append(Ri)
            index.append(int((np.linalg.eigvalsh(Hi) < 0).sum()))
    return np.array(found).reshape(-1, 3, 3), np.array(index, dtype=int)
