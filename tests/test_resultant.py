"""The paper's Sylvester-resultant route (`cotm_bertini.resultant`), an independent cross-check.

Known answers come from the paper (Tables 2 and 3), from Bertini on the cos/sin formulation, and
from closed forms derived below from the geometry for the small factors of the case-2 resultant.
Tables 2-3 use the parameters of Table 1; Table 3 needs k2/k1 = 0.98909 (docs/paper.md).
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pandas as pd
import pytest
import sympy as sp
from conftest import solved
from paper_tables import K_RATIO, TABLE2, TABLE2_COMPLEX, TABLE3

from cotm_bertini.analysis import resultant as rs
from cotm_bertini.params import make_params

X1, X2 = rs.X1, rs.X2


@pytest.fixture(scope="module")
def case1() -> rs.ResultantResult:
    return rs.case1_resultant(make_params("case1"))


@pytest.fixture(scope="module")
def case2() -> rs.ResultantResult:
    return rs.case2_resultant(make_params("case2"))


def _wrap(a):
    return np.abs((np.asarray(a, float) + 180.0) % 360.0 - 180.0)


def _proportional(f: sp.Poly, g: sp.Expr) -> bool:
    """f and g are the same polynomial in x2 up to a constant factor."""
    g = sp.Poly(g, X2)
    return sp.Poly(f.as_expr(), X2).degree() == g.degree() and not sp.cancel(
        f.as_expr() / g.as_expr()
    ).has(X2)


def _sylvester(a: sp.Poly, b: sp.Poly) -> sp.Matrix:
    """The Sylvester matrix of eq. (18) (12x12 for two sextics), rows of shifted coefficients."""
    ca, cb = a.all_coeffs(), b.all_coeffs()
    m, n = len(ca) - 1, len(cb) - 1
    rows = [[0] * k + ca + [0] * (n - 1 - k) for k in range(n)]
    rows += [[0] * k + cb + [0] * (m - 1 - k) for k in range(m)]
    return sp.Matrix(rows)


def _fixed_x2(p: sp.Poly, t) -> sp.Poly:
    return sp.Poly(p.as_expr().subs(X2, t), X1)


def _frac(name: str, case: str = "case2") -> Fraction:
    return Fraction(str(getattr(make_params(case), name)))


# --- case 1 ------------------------------------------------------------------------------------


def test_case1_determinant_is_eq18_of_degree_8_with_the_papers_sextic(case1):
    """det of the 4x4 matrix (18) has degree 8 = (x2^2 + 1) times the paper's degree-6 factor."""
    F, tau = rs.case1_polynomials(make_params("case1"))
    assert F.degree(X1) == tau.degree(X1) == 2
    C = sp.Poly(F.as_expr(), X1).all_coeffs()
    D = sp.Poly(tau.as_expr(), X1).all_coeffs()
    eq18 = sp.Matrix([[*C, 0], [0, *C], [*D, 0], [0, *D]]).det()
    assert _proportional(case1.resultant, sp.expand(eq18))

    assert case1.degree == 8
    table = [(f.degree, f.multiplicity, f.label, f.real_roots) for f in case1.factors]
    assert table == [(6, 1, rs.GENUINE, 4), (2, 1, rs.EXTRA_X2, 0)]
    assert _proportional(case1.factors[1].polynomial, X2**2 + 1)
    assert case1.genuine_degree == 6  # the paper's "sixth degree polynomial in x2"


def test_case1_roots_match_table2(case1):
    """The 6 genuine roots are the 6 rows of Table 2, each within one unit of the last digit."""
    roots = case1.roots
    assert len(roots) == 6 and int(roots["is_real"].sum()) == 4
    for g1, g2 in TABLE2:
        tol1, tol2 = (10.0 ** -len(g.split(".")[1]) for g in (g1, g2))
        hit = (_wrap(roots["gamma1_deg"] - float(g1)) <= tol1) & (
            _wrap(roots["gamma2_deg"] - float(g2)) <= tol2
        )
        assert hit[roots["is_real"]].sum() == 1, (g1, g2)
    for z1, z2 in TABLE2_COMPLEX:
        hit = (
            (_wrap(roots["gamma1_deg"] - z1.real) <= 1e-4)
            & (np.abs(roots["gamma1_imag_deg"] - z1.imag) <= 1e-4)
            & (_wrap(roots["gamma2_deg"] - z2.real) <= 1e-4)
            & (np.abs(roots["gamma2_imag_deg"] - z2.imag) <= 1e-4)
        )
        assert hit.sum() == 1, (z1, z2)


