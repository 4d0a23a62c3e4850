"""Equilibrium equations and energy of the CoTM, derived with sympy from the kinematics."""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cache, lru_cache
from types import SimpleNamespace

import numpy as np
import sympy as sp

from ..params import PARAM_NAMES
from .kinematics import cross, dot, points, spring_vectors
from .polynomial import ParametricSystem

ANGLE_VARS = ("c1", "s1", "c2", "s2")

P = sp.symbols(PARAM_NAMES, real=True)
PSYM = dict(zip(PARAM_NAMES, P, strict=True))
SYMBOLIC_PARAMS = SimpleNamespace(**PSYM)


@dataclass(frozen=True)
class SymbolicSystem:
    """Polynomial equations in the solver variables, coefficients symbolic in the parameters."""

    zfl: tuple[bool, bool]
    variables: tuple[str, ...]
    names: tuple[str, ...]
    functions: tuple[sp.Expr, ...]


def variables_for(zfl: tuple[bool, bool]) -> tuple[str, ...]:
    """Solver variables: cos/sin of both angles, plus d_i for each spring with L0i != 0."""
    return ANGLE_VARS + tuple(f"d{i}" for i in (1, 2) if not zfl[i - 1])


@cache
def derive(zfl: tuple[bool, bool]) -> SymbolicSystem:
    """Force balance (7), moment balance (8), spring lengths (9)-(10) and unit circles.

    A spring with L0 > 0 pulls with force density k (d - L0) / d; its length d becomes a variable
    and the balance equations are multiplied through by d (which adds the d = 0 artefacts of
    docs/paper.md). A zero-free-length spring has force density k and needs no d.
    """
    names = variables_for(zfl)
    v = {n: sp.Symbol(n) for n in names}
    angles = (v["c1"], v["s1"], v["c2"], v["s2"])
    pts = points(SYMBOLIC_PARAMS, *angles)
    vec = spring_vectors(SYMBOLIC_PARAMS, *angles)
    spring = {1: vec["spring1"], 2: vec["spring2"]}
    anchor = {1: pts[2], 2: pts[3]}
    rod = vec["rod"]
    k = {1: PSYM["k1"], 2: PSYM["k2"]}
    L0 = {1: PSYM["L01"], 2: PSYM["L02"]}
    d = {i: v.get(f"d{i}") for i in (1, 2)}

    # Force density of spring i, times the d's that clear denominators.
    density = {}
    for i, j in ((1, 2), (2, 1)):
        w = k[i] if zfl[i - 1] else k[i] * (d[i] - L0[i])
        if not zfl[j - 1]:
            w = w * d[j]
        density[i] = w

    force = sum(density[i] * cross(rod, spring[i]) for i in (1, 2))
    moment = sum(density[i] * cross(anchor[i], spring[i]) for i in (1, 2))
    eqs = [sp.expand(force), sp.expand(moment)]
    labels = ["force", "moment"]
    for i in (1, 2):
        if not zfl[i - 1]:
            eqs.append(sp.expand(d[i] ** 2 - dot(spring[i], spring[i])))
            labels.append(f"length{i}")
    for i in (1, 2):
        eqs.append(v[f"c{i}"] ** 2 + v[f"s{i}"] ** 2 - 1)
        labels.append(f"circle{i}")
    return SymbolicSystem(zfl, names, tuple(labels), tuple(eqs))


@cache
def derive_parametric(zfl: tuple[bool, bool]) -> ParametricSystem:
    """`derive` as numbers: sparse terms in the variables and the parameters, and Bertini text."""
    from .symbolic import parametric_from_sympy

    sym = derive(zfl)
    return parametric_from_sympy(sym.variables, sym.names, sym.functions, PARAM_NAMES)


# --- energy in the angles -------------------------------------------------------------------

G1, G2 = sp.symbols("gamma1 gamma2", real=True)


