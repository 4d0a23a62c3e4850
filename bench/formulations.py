"""Formulations and start systems, cases 2 and 3: paths, finite and spurious solutions, physical.

- cos/sin, total degree: the package's system (c_i, s_i, d_i), bertini2 total-degree start;
- cos/sin, multihomogeneous: same system, groups {c1,s1},{c2,s2},{d1},{d2};
- tan-half (the paper's form): `equations.tan_half_system(zfl)`, x_i = tan(gamma_i / 2), with
  the numbers substituted, solved by the bertini2 command (total degree);
- force density: variables c_i, s_i and, for each spring with L0i > 0, d_i and the force density
  q_i = k_i (1 - L0i / d_i), written q_i d_i - k_i (d_i - L0i) = 0 (a ZFL spring has q_i = k_i);
  balance equations linear in q: sum q_i cross(P4, S_i) = 0, sum q_i cross(A_i, S_i) = 0; plus
  d_i^2 = |S_i|^2 and the unit circles. Derived here with sympy from the points.

Spurious: a distinct finite solution with 1 + x_i^2 = 0 (tan-half), or whose image in
(c, s, d) does not solve the cos/sin system. The others are classified by the package
(`stability.classify`) and their physical rows matched to the reference equilibria.

Usage: .venv/bin/python bench/formulations.py
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
import sympy as sp
from benchlib import match, run_bertini2, show, write_csv

FORMULATION_CASES = ("case2", "case3")
SPURIOUS_REL = 1e-6  # relative residual in the cos/sin system above this: not a solution


def _rational(value: float) -> sp.Rational:
    return sp.Rational(repr(float(value)))


def numeric_system(variables, names, exprs, subs: dict):
    """sympy polynomials with numbers substituted -> the package's PolySystem."""
    from cotm_bertini.model.polynomial import PolySystem

    exps, coeffs = [], []
    for e in exprs:
        poly = sp.Poly(sp.expand(e.subs(subs)), *variables)
        exps.append(np.array([m for m, _ in poly.terms()], dtype=np.int64))
        coeffs.append(np.array([float(c) for _, c in poly.terms()], dtype=float))
    return PolySystem(tuple(str(v) for v in variables), tuple(names), tuple(exps), tuple(coeffs))


def tan_half(params):
    """The paper's tan-half system of this case, numbers substituted."""
    from cotm_bertini.model.equations import PSYM, tan_half_system

    variables, eqs = tan_half_system(params.zfl)
    subs = {PSYM[k]: _rational(v) for k, v in params.as_dict().items()}
    return numeric_system(variables, [f"f{i + 1}" for i in range(len(eqs))], eqs, subs)


def force_density(params):
    """The force-density system, derived here from the points (Table 1 numbers, exact)."""
    p = {k: _rational(v) for k, v in params.as_dict().items()}
    c1, s1, c2, s2 = sp.symbols("c1 s1 c2 s2")
    rot = sp.Matrix([[c2, -s2], [s2, c2]])
    p4 = p["L3"] * sp.Matrix([c1, s1])
    anchors = {1: sp.Matrix([p["p2x"], 0]), 2: sp.Matrix([p["p3x"], p["p3y"]])}
    tops = {1: p4 + rot * sp.Matrix([p["p6x"], 0]), 2: p4 + rot * sp.Matrix([p["p5x"], p["p5y"]])}
    springs = {i: tops[i] - anchors[i] for i in (1, 2)}

    def cross(a, b):
        return a[0] * b[1] - a[1] * b[0]

    variables, names, eqs = [c1, s1, c2, s2], [], []
    q, extra = {}, []
    for i in (1, 2):
        k, free = p[f"k{i}"], p[f"L0{i}"]
        if free == 0:
            q[i] = k  # zero free length: force density k_i, no length variable needed
            continue
        d, q[i] = sp.symbols(f"d{i} q{i}")
        variables += [d, q[i]]
        extra += [
            (f"length{i}", d**2 - springs[i].dot(springs[i])),
            (f"density{i}", q[i] * d - k * (d - free)),
        ]
    eqs = [
        ("force", sum(q[i] * cross(p4, springs[i]) for i in (1, 2))),
        ("moment", sum(q[i] * cross(anchors[i], springs[i]) for i in (1, 2))),
        *extra,
        ("circle1", c1**2 + s1**2 - 1),
        ("circle2", c2**2 + s2**2 - 1),
    ]
    names = [n for n, _ in eqs]
    return numeric_system(variables, names, [e for _, e in eqs], {})


