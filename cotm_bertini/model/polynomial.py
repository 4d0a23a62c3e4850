"""Polynomial systems as numbers: sparse parametric form, numeric instantiation, evaluation."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


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

    def to_json(self) -> dict:
        """A JSON-able dict (see from_json)."""
        return {
            "variables": list(self.variables),
            "names": list(self.names),
            "parameters": list(self.parameters),
            "var_exps": [e.tolist() for e in self.var_exps],
            "par_exps": [e.tolist() for e in self.par_exps],
            "coeffs": [c.tolist() for c in self.coeffs],
            "texts": list(self.texts),
        }

    @classmethod
    def from_json(cls, data: dict) -> ParametricSystem:
        """Inverse of to_json."""
        nv, npar = len(data["variables"]), len(data["parameters"])
        return cls(
            tuple(data["variables"]),
            tuple(data["names"]),
            tuple(data["parameters"]),
            tuple(np.array(e, dtype=np.int64).reshape(-1, nv) for e in data["var_exps"]),
            tuple(np.array(e, dtype=np.int64).reshape(-1, npar) for e in data["par_exps"]),
            tuple(np.array(c, dtype=float) for c in data["coeffs"]),
            tuple(data["texts"]),
        )

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

    def instantiate(self, values: Sequence[complex]) -> PolySystem:
        """The numeric system at parameter values (same order as `parameters`)."""
        p = np.asarray(values)
        exps, cfs = [], []
        for ve, pe, c in zip(self.var_exps, self.par_exps, self.coeffs, strict=True):
            term = c * np.prod(p[None, :] ** pe, axis=1)
            uniq, inverse = np.unique(ve, axis=0, return_inverse=True)
            total = np.zeros(len(uniq), dtype=term.dtype)
            np.add.at(total, inverse.ravel(), term)
            keep = total != 0
            exps.append(uniq[keep])
            cfs.append(total[keep])
        return PolySystem(self.variables, self.names, tuple(exps), tuple(cfs))


@dataclass(frozen=True)
class PolySystem:
    """A square polynomial system with numeric coefficients: one (exponents, coefficients) a row."""

    variables: tuple[str, ...]
    names: tuple[str, ...]
    exponents: tuple[np.ndarray, ...]
    coefficients: tuple[np.ndarray, ...]

    @property
    def degrees(self) -> tuple[int, ...]:
        """Total degree of each function."""
        return tuple(int(e.sum(axis=1).max()) for e in self.exponents)

    @property
    def total_degree(self) -> int:
        """Bezout number: the path count of a total-degree homotopy."""
        return int(np.prod(self.degrees))

    def evaluate(self, x: np.ndarray) -> np.ndarray:
        """Values of every function at the rows of x, shape (n_points, n_functions)."""
        x = np.atleast_2d(np.asarray(x, dtype=complex))
        out = np.empty((x.shape[0], len(self.exponents)), dtype=complex)
        for i, (e, c) in enumerate(zip(self.exponents, self.coefficients, strict=True)):
            out[:, i] = np.prod(x[:, None, :] ** e[None, :, :], axis=2) @ c
        return out

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """Jacobian at the rows of x, shape (n_points, n_functions, n_variables)."""
        x = np.atleast_2d(np.asarray(x, dtype=complex))
        n, m = x.shape
        jac = np.zeros((n, len(self.exponents), m), dtype=complex)
        for i, (e, c) in enumerate(zip(self.exponents, self.coefficients, strict=True)):
            for j in range(m):
                ej = e[:, j]
                mask = ej > 0
                if not mask.any():
                    continue
                de = e[mask].copy()
                de[:, j] -= 1
                jac[:, i, j] = np.prod(x[:, None, :] ** de[None, :, :], axis=2) @ (
                    c[mask] * ej[mask]
                )
        return jac

    def scale(self) -> np.ndarray:
        """Largest coefficient magnitude of each function, to make residuals relative."""
        return np.array([np.abs(c).max() for c in self.coefficients])
