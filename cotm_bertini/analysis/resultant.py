"""The paper's Sylvester-resultant route (eqs. (13)-(26)) in exact arithmetic: a cross-check.

The balance equations of `equations.derive` are put in tan-half form (13), x_i = tan(gamma_i / 2),
and multiplied by W = (1 + x1^2)(1 + x2^2). Parameters enter as exact rationals (each decimal of
Table 1 is read as the rational it prints), so every resultant below is exact.

* Case 1 (L01 = L02 = 0): F and tau are quadratic in x1 (eqs. (16)-(17)); their 4x4 Sylvester
  determinant (18) is a polynomial in x2.
* Case 2 (L01 != 0, L02 = 0): force and moment are linear in d1, so d1F = H1 / H2 and
  d1tau = I1 / I2 (24); substituted into the length constraint (23) times H2^2 (resp. I2^2) they
  give C1F = H1^2 W - H2^2 q and C1tau = I1^2 W - I2^2 q, of degree 6 in x1 (25)-(26), with
  q = |P_{2->6}|^2 W. Their 12x12 Sylvester resultant in x1 is a polynomial in x2.

The resultant is factored over the rationals, and each irreducible factor is labelled by what its
roots are, found by recovering the common x1 of each root (50-digit mpmath) and testing, in order:
1 + x2^2 = 0, 1 + x1^2 = 0 (the denominators of (13)), then for case 2 d1F = d1tau = 0 (spring 1 of
zero length), d1F = d1tau (a solution of the cos/sin system) or d1F = -d1tau (C1F and C1tau
vanish with opposite signs of d1: an extra root of the elimination). Roots at gamma = 180 deg
(x = infinity) are not roots of a polynomial in x2; `compare` accounts for them.

With Table 1: case 1 gives degree 8 = 6 (genuine: the paper's sextic) + 2 (x2^2 + 1). Case 2 gives
the paper's degree 72 = 20 (genuine) + 2 x 4 (d1 = 0, complex since L3 > p2x + p6x) + 20 (d1F =
-d1tau, with Table 3 rows 7, 8, 13, 14 among its real roots) + 2 (x1 = +-i) + 2 x 11 (x2^2 + 1):
22 of the 72 roots are solutions of the cos/sin system, as Bertini finds (tests/test_resultant.py).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import NamedTuple

import mpmath as mp
import numpy as np
import pandas as pd
import sympy as sp

from ..model import equations
from ..model.compiled import polynomial_system
from ..params import PARAM_NAMES, Params

X1, X2 = sp.symbols("x1 x2")
_C1, _S1, _C2, _S2, _D1 = sp.symbols("c1 s1 c2 s2 d1")

DPS = 50  # working digits of the numerical stage (roots of the exact factors)
_ZERO = mp.mpf(10) ** -20  # relative size below which a 50-digit residual counts as zero
_EXTRAPREC = 60  # extra bits for mpmath.polyroots
_SAME = mp.mpf(10) ** -12  # relative gap below which two values of d1 count as equal

GENUINE = "genuine"
GENUINE_D0 = "genuine: d1 = 0 (spring 1 of zero length, P2 = P6; not an equilibrium)"
EXTRA_X2 = "extra: x2 = +-i (1 + x2^2 = 0, a denominator of the tan-half substitution)"
EXTRA_X1 = "extra: x1 = +-i (1 + x1^2 = 0, a denominator of the tan-half substitution)"
EXTRA_SIGN = "extra: d1F = -d1tau (C1F = C1tau = 0 with opposite signs of d1)"
UNEXPLAINED = "unexplained"


@dataclass(frozen=True)
class Factor:
    """One irreducible factor over Q of the resultant, in x2, with what its roots are."""

    degree: int
    multiplicity: int
    label: str
    real_roots: int
    polynomial: sp.Poly  # primitive, integer coefficients, positive leading coefficient

    @property
    def genuine(self) -> bool:
        """Whether the roots of this factor are solutions of the cos/sin system."""
        return self.label.startswith(GENUINE)


@dataclass(frozen=True)
class ResultantResult:
    """The exact resultant in x2, its factorisation over Q, and the roots of every factor."""

    case: str
    degree: int  # degree in x2 of the full Sylvester determinant
    resultant: sp.Poly
    factors: tuple[Factor, ...]
    roots: pd.DataFrame  # roots of the genuine factors (solutions.csv conventions)
    extra_roots: pd.DataFrame  # roots of the extra factors that have finite angles
    seconds: float

    @property
    def genuine_degree(self) -> int:
        """Number of distinct x2 roots of the genuine factors."""
        return sum(f.degree for f in self.factors if f.genuine)

    def factor_table(self) -> pd.DataFrame:
        """Degree, multiplicity, real-root count and label of each factor."""
        return pd.DataFrame(
            {
                "degree": [f.degree for f in self.factors],
                "multiplicity": [f.multiplicity for f in self.factors],
                "real_roots": [f.real_roots for f in self.factors],
                "label": [f.label for f in self.factors],
            }
        )


# --- exact polynomials ------------------------------------------------------------------------


def exact_values(params: Params) -> dict[sp.Symbol, sp.Rational]:
    """Each parameter as the exact rational its decimal representation prints."""
    return {equations.PSYM[n]: sp.Rational(str(getattr(params, n))) for n in PARAM_NAMES}


def tan_half(expr: sp.Expr) -> sp.Poly:
    """expr(c1, s1, c2, s2) after substitution (13), times (1 + x1^2)(1 + x2^2), in QQ[x1, x2]."""
    sub = {
        _C1: (1 - X1**2) / (1 + X1**2),
        _S1: 2 * X1 / (1 + X1**2),
        _C2: (1 - X2**2) / (1 + X2**2),
        _S2: 2 * X2 / (1 + X2**2),
    }
    return sp.Poly(sp.cancel(expr.subs(sub) * (1 + X1**2) * (1 + X2**2)), X1, X2, domain="QQ")


def case1_polynomials(params: Params) -> tuple[sp.Poly, sp.Poly]:
    """F and tau of eqs. (16)-(17) (our force and moment), quadratic in x1."""
    _require(params, "case1")
    sym = equations.derive((True, True))
    vals = exact_values(params)
    force, moment = (sym.functions[sym.names.index(n)].subs(vals) for n in ("force", "moment"))
    return tan_half(force), tan_half(moment)


@dataclass(frozen=True)
class Case2Polynomials:
    """d1F = H1/H2, d1tau = I1/I2 (24), q = |P_{2->6}|^2 W, and C1F, C1tau (25)-(26)."""

    H1: sp.Poly
    H2: sp.Poly
    I1: sp.Poly
    I2: sp.Poly
    q: sp.Poly
    C1F: sp.Poly
    C1tau: sp.Poly


def case2_polynomials(params: Params) -> Case2Polynomials:
    """The polynomials of the paper's case-2 elimination, from our force, moment and length."""
    _require(params, "case2")
    sym = equations.derive((False, True))
    vals = exact_values(params)
    names = ("force", "moment", "length1")
    force, moment, length = (sym.functions[sym.names.index(n)].subs(vals) for n in names)
    fd, md = sp.Poly(force, _D1), sp.Poly(moment, _D1)
    assert fd.degree() == 1 and md.degree() == 1
    H2, H1 = tan_half(fd.coeff_monomial(_D1)), tan_half(-fd.coeff_monomial(1))
    I2, I1 = tan_half(md.coeff_monomial(_D1)), tan_half(-md.coeff_monomial(1))
    q = tan_half(sp.expand(_D1**2 - length))  # length1 = d1^2 - |P_{2->6}|^2
    W = sp.Poly((1 + X1**2) * (1 + X2**2), X1, X2, domain="QQ")
    return Case2Polynomials(H1, H2, I1, I2, q, H1**2 * W - H2**2 * q, I1**2 * W - I2**2 * q)


