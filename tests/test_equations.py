"""Cross-checks of the equilibrium equations of `cotm_bertini.equations`.

Each test compares the package's sympy derivation with something built independently of it:

* a plain-numpy implementation of the paper's geometry and eqs. (7)-(10);
* the paper's case-1 equations (11)-(12) as printed;
* the tan-half form (14)-(15) with the Appendix A coefficients as printed (typos fixed);
* the Bertini 1.6 input files in tests/fixtures/bertini-1.6, written by someone else.

Conventions (docs/paper.md): in frame B, P1 = 0, P2 = [p2x, 0], P3 = [p3x, p3y]; in frame T (origin
P4 = L3 [c1, s1], rotated by gamma2), P6 = [p6x, 0], P5 = [p5x, p5y]. Spring 1 joins P2 and P6,
spring 2 joins P3 and P5, the rod joins P1 and P4.
"""

import numpy as np
import pytest
import sympy as sp
from conftest import FIXTURES

from cotm_bertini import params as geometry
from cotm_bertini.model import equations
from cotm_bertini.model.compiled import polynomial_system

ZFL_PATTERNS = [(True, True), (False, True), (True, False), (False, False)]
GEOMETRY_NAMES = ("L3", "k1", "k2", "p2x", "p3x", "p3y", "p6x", "p5x", "p5y")


# --- helpers ----------------------------------------------------------------------------------


def _symbols_by_name(exprs):
    """The free symbols of `exprs`, keyed by name (independent of sympy assumptions)."""
    out = {}
    for e in exprs:
        for s in e.free_symbols:
            out[s.name] = s
    return out


def _params_for(geometry_kind, zfl):
    """Table 1 or a random geometry, with L0i = 0 exactly for the ZFL springs."""
    if geometry_kind == "table1":
        values = dict(geometry.TABLE1)
        free = {"L01": 11.5, "L02": 11.5}
    else:
        rng = np.random.default_rng(20180826)
        values = {
            "L3": rng.uniform(5, 12),
            "k1": rng.uniform(1, 4),
            "k2": rng.uniform(1, 4),
            **{n: rng.uniform(-6, 6) for n in ("p2x", "p3x", "p3y", "p6x", "p5x", "p5y")},
        }
        free = {"L01": rng.uniform(2, 15), "L02": rng.uniform(2, 15)}
    values["L01"] = 0.0 if zfl[0] else free["L01"]
    values["L02"] = 0.0 if zfl[1] else free["L02"]
    return geometry.Params(**{n: float(v) for n, v in values.items()})


def _sample_points(rng, n_real=7, n_complex_angle=7, n_generic=6):
    """Rows (c1, s1, c2, s2, d1, d2): real angles, complex angles, and generic complex values."""
    rows = []
    g = rng.uniform(-np.pi, np.pi, size=(n_real, 2))
    d = rng.uniform(-20, 20, size=(n_real, 2))
    rows.append(
        np.column_stack(
            [np.cos(g[:, 0]), np.sin(g[:, 0]), np.cos(g[:, 1]), np.sin(g[:, 1]), d]
        ).astype(complex)
    )
    g = rng.uniform(-np.pi, np.pi, (n_complex_angle, 2)) + 1j * rng.uniform(
        -1, 1, (n_complex_angle, 2)
    )
    d = rng.normal(size=(n_complex_angle, 2)) * 10 + 10j * rng.normal(size=(n_complex_angle, 2))
    rows.append(
        np.column_stack([np.cos(g[:, 0]), np.sin(g[:, 0]), np.cos(g[:, 1]), np.sin(g[:, 1]), d])
    )
    z = rng.normal(size=(n_generic, 6)) + 1j * rng.normal(size=(n_generic, 6))
    z[:, 4:] *= 10
    rows.append(z)
    return np.vstack(rows)


