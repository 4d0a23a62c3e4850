"""Rendered Bertini input files say exactly the polynomial system we derived."""

from __future__ import annotations

import re

import numpy as np
import sympy as sp

from cotm_bertini.backends.render import render_input
from cotm_bertini.model.compiled import polynomial_system
from cotm_bertini.params import make_params
from cotm_bertini.settings import Settings


def _functions(text: str) -> dict[str, sp.Expr]:
    body = text.split("INPUT", 1)[1]
    out = {}
    for name, expr in re.findall(r"^(\w+) = (.+);$", body, re.M):
        out[name] = sp.sympify(expr.replace("^", "**"))
    return out


def test_rendered_input_round_trips():
    """Each function of the input file, read back by sympy, equals the system to 1e-14."""
    rng = np.random.default_rng(3)
    for case in ("case1", "case2", "case3"):
        params = make_params(case, {"k2": 2.7, "p5y": -3.1e-4})
        system = polynomial_system(params)
        text = render_input(system, Settings(seed=5, final_tol=1e-12), params.as_dict(), case)
        assert "RandomSeed: 5;" in text and "MPType: 2;" in text and "FinalTol: 1.0e-12;" in text
        assert f"variable_group {', '.join(system.variables)};" in text
        funcs = _functions(text)
        assert list(funcs) == list(system.names)
        x = (
            rng.normal(size=(5, len(system.variables)))
            + 1j * rng.normal(size=(5, 6))[:, : len(system.variables)]
        )
        ours = system.evaluate(x)
        syms = [sp.Symbol(v) for v in system.variables]
        for k, name in enumerate(system.names):
            f = sp.lambdify(syms, funcs[name], "numpy")
            theirs = np.array([complex(f(*row)) for row in x])
            np.testing.assert_allclose(theirs, ours[:, k], rtol=1e-14, atol=1e-12)


def test_multihomogeneous_groups():
    """The multihomogeneous option groups {c1,s1}, {c2,s2} and each d alone."""
    params = make_params("case3")
    text = render_input(
        polynomial_system(params),
        Settings(engine="cli", variable_groups="multihomogeneous"),
        params.as_dict(),
    )
    for g in ("c1, s1", "c2, s2", "d1", "d2"):
        assert f"variable_group {g};" in text
