"""The fold systems' Bertini rendering with subfunctions (model/framework/folds.py,
_with_subfunctions): the fold condition written as minors of a larger matrix is the same
polynomial as the expanded sympy fold condition, and Bertini counts the same paths for it."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import cotm_bertini as cb

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
# (file, map parameters, taut set): fourbar has one spring with L0 > 0 (an odd sign) and a
# closing pin (a bordered Hessian); cotm two springs and no constraint.
CASES = [("fourbar", "ex", "ey", ("lift", "tie")), ("cotm", "L01", "L02", ())]


def _crand(rng, n: int) -> np.ndarray:
    return rng.normal(size=n) + 1j * rng.normal(size=n)


@pytest.fixture(scope="module", params=CASES, ids=[c[0] for c in CASES])
def fold(request):
    from cotm_bertini.model.framework.folds import _slot_values, curve_system

    name, x, y, taut = request.param
    fw = cb.Framework.from_toml(EXAMPLES / f"{name}.toml")
    cs = curve_system(fw, taut, x, y)
    mx, my = sp.symbols("map_x map_y")
    return fw, taut, cs, _slot_values(fw, x, y, mx, my)


def test_structured_fold_equals_the_expanded_sympy_condition(fold):
    """Bertini's value of the rendered fold function (subfunctions) against sympy's expanded
    fold condition, lambdified, at random complex points and a random complex line."""
    import bertini

    from cotm_bertini.backends.render import render_system
    from cotm_bertini.model.framework.folds import LINE, fold_condition

    fw, taut, cs, values = fold
    assert cs.ps.structured is not None, "the fold system has no subfunctions"
    text = render_system(cs.ps.instantiate(_crand(np.random.default_rng(3), 4)))
    assert "fold_m" in text  # the minors are what Bertini reads
    rng = np.random.default_rng(7)
    line = dict(zip(cs.ps.parameters, _crand(rng, len(cs.ps.parameters)), strict=True))
    system = bertini.parse.system(render_system(cs.ps.instantiate(list(line.values()))))
    X = sp.symbols(cs.variables)
    tline = sp.Symbol("tline")
    expanded = sp.expand(fold_condition(fw, taut, values))
    assert len(sp.Add.make_args(expanded)) > 300  # the large expanded form it replaces
    at = {n: line.get(n, 0.0) for n in LINE}
    f = sp.lambdify([*X, tline], expanded.subs({
        sp.Symbol("map_x"): at["line_x0"] + tline * at["line_dx"],
        sp.Symbol("map_y"): at["line_y0"] + tline * at["line_dy"]}), "numpy")  # fmt: skip
    for _ in range(5):
        z = _crand(rng, len(cs.ps.variables)) / np.sqrt(2)
        got, want = complex(system.eval(z)[-1]), complex(f(*z))
        assert abs(got - want) <= 1e-12 * max(1.0, abs(want)), (got, want)


def test_structured_and_expanded_renderings_agree_with_their_jacobians(fold):
    """The parameter homotopy text and the fixed system with and without subfunctions:
    the same values and Jacobians at random complex points (a wrong subfunction or sign shows)."""
    import bertini

    from cotm_bertini.backends.render import render_parameter_homotopy, render_system

    _, _, cs, _ = fold
    rng = np.random.default_rng(11)
    k = len(cs.ps.parameters)
    start, target = (dict(zip(cs.ps.parameters, _crand(rng, k), strict=True)) for _ in range(2))
    plain = dataclasses.replace(cs.ps, structured=None)
    homs = [
        bertini.parse.system(render_parameter_homotopy(p, start, target)) for p in (plain, cs.ps)
    ]
    sysx = cs.ps.instantiate(list(target.values()))
    fixed = [bertini.parse.system(render_system(s)) for s in
             (dataclasses.replace(sysx, structured=None), sysx)]  # fmt: skip
    for _ in range(3):
        z, t = _crand(rng, len(cs.ps.variables)), complex(*rng.random(2))
        for a, b, args in ((*homs, (z, t)), (*fixed, (z,))):
            for method in ("eval", "eval_jacobian"):
                va, vb = getattr(a, method)(*args), getattr(b, method)(*args)
                assert np.max(np.abs(va - vb)) <= 1e-11 * np.max(np.abs(va)), method


def test_bertini_counts_the_paths_we_count(fold):
    """Bertini's multihomogeneous degrees of the structured system are those of the expanded
    terms (which decide the route and the announced path count), group by group."""
    import bertini

    from cotm_bertini.backends.render import render_system
    from cotm_bertini.catastrophe.framework_folds import _degrees, _groups

    _, _, cs, _ = fold
    groups = _groups(cs, 1)
    sysx = cs.ps.instantiate(_crand(np.random.default_rng(5), len(cs.ps.parameters)))
    parsed = bertini.parse.system(render_system(sysx, groups))
    theirs = np.array([list(parsed.degrees(g)) for g in parsed.variable_groups()]).T
    assert theirs.tolist() == _degrees(cs, 1, groups).tolist()


def test_json_without_structure_is_unchanged_and_round_trips():
    """A system without subfunctions keeps its JSON (a cache key) as before; one with them
    round-trips."""
    from cotm_bertini.model.polynomial import ParametricSystem, Subfunctions

    e = np.array([[1, 0]])
    ps = ParametricSystem(("x", "y"), ("f",), (), (e,), (np.zeros((1, 0), int),),
                          (np.array([2.0]),), ("2.0*x",))  # fmt: skip
    assert "structured" not in ps.to_json()
    sub = dataclasses.replace(ps, structured=Subfunctions((("s1", "x*y"),), ("s1 + x",)))
    back = ParametricSystem.from_json(sub.to_json())
    assert back.structured == sub.structured
    assert back.instantiate([]).structured.texts == ("s1 + x",)