def _cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def _reference(p, zfl, pts):
    """Paper eqs. (7)-(10) and the unit circles, in plain numpy, keyed by the package's names.

    Balance equations are multiplied by D = prod(d_j for springs j with L0j != 0); spring i
    then has force density k_i (1 - L0i / d_i) * D, or k_i * D if it is ZFL.
    """
    c1, s1, c2, s2, d1, d2 = pts.T
    d = {1: d1, 2: d2}
    k = {1: p.k1, 2: p.k2}
    L0 = {1: p.L01, 2: p.L02}
    P1 = np.array([0.0, 0.0])[:, None]
    P2 = np.array([p.p2x, 0.0])[:, None]
    P3 = np.array([p.p3x, p.p3y])[:, None]
    P4 = p.L3 * np.array([c1, s1])
    rot = np.array([[c2, -s2], [s2, c2]])  # shape (2, 2, n)
    P6 = P4 + np.einsum("ijn,j->in", rot, np.array([p.p6x, 0.0]))
    P5 = P4 + np.einsum("ijn,j->in", rot, np.array([p.p5x, p.p5y]))
    spring = {1: P6 - P2, 2: P5 - P3}  # P_{2->6}, P_{3->5}
    anchor = {1: P2 - P1, 2: P3 - P1}  # P_{1->2}, P_{1->3}
    rod = P4 - P1  # P_{1->4}

    D = np.ones(len(pts), dtype=complex)
    for i in (1, 2):
        if not zfl[i - 1]:
            D = D * d[i]
    w = {i: (k[i] if zfl[i - 1] else k[i] * (1 - L0[i] / d[i])) * D for i in (1, 2)}

    out = {
        "force": sum(w[i] * _cross(rod, spring[i]) for i in (1, 2)),  # eq. (7)
        "moment": sum(w[i] * _cross(anchor[i], spring[i]) for i in (1, 2)),  # eq. (8)
    }
    for i in (1, 2):  # eqs. (9), (10); plain squares, not |.|^2, so they stay polynomial
        if not zfl[i - 1]:
            out[f"length{i}"] = d[i] ** 2 - (spring[i][0] ** 2 + spring[i][1] ** 2)
    out["circle1"] = c1**2 + s1**2 - 1
    out["circle2"] = c2**2 + s2**2 - 1
    return out


def _assert_close(name, ours, ref, rtol):
    scale = np.abs(ref).max()
    err = np.abs(ours - ref).max()
    assert err <= rtol * scale, f"{name}: max |ours - ref| = {err:.3e}, scale {scale:.3e}"


def _proportionality(a, b):
    """The constant c with a == c * b (symbolic polynomials), or None if there is none."""
    ratio = sp.cancel(sp.expand(a) / sp.expand(b))
    if ratio.free_symbols or ratio == 0:
        return None
    return ratio


# --- 1. eqs. (7)-(10), independently in numpy ----------------------------------------------


@pytest.mark.parametrize("geometry_kind", ["table1", "random"])
@pytest.mark.parametrize("zfl", ZFL_PATTERNS, ids=lambda z: "zfl" + "".join("TF"[not b] for b in z))
def test_derive_matches_independent_numpy_equations(zfl, geometry_kind):
    """derive() and polynomial_system() equal eqs. (7)-(10) evaluated in plain numpy."""
    p = _params_for(geometry_kind, zfl)
    assert p.zfl == zfl
    sym = equations.derive(zfl)

    expected_vars = ("c1", "s1", "c2", "s2") + tuple(f"d{i}" for i in (1, 2) if not zfl[i - 1])
    expected_names = (
        ("force", "moment")
        + tuple(f"length{i}" for i in (1, 2) if not zfl[i - 1])
        + ("circle1", "circle2")
    )
    assert sym.variables == expected_vars
    assert sym.names == expected_names

    by_name = _symbols_by_name(sym.functions)
    assert set(by_name) <= set(sym.variables) | set(geometry.PARAM_NAMES)
    xs = [by_name.get(n, sp.Symbol(n)) for n in sym.variables]
    ps = [by_name.get(n, equations.PSYM[n]) for n in geometry.PARAM_NAMES]
    fn = sp.lambdify(xs + ps, list(sym.functions), "numpy")

    pts = _sample_points(np.random.default_rng(7))
    cols = [("c1", "s1", "c2", "s2", "d1", "d2").index(v) for v in sym.variables]
    x = pts[:, cols]
    values = [getattr(p, n) for n in geometry.PARAM_NAMES]
    derived = fn(*x.T, *values)
    poly = polynomial_system(p)
    assert poly.variables == sym.variables and poly.names == sym.names
    numeric = poly.evaluate(x)

    ref = _reference(p, zfl, pts)
    for j, name in enumerate(sym.names):
        ours = np.broadcast_to(np.asarray(derived[j], dtype=complex), (len(pts),))
        _assert_close(f"derive {name}", ours, ref[name], 1e-12)
        _assert_close(f"polynomial_system {name}", numeric[:, j], ref[name], 1e-12)


# --- 2. eqs. (11)-(12) as printed ------------------------------------------------------------