def test_case1_roots_match_bertini(case1):
    """The resultant's 6 roots and Bertini's 6 solutions agree to 1e-8 deg, none missing."""
    cmp = rs.compare(case1.roots, solved("case1")[0].table)
    assert cmp.matched == 6
    assert (cmp.only_resultant, cmp.only_solutions, cmp.at_infinity) == (0, 0, 0)
    assert cmp.max_angle_deg < 1e-8


# --- case 2 ------------------------------------------------------------------------------------


def test_case2_resultant_is_the_12x12_sylvester_determinant(case2):
    """The resultant equals det of the 12x12 Sylvester matrix of C1F, C1tau (fixed x2), times c."""
    P = rs.case2_polynomials(make_params("case2"))
    assert P.C1F.degree(X1) == P.C1tau.degree(X1) == 6
    assert P.C1F.degree(X2) == P.C1tau.degree(X2) == 6
    ratios = set()
    for t in (sp.Rational(1, 3), sp.Rational(-7, 5)):
        det = _sylvester(_fixed_x2(P.C1F, t), _fixed_x2(P.C1tau, t)).det(method="bareiss")
        ratios.add(sp.nsimplify(case2.resultant.eval(t) / det))
    assert len(ratios) == 1 and 0 not in ratios


def test_case2_degree_72_and_its_factorisation(case2):
    """Degree 72 as the paper says, but only 20 + 2 of its roots are solutions.

    Over Q it factors as (genuine, 20)(d1 = 0, 2)^4 (d1F = -d1tau, 20)(x1 = +-i, 2)(x2^2 + 1)^11.
    The small factors have closed forms, derived here from the geometry (u = exp(i gamma), so
    x = tan(gamma / 2) = -i (u - 1) / (u + 1)):

    * d1 = 0: P6 = P2 with P1P2 = p2x, P4P6 = p6x, P1P4 = L3 is a triangle whose law of cosines
      gives cos gamma2 = (p2x^2 + p6x^2 - L3^2) / (2 p2x p6x) =: c, so x2^2 = (1 - c) / (1 + c).
      L3 > p2x + p6x, so c < -1 and these configurations are complex.
    * x1 = +-i means u1 = 0 (or oo): there |P_{2->6}|^2 (1 + x1^2)(1 + x2^2) is proportional to
      (p6x u2 - p2x) (or its mirror), so u2 = (p2x / p6x)^(+-1): x2 = +-i (p6x - p2x) / (p6x + p2x).
    """
    assert case2.degree == 72
    table = [(f.degree, f.multiplicity, f.label, f.real_roots) for f in case2.factors]
    assert table == [
        (20, 1, rs.GENUINE, 10),
        (2, 4, rs.GENUINE_D0, 0),
        (20, 1, rs.EXTRA_SIGN, 4),
        (2, 1, rs.EXTRA_X1, 0),
        (2, 11, rs.EXTRA_X2, 0),
    ]
    assert sum(f.degree * f.multiplicity for f in case2.factors) == 72
    assert case2.genuine_degree == 22

    L3, p2x, p6x = (_frac(n) for n in ("L3", "p2x", "p6x"))
    c = (p2x**2 + p6x**2 - L3**2) / (2 * p2x * p6x)
    assert c < -1
    poly = {f.label: f.polynomial for f in case2.factors}
    assert _proportional(poly[rs.GENUINE_D0], sp.Rational(1 + c) * X2**2 - sp.Rational(1 - c))
    r = sp.Rational((p6x - p2x) / (p6x + p2x))
    assert r == sp.Rational(1, 7)
    assert _proportional(poly[rs.EXTRA_X1], X2**2 + r**2)
    assert _proportional(poly[rs.EXTRA_X2], X2**2 + 1)


