"""A framework's generated functions (positions, hessian, constraint_jacobian, first_order)
compiled for ball arithmetic: the same source the numeric module runs, with sqrt, sin and cos
taken as methods of the numbers passed in (python-flint's arb and acb have them) and each
argument a plain sequence (X[k] for X[..., k]), so the enclosures come from the derivation
itself and no second copy of the equations exists. Every power x**n is evaluated by `_power`:
python-flint's arb ** n is NaN for a ball centred exactly at 0 with a positive radius (a node
coordinate of 0 in a flat pose), where x * x is not."""

from __future__ import annotations

import ast
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


def _power(x, n):
    """x**n, an integer n by repeated squaring (exact for floats, valid for balls), any other
    by the number's own power."""
    if not (isinstance(n, int) or (isinstance(n, float) and n.is_integer())) or n == 0:
        return x**n
    k, base, out = abs(int(n)), x, None
    while k:
        if k & 1:
            out = base if out is None else out * base
        k >>= 1
        base = base * base if k else base
    return out if n > 0 else 1 / out


class _Powers(ast.NodeTransformer):
    """a ** b -> _power(a, b); a name squared or cubed -> a * a (* a), the most common powers,
    without a call."""

    def visit_BinOp(self, node: ast.BinOp) -> ast.AST:
        self.generic_visit(node)
        if not isinstance(node.op, ast.Pow):
            return node
        n = node.right.value if isinstance(node.right, ast.Constant) else None
        if isinstance(node.left, ast.Name) and n in (2, 3):
            out = node.left
            for _ in range(int(n) - 1):
                out = ast.BinOp(out, ast.Mult(), ast.Name(node.left.id, ast.Load()))
            return ast.copy_location(out, node)
        call = ast.Call(ast.Name("_power", ast.Load()), [node.left, node.right], [])
        return ast.copy_location(call, node)


_MODULES: dict[str, types.ModuleType] = {}


def ball_module(fs: FrameworkSystem) -> types.ModuleType:
    """The structure's generated functions, evaluable on balls: f(X, P) with X the solver
    variables and P every slot (normalised units), each a list of balls; returns a list."""
    if fs.key in _MODULES:
        return _MODULES[fs.key]
    path = cache_root() / "frameworks" / f"system-{fs.key}.json"
    source = fs.source or json.loads(path.read_text())["source"]
    lines = [line for line in source.splitlines() if not line.startswith("from numpy")]
    text = "\n".join(lines).replace("[..., ", "[")
    module = types.ModuleType(f"cotm_framework_balls_{fs.key}")
    module.__dict__.update(sqrt=_sqrt, sin=_sin, cos=_cos, _power=_power)
    tree = ast.fix_missing_locations(_Powers().visit(ast.parse(text)))
    exec(compile(tree, str(path), "exec"), module.__dict__)
    _MODULES[fs.key] = module
    return module
