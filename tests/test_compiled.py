"""The cached numeric forms equal a fresh sympy derivation and an independent numpy model."""

from __future__ import annotations

import json

import numpy as np
import sympy as sp
from physics import energy as energy_np
from physics import energy_gradient_fd

from cotm_bertini.model import compiled, equations
from cotm_bertini.model.polynomial import ParametricSystem
from cotm_bertini.params import make_params


def test_cached_system_round_trips_and_matches_derivation():
    """JSON cache -> ParametricSystem equals the sympy derivation, for each structure."""
    rng = np.random.default_rng(5)
    for zfl in equations.ZFL_PATTERNS:
        fresh = equations.derive_parametric(zfl)
        back = ParametricSystem.from_json(json.loads(json.dumps(fresh.to_json())))
        values = rng.normal(size=len(fresh.parameters)) + 1j * rng.normal(
            size=len(fresh.parameters)
        )
        x = rng.normal(size=(4, len(fresh.variables))) + 0j
        np.testing.assert_allclose(
            back.instantiate(values).evaluate(x), fresh.instantiate(values).evaluate(x), rtol=1e-13
        )
        np.testing.assert_allclose(
            compiled.parametric_system(zfl).instantiate(values).evaluate(x),
            fresh.instantiate(values).evaluate(x),
            rtol=1e-13,
        )


def test_generated_energy_code_matches_sympy_and_numpy():
    """Generated V, grad V, Hessian equal sympy's lambdify; V equals a plain-numpy model and
    grad V its finite differences."""
    V, grad, hess = equations.energy_expressions()
    args = (equations.G1, equations.G2, *equations.P)
    f_v, f_h = sp.lambdify(args, V, "numpy"), sp.lambdify(args, hess, "numpy")
    rng = np.random.default_rng(2)
    for case in ("case1", "case2", "case3"):
        p = make_params(case, {"k2": 2.5})
        vals = list(p.as_dict().values())
        for g1, g2 in rng.uniform(0, 2 * np.pi, size=(5, 2)):
            assert abs(compiled.energy(p, g1, g2) - f_v(g1, g2, *vals)) < 1e-12 * (
                1 + f_v(g1, g2, *vals)
            )
            np.testing.assert_allclose(
                compiled.energy_hessian(p, g1, g2)[0],
                np.array(f_h(g1, g2, *vals), dtype=float),
                rtol=1e-12,
            )
            assert abs(compiled.energy(p, g1, g2) - energy_np(p, g1, g2)) < 1e-10
            np.testing.assert_allclose(
                compiled.energy_gradient(p, g1, g2)[0],
                energy_gradient_fd(p, g1, g2),
                rtol=1e-6,
                atol=1e-6,
            )


def test_tan_half_jacobian_matches_sympy():
    """The Jacobians of the paper's tan-half equations (evaluated from their terms) equal
    sympy's."""
    rng = np.random.default_rng(9)
    for zfl in equations.ZFL_PATTERNS:
        p = make_params(None, {"L01": 0.0 if zfl[0] else 7.0, "L02": 0.0 if zfl[1] else 9.0})
        variables, eqs = equations.tan_half_system(zfl)
        jac = sp.lambdify((*variables, *equations.P), sp.Matrix(eqs).jacobian(variables))
        point = tuple(rng.normal(size=len(variables)))
        np.testing.assert_allclose(
            compiled.tan_half_jacobian(p, point),
            np.array(jac(*point, *p.as_dict().values()), dtype=complex),
            rtol=1e-12,
        )
