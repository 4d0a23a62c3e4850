"""Independent plain-numpy mechanics of the CoTM for tests (no sympy, no package code)."""

from __future__ import annotations

import numpy as np


def points(p, g1, g2):
    """P2, P3, P4, P5, P6 in frame B for angles in radians (docs/paper.md labels)."""
    c1, s1, c2, s2 = np.cos(g1), np.sin(g1), np.cos(g2), np.sin(g2)
    p4 = np.array([p.L3 * c1, p.L3 * s1])
    rot = np.array([[c2, -s2], [s2, c2]])
    return {
        2: np.array([p.p2x, 0.0]),
        3: np.array([p.p3x, p.p3y]),
        4: p4,
        5: p4 + rot @ np.array([p.p5x, p.p5y]),
        6: p4 + rot @ np.array([p.p6x, 0.0]),
    }


def cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def balance(p, g1, g2):
    """Eqs. (7) and (8) of the paper in their rational form, d_i = |P_spring|."""
    pt = points(p, g1, g2)
    v1, v2 = pt[6] - pt[2], pt[5] - pt[3]
    d1, d2 = np.linalg.norm(v1), np.linalg.norm(v2)
    w1 = p.k1 * (1 - p.L01 / d1)
    w2 = p.k2 * (1 - p.L02 / d2)
    force = w1 * cross(pt[4], v1) + w2 * cross(pt[4], v2)
    moment = w1 * cross(pt[2], v1) + w2 * cross(pt[3], v2)
    return np.array([force, moment]), (d1, d2)


def energy(p, g1, g2):
    """V = 1/2 k1 (d1 - L01)^2 + 1/2 k2 (d2 - L02)^2."""
    pt = points(p, g1, g2)
    d1 = np.linalg.norm(pt[6] - pt[2])
    d2 = np.linalg.norm(pt[5] - pt[3])
    return 0.5 * p.k1 * (d1 - p.L01) ** 2 + 0.5 * p.k2 * (d2 - p.L02) ** 2


def energy_gradient_fd(p, g1, g2, h=1e-6):
    """Central finite differences of V (an independent check of the analytic gradient)."""
    return np.array(
        [
            (energy(p, g1 + h, g2) - energy(p, g1 - h, g2)) / (2 * h),
            (energy(p, g1, g2 + h) - energy(p, g1, g2 - h)) / (2 * h),
        ]
    )


def angle_distance(a, b):
    """Distance of two angles in degrees, modulo 360."""
    return abs((a - b + 180.0) % 360.0 - 180.0)


def mp_refine(p, g1_deg, g2_deg, dps=40):
    """Angles (degrees) of the equilibrium near a guess, by 40-digit Newton on eqs (7)-(8)."""
    import mpmath as mp

    with mp.workdps(dps):
        v = {
            k: mp.mpf(repr(getattr(p, k)))
            for k in ("L3", "k1", "k2", "p2x", "p3x", "p3y", "p6x", "p5x", "p5y", "L01", "L02")
        }

        def f(g1, g2):
            c1, s1, c2, s2 = mp.cos(g1), mp.sin(g1), mp.cos(g2), mp.sin(g2)
            p4 = (v["L3"] * c1, v["L3"] * s1)
            p6 = (p4[0] + c2 * v["p6x"], p4[1] + s2 * v["p6x"])
            p5 = (p4[0] + c2 * v["p5x"] - s2 * v["p5y"], p4[1] + s2 * v["p5x"] + c2 * v["p5y"])
            a = (p6[0] - v["p2x"], p6[1])
            b = (p5[0] - v["p3x"], p5[1] - v["p3y"])
            w1 = v["k1"] * (1 - v["L01"] / mp.sqrt(a[0] ** 2 + a[1] ** 2))
            w2 = v["k2"] * (1 - v["L02"] / mp.sqrt(b[0] ** 2 + b[1] ** 2))

            def cr(x, y):
                return x[0] * y[1] - x[1] * y[0]

            return [
                w1 * cr(p4, a) + w2 * cr(p4, b),
                w1 * cr((v["p2x"], 0), a) + w2 * cr((v["p3x"], v["p3y"]), b),
            ]

        r = mp.findroot(f, (mp.radians(g1_deg), mp.radians(g2_deg)))
        return float(mp.degrees(r[0]) % 360), float(mp.degrees(r[1]) % 360)