@lru_cache(maxsize=1)
def energy_expressions() -> tuple[sp.Expr, list[sp.Expr], sp.Matrix]:
    """V = sum 1/2 k_i (d_i - L0i)^2 with d_i = |P_spring|, with its gradient and Hessian."""
    vec = spring_vectors(SYMBOLIC_PARAMS, sp.cos(G1), sp.sin(G1), sp.cos(G2), sp.sin(G2))
    q1 = dot(vec["spring1"], vec["spring1"])
    q2 = dot(vec["spring2"], vec["spring2"])
    s = PSYM
    V = (s["k1"] * (sp.sqrt(q1) - s["L01"]) ** 2 + s["k2"] * (sp.sqrt(q2) - s["L02"]) ** 2) / 2
    grad = [sp.diff(V, g) for g in (G1, G2)]
    hess = sp.hessian(V, (G1, G2))
    return V, grad, hess


# --- the paper's tan-half form (for its stability criterion) -------------------------------

X1, X2 = sp.symbols("x1 x2")


@cache
def tan_half_system(zfl: tuple[bool, bool]) -> tuple[tuple[sp.Symbol, ...], tuple[sp.Expr, ...]]:
    """Eqs. (14)-(15), (21)-(23), (28)-(31): our equations with c = (1-x^2)/(1+x^2),
    s = 2x/(1+x^2), cleared of denominators by (1+x1^2)(1+x2^2); the unit circles drop out."""
    sym = derive(zfl)
    subs = {
        sp.Symbol("c1"): (1 - X1**2) / (1 + X1**2),
        sp.Symbol("s1"): 2 * X1 / (1 + X1**2),
        sp.Symbol("c2"): (1 - X2**2) / (1 + X2**2),
        sp.Symbol("s2"): 2 * X2 / (1 + X2**2),
    }
    clear = (1 + X1**2) * (1 + X2**2)
    eqs = tuple(
        sp.expand(sp.cancel(f.subs(subs) * clear))
        for f, name in zip(sym.functions, sym.names, strict=True)
        if not name.startswith("circle")
    )
    variables = (X1, X2) + tuple(sp.Symbol(v) for v in sym.variables if v.startswith("d"))
    return variables, eqs


def derive_tan_half(zfl: tuple[bool, bool]) -> ParametricSystem:
    """`tan_half_system` as numbers (its Jacobian is the paper's stability criterion's)."""
    from .symbolic import parametric_from_sympy

    variables, eqs = tan_half_system(zfl)
    names = tuple(f"th{k + 1}" for k in range(len(eqs)))
    return parametric_from_sympy(tuple(v.name for v in variables), names, eqs, PARAM_NAMES)


ZFL_PATTERNS = ((True, True), (False, True), (True, False), (False, False))


def _source(name: str, args: tuple, expr) -> str:
    import inspect

    fn = sp.lambdify(args, expr, "numpy", cse=True)
    return inspect.getsource(fn).replace("def _lambdifygenerated(", f"def {name}(", 1)


def generated_source() -> str:
    """Python source of the numeric functions (energy, gradient, Hessian), from sympy's
    lambdify: it is written to the cache so later runs need no sympy."""
    V, grad, hess = energy_expressions()
    args = (G1, G2, *P)
    parts = [
        _source("energy", args, V),
        _source("gradient", args, grad),
        _source("hessian", args, hess),
    ]
    body = "\n\n".join(parts) + "\n"
    # Import only the numpy names the code calls: `from numpy import *` costs ~50 ms a process.
    called = set(re.findall(r"\b([A-Za-z_]\w*)\(", body))
    defined = set(re.findall(r"^def (\w+)\(", body, re.M))
    names = sorted(n for n in called - defined if n in dir(np) and not n.startswith("_"))
    head = [
        '"""Generated by cotm_bertini.model.equations.generated_source(); do not edit."""',
        f"from numpy import {', '.join(names)}",
    ]
    return "\n".join(head) + "\n\n\n" + body
