"""Polynomial systems as numbers: sparse parametric form, numeric instantiation, evaluation."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np


@dataclass(frozen=True)
class Subfunctions:
    """The same functions as Bertini text over named subexpressions (an input file's subfunction
    lines), cheaper for Bertini to evaluate than the expanded terms (a fold condition's minors:
    model/framework/folds.py): `definitions` (name, text) in order, each in the variables, the
    parameters and the names defined before it; `texts` the functions; `constants` the
    parameters at values (an instantiated system), written as Bertini constants."""

    definitions: tuple[tuple[str, str], ...]
    texts: tuple[str, ...]
    constants: tuple[tuple[str, complex], ...] = ()


@dataclass(frozen=True)
class ParametricSystem:
    """Each function as terms coeff * x^var_exps * p^par_exps (p: the parameters, in order).

    Pure numbers, so it can be cached on disk and instantiated without sympy, for real or complex
    parameter values. `texts` are the functions in Bertini syntax with parameter names.
    """

    variables: tuple[str, ...]
    names: tuple[str, ...]
    parameters: tuple[str, ...]
    var_exps: tuple[np.ndarray, ...]
    par_exps: tuple[np.ndarray, ...]
    coeffs: tuple[np.ndarray, ...]
    texts: tuple[str, ...]
    structured: Subfunctions | None = None  # rendered for Bertini in place of the terms

    def to_json(self) -> dict:
        """A JSON-able dict (see from_json)."""
        out = {
            "variables": list(self.variables),
            "names": list(self.names),
            "parameters": list(self.parameters),
            "var_exps": [e.tolist() for e in self.var_exps],
            "par_exps": [e.tolist() for e in self.par_exps],
            "coeffs": [c.tolist() for c in self.coeffs],
            "texts": list(self.texts),
        }
        if self.structured:  # only then: the JSON (a cache key) of the others is unchanged
            s = self.structured
            out["structured"] = {"definitions": [list(d) for d in s.definitions],
                                 "texts": list(s.texts)}  # fmt: skip
        return out

    @classmethod
    def from_json(cls, data: dict) -> ParametricSystem:
        """Inverse of to_json."""
        nv, npar = len(data["variables"]), len(data["parameters"])
        return cls(
            tuple(data["variables"]),
            tuple(data["names"]),
            tuple(data["parameters"]),
            tuple(np.array(e, dtype=np.int64).reshape(-1, nv) for e in data["var_exps"]),
            tuple(np.array(e, dtype=np.int64).reshape(len(e), npar) for e in data["par_exps"]),
            tuple(np.array(c, dtype=float) for c in data["coeffs"]),
            tuple(data["texts"]),
            Subfunctions(tuple(tuple(d) for d in data["structured"]["definitions"]),
                         tuple(data["structured"]["texts"])) if "structured" in data else None,
        )  # fmt: skip

    def fix(self, values: dict[str, complex]) -> ParametricSystem:
        """The same system with the named parameters replaced by values (folded into the
        coefficients); the others stay parameters. `texts` is empty: render from the terms."""
        keep = [k for k, n in enumerate(self.parameters) if n not in values]
        fixed = np.array(
            [values[n] if n in values else 1.0 for n in self.parameters], dtype=complex
        )
        fold = np.ones(len(self.parameters), dtype=bool)
        fold[keep] = False
        var_exps, par_exps, coeffs = [], [], []
        for ve, pe, c in zip(self.var_exps, self.par_exps, self.coeffs, strict=True):
            term = c * np.prod(fixed[None, fold] ** pe[:, fold], axis=1)
            both = np.hstack([ve, pe[:, keep]])
            uniq, inverse = np.unique(both, axis=0, return_inverse=True)
            total = np.zeros(len(uniq), dtype=complex)
            np.add.at(total, inverse.ravel(), term)
            nz = total != 0
            total = total.real if not np.any(total.imag) else total
            var_exps.append(uniq[nz, : len(self.variables)])
            par_exps.append(uniq[nz, len(self.variables) :])
            coeffs.append(total[nz])
        return ParametricSystem(
            self.variables,
            self.names,
            tuple(self.parameters[k] for k in keep),
            tuple(var_exps),
            tuple(par_exps),
            tuple(coeffs),
            (),
        )

    @cached_property
    def _monomials(self) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
        # Per function: its distinct monomials in the variables, and which one each term is
        # (independent of the parameter values, so found once, not at every instantiate).
        return tuple(np.unique(ve, axis=0, return_inverse=True) for ve in self.var_exps)

    def instantiate(self, values: Sequence[complex]) -> PolySystem:
        """The numeric system at parameter values (same order as `parameters`); the last few
        are kept (a sweep's point asks for its system to solve it, then to classify it)."""
        p = np.asarray(values)
        key = (p.dtype.str, p.tobytes())
        recent = self.__dict__.setdefault("_recent", {})
        if key not in recent:
            if len(recent) >= 4:
                del recent[next(iter(recent))]
            recent[key] = self._instantiate(p)
        return recent[key]

    def _instantiate(self, p: np.ndarray) -> PolySystem:
        exps, cfs = [], []
        for (uniq, inverse), pe, c in zip(self._monomials, self.par_exps, self.coeffs, strict=True):
            term = c * np.prod(p[None, :] ** pe, axis=1)
            total = np.zeros(len(uniq), dtype=term.dtype)
            np.add.at(total, inverse.ravel(), term)
            keep = total != 0
            exps.append(uniq[keep])
            cfs.append(total[keep])
        structured = None
        if self.structured:
            constants = tuple(zip(self.parameters, p.tolist(), strict=True))
            structured = Subfunctions(self.structured.definitions, self.structured.texts, constants)
        return PolySystem(self.variables, self.names, tuple(exps), tuple(cfs), structured)


@dataclass(frozen=True)
class PolySystem:
    """A square polynomial system with numeric coefficients: one (exponents, coefficients) a row."""

    variables: tuple[str, ...]
    names: tuple[str, ...]
    exponents: tuple[np.ndarray, ...]
    coefficients: tuple[np.ndarray, ...]
    structured: Subfunctions | None = None  # rendered for Bertini in place of the terms

    @property
    def degrees(self) -> tuple[int, ...]:
        """Total degree of each function."""
        return tuple(int(e.sum(axis=1).max()) for e in self.exponents)

    @property
    def total_degree(self) -> int:
        """Bezout number: the path count of a total-degree homotopy."""
        return int(np.prod(self.degrees))

    @cached_property
    def _flat(self) -> tuple[np.ndarray, ...]:
        # Every term of every function in one table: exponents (T, V), coefficients (T,), and
        # where each function's terms start, for one vectorised pass over all of them.
        exps = np.vstack(self.exponents).astype(np.intp)
        coefs = np.concatenate(self.coefficients).astype(complex)
        starts = np.cumsum([0] + [len(e) for e in self.exponents[:-1]])
        return exps, coefs, starts, int(exps.max(initial=0))

    def _powers(self, x: np.ndarray, top: int) -> np.ndarray:
        """x_v^k for k = 0..top, shape (n, V, top + 1)."""
        pw = np.empty((*x.shape, top + 1), dtype=complex)
        pw[..., 0] = 1.0
        for k in range(1, top + 1):
            pw[..., k] = pw[..., k - 1] * x
        return pw

    def _sum_terms(self, terms: np.ndarray, starts: np.ndarray) -> np.ndarray:
        return np.add.reduceat(terms, starts, axis=1)

    def evaluate(self, x: np.ndarray) -> np.ndarray:
        """Values of every function at the rows of x, shape (n_points, n_functions)."""
        x = np.atleast_2d(np.asarray(x, dtype=complex))
        exps, coefs, starts, top = self._flat
        factors = self._powers(x, top)[:, np.arange(x.shape[1]), exps]  # (n, T, V)
        return self._sum_terms(factors.prod(axis=2) * coefs, starts)

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """Jacobian at the rows of x, shape (n_points, n_functions, n_variables)."""
        return self.value_and_jacobian(x)[1]

    def value_and_jacobian(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """evaluate(x) and jacobian(x) in one pass over the terms."""
        x = np.atleast_2d(np.asarray(x, dtype=complex))
        exps, coefs, starts, top = self._flat
        n, m = x.shape
        pw = self._powers(x, top)
        cols = np.arange(m)
        factors = pw[:, cols, exps]  # (n, T, m): x_v^e_tv
        # d/dx_v of a term: coeff e_tv x_v^(e_tv - 1) times the product of its other factors,
        # that product from exclusive prefix and suffix products: O(T m), not O(T m^2); the
        # last prefix product times the last factor is the term itself.
        ones = np.ones((n, len(coefs), 1), dtype=complex)
        left = np.concatenate([ones, np.cumprod(factors[:, :, :-1], axis=2)], axis=2)
        right = np.concatenate([np.cumprod(factors[:, :, :0:-1], axis=2)[:, :, ::-1], ones], axis=2)
        lowered = exps * pw[:, cols, np.maximum(exps - 1, 0)]
        values = self._sum_terms(left[:, :, -1] * factors[:, :, -1] * coefs, starts)
        return values, self._sum_terms(left * right * lowered * coefs[:, None], starts)

    def scale(self) -> np.ndarray:
        """Largest coefficient magnitude of each function, to make residuals relative."""
        return np.array([np.abs(c).max() for c in self.coefficients])
