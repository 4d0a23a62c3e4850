"""A planar framework on a circle or torus is derived without sympy (model/framework/planar.py);
checked against the sympy derivation (derive.derive: sympy's own differentiation, expansion and
common subexpressions), which shares none of its algebra, and a first solve by the real route
is checked not to import sympy at all."""

from __future__ import annotations

import itertools
import os
import subprocess
import sys
import types

import numpy as np
import pytest
from conftest import ROOT

import cotm_bertini as cb
from cotm_bertini.model.framework.derive import derive
from cotm_bertini.model.framework.planar import derive_planar, planar_torus
from cotm_bertini.model.framework.units import normalized_slots

# Three bodies in a chain, a node pinned to a body, a spring and a cable of zero free length,
# a cable with one, loads on a body point and on the node, parameters in a ground point, a body
# point, a stiffness and a free length.
EVERYTHING = """
name = "everything"
dim = 2
nodes = ["n"]

[parameters]
gx = 1.7
arm = 0.9
k = 1.3
L0c = 2.1

[ground]
o = [0.0, 0.0]
a = ["gx", 1.1]
b = [-0.4, -1.9]

[bodies.one]
o = [0.0, 0.0]
e = ["arm", 0.2]

[bodies.two]
o = [0.1, 0.0]
e = [0.8, -0.3]

[bodies.three]
o = [0.0, 0.0]
tip = [0.6, 0.25]

[[pins]]
a = "one.o"
b = "ground.o"

[[pins]]
a = "two.o"
b = "one.e"

[[pins]]
a = "three.o"
b = "two.e"

[[pins]]
a = "n"
b = "three.tip"

[[springs]]
name = "s"
a = "one.e"
b = "ground.a"
k = "k"
L0 = 0.7

[[springs]]
name = "z"
a = "two.e"
b = "ground.b"
k = 0.6
L0 = 0.0

[[cables]]
name = "c"
a = "n"
b = "ground.b"
k = 2.0
L0 = "L0c"

[[cables]]
name = "cz"
a = "three.tip"
b = "ground.a"
k = 0.4
L0 = 0.0

[[loads]]
name = "w"
point = "two.e"
force = [0.05, -0.2]

[[loads]]
name = "pull"
point = "n"
force = ["0.1*k", 0.0]
"""

FILES = ["xmodule", "chain3", "zeeman_cables", "double_pendulum", "cotm"]


def _module(source: str) -> types.ModuleType:
    module = types.ModuleType("generated")
    exec(source, module.__dict__)
    return module


def _same_system(a: dict, b: dict) -> None:
    for key in ("variables", "names", "parameters"):
        assert a[key] == b[key], key
    for key in ("var_exps", "par_exps", "coeffs"):
        for x, y in zip(a[key], b[key], strict=True):
            np.testing.assert_allclose(np.array(x, float), np.array(y, float), rtol=1e-15, atol=0)


def _agree(fw: cb.Framework, taut: tuple[str, ...]) -> None:
    want, got = derive(fw, taut), derive_planar(fw, taut)
    for field in ("kinds", "descriptions", "free", "points", "local_size", "constraints",
                  "active"):  # fmt: skip
        assert getattr(got, field) == getattr(want, field), field
    _same_system(want.system, got.system)
    assert got.cones.keys() == want.cones.keys()
    for name in want.cones:
        _same_system(want.cones[name], got.cones[name])
    # The generated functions at random poses (c, s on the unit circles; d, w anything).
    rng = np.random.default_rng(7)
    X = rng.normal(size=(40, len(want.system["variables"])))
    angles = rng.uniform(-np.pi, np.pi, size=(40, want.local_size))
    X[:, 0 : 2 * want.local_size : 2], X[:, 1 : 2 * want.local_size : 2] = (
        np.cos(angles), np.sin(angles))  # fmt: skip
    P = np.array(list(normalized_slots(fw).values()))
    a, b = _module(want.source), _module(got.source)
    for name in ("positions", "hessian", "constraint_jacobian", "first_order",
                 "constraint_values"):  # fmt: skip
        ya = np.array([np.broadcast_to(v, (40,)) for v in getattr(a, name)(X, P)], float)
        yb = np.array([np.broadcast_to(v, (40,)) for v in getattr(b, name)(X, P)], float)
        np.testing.assert_allclose(yb, ya, rtol=1e-12, atol=1e-12, err_msg=name)


def test_a_framework_of_every_element_is_derived_as_sympy_derives_it(tmp_path):
    path = tmp_path / "everything.toml"
    path.write_text(EVERYTHING)
    fw = cb.Framework.from_toml(path)
    assert planar_torus(fw)
    for r in range(3):
        for taut in itertools.combinations(("c", "cz"), r):
            _agree(fw, taut)


@pytest.mark.parametrize("name", FILES)
def test_shipped_tori_are_derived_as_sympy_derives_them(name):
    fw = cb.Framework.from_toml(ROOT / "examples" / f"{name}.toml")
    cables = tuple(c.name for c in fw.cables)
    for taut in (cables, ()):
        _agree(fw, taut)


@pytest.mark.parametrize("path", ["examples/fourbar.toml", "tests/fixtures/fivebar.toml",
                                  "tests/fixtures/fourbar_springs.toml"])  # fmt: skip
def test_closed_loops_are_derived_as_sympy_derives_them(path):
    """Bodies pinned in a tree with a pin closing the loop: the multipliers, the pins'
    equations, the Lagrangian's Hessian and the constraints' functions, every taut set."""
    fw = cb.Framework.from_toml(ROOT / path)
    assert planar_torus(fw)
    cables = tuple(c.name for c in fw.cables)
    for r in range(len(cables) + 1):
        for taut in itertools.combinations(cables, r):
            _agree(fw, taut)


def test_spatial_frameworks_keep_the_sympy_derivation():
    assert not planar_torus(cb.Framework.from_toml(ROOT / "examples" / "prism.toml"))


def test_a_first_real_solve_imports_no_sympy(tmp_path):
    code = (
        "import sys, cotm_bertini as cb\n"
        f"fw = cb.Framework.from_toml({str(ROOT / 'examples' / 'zeeman.toml')!r})\n"
        "res = cb.solve(fw, route='real', cache=False)\n"
        "assert res.status == 'ok', res.status\n"
        "print(len(res.physical) > 0, 'sympy' in sys.modules)\n"
    )
    env = {**os.environ, "COTM_CACHE": str(tmp_path / "cache")}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True, cwd=tmp_path)  # fmt: skip
    assert out.stdout.split() == ["True", "False"]