def _require(params: Params, case: str) -> None:
    zfl = {"case1": (True, True), "case2": (False, True)}[case]
    if params.zfl != zfl:
        want = "L01 = L02 = 0" if case == "case1" else "L01 != 0, L02 = 0"
        raise ValueError(f"{case} resultant needs {want}; got L01={params.L01}, L02={params.L02}")


def sylvester_resultant(a: sp.Poly, b: sp.Poly) -> sp.Poly:
    """Resultant in x1 (the Sylvester determinant) of a, b in QQ[x1, x2], a polynomial in x2.

    Denominators are cleared first (integer arithmetic is far faster than rational), so the
    result is the determinant for integer multiples of a and b: exact up to a constant factor.
    """
    za = sp.Poly(a, X1, X2).clear_denoms(convert=True)[1]
    zb = sp.Poly(b, X1, X2).clear_denoms(convert=True)[1]
    return sp.Poly(za.resultant(zb).as_expr(), X2, domain="ZZ")


# --- 50-digit evaluation ----------------------------------------------------------------------


class _MP:
    """A polynomial of QQ[x1, x2] for mpmath evaluation (build inside mp.workdps)."""

    def __init__(self, poly: sp.Poly):
        self.deg1 = poly.degree(X1)
        self.terms = [(i, j, mp.mpf(c.p) / c.q) for (i, j), c in poly.terms()]

    def coeffs_x1(self, x2) -> list:
        """Coefficients in x1 at x2, highest power first."""
        out = [mp.mpc(0)] * (self.deg1 + 1)
        for i, j, c in self.terms:
            out[self.deg1 - i] += c * x2**j
        return out

    def __call__(self, x1, x2):
        return sum(c * x1**i * x2**j for i, j, c in self.terms)