def solve_bertini2(system, params, title: str) -> tuple[float, object]:
    """Total-degree solve by the bertini2 command (default config: MPType 2, seed 1)."""
    from cotm_bertini.backends.parse import read_output
    from cotm_bertini.backends.render import render_input
    from cotm_bertini.settings import Settings

    text = render_input(system, Settings(seed=1, engine="cli"), params.as_dict(), title)
    with tempfile.TemporaryDirectory(prefix="bench-form-") as tmp:
        folder = Path(tmp) / "run"
        seconds = run_bertini2(text, folder)
        out = read_output(folder)
    return seconds, out.endpoints


def _cos_sin_residual(params, cs: np.ndarray) -> np.ndarray:
    """Relative residual of the package's cos/sin system at points (c1, s1, c2, s2, d...)."""
    from cotm_bertini.model.compiled import polynomial_system

    system = polynomial_system(params.normalized())
    z = cs.copy()
    z[:, 4:] /= params.L3
    size = 1.0 + np.abs(z).max(axis=1)
    res = np.abs(system.evaluate(z)) / system.scale()
    return (res / size[:, None] ** np.array(system.degrees)).max(axis=1)


def d0_counts(table: pd.DataFrame, params) -> dict:
    """Solutions with a spring length d_i = 0 (|d_i| < 1e-6 L3): not equilibria. The package
    labels the singular, real-configuration ones zero_length_spring; complex ones with
    d1 = d2 = 0 (both spring vectors isotropic, S.S = 0 with S != 0) it calls 'complex'."""
    zero = np.zeros(len(table), dtype=bool)
    for i in (1, 2):
        if f"d{i}_re" in table:
            d = table[f"d{i}_re"].to_numpy(float) + 1j * table[f"d{i}_im"].to_numpy(float)
            zero |= np.abs(d) < 1e-6 * params.L3
    return {
        "d0_roots": int(zero.sum()),
        "d0_labelled": int((table["reason"] == "zero_length_spring").sum()),
    }


def _near_i(x: np.ndarray) -> np.ndarray:
    """1 + x^2 = 0 (x = +-i), relative to 1 + |x|^2."""
    with np.errstate(all="ignore"):
        return np.abs(1 + x**2) / (1 + np.abs(x) ** 2) < SPURIOUS_REL


def analyse(case: str, name: str, system, seconds: float, endpoints, params, reference) -> dict:
    """Distinct finite, spurious, artefacts and physical equilibria of one formulation's solve."""
    from cotm_bertini.analysis.classify import classify
    from cotm_bertini.analysis.cluster import cluster_endpoints
    from cotm_bertini.backends.endpoints import FIELDS, Endpoints
    from cotm_bertini.model.compiled import polynomial_system

    variables = list(system.variables)
    x = endpoints.points
    singular = (endpoints.condition_number > 1e8) | (endpoints.bertini_multiplicity > 1)
    acc = np.nan_to_num(endpoints.accuracy_estimate, nan=1e-11)
    labels = cluster_endpoints(x, singular, acc, 1e-8)
    cs_vars = polynomial_system(params).variables
    # Image in the cos/sin variables (c1, s1, c2, s2, d...).
    with np.errstate(all="ignore"):
        if "x1" in variables:
            x1, x2 = (x[:, variables.index(v)] for v in ("x1", "x2"))
            cols = [(1 - x1**2) / (1 + x1**2), 2 * x1 / (1 + x1**2)]
            cols += [(1 - x2**2) / (1 + x2**2), 2 * x2 / (1 + x2**2)]
            at_i = _near_i(x1) | _near_i(x2)
        else:
            cols = [x[:, variables.index(v)] for v in ("c1", "s1", "c2", "s2")]
            at_i = np.zeros(len(x), dtype=bool)
        cs = np.column_stack(cols + [x[:, variables.index(v)] for v in cs_vars[4:]])
        bad = at_i | ~(_cos_sin_residual(params, cs) < SPURIOUS_REL)
    n = labels.max() + 1 if len(labels) else 0
    spurious_groups = {g for g in range(n) if bad[labels == g].all()}
    keep = np.array([lab not in spurious_groups for lab in labels], dtype=bool)
    # The same endpoints (metadata kept) mapped into the cos/sin variables.
    kept = endpoints.select(keep)
    mapped = Endpoints(tuple(cs_vars), cs[keep], **{f: getattr(kept, f) for f in FIELDS})
    table = classify(params, mapped)
    phys = table[table["physical"]]
    m = match(reference, phys)
    return {
        "case": case,
        "formulation": name,
        "variables": " ".join(variables),
        "degrees": " ".join(str(d) for d in system.degrees),
        "paths": None,
        "finite_endpoints": len(endpoints),
        "distinct_finite": int(n),
        "spurious": len(spurious_groups),
        "x_eq_pm_i": len({labels[j] for j in np.flatnonzero(at_i)}),
        **d0_counts(table, params),
        "real": int(table["is_real"].sum()),
        "physical": len(phys),
        "reference_found": len(reference) - m["missed"],
        "missed": m["missed"],
        "worst_err_deg": m["worst_err_deg"],
        "bertini_s": seconds,
    }


