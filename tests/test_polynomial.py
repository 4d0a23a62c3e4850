"""The term-vectorised polynomial systems (model/polynomial.py) against sympy."""

import numpy as np
import pytest
import sympy as sp

from cotm_bertini.model import polynomial
from cotm_bertini.model.symbolic import parametric_from_sympy

# Both evaluation routes: the coefficient table (small systems) and the sparse terms (large).
ROUTES = pytest.mark.parametrize("route", ["table", "sparse"])


def _route(monkeypatch, route: str, poly) -> None:
    """Make `poly` evaluate by `route`, and check that it does."""
    if route == "sparse":
        monkeypatch.setattr(polynomial, "TABLE_LIMIT", 0)
    assert (poly._table is None) == (route == "sparse")


def _random_system(rng, n_vars: int = 6, n_funcs: int = 5, terms: int = 40):
    """Random sparse polynomials (exponents 0 to 4, many variables absent from a term)."""
    xs = sp.symbols(f"x0:{n_vars}")
    funcs = []
    for _ in range(n_funcs):
        f = sp.Integer(0)
        for _ in range(terms):
            exps = rng.integers(0, 5, size=n_vars) * (rng.random(n_vars) < 0.5)
            f += sp.Float(rng.normal()) * sp.Mul(*(x**e for x, e in zip(xs, exps, strict=True)))
        funcs.append(sp.expand(f))
    return xs, funcs


@ROUTES
def test_jacobian_matches_sympy_also_where_coordinates_vanish(monkeypatch, route):
    """PolySystem.jacobian (products of the other factors from prefix and suffix products)
    equals sympy's derivative, at random complex points and at points with zero coordinates
    (where a quotient rule would divide by zero)."""
    rng = np.random.default_rng(4)
    xs, funcs = _random_system(rng)
    names = tuple(f"f{i}" for i in range(len(funcs)))
    poly = parametric_from_sympy(tuple(x.name for x in xs), names, tuple(funcs), ()).instantiate([])
    _route(monkeypatch, route, poly)
    jac = sp.lambdify(xs, sp.Matrix(funcs).jacobian(xs), "numpy")
    z = rng.normal(size=(4, len(xs))) + 1j * rng.normal(size=(4, len(xs)))
    z[1, 0] = 0.0
    z[2, [1, 3]] = 0.0
    z[3] = 0.0
    ours = poly.jacobian(z)
    assert ours.shape == (4, len(funcs), len(xs))
    for k in range(len(z)):
        theirs = np.array(jac(*z[k]), dtype=complex)
        assert np.allclose(ours[k], theirs, rtol=1e-12, atol=1e-12 * np.abs(theirs).max())


@ROUTES
def test_value_and_jacobian_is_evaluate_and_jacobian(monkeypatch, route):
    """The one-pass value_and_jacobian gives evaluate's values (sympy's, through lambdify) and
    the same Jacobian."""
    rng = np.random.default_rng(5)
    xs, funcs = _random_system(rng, n_vars=4, n_funcs=3, terms=25)
    names = tuple(f"f{i}" for i in range(len(funcs)))
    poly = parametric_from_sympy(tuple(x.name for x in xs), names, tuple(funcs), ()).instantiate([])
    _route(monkeypatch, route, poly)
    z = rng.normal(size=(3, len(xs))) + 1j * rng.normal(size=(3, len(xs)))
    z[2, 1] = 0.0
    values, jac = poly.value_and_jacobian(z)
    f = sp.lambdify(xs, funcs, "numpy")
    theirs = np.array([np.array(f(*row), dtype=complex) for row in z])
    assert np.allclose(values, theirs, rtol=1e-12, atol=1e-12 * np.abs(theirs).max())
    assert np.array_equal(jac, poly.jacobian(z))