def _rel(coeffs: list, x) -> mp.mpf:
    """|p(x)| relative to sum |c_k| |x|^k (p given by coefficients, highest first)."""
    n = len(coeffs) - 1
    scale = sum(abs(c) * abs(x) ** (n - k) for k, c in enumerate(coeffs))
    return abs(mp.polyval(coeffs, x)) / scale if scale else mp.mpf(0)


def _roots(coeffs: list) -> list:
    """All roots of a univariate polynomial (coefficients highest first) to DPS digits."""
    while len(coeffs) > 1 and coeffs[0] == 0:
        coeffs = coeffs[1:]
    if len(coeffs) < 2:
        return []
    lead = coeffs[0]
    return list(
        mp.polyroots([c / lead for c in coeffs], maxsteps=400, extraprec=_EXTRAPREC, error=False)
    )


def _common_x1(a: _MP, b: _MP, x2) -> list:
    """The distinct common roots x1 of a(., x2) and b(., x2), mp.inf among them when both
    leading coefficients vanish (gamma1 = 180 deg: a common root of the homogenised pair)."""
    ca, cb = a.coeffs_x1(x2), b.coeffs_x1(x2)
    found = []
    for r in _roots(ca):
        if _rel(cb, r) < _ZERO and all(abs(r - s) > _SAME * (1 + abs(r)) for s in found):
            found.append(r)  # a double root of both (d1 = 0) is found twice: keep it once
    if abs(ca[0]) < _ZERO * sum(abs(c) for c in ca) and abs(cb[0]) < _ZERO * sum(
        abs(c) for c in cb
    ):
        found.append(mp.inf)
    if not found:
        raise ArithmeticError(f"no common x1 at x2 = {mp.nstr(x2, 15)}")
    return found


def _angle(x) -> mp.mpc:
    """gamma = -i log(c + i s) in degrees for x = tan(gamma / 2), as in stability.complex_angles."""
    if x == mp.inf:
        return mp.mpc(180)
    return -1j * mp.log((1 + 1j * x) / (1 - 1j * x)) * 180 / mp.pi


def _near_pm_i(x) -> bool:
    return x != mp.inf and abs(1 + x * x) < _ZERO * (1 + abs(x) ** 2)


# --- the two cases ----------------------------------------------------------------------------


def case1_resultant(params: Params) -> ResultantResult:
    """Case 1: the 4x4 Sylvester determinant (18) of F, tau in x1, factored, with its roots."""
    t0 = time.perf_counter()
    F, tau = case1_polynomials(params)
    R = sylvester_resultant(F, tau)
    with mp.workdps(DPS):
        a, b = _MP(F), _MP(tau)

        def classify(x2, x1):
            if _near_pm_i(x1):
                return EXTRA_X1, None
            return GENUINE, {"x1": x1}

        return _finish("case1", params, R, a, b, classify, t0)


def case2_resultant(params: Params) -> ResultantResult:
    """Case 2: the 12x12 Sylvester resultant of C1F, C1tau in x1, factored, with its roots."""
    t0 = time.perf_counter()
    P = case2_polynomials(params)
    R = sylvester_resultant(P.C1F, P.C1tau)
    with mp.workdps(DPS):
        cf, ct = _MP(P.C1F), _MP(P.C1tau)
        h1, h2, i1, i2 = (_MP(p) for p in (P.H1, P.H2, P.I1, P.I2))
        scale = mp.mpf(params.L3)

        def ratio(num: _MP, den: _MP, x1, x2):
            if x1 == mp.inf:  # leading coefficients in x1
                n, d = num.coeffs_x1(x2)[0], den.coeffs_x1(x2)[0]
            else:
                n, d = num(x1, x2), den(x1, x2)
            return n / d if d != 0 else mp.inf

        def classify(x2, x1):
            if _near_pm_i(x1):
                return EXTRA_X1, None
            dF, dT = ratio(h1, h2, x1, x2), ratio(i1, i2, x1, x2)
            info = {"x1": x1, "d1": dF}
            if abs(dF) < _SAME * scale and abs(dT) < _SAME * scale:
                return GENUINE_D0, info
            if abs(dF - dT) < _SAME * (scale + abs(dF)):
                return GENUINE, info
            if abs(dF + dT) < _SAME * (scale + abs(dF)):
                return EXTRA_SIGN, info  # d1 = d1F, the paper's choice (24)
            return UNEXPLAINED, info

        return _finish("case2", params, R, cf, ct, classify, t0)


