"""Polynomial systems as numbers: sparse parametric form, numeric instantiation, evaluation."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from ..errors import ParameterError


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
class _Terms:
    """A PolySystem's terms by the variables each holds (PolySystem._sparse)."""

    var: np.ndarray  # (T, K): the variables a term holds; index m (a column of ones) pads
    power: np.ndarray  # (T, K): their exponents
    coefs: np.ndarray  # (T,)
    starts: np.ndarray  # where each function's terms start
    order: np.ndarray  # the real (term, slot) pairs, sorted by their Jacobian entry
    targets: np.ndarray  # each entry (function * m + variable) that some slot feeds
    first: np.ndarray  # where each target's slots start in `order`


@dataclass(frozen=True)
class _Table:
    """A PolySystem's values and Jacobian from its monomials (PolySystem._table): every monomial
    they hold, evaluated at the points, then each value and Jacobian entry as a sum of
    coefficient times monomial. Only `coefs` depends on the coefficients (see _layout)."""

    var: np.ndarray  # (M, K): the variables a monomial holds; index m (a column of ones) pads
    power: np.ndarray  # (M, K): their exponents
    monomial: np.ndarray  # (E,): each (output, monomial) pair's monomial, sorted by output
    targets: np.ndarray  # the outputs (values first, then the Jacobian row by row) fed
    first: np.ndarray  # where each target's pairs start
    top: int  # the highest exponent
    term: np.ndarray  # each term and each derivative term: the term it comes from,
    factor: np.ndarray  # its factor (1, or the exponent it lowers),
    pair: np.ndarray  # and the pair it is summed into
    coefs: np.ndarray | None = None  # (E,): each pair's coefficient


# The most (output, monomial) pairs the monomial route is used for: the paper's systems have
# ~150; a spatial framework's derivatives multiply its terms, and the sparse route (_Terms) is
# kept there.
TABLE_LIMIT = 1 << 14
_LAYOUTS: dict[tuple, _Table | None] = {}  # by exponents: a sweep's points share their layout


def _layout(exponents: tuple[np.ndarray, ...]) -> _Table | None:
    """The coefficient-free part of the table of systems with these exponents (None when
    there would be more than TABLE_LIMIT pairs)."""
    if not sum(len(e) for e in exponents):
        return None  # no terms at all: the sparse route knows what to do
    exps = np.vstack(exponents).astype(np.intp)
    key = (exps.shape, exps.tobytes(), tuple(len(e) for e in exponents), TABLE_LIMIT)
    if key not in _LAYOUTS:
        if len(_LAYOUTS) > 64:
            _LAYOUTS.clear()
        _LAYOUTS[key] = _new_layout(exps, [len(e) for e in exponents])
    return _LAYOUTS[key]


