"""A framework's generated functions (positions, hessian, constraint_jacobian, first_order)
compiled for ball arithmetic: the same source the numeric module runs, with sqrt, sin and cos
taken as methods of the numbers passed in (python-flint's arb and acb have them) and each
argument a plain sequence (X[k] for X[..., k]), so the enclosures come from the derivation
itself and no second copy of the equations exists."""

from __future__ import annotations

import json
import types

from ...fs import cache_root
from .compiled import FrameworkSystem


def _sqrt(x):
    return x.sqrt()


def _sin(x):
    return x.sin()


def _cos(x):
    return x.cos()


_MODULES: dict[str, types.ModuleType] = {}


def ball_module(fs: FrameworkSystem) -> types.ModuleType:
    """The structure's generated functions, evaluable on balls: f(X, P) with X the solver
    variables and P every slot (normalised units), each a list of balls; returns a list."""
    if fs.key in _MODULES:
        return _MODULES[fs.key]
    path = cache_root() / "frameworks" / f"system-{fs.key}.json"
    source = json.loads(path.read_text())["source"]
    lines = [line for line in source.splitlines() if not line.startswith("from numpy")]
    text = "\n".join(lines).replace("[..., ", "[")
    module = types.ModuleType(f"cotm_framework_balls_{fs.key}")
    module.__dict__.update(sqrt=_sqrt, sin=_sin, cos=_cos)
    exec(compile(text, str(path), "exec"), module.__dict__)
    _MODULES[fs.key] = module
    return module