def test_paper_case1_equations_11_12_have_swapped_labels():
    """Printed eq. (11) 'F' is our moment (6) and eq. (12) 'tau' is our force (5), factor 1."""
    sym = equations.derive((True, True))
    force, moment = sym.functions[0], sym.functions[1]
    v = _symbols_by_name(sym.functions)
    c1, s1, c2, s2 = (v[n] for n in ("c1", "s1", "c2", "s2"))
    L3, k1, k2, p2x, p3x, p3y, p6x, p5x, p5y = (v[n] for n in GEOMETRY_NAMES)

    eq11 = k2 * (
        -c1 * L3 * p3y
        - c2 * p3y * p5x
        + c2 * p3x * p5y
        + L3 * p3x * s1
        + p3x * p5x * s2
        + p3y * p5y * s2
    ) + k1 * p2x * (L3 * s1 + p6x * s2)
    eq12 = L3 * (
        k1 * s1 * (p2x - c2 * p6x)
        + c1 * k1 * p6x * s2
        + c1 * k2 * (-p3y + c2 * p5y + p5x * s2)
        + k2 * s1 * (p3x - c2 * p5x + p5y * s2)
    )
    # The truth: the label "F" of (11) belongs to the moment balance (6), whose terms carry
    # P_{1->2} (p2x) and P_{1->3}; "tau" of (12) is the force balance (5) along the rod (factor L3).
    assert _proportionality(eq11, moment) == 1
    assert _proportionality(eq12, force) == 1
    assert _proportionality(eq11, force) is None
    assert _proportionality(eq12, moment) is None


# --- 3. Appendix A, eqs. (13)-(15) -----------------------------------------------------------


def test_appendix_a_tan_half_coefficients_and_b9_typo():
    """Tan-half form of our case-1 equations is (14) = force, (15) = moment; printed B9 is wrong."""
    sym = equations.derive((True, True))
    force, moment = sym.functions[0], sym.functions[1]
    v = _symbols_by_name(sym.functions)
    c1, s1, c2, s2 = (v[n] for n in ("c1", "s1", "c2", "s2"))
    L3, k1, k2, p2x, p3x, p3y, p6x, p5x, p5y = (v[n] for n in GEOMETRY_NAMES)
    x1, x2 = sp.symbols("x1 x2")

    # Appendix A, as printed.
    A = {
        1: L3 * (k2 * p3y + k2 * p5y),
        2: -L3 * (2 * k1 * p6x + 2 * k2 * p5x),
        3: L3 * (k2 * p3y - k2 * p5y),
        4: L3 * (2 * k1 * p2x + 2 * k2 * p3x + 2 * k1 * p6x + 2 * k2 * p5x),
        5: 4 * L3 * k2 * p5y,
        6: L3 * (2 * k1 * p2x + 2 * k2 * p3x - 2 * k1 * p6x - 2 * k2 * p5x),
        7: -L3 * (k2 * p3y + k2 * p5y),
        8: L3 * (2 * k1 * p6x + 2 * k2 * p5x),
        9: -L3 * (k2 * p3y - k2 * p5y),
    }
    b9_printed = k2 * p3x * p5y - k2 * p3y * p5x - k2 * p5x * p3y
    b9_fixed = k2 * p3x * p5y - k2 * p3y * p5x - L3 * k2 * p3y  # last term is L3 k2 p3y
    B = {
        1: L3 * k2 * p3y - k2 * p3x * p5y + k2 * p5x * p3y,
        2: 2 * k1 * p2x * p6x + 2 * k2 * p3x * p5x + 2 * k2 * p3y * p5y,
        3: L3 * k2 * p3y + k2 * p3x * p5y - k2 * p5x * p3y,
        4: 2 * L3 * k1 * p2x + 2 * L3 * k2 * p3x,
        5: sp.Integer(0),
        6: 2 * L3 * k1 * p2x + 2 * L3 * k2 * p3x,
        7: k2 * p5x * p3y - k2 * p3x * p5y - L3 * k2 * p3y,
        8: 2 * k1 * p2x * p6x + 2 * k2 * p3x * p5x + 2 * k2 * p3y * p5y,
        9: b9_printed,  # wrong, see below
    }

    def tan_half_form(expr):
        sub = {
            c1: (1 - x1**2) / (1 + x1**2),
            s1: 2 * x1 / (1 + x1**2),
            c2: (1 - x2**2) / (1 + x2**2),
            s2: 2 * x2 / (1 + x2**2),
        }
        g = sp.cancel(sp.together(expr.subs(sub) * (1 + x1**2) * (1 + x2**2)))
        return sp.Poly(sp.expand(g), x1, x2)

    def quadratic_form(coef):
        # Eqs. (14)/(15): (C1 x2^2 + C2 x2 + C3) x1^2 + (C4 ..) x1 + (C7 ..), with the
        # "A1 x1^2" misprint of (14) read as "A1 x2^2" (docs/paper.md).
        return sp.Poly(
            sum(
                (coef[3 * r + 1] * x2**2 + coef[3 * r + 2] * x2 + coef[3 * r + 3]) * x1 ** (2 - r)
                for r in range(3)
            ),
            x1,
            x2,
        )

    def factor_between(ours, paper):
        """Constant c with ours == c * paper, coefficient by coefficient, else None."""
        ours_c, paper_c = ours.as_dict(), paper.as_dict()
        if set(ours_c) != set(paper_c):
            return None
        ratios = {sp.cancel(ours_c[m] / paper_c[m]) for m in ours_c}
        if len(ratios) != 1:
            return None
        (c,) = ratios
        return None if c.free_symbols else c

    tf, tm = tan_half_form(force), tan_half_form(moment)
    eq14 = quadratic_form(A)
    eq15_printed = quadratic_form(B)
    eq15_fixed = quadratic_form({**B, 9: b9_fixed})

    # Which is which: (14) is our force balance (5)/(7), (15) our moment balance (6)/(8).
    assert factor_between(tf, eq14) == 1
    assert factor_between(tm, eq14) is None
    assert factor_between(tf, eq15_fixed) is None
    assert factor_between(tm, eq15_fixed) == 1

    # B9 as printed is wrong; every other coefficient matches, and the derived B9 is the fix.
    assert factor_between(tm, eq15_printed) is None
    ours_f, ours_m = tf.as_dict(), tm.as_dict()
    for idx in range(1, 10):
        r, col = divmod(idx - 1, 3)
        monom = (2 - r, 2 - col)  # A_idx, B_idx multiply x1^(2-r) x2^(2-col)
        derived = ours_m.get(monom, sp.Integer(0))
        if idx == 9:
            assert sp.expand(derived - b9_printed) != 0
            assert sp.expand(derived - b9_fixed) == 0
        else:
            assert sp.expand(derived - B[idx]) == 0, f"B{idx}"
        assert sp.expand(ours_f.get(monom, sp.Integer(0)) - A[idx]) == 0, f"A{idx}"

    # Eq. (14) read literally (A1 x1^2 x1^2) is not our force equation, not even up to a factor.
    eq14_literal = sp.Poly(eq14.as_expr() - A[1] * x2**2 * x1**2 + A[1] * x1**4, x1, x2)
    assert factor_between(tf, eq14_literal) is None

    # The system behind the paper's stability criterion (eq. (20)) is exactly (14), (15).
    tvars, teqs = equations.tan_half_system((True, True))
    names = {str(t): t for t in tvars}
    swap = {names["x1"]: x1, names["x2"]: x2}
    assert sp.expand(teqs[0].subs(swap) - eq14.as_expr()) == 0
    assert sp.expand(teqs[1].subs(swap) - eq15_fixed.as_expr()) == 0


