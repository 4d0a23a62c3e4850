"""sympy expressions as the package's numeric forms: sparse parametric systems, numpy source."""

from __future__ import annotations

import numpy as np
import sympy as sp

from ..literals import bertini_number
from .polynomial import ParametricSystem


class _BertiniPrinter(sp.printing.str.StrPrinter):
    """sympy's str form with every float written as bertini_number writes it (sstr's
    "1.0000000000000000e+16" has the "+" Bertini 2's parser refuses)."""

    def _print_Float(self, expr: sp.Float) -> str:
        return bertini_number(float(expr))


def bertini_text(expr: sp.Expr) -> str:
    """An expression in Bertini's syntax: floats as bertini_number, powers as ^."""
    return _BertiniPrinter().doprint(expr).replace("**", "^")


def parametric_from_sympy(
    variables: tuple[str, ...],
    names: tuple[str, ...],
    functions: tuple[sp.Expr, ...],
    parameters: tuple[str, ...],
) -> ParametricSystem:
    """Polynomials in `variables` with coefficients polynomial in `parameters`, as terms.

    Parameters that no function uses are dropped (the system's `parameters` lists the used ones
    in the given order)."""
    # The functions' own symbols by name (whatever assumptions they were made with).
    named = {s.name: s for f in functions for s in f.free_symbols}
    xs = [named.get(n, sp.Symbol(n)) for n in variables]
    used = tuple(n for n in parameters if n in named)
    ps = [named[n] for n in used]
    var_exps, par_exps, coeffs, texts = [], [], [], []
    for f in functions:
        poly = sp.Poly(sp.expand(f), *xs, *ps)
        terms = poly.terms()
        var_exps.append(np.array([m[: len(xs)] for m, _ in terms], dtype=np.int64))
        par_exps.append(np.array([m[len(xs) :] for m, _ in terms], dtype=np.int64))
        coeffs.append(np.array([float(c) for _, c in terms], dtype=float))
        texts.append(bertini_text(f))
    return ParametricSystem(
        tuple(variables), tuple(names), used, tuple(var_exps), tuple(par_exps), tuple(coeffs),
        tuple(texts),
    )  # fmt: skip


def numpy_function(name: str, args: dict[str, list[sp.Symbol]], exprs: list[sp.Expr]) -> str:
    """Source of `def name(<args>)` returning the list `exprs`, common subexpressions shared.

    Each argument is an array whose last axis holds the listed symbols in order."""
    from sympy.printing.numpy import NumPyPrinter

    printer = NumPyPrinter({"fully_qualified_modules": False})
    lines = [f"def {name}({', '.join(args)}):"]
    for arg, symbols in args.items():
        for k, s in enumerate(symbols):
            lines.append(f"    {s.name} = {arg}[..., {k}]")
    subs, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("_t"))
    for sym, expr in subs:
        lines.append(f"    {sym} = {printer.doprint(expr)}")
    lines.append(f"    return [{', '.join(printer.doprint(e) for e in reduced)}]")
    return "\n".join(lines) + "\n"