def _finish(
    case: str, params: Params, R: sp.Poly, a: _MP, b: _MP, classify, t0: float
) -> ResultantResult:
    """Factor R = Res_x1(a, b) over Q, label each factor by its roots, tabulate the roots.

    Each root x2 of a factor is paired with every common root x1 of a and b there, and each pair
    is classified (`classify(x2, x1) -> (label, row data or None)`); roots with 1 + x2^2 = 0 are
    labelled without pairing (every x1 with 1 + x1^2 = 0 is then a common root).
    """
    _, factor_list = R.factor_list()
    factors, genuine_rows, extra_rows = [], [], []
    for f, mult in factor_list:
        f = f.clear_denoms(convert=True)[1].primitive()[1]
        if f.LC() < 0:
            f = -f
        labels, rows, real = set(), [], 0
        for x2 in _factor_roots(f):
            if abs(mp.im(x2)) < _ZERO * (1 + abs(x2)):
                x2 = mp.mpf(mp.re(x2))
                real += 1
            if _near_pm_i(x2):
                labels.add(EXTRA_X2)
                continue
            for x1 in _common_x1(a, b, x2):
                label, info = classify(x2, x1)
                labels.add(label)
                if info is not None:
                    rows.append(_row(params, x2, info))
        label = labels.pop() if len(labels) == 1 else "mixed: " + "; ".join(sorted(labels))
        factors.append(Factor(f.degree(), mult, label, real, f))
        for r in rows:
            r["factor"] = label
        (genuine_rows if label.startswith(GENUINE) else extra_rows).extend(rows)
    factors.sort(key=lambda f: (not f.genuine, f.label != GENUINE, -f.degree, f.label))
    return ResultantResult(
        case=case,
        degree=R.degree(),
        resultant=R,
        factors=tuple(factors),
        roots=_frame(genuine_rows, params),
        extra_roots=_frame(extra_rows, params),
        seconds=time.perf_counter() - t0,
    )


def _factor_roots(f: sp.Poly) -> list:
    """The roots of an exact squarefree factor, each checked to DPS digits and distinct."""
    coeffs = [mp.mpf(int(c)) for c in f.all_coeffs()]
    roots = _roots(coeffs)
    bad = [r for r in roots if _rel(coeffs, r) > _ZERO]
    gaps = [abs(a - b) for k, a in enumerate(roots) for b in roots[k + 1 :]]
    if len(roots) != f.degree() or bad or (gaps and min(gaps) < _ZERO):
        raise ArithmeticError(f"root finding failed on a factor of degree {f.degree()}")
    return roots


def _wrap(deg: float) -> float:
    """An angle in [0, 360) (a tiny negative angle must not become 360.0)."""
    out = deg % 360.0
    return 0.0 if out == 360.0 else out


def _row(params: Params, x2, info: dict) -> dict:
    """One root in the conventions of solutions.csv (angles real parts in [0, 360))."""
    x1 = info["x1"]
    g1, g2 = _angle(x1), _angle(x2)
    row = {
        "gamma1_deg": _wrap(float(mp.re(g1))),
        "gamma2_deg": _wrap(float(mp.re(g2))),
        "gamma1_imag_deg": float(mp.im(g1)),
        "gamma2_imag_deg": float(mp.im(g2)),
    }
    values = [complex(x1), complex(x2)]
    if "d1" in info:
        d1 = info["d1"]
        row["d1"] = float(mp.re(d1))
        row["d1_imag"] = float(mp.im(d1))
        values.append(complex(d1))
    mag = np.abs(np.array(values))
    imag = np.abs(np.array(values).imag) / (1.0 + np.where(np.isfinite(mag), mag, 0.0))
    row["is_real"] = bool(np.nan_to_num(imag, nan=0.0).max() < 1e-8)
    row["x1_re"], row["x1_im"] = float(mp.re(x1)), float(mp.im(x1))
    row["x2_re"], row["x2_im"] = float(mp.re(x2)), float(mp.im(x2))
    return row


