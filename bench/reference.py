"""Reference equilibria: the physical equilibria of cases 1-3 to 40 digits, without Bertini.

Start points: the energy route (`critical_points`, Newton on grad V from a grid on the torus).
Refinement: Newton's method in mpmath at 60 digits on the paper's equilibrium equations (7)-(8)
written in the angles: with S_i the spring vectors (P6 - P2, P5 - P3), P4 the rod and A_i the
bottom anchors (P2, P3), and the force density t_i = k_i (1 - L0i / |S_i|),

    (7)  sum_i t_i cross(P4, S_i) = 0      (top body, force across the rod)
    (8)  sum_i t_i cross(A_i, S_i) = 0     (moment about P1)

Usage: .venv/bin/python bench/reference.py
"""

from __future__ import annotations

import mpmath as mp
import pandas as pd
from benchlib import CASES, show, write_csv

DIGITS = 40
WORKING_DPS = 60


def _balance(p: dict, g1, g2) -> tuple:
    """Eqs (7)-(8) at angles g1, g2 (radians, mpmath numbers)."""
    c1, s1, c2, s2 = mp.cos(g1), mp.sin(g1), mp.cos(g2), mp.sin(g2)
    p4 = (p["L3"] * c1, p["L3"] * s1)
    p6 = (p4[0] + c2 * p["p6x"], p4[1] + s2 * p["p6x"])
    p5 = (p4[0] + c2 * p["p5x"] - s2 * p["p5y"], p4[1] + s2 * p["p5x"] + c2 * p["p5y"])
    anchors = ((p["p2x"], mp.mpf(0)), (p["p3x"], p["p3y"]))
    springs = ((p6[0] - anchors[0][0], p6[1]), (p5[0] - anchors[1][0], p5[1] - anchors[1][1]))
    force, moment = mp.mpf(0), mp.mpf(0)
    for i, (a, s) in enumerate(zip(anchors, springs, strict=True), start=1):
        t = p[f"k{i}"] * (1 - p[f"L0{i}"] / mp.sqrt(s[0] ** 2 + s[1] ** 2))
        force += t * (p4[0] * s[1] - p4[1] * s[0])
        moment += t * (a[0] * s[1] - a[1] * s[0])
    return force, moment


def newton_mp(params, g1_deg: float, g2_deg: float, steps: int = 40) -> dict:
    """Newton on eqs (7)-(8) from (g1, g2) in degrees; the Jacobian by central differences
    (step 1e-25 at 60 digits: its error is far below what Newton's rate needs)."""
    with mp.workdps(WORKING_DPS):
        p = {k: mp.mpf(repr(v)) for k, v in params.as_dict().items()}
        x = mp.matrix([mp.radians(mp.mpf(repr(g1_deg))), mp.radians(mp.mpf(repr(g2_deg)))])
        start = x.copy()
        h = mp.mpf(10) ** -25
        for _ in range(steps):
            f = mp.matrix(_balance(p, x[0], x[1]))
            jac = mp.matrix(2, 2)
            for j in range(2):
                e = mp.matrix(2, 1)
                e[j] = h
                plus, minus = _balance(p, *(x + e)), _balance(p, *(x - e))
                for i in range(2):
                    jac[i, j] = (plus[i] - minus[i]) / (2 * h)
            step = mp.lu_solve(jac, f)
            x -= step
            if mp.norm(step) < mp.mpf(10) ** -(DIGITS + 8):
                break
        residual = max(abs(v) for v in _balance(p, x[0], x[1]))
        g = [mp.degrees(v) % 360 for v in x]
        shift = max(abs(mp.degrees(a - b)) for a, b in zip(x, start, strict=True))
        return {
            "gamma1_deg": float(g[0]),
            "gamma2_deg": float(g[1]),
            "gamma1_40": mp.nstr(g[0], DIGITS, strip_zeros=False),
            "gamma2_40": mp.nstr(g[1], DIGITS, strip_zeros=False),
            "residual": float(residual),
            "shift_deg": float(shift),
        }


def reference_case(case: str) -> pd.DataFrame:
    """The physical equilibria of one case (Table 1 parameters), refined to 40 digits."""
    from cotm_bertini.analysis.critical_points import critical_points
    from cotm_bertini.params import make_params

    params = make_params(case)
    rows = []
    for k, cp in enumerate(critical_points(params).itertuples(index=False), start=1):
        rows.append(
            {
                "case": case,
                "eq": k,
                "kind": cp.kind,
                **newton_mp(params, cp.gamma1_deg, cp.gamma2_deg),
            }
        )
    return pd.DataFrame(rows)


def run() -> dict[str, pd.DataFrame]:
    """Every case's reference equilibria: printed, written to reference.csv, returned by case."""
    tables = {case: reference_case(case) for case in CASES}
    table = pd.concat(tables.values(), ignore_index=True)
    show(
        "1. Reference physical equilibria (mpmath Newton on eqs (7)-(8), 40 digits)",
        table[["case", "eq", "kind", "gamma1_40", "gamma2_40", "residual", "shift_deg"]],
        {"residual": ".1e", "shift_deg": ".1e"},
    )
    counts = ", ".join(f"{c}: {len(t)}" for c, t in tables.items())
    print(f"physical equilibria: {counts}; shift_deg = move from the energy-route start point")
    write_csv(table, "reference")
    return tables


if __name__ == "__main__":
    run()