def test_case2_genuine_roots_are_bertinis_solutions(case2):
    """The genuine factor gives Bertini's 20 regular solutions, the d1 = 0 one its 2 artefacts."""
    sols = solved("case2")[0].table
    artefact = sols["reason"] == "zero_length_spring"
    assert int(artefact.sum()) == 2
    regular = case2.roots[case2.roots["factor"] == rs.GENUINE]
    d0 = case2.roots[case2.roots["factor"] == rs.GENUINE_D0]
    assert (len(regular), len(d0)) == (20, 2)

    cmp = rs.compare(regular, sols[~artefact])
    assert cmp.matched == 20
    assert (cmp.only_resultant, cmp.only_solutions, cmp.at_infinity) == (0, 0, 0)
    assert cmp.max_angle_deg < 1e-6
    assert cmp.max_d1 < 1e-6
    assert int(regular["is_real"].sum()) == int(sols["is_real"].sum()) == 10

    cmp = rs.compare(d0, sols[artefact], tol=1e-3)  # singular: Bertini knows them less well
    assert (cmp.matched, cmp.only_resultant, cmp.only_solutions) == (2, 0, 0)
    assert np.abs(d0["d1"] + 1j * d0["d1_imag"]).max() < 1e-12

    cmp = rs.compare(case2.roots, sols)
    assert (cmp.matched, cmp.only_resultant, cmp.only_solutions, cmp.at_infinity) == (22, 0, 0, 0)
    # The genuine roots solve the cos/sin system; the d1F = -d1tau roots do not.
    assert case2.roots["residual"].max() < 1e-10
    assert case2.extra_roots["residual"].min() > 1e-2
    assert set(case2.extra_roots["factor"]) == {rs.EXTRA_SIGN}


def test_case2_table3_rows_with_corrected_ratio():
    """With k2/k1 = 0.98909, Table 3 rows 7, 8, 13, 14 are real roots of the d1F = -d1tau factor.

    The other ten rows are the ten real genuine roots. Tolerances as in test_cases (0.02 deg,
    2e-3 m); d1 of an extra root is d1F, the paper's choice in (24).
    """
    result = rs.case2_resultant(make_params("case2", {"k2": 2.81 * K_RATIO}))
    assert result.degree == 72
    assert [(f.degree, f.multiplicity) for f in result.factors] == [
        (20, 1),
        (2, 4),
        (20, 1),
        (2, 1),
        (2, 11),
    ]
    genuine = result.roots[result.roots["is_real"] & (result.roots["factor"] == rs.GENUINE)]
    extra = result.extra_roots[result.extra_roots["is_real"]]
    assert (len(genuine), len(extra)) == (10, 4)
    for i, (g1, g2, d1) in enumerate(TABLE3, start=1):
        frame = extra if i in (7, 8, 13, 14) else genuine
        dist = np.maximum(_wrap(frame["gamma1_deg"] - g1), _wrap(frame["gamma2_deg"] - g2))
        k = int(np.argmin(dist))
        assert dist[k] < 0.02, (i, dist[k])
        assert frame["d1"].iloc[k] == pytest.approx(d1, abs=2e-3), i

    cmp = rs.compare(result.roots, solved("case2", 2.81 * K_RATIO)[0].table)
    assert (cmp.matched, cmp.only_resultant, cmp.only_solutions) == (22, 0, 0)


# --- compare ----------------------------------------------------------------------------------


def test_compare_counts_unmatched_rows_and_roots_at_infinity(case1):
    """A real gamma = 180 deg row (x = oo) is counted apart; other unmatched rows on each side."""
    cols = ["gamma1_deg", "gamma2_deg", "gamma1_imag_deg", "gamma2_imag_deg"]
    base = case1.roots[cols]
    added = pd.DataFrame(
        [[40.0, 180.0, 0.0, 0.0], [1.0, 2.0, 0.0, 0.0], [180.0, 5.0, 30.0, 0.0]], columns=cols
    )  # real gamma2 = 180 (invisible); an ordinary row; a complex angle with real part 180
    sols = pd.concat([base, added], ignore_index=True)
    ours = base.copy()
    ours.loc[0, "gamma1_deg"] = (ours.loc[0, "gamma1_deg"] + 359.9999995) % 360.0  # -5e-7 deg
    ours = pd.concat([ours, pd.DataFrame([[1.0, 3.0, 0.0, 0.0]], columns=cols)])
    cmp = rs.compare(ours, sols)
    assert cmp.matched == 6
    assert cmp.only_resultant == 1
    assert cmp.only_solutions == 2
    assert cmp.at_infinity == 1
    assert cmp.max_angle_deg == pytest.approx(5e-7, rel=1e-3)


def test_case2_needs_one_zero_free_length_spring():
    with pytest.raises(ValueError, match="L01 != 0, L02 = 0"):
        rs.case2_resultant(make_params("case1"))
    with pytest.raises(ValueError, match="L01 = L02 = 0"):
        rs.case1_resultant(make_params("case3"))