def _frame(rows: list[dict], params: Params) -> pd.DataFrame:
    """Rows sorted real first then by angle, with the residual of the cos/sin system."""
    frame = pd.DataFrame(rows)
    if frame.empty:
        return frame
    deg = np.pi / 180.0
    g1 = (frame["gamma1_deg"] + 1j * frame["gamma1_imag_deg"]).to_numpy(complex) * deg
    g2 = (frame["gamma2_deg"] + 1j * frame["gamma2_imag_deg"]).to_numpy(complex) * deg
    cols = [np.cos(g1), np.sin(g1), np.cos(g2), np.sin(g2)]
    if "d1" in frame:
        cols.append((frame["d1"] + 1j * frame["d1_imag"]).to_numpy(complex))
    system = polynomial_system(params)
    res = np.abs(system.evaluate(np.column_stack(cols)) / system.scale()).max(axis=1)
    frame["residual"] = res
    frame = frame.sort_values(
        ["is_real", "gamma1_deg", "gamma2_deg", "gamma1_imag_deg"],
        ascending=[False, True, True, True],
    ).reset_index(drop=True)
    return frame


# --- comparison with the cos/sin solutions ----------------------------------------------------


class Comparison(NamedTuple):
    """How two sets of finite solutions agree (angles in degrees, modulo 360)."""

    max_angle_deg: float  # largest distance of a matched row to its nearest partner
    matched: int  # resultant rows with a solutions row within tol
    only_resultant: int  # resultant rows with no solutions row within tol
    only_solutions: int  # solutions rows with no resultant row within tol (not at infinity)
    at_infinity: int  # unmatched solutions rows with a real gamma = 180 deg: x = oo, invisible
    max_d1: float  # largest |d1 difference| over matched rows (NaN without a d1 column)


def _complex_angles(df: pd.DataFrame) -> np.ndarray:
    out = []
    for k in (1, 2):
        re = df[f"gamma{k}_deg"].to_numpy(float)
        im = df[f"gamma{k}_imag_deg"].to_numpy(float) if f"gamma{k}_imag_deg" in df else 0 * re
        out.append(re + 1j * im)
    return np.column_stack(out) if out[0].size else np.zeros((0, 2), complex)


def angle_gaps(a: pd.DataFrame, b: pd.DataFrame) -> np.ndarray:
    """Distances (degrees) between every row of a and of b: the larger over the two angles."""
    za, zb = _complex_angles(a), _complex_angles(b)
    dre = (za.real[:, None, :] - zb.real[None, :, :] + 180.0) % 360.0 - 180.0
    dim = za.imag[:, None, :] - zb.imag[None, :, :]
    return np.hypot(dre, dim).max(axis=2)


def compare(
    resultant_df: pd.DataFrame, solutions_df: pd.DataFrame, tol: float = 1e-3
) -> Comparison:
    """Match each row of either set to its nearest in the other; rows farther than tol are extra."""
    gaps = angle_gaps(resultant_df, solutions_df)
    n_r, n_s = gaps.shape
    near_r = gaps.min(axis=1) if n_s else np.full(n_r, np.inf)
    near_s = gaps.min(axis=0) if n_r else np.full(n_s, np.inf)
    ok_r, ok_s = near_r <= tol, near_s <= tol
    za = _complex_angles(solutions_df)
    at_180 = (
        (np.abs((za.real - 180.0 + 180.0) % 360.0 - 180.0) <= tol) & (np.abs(za.imag) <= tol)
    ).any(axis=1)
    infinite = ~ok_s & at_180
    worst = max([0.0, *near_r[ok_r], *near_s[ok_s]])
    max_d1 = float("nan")
    if "d1" in resultant_df and "d1" in solutions_df and ok_r.any():
        nearest = gaps.argmin(axis=1)
        d_r = resultant_df["d1"].to_numpy(float)[ok_r]
        d_s = solutions_df["d1"].to_numpy(float)[nearest[ok_r]]
        max_d1 = float(np.abs(d_r - d_s).max())
    return Comparison(
        max_angle_deg=float(worst),
        matched=int(ok_r.sum()),
        only_resultant=int((~ok_r).sum()),
        only_solutions=int((~ok_s & ~infinite).sum()),
        at_infinity=int(infinite.sum()),
        max_d1=max_d1,
    )
