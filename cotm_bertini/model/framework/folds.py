"""Curves over two parameters of a framework as polynomial systems: fold curves and cable switches.

For one taut set with equilibrium system F(X; p) = 0 (derive.equilibrium_equations, normalised
units) and two map parameters (x, y) of the file, a curve is F = 0 plus one more equation:

- fold: the bordered Hessian of the Lagrangian (the reduced Hessian bordered by the constraints'
  Jacobian, in local coordinates) is singular, its determinant cleared of the springs' 1/d
  (fold_condition): no null vector among the unknowns, so the system stays as small as F;
- relaxed fold (no loads, no bars or closing pins, no taut cable, as many springs as degrees of
  freedom, every one with L0 > 0): every force density w = 0 (each link at its free length, a
  configuration of zero energy) and the lengths' Jacobian in local coordinates singular
  (relaxed_condition): where two zero-energy minima meet with the saddle between them. There the
  fold system above is singular (its Jacobian loses rank: the moment equations vanish with w),
  so neither Newton nor tracing works on it, and these folds get their own system;
- switch of cable c (taut, L0 > 0): d_c = L0_c (the cable exactly at its free length, so it
  exerts no force and the equilibrium is also one of the taut set without c).

Each is generated twice from the same sympy expressions: the curve's equations as polynomials in
Z = (X, mx, my) (mx = x / sx, my = y / sy: the map coordinates in the units of the slots they
enter) for tracing, evaluated term-vectorised by model/polynomial.py (a two-body fold equation
has over a thousand terms: generated scalar code took milliseconds a Jacobian); and a Bertini
system with (mx, my) = (x0, y0) + tline (dx, dy) on a
line, tline unknown, whose parameters are the line's coefficients: solved once at a random
complex line (a witness set of the curve), then reached on any real line by parameter homotopy.
Bertini reads the fold condition as the minors of a larger matrix, in subfunctions (fold_matrix,
_with_subfunctions): about 10 times cheaper to evaluate than its expanded terms.
The file's other parameters enter as their values (_slot_values). Cached on disk by structure,
map parameters, curve kind and those values, like compiled.py.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from functools import cache
from pathlib import Path

import sympy as sp
from sympy.polys.matrices import DomainMatrix

from ...errors import ParameterError
from ...fs import files_hash
from ..polynomial import ParametricSystem, PolySystem, Subfunctions
from .compiled import cached_derivation, framework_system, variable_groups
from .expressions import Expr
from .spec import Framework
from .structure import source_hash, structure_key
from .units import normalized_slots, scale_of, slot_kind, units

LINE = ("line_x0", "line_y0", "line_dx", "line_dy")
RELAXED = "(relaxed)"  # curve_system's `cable` for the relaxed folds (no cable name has brackets)


@dataclass(frozen=True)
class CurveDerived:
    """A curve system as plain data (JSON-able)."""

    kind: str  # "fold", "relaxed" or "switch"
    cable: str  # the cable at its free length (switch), else ""
    variables: list[str]  # X: the equilibrium system's unknowns, in its order
    system: dict  # ParametricSystem JSON: unknowns X, tline; parameters LINE
    scales: list[float]  # (sx, sy): user value = scale * map coordinate
    trace: dict  # ParametricSystem JSON without parameters: the equations in Z = X, mx, my
    source: str = ""  # no generated code (cached_derivation compiles what there is)


@dataclass(frozen=True, eq=False)
class CurveSystem:
    """A curve system ready to solve and trace."""

    key: str
    taut: tuple[str, ...]
    kind: str
    cable: str
    variables: tuple[str, ...]
    ps: ParametricSystem
    scales: tuple[float, float]
    trace: PolySystem  # the equations in Z = (X, mx, my)
    groups: list[list[str]]


def to_sympy(e: Expr, symbol) -> sp.Expr:
    """A file expression as sympy, each parameter name mapped by `symbol(name)`."""
    if e.op == "num":
        return sp.nsimplify(e.value) if float(e.value).is_integer() else sp.Float(e.value, 17)
    if e.op == "name":
        return symbol(e.name)
    a = [to_sympy(x, symbol) for x in e.args]
    if e.op == "neg":
        return -a[0]
    ops = {"+": sp.Add, "*": sp.Mul, "-": lambda p, q: p - q, "/": lambda p, q: p / q,
           "^": sp.Pow}  # fmt: skip
    return ops[e.op](a[0], a[1])


def map_scales(fw: Framework, xname: str, yname: str) -> tuple[float, float]:
    """Each map parameter's unit: that of the first slot it enters (a length, stiffness or
    force), so the map coordinates are of order one."""
    L, K = units(fw)
    exprs = fw.slot_expressions()
    out = []
    for name in (xname, yname):
        slots = [s for s, e in exprs.items() if name in e.names()]
        if not slots:
            raise ParameterError(
                f"{name}: parameter of framework {fw.name!r} that no number of its equations "
                "uses (a map over it would be empty)"
            )
        out.append(scale_of(slot_kind(slots[0]), L, K))
    return out[0], out[1]


def _slot_values(fw: Framework, xname: str, yname: str, mx, my) -> dict:
    """sympy substitutions of every slot (normalised units): those that name a map parameter as
    polynomials in (mx, my), with the file's other parameters at their values; the rest as
    numbers. A curve system is thus derived for the values of the parameters that are not on the
    map (the determinant of the bordered Hessian, expanded with every geometry slot a symbol, is
    too large for sympy on two bodies), and derived and solved again if one of them changes."""
    L, K = units(fw)
    sx, sy = map_scales(fw, xname, yname)

    def symbol(name: str):
        if name == xname:
            return sx * mx
        if name == yname:
            return sy * my
        return sp.Float(fw.values[name], 17)

    slots = normalized_slots(fw)
    out = {}
    for slot, e in fw.slot_expressions().items():
        if e.names() & {xname, yname}:
            out[sp.Symbol(slot)] = to_sympy(e, symbol) / scale_of(slot_kind(slot), L, K)
        else:
            out[sp.Symbol(slot)] = sp.Float(slots[slot], 17)
    return out


def _upper(m: int) -> list[tuple[int, int]]:
    return [(i, j) for i in range(m) for j in range(i, m)]


def _bordered_hessian(fw: Framework, taut: tuple[str, ...]) -> tuple[sp.Matrix, list]:
    """(B, springs): the bordered Hessian of the Lagrangian (fold_condition) with each spring's
    alpha a symbol, and for each spring with L0 > 0 (alpha, v, k - w, d^2), its term in B
    alpha v v^T (v zero on the constraints' rows)."""
    from .derive import _active, local_frame

    local, at, pos, cons, loads = local_frame(fw)
    zfl, m = set(fw.zero_free_length()), len(local)
    H = sp.zeros(m, m)
    springs = []
    for x in _active(fw, taut):
        r = pos.of(x.a) - pos.of(x.b)
        r0 = r.subs(at)
        ri = [sp.diff(r, a).subs(at) for a in local]
        k = sp.Symbol(f"k_{x.name}")
        w = k if x.name in zfl else sp.Symbol(f"w_{x.name}")
        if x.name not in zfl:
            alpha, v = sp.Symbol(f"alpha_{x.name}"), [r0.dot(ri[i]) for i in range(m)]
            springs.append((alpha, v + [0] * len(cons), k - w, sp.Symbol(f"d_{x.name}") ** 2))
        for i, j in _upper(m):
            term = w * (ri[i].dot(ri[j]) + r0.dot(sp.diff(r, local[i], local[j]).subs(at)))
            if x.name not in zfl:
                term += alpha * v[i] * v[j]
            H[i, j] += term
    L = -loads + sum(sp.Symbol(name) * g for g, name, _, _ in cons)
    for i, j in _upper(m):
        H[i, j] += sp.diff(L, local[i], local[j]).subs(at)
        H[j, i] = H[i, j]
    G = sp.Matrix([[sp.diff(g, a).subs(at) for a in local] for g, *_ in cons])
    B = H if not len(cons) else sp.Matrix(sp.BlockMatrix([[H, G.T], [G, sp.zeros(len(cons))]]))
    return B, springs


def _exact(e: sp.Expr) -> sp.Expr:
    """Every float of `e` as the rational it is: sums then cancel exactly (in floats the
    determinant kept terms of 1e-19 that raised its degree, and so the path count, 1408 paths
    instead of 1280 for cotm.toml's witness set)."""
    return e.xreplace({f: sp.Rational(f) for f in e.atoms(sp.Float)})


def _floats(e: sp.Expr) -> sp.Expr:
    """The rational coefficients of a polynomial as floats (Bertini's text wants numbers)."""
    return e.xreplace({q: sp.Float(q, 17) for q in e.atoms(sp.Rational) if not q.is_Integer})


def fold_condition(fw: Framework, taut: tuple[str, ...], values: dict) -> sp.Expr:
    """A polynomial in the unknowns that vanishes where the bordered Hessian of the Lagrangian
    (local coordinates, constraints bordering it) is singular: a fold. `values`: every slot's
    substitution (_slot_values), made in the entries before the determinant is expanded.

    A spring's energy k/2 (|r| - L0)^2 has second derivatives w (r_i . r_j + r . r_ij) +
    alpha (r . r_i)(r . r_j) with w = k (1 - L0/d) and alpha = k L0 / d^3 = (k - w) / d^2. The
    determinant is affine in each alpha (each enters a rank-one term), so multiplying it by every
    d^2 clears the denominators: alpha -> k - w in a term that has it, else a factor d^2."""
    B, springs = _bordered_hessian(fw, taut)
    exact = {s: _exact(v) for s, v in values.items()}
    # Numbers first: the determinant's size grows with every symbol left in its entries.
    B = B.applyfunc(lambda e: sp.expand(e.xreplace(exact)))
    # Over the polynomial ring, by minors (_det_by_minors): sympy's Matrix.det simplifies every
    # product and takes minutes on two bodies, and its Bareiss (dm.det()) divides exactly, which
    # with float coefficients (the four-bar's) did not finish in 14 CPU-minutes on a 5 x 5.
    dm = DomainMatrix.from_Matrix(B)
    det = sp.expand(dm.domain.to_sympy(_det_by_minors(dm)))
    alphas = [a for a, *_ in springs]
    out = sp.Integer(0)
    for monomial, coeff in sp.Poly(det, *alphas).terms() if alphas else [((), det)]:
        factor = sp.Integer(1)
        for e, (_, _, has, lacks) in zip(monomial, springs, strict=True):
            factor *= (has if e else lacks).xreplace(exact)
        out += coeff * factor
    return _floats(sp.expand(out))


def fold_matrix(fw: Framework, taut: tuple[str, ...], values: dict) -> tuple[sp.Matrix, int]:
    """(M, r): M = [[B0, V diag(k - w)], [V^T, -diag(d^2)]] (B0: the bordered Hessian without
    its alpha terms, V: the r springs' v as columns, fold_condition's notation), whose
    determinant is (-1)^r fold_condition without expanding it: by the Schur complement of the
    lower right block, det M = (-1)^r prod d^2 det(B at alpha = (k - w) / d^2)."""
    B, springs = _bordered_hessian(fw, taut)
    n, r = B.shape[0], len(springs)
    M = sp.zeros(n + r, n + r)
    M[:n, :n] = B.xreplace({alpha: 0 for alpha, *_ in springs})
    for s, (_, v, has, lacks) in enumerate(springs):
        for i, vi in enumerate(v):
            M[i, n + s], M[n + s, i] = vi * has, vi
        M[n + s, n + s] = -lacks
    exact = {s: _exact(v) for s, v in values.items()}
    return M.applyfunc(lambda e: _floats(sp.expand(e.xreplace(exact)))), r


def _laplace(n: int, entry: Callable, one, combine: Callable):
    """The determinant of an n x n matrix, division-free: Laplace expansion along each row in
    turn, every minor of the bottom rows computed once (n 2^n products). `entry(k, j)`: an
    entry (None if zero); `combine(columns bitmask, [(sign, entry, minor)])`: that minor. None
    if every expansion has a zero factor."""
    below = {0: one}  # column set (bitmask) -> minor of the bottom rows on it
    for k in range(n - 1, -1, -1):
        above: dict = {}
        for cols, minor in below.items():
            for j in range(n):
                a = None if cols >> j & 1 else entry(k, j)
                if a is None:
                    continue
                sign = -1 if bin(cols & ((1 << j) - 1)).count("1") % 2 else 1
                above.setdefault(cols | 1 << j, []).append((sign, a, minor))
        below = {cols: combine(cols, terms) for cols, terms in above.items()}
    return below.get((1 << n) - 1)


def _det_by_minors(dm: DomainMatrix):
    """The determinant of a square DomainMatrix over a ring (_laplace; 0.01 s for the
    four-bar's 5 x 5 bordered Hessian)."""
    rows, ring = dm.rep.to_ddm(), dm.domain

    def combine(_, terms):
        out = ring.zero
        for sign, a, minor in terms:
            out = out + a * minor if sign > 0 else out - a * minor
        return out

    det = _laplace(len(rows), lambda k, j: rows[k][j] or None, ring.one, combine)
    return ring.zero if det is None else det


def _minors_program(M: sp.Matrix) -> tuple[list[tuple[str, str]], str | None]:
    """det M as Bertini subfunctions: (name, text) of each nonzero entry, then of each minor of
    the bottom rows (_laplace), and the name of the determinant (None if M is singular by its
    zeros). Fixed-width numbers: Bertini 2's parser refuses a name that another one extends
    (fold_m1 defined, then fold_m10)."""
    from ..symbolic import bertini_text

    n = M.shape[0]
    wide, lines = len(str(n)), []
    for i, j in ((i, j) for i in range(n) for j in range(n) if M[i, j] != 0):
        lines.append((f"fold_b{i:0{wide}d}_{j:0{wide}d}", bertini_text(M[i, j])))
    names = dict(lines)

    def entry(k: int, j: int) -> str | None:
        name = f"fold_b{k:0{wide}d}_{j:0{wide}d}"
        return name if name in names else None

    def combine(cols: int, terms: list) -> str:
        text = " ".join(f"{'-' if s < 0 else '+'} {a}{'' if m is None else '*' + m}"
                        for s, a, m in terms)  # fmt: skip
        name = f"fold_m{cols:0{len(str(1 << n))}d}"
        lines.append((name, text[2:] if text.startswith("+ ") else text))
        return name

    return lines, _laplace(n, entry, None, combine)


def _with_subfunctions(ps: ParametricSystem, M: sp.Matrix, r: int, maps: dict):
    """`ps` with its last function (the fold condition) written as (-1)^r det M by minors in
    subfunctions (Bertini evaluates it 10 to 20 times faster than its 1,000 expanded terms:
    bench/fold_eval.py), the map coordinates as subfunctions of the line (`maps`); `ps` as it
    is if the subfunctions would name something it does not have."""
    from ..symbolic import bertini_text

    lines, top = _minors_program(M)
    used = set().union(*(e.free_symbols for e in M))
    defs = [(s.name, bertini_text(e)) for s, e in maps.items() if s in used]
    named = {s.name for s in used - set(maps)}
    named |= {x.name for s, e in maps.items() if s in used for x in e.free_symbols}
    if top is None or not named <= {*ps.variables, *ps.parameters}:
        return ps
    texts = (*ps.texts[:-1], ("-" if r % 2 else "") + top)
    return replace(ps, structured=Subfunctions(tuple(defs + lines), texts))


def relaxed_applies(fw: Framework, taut: tuple[str, ...]) -> bool:
    """Whether a taut set can have relaxed folds (module docstring)."""
    from .derive import _active, local_frame

    local, _, _, cons, _ = local_frame(fw)
    links = _active(fw, taut)
    zfl = set(fw.zero_free_length())
    # No taut cable: at zero force a cable is as slack as it is taut, so the zero-energy states
    # of a taut set with cables are not isolated minima.
    return (not fw.loads and not cons and len(links) == len(local)
            and all(x.kind == "spring" and x.name not in zfl for x in links))  # fmt: skip


def relaxed_condition(fw: Framework, taut: tuple[str, ...]) -> sp.Expr:
    """det [d(|r_s|^2) / d local_j]: the links' squared lengths as functions of the local
    coordinates have a singular Jacobian (square where relaxed_applies)."""
    from .derive import _active, local_frame

    local, at, pos, _, _ = local_frame(fw)
    rows = []
    for x in _active(fw, taut):
        r = pos.of(x.a) - pos.of(x.b)
        rows.append([2 * r.subs(at).dot(sp.diff(r, a).subs(at)) for a in local])
    return sp.expand(sp.Matrix(rows).det())


def _curve_equations(fw: Framework, taut: tuple[str, ...], cable: str, F: list, values: dict):
    """The curve's equations before the slots' values: F plus one (fold, switch), or for the
    relaxed folds F with every w = 0 (the moments vanish and are dropped), w = 0 and the
    condition."""
    if cable == RELAXED:
        from .derive import _active

        w0 = {sp.Symbol(f"w_{x.name}"): 0 for x in _active(fw, taut)}
        kept = [f.xreplace(w0) for f in F]
        return [f for f in kept if f != 0] + list(w0) + [relaxed_condition(fw, taut)]
    if cable:
        return [*F, sp.Symbol(f"d_{cable}") - sp.Symbol(f"L0_{cable}")]
    return [*F, fold_condition(fw, taut, values)]


def _derive(fw: Framework, taut: tuple[str, ...], xname: str, yname: str, cable: str) -> dict:
    """The curve system (fold when `cable` is empty, relaxed folds for RELAXED, else that cable's
    switch) as plain data."""
    from ..symbolic import parametric_from_sympy
    from .derive import equilibrium_equations

    names, _, F, _ = equilibrium_equations(fw, taut)
    X = [sp.Symbol(n) for n in names]
    mx, my, t = sp.symbols("map_x map_y tline")
    values = _slot_values(fw, xname, yname, mx, my)
    G = [sp.expand(g.xreplace(values)) for g in _curve_equations(fw, taut, cable, F, values)]
    if len(G) != len(X) + 1:
        raise AssertionError(f"{len(G)} curve equations in {len(X)} unknowns and (x, y)")
    Z = [*X, mx, my]
    line = {mx: sp.Symbol(LINE[0]) + t * sp.Symbol(LINE[2]),
            my: sp.Symbol(LINE[1]) + t * sp.Symbol(LINE[3])}  # fmt: skip
    eqs = [sp.expand(g.xreplace(line)) for g in G]
    labels = tuple(f"g{i + 1}" for i in range(len(eqs)))
    try:
        ps = parametric_from_sympy((*names, t.name), labels, tuple(eqs), LINE)
        trace = parametric_from_sympy(tuple(z.name for z in Z), labels, tuple(G), ())
        if not cable:
            ps = _with_subfunctions(ps, *fold_matrix(fw, taut, values), line)
    except sp.PolynomialError as exc:
        raise ParameterError(
            f"{xname}, {yname}: a map parameter enters a number of framework {fw.name!r} "
            f"other than polynomially ({exc}); a fold map needs polynomial equations"
        ) from None
    return asdict(
        CurveDerived(
            "relaxed" if cable == RELAXED else "switch" if cable else "fold",
            "" if cable == RELAXED else cable,
            names,
            ps.to_json(),
            list(map_scales(fw, xname, yname)),
            trace.to_json(),
        )  # fmt: skip
    )


@cache
def _code_hash() -> str:
    return files_hash((Path(__file__).resolve(),)) + source_hash()


def curve_key(fw: Framework, taut: tuple[str, ...], xname: str, yname: str, cable: str) -> str:
    """Content hash of what a curve system depends on."""
    exprs = {s: repr(e) for s, e in fw.slot_expressions().items()}
    others = {n: v for n, v in fw.values.items() if n not in (xname, yname)}
    blob = json.dumps(
        {"s": structure_key(fw, taut), "map": [xname, yname], "cable": cable, "exprs": exprs,
         "values": others, "units": units(fw), "code": _code_hash()}, sort_keys=True,
    )  # fmt: skip
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


_LOADED: dict[str, CurveSystem] = {}


def curve_system(
    fw: Framework, taut: tuple[str, ...], xname: str, yname: str, cable: str = ""
) -> CurveSystem:
    """The fold system (cable ""), the relaxed folds' (RELAXED) or a cable's switch system of a
    taut set, from memory, the disk cache, or derived with sympy."""
    taut = tuple(sorted(taut))
    key = curve_key(fw, taut, xname, yname, cable)
    if key in _LOADED:
        return _LOADED[key]
    data, _ = cached_derivation(
        f"curve-{key}", CurveDerived, lambda: CurveDerived(**_derive(fw, taut, xname, yname, cable))
    )
    groups = [*variable_groups(framework_system(fw, taut)), ["tline"]]
    out = CurveSystem(
        key, taut, data.kind, data.cable, tuple(data.variables),
        ParametricSystem.from_json(data.system),
        (data.scales[0], data.scales[1]), ParametricSystem.from_json(data.trace).instantiate([]),
        groups,
    )  # fmt: skip
    _LOADED[key] = out
    return out