def _new_layout(exps: np.ndarray, sizes: list[int]) -> _Table | None:
    m, F = exps.shape[1], len(sizes)
    func = np.repeat(np.arange(F), sizes)
    t, v = np.nonzero(exps)  # one derivative term per variable a term holds
    lowered = exps[t].copy()
    lowered[np.arange(len(t)), v] -= 1
    output = np.concatenate([func, F + func[t] * m + v])
    monomials, which = np.unique(np.vstack([exps, lowered]), axis=0, return_inverse=True)
    pairs, pair = np.unique(np.stack([output, which.ravel()], axis=1), axis=0,
                            return_inverse=True)  # fmt: skip
    if len(pairs) > TABLE_LIMIT:
        return None
    targets, first = np.unique(pairs[:, 0], return_index=True)  # pairs sorted by output
    held = [np.flatnonzero(e) for e in monomials]
    K = max(1, max((len(h) for h in held), default=1))
    var = np.full((len(monomials), K), m, np.intp)
    power = np.zeros((len(monomials), K), np.intp)
    for i, h in enumerate(held):
        var[i, : len(h)], power[i, : len(h)] = h, monomials[i, h]
    term = np.concatenate([np.arange(len(exps)), t])
    factor = np.concatenate([np.ones(len(exps)), exps[t, v]])
    top = max(int(monomials.max(initial=0)), 1)
    return _Table(var, power, pairs[:, 1], targets, first, top, term, factor, pair.ravel())


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

    def _powers(self, x: np.ndarray, top: int) -> np.ndarray:
        """x_v^k for k = 0..top, shape (n, V, top + 1)."""
        pw = np.empty((*x.shape, top + 1), dtype=complex)
        pw[..., 0] = 1.0
        for k in range(1, top + 1):
            pw[..., k] = pw[..., k - 1] * x
        return pw

    def evaluate(self, x: np.ndarray) -> np.ndarray:
        """Values of every function at the rows of x, shape (n_points, n_functions)."""
        if self._table is not None:
            return self.value_and_jacobian(x)[0]
        _, factors = self._factors(x)
        sp = self._sparse
        return np.add.reduceat(factors.prod(axis=2) * sp.coefs, sp.starts, axis=1)

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """Jacobian at the rows of x, shape (n_points, n_functions, n_variables)."""
        return self.value_and_jacobian(x)[1]

    @cached_property
    def _sparse(self) -> _Terms:
        # Each term by the variables it holds (K at most, padded with a variable of value 1 at
        # index m and exponent 0): a term of a mechanism's system holds two to four of its m
        # variables, so a pass costs K/m of a dense one (7 times less on the prism's system).
        exps = np.vstack(self.exponents).astype(np.intp)  # every term of every function
        T, m = exps.shape
        held = [np.flatnonzero(e) for e in exps]
        K = max(1, max((len(h) for h in held), default=1))
        var, power = np.full((T, K), m, dtype=np.intp), np.zeros((T, K), dtype=np.intp)
        starts = np.cumsum([0] + [len(e) for e in self.exponents[:-1]])
        func = np.repeat(np.arange(len(self.exponents)), [len(e) for e in self.exponents])
        entry = np.full((T, K), -1)  # the Jacobian entry (function, variable) of each slot
        for t, h in enumerate(held):
            var[t, : len(h)], power[t, : len(h)] = h, exps[t, h]
            entry[t, : len(h)] = func[t] * m + h
        flat = entry.ravel()
        order = np.argsort(flat, kind="stable")[np.sum(flat < 0) :]  # the real slots, by entry
        targets, first = np.unique(flat[order], return_index=True)
        coefs = np.concatenate(self.coefficients).astype(complex)
        return _Terms(var, power, coefs, starts, order, targets, first)

    def _factors(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """x_v^k for k = 0..top of x with a column of ones, and x_v^e of each variable each
        term holds, (n, T, K)."""
        x = np.atleast_2d(np.asarray(x, dtype=complex))
        sp = self._sparse
        pw = self._powers(np.hstack([x, np.ones((len(x), 1))]), max(int(sp.power.max()), 1))
        return pw, pw[:, sp.var, sp.power]

    @cached_property
    def _table(self) -> _Table | None:
        # The values' terms and every partial derivative's, merged into distinct monomials:
        # one evaluation of those and one sum per output give values and Jacobian (5-10 times
        # faster than the sparse route on the paper's system, 2-3 times on the frameworks',
        # bench/evaluate.py; a sum, not a matrix product: BLAS threads stall when every core
        # already runs a sweep worker). None when there would be many pairs.
        layout = _layout(self.exponents)
        if layout is None:
            return None
        coefs = np.concatenate(self.coefficients).astype(complex)[layout.term] * layout.factor
        total = np.zeros(len(layout.monomial), dtype=complex)
        np.add.at(total, layout.pair, coefs)
        return replace(layout, coefs=total)

    def _by_table(self, x: np.ndarray, tb: _Table) -> tuple[np.ndarray, np.ndarray]:
        n, m = x.shape
        pw = self._powers(np.hstack([x, np.ones((n, 1))]), tb.top)
        mono = pw[:, tb.var[:, 0], tb.power[:, 0]]
        for k in range(1, tb.var.shape[1]):
            mono = mono * pw[:, tb.var[:, k], tb.power[:, k]]
        F = len(self.exponents)
        out = np.zeros((n, F * (m + 1)), dtype=complex)
        if len(tb.targets):
            out[:, tb.targets] = np.add.reduceat(mono[:, tb.monomial] * tb.coefs, tb.first, axis=1)
        return out[:, :F], out[:, F:].reshape(n, F, m)

    def value_and_jacobian(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """evaluate(x) and jacobian(x) in one pass over the terms."""
        x = np.atleast_2d(np.asarray(x, dtype=complex))
        if self._table is not None:
            return self._by_table(x, self._table)
        sp, (n, m) = self._sparse, x.shape
        pw, factors = self._factors(x)
        # d/dx_v of a term: coeff e x_v^(e - 1) times the product of its other factors, that
        # product from exclusive prefix and suffix products; the last prefix product times the
        # last factor is the term itself.
        ones = np.ones((*factors.shape[:2], 1), dtype=complex)
        left = np.concatenate([ones, np.cumprod(factors[:, :, :-1], axis=2)], axis=2)
        right = np.concatenate([np.cumprod(factors[:, :, :0:-1], axis=2)[:, :, ::-1], ones], axis=2)
        lowered = sp.power * pw[:, sp.var, np.maximum(sp.power - 1, 0)]
        values = np.add.reduceat(left[:, :, -1] * factors[:, :, -1] * sp.coefs, sp.starts, axis=1)
        parts = (left * right * lowered * sp.coefs[:, None]).reshape(n, -1)[:, sp.order]
        jac = np.zeros((n, len(self.exponents) * m), dtype=complex)
        if len(sp.targets):
            jac[:, sp.targets] = np.add.reduceat(parts, sp.first, axis=1)
        return values, jac.reshape(n, len(self.exponents), m)

    def scale(self) -> np.ndarray:
        """Largest coefficient magnitude of each function, to make residuals relative."""
        empty = [n for n, c in zip(self.names, self.coefficients, strict=True) if not len(c)]
        if empty:  # every point solves it: no residual to scale, and no finite set of roots
            raise ParameterError(
                f"equation {empty[0]} has no terms at these parameter values (every "
                "coefficient is 0): the system is degenerate there"
            )
        return np.array([np.abs(c).max() for c in self.coefficients])