def _from_grid(case: str, name: str, outcome, params, reference, groups: str) -> dict:
    """A row for the package's cos/sin system from a settings-grid measurement."""
    from cotm_bertini.model.compiled import polynomial_system

    r, table = outcome.row, outcome.solutions
    system = polynomial_system(params)
    return {
        "case": case,
        "formulation": name,
        "variables": " ".join(system.variables) + f" {groups}",
        "degrees": " ".join(str(d) for d in system.degrees),
        "paths": r["paths"],
        "finite_endpoints": r["finite_endpoints"],
        "distinct_finite": r["distinct"],
        "spurious": 0,
        "x_eq_pm_i": 0,
        **d0_counts(table, params),
        "real": r["real"],
        "physical": r["physical"],
        "reference_found": len(reference) - r["missed"],
        "missed": r["missed"],
        "worst_err_deg": r["worst_err_deg"],
        "bertini_s": r["bertini_s"],
    }


def run(
    reference: dict[str, pd.DataFrame],
    grid: dict | None = None,
    cases: tuple[str, ...] = FORMULATION_CASES,
) -> pd.DataFrame:
    """Cases 2 and 3 in four formulations: printed, written to formulations.csv, returned."""
    from settings_grid import GRID, measure

    from cotm_bertini.params import make_params

    grid = dict(grid or {})
    points = {p.name: p for p in GRID}
    rows = []
    for case in cases:
        params, ref = make_params(case), reference[case]
        for key, name, groups in (
            ("cli_mp2", "cos/sin, total degree", "(1 group)"),
            ("cli_mhom", "cos/sin, multihomogeneous", "({c,s} {c,s} {d}..)"),
        ):
            if (case, key) not in grid:
                grid[case, key] = measure(case, points[key], ref, repeats=1)
            rows.append(_from_grid(case, name, grid[case, key], params, ref, groups))
        for name, build in (("tan-half (paper)", tan_half), ("force density", force_density)):
            system = build(params)
            seconds, endpoints = solve_bertini2(system, params, f"{case} {name}")
            row = analyse(case, name, system, seconds, endpoints, params, ref)
            row["paths"] = system.total_degree
            rows.append(row)
            print(f"  {case} {name:<16} {seconds:6.2f} s", flush=True)
    table = pd.DataFrame(rows)
    show(
        "3. Formulations and start systems (bertini2 4.0.0, MPType 2, seed 1; time: Bertini)",
        table.drop(columns=["variables", "degrees"]),
        {"worst_err_deg": ".1e", "bertini_s": ".2f"},
    )
    print(
        "spurious: 1 + x^2 = 0 (x_eq_pm_i) or not a solution of the cos/sin system;\n"
        "d0_roots: a spring length d_i = 0, roots of the balance multiplied through by d (not "
        "equilibria);\nd0_labelled: those the package labels zero_length_spring "
        "(the others, d1 = d2 = 0 with complex isotropic spring vectors, it calls 'complex')"
    )
    write_csv(table, "formulations")
    return table


if __name__ == "__main__":
    from reference import run as reference_run

    run(reference_run())