# --- 4. Bertini 1.6 fixture inputs -----------------------------------------------------------


def _parse_bertini_input(path):
    """Variables and function expressions of a Bertini 1.x input file."""
    variables, functions = [], {}
    order = []
    for raw in path.read_text().splitlines():
        line = raw.strip().rstrip(";")
        if line.startswith("variable_group"):
            variables += [s.strip() for s in line.split(None, 1)[1].split(",")]
        elif line.startswith("function"):
            order = [s.strip() for s in line.split(None, 1)[1].split(",")]
        elif "=" in line and line.split("=", 1)[0].strip() in order:
            name, rhs = (s.strip() for s in line.split("=", 1))
            functions[name] = rhs.replace("^", "**")
    syms = {n: sp.Symbol(n) for n in variables}
    exprs = [sp.sympify(functions[n], locals=syms) for n in order]
    return variables, exprs


@pytest.mark.parametrize("case", ["case1", "case2", "case3"])
def test_polynomial_system_matches_bertini_fixture_input(case):
    """Each of our numeric functions is a constant multiple of one function of the fixture input."""
    variables, exprs = _parse_bertini_input(FIXTURES / case / "input")
    poly = polynomial_system(geometry.make_params(case))
    assert sorted(variables) == sorted(poly.variables)
    assert len(exprs) == len(poly.names)

    rng = np.random.default_rng(1234)
    n = 12
    x = rng.normal(size=(n, len(poly.variables))) + 1j * rng.normal(size=(n, len(poly.variables)))
    x[:, 4:] *= 10  # spring lengths are ~10 m
    ours = poly.evaluate(x)
    fn = sp.lambdify([sp.Symbol(v) for v in poly.variables], exprs, "numpy")
    theirs = np.column_stack(
        [np.broadcast_to(np.asarray(t, dtype=complex), (n,)) for t in fn(*x.T)]
    )

    used = set()
    for i, name in enumerate(poly.names):
        matches = []
        for j in range(theirs.shape[1]):
            t, o = theirs[:, j], ours[:, i]
            c = np.vdot(t, o) / np.vdot(t, t)  # least-squares factor
            if abs(c) > 0 and np.linalg.norm(o - c * t) <= 1e-9 * np.linalg.norm(o):
                matches.append(j)
        assert len(matches) == 1, f"{case} {name}: matches fixture functions {matches}"
        used.add(matches[0])
    assert len(used) == len(poly.names)
