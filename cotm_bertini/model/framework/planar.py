"""The equations of a planar framework on a circle or torus (every body pinned in an open chain,
no bar), derived without sympy: the same Derived as derive.derive, in exact polynomial
arithmetic of a few lines, so that a first solve by the real route does not import sympy
(0.2-0.3 s, more than a whole later solve of a small file) nor run its general derivation.

Each point is linear in each body's (c, s), so its derivative along body b's angle is the
derivation D_b = -s_b d/dc_b + c_b d/ds_b of its polynomial (derive._Jets's R0 R'(0) c), and
its second derivative D_b D_b (R0 R''(0) c = -R0 c). The equilibrium system is derive's,
term for term: E = sum w/2 |r|^2 - sum F . x (w = k at zero free length), a body's moment
D_b E, its unit rotation c^2 + s^2 - 1, a link's length d^2 - |r|^2 and law w d - k (d - L0);
constants enter as the exact values of their doubles (derive._polynomials). The generated
functions (positions, hessian, constraint_jacobian, first_order, constraint_values) take the
same arguments and give the same values; the Hessian is written per link from r, r . r_i and
r_i . r_j + r . r_ij (derive._link_hessian). texts are left empty: rendered from the terms.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from ..polynomial import ParametricSystem
from .spec import Framework, owner, point_names
from .structure import Derived, active_links, layout
from .units import constants

Monomial = tuple[int, ...]


class Poly:
    """A polynomial with exact coefficients over a fixed list of generators."""

    __slots__ = ("gens", "terms")

    def __init__(self, gens: tuple[str, ...], terms: dict[Monomial, Fraction] | None = None):
        self.gens, self.terms = gens, {m: c for m, c in (terms or {}).items() if c}

    def _new(self, terms: dict) -> Poly:
        return Poly(self.gens, terms)

    def __add__(self, other: Poly) -> Poly:
        out = dict(self.terms)
        for m, c in other.terms.items():
            out[m] = out.get(m, 0) + c
        return self._new(out)

    def __neg__(self) -> Poly:
        return self._new({m: -c for m, c in self.terms.items()})

    def __sub__(self, other: Poly) -> Poly:
        return self + (-other)

    def __mul__(self, other: Poly) -> Poly:
        out: dict[Monomial, Fraction] = {}
        for m, c in self.terms.items():
            for n, d in other.terms.items():
                key = tuple(a + b for a, b in zip(m, n, strict=True))
                out[key] = out.get(key, 0) + c * d
        return self._new(out)

    def scale(self, c: Fraction) -> Poly:
        """c times the polynomial."""
        return self._new({m: c * v for m, v in self.terms.items()})

    def diff(self, k: int) -> Poly:
        """The derivative along generator k."""
        out = {}
        for m, c in self.terms.items():
            if m[k]:
                out[m[:k] + (m[k] - 1,) + m[k + 1 :]] = c * m[k]
        return self._new(out)

    def uses(self, k: int) -> bool:
        """Whether generator k occurs."""
        return any(m[k] for m in self.terms)


def planar_torus(fw: Framework) -> bool:
    """Whether `derive_planar` covers the framework: planar, only rotations (bodies pinned to
    the ground in a tree, loop-closing pins allowed), no bar."""
    lay = layout(fw)
    return fw.dim == 2 and not (lay.translations or lay.free_nodes or fw.bars)


class _Algebra:
    """Generators (variables, then the slots that are not constant) and the framework's points
    as vectors of polynomials in them."""

    def __init__(self, fw: Framework, variables: list[str]):
        self.fw, self.lay = fw, layout(fw)
        self.const = {n: Fraction(v) for n, v in constants(fw).items()}
        self.slots = [n for n in fw.slots() if n not in self.const]
        self.gens = tuple(variables) + tuple(self.slots)
        self.index = {g: k for k, g in enumerate(self.gens)}
        self.placed = {e: (pt, src) for e, pt, src in self.lay.placed_by}
        self.cache: dict[str, list[Poly]] = {}

    def number(self, c) -> Poly:
        return Poly(self.gens, {(0,) * len(self.gens): Fraction(c)})

    def symbol(self, name: str) -> Poly:
        """A variable or slot (a constant slot as its value)."""
        if name in self.const:
            return self.number(self.const[name])
        m = [0] * len(self.gens)
        m[self.index[name]] = 1
        return Poly(self.gens, {tuple(m): Fraction(1)})

    def local(self, point: str) -> list[Poly]:
        body, name = point.split(".", 1)
        return [self.symbol(f"b_{body}_{name}_{a}") for a in "xy"]

    def rotate(self, body: str, v: list[Poly]) -> list[Poly]:
        c, s = self.symbol(f"c_{body}"), self.symbol(f"s_{body}")
        return [c * v[0] - s * v[1], s * v[0] + c * v[1]]

    def translation(self, body: str) -> list[Poly]:
        """A body's frame origin (each body is placed by a pin: a torus)."""
        pt, src = self.placed[body]
        return [a - b for a, b in zip(self.of(src), self.rotate(body, self.local(pt)),
                                      strict=True)]  # fmt: skip

    def of(self, point: str) -> list[Poly]:
        """The point's world coordinates."""
        if point not in self.cache:
            ent = owner(point)
            if ent == "ground":
                out = [self.symbol(f"g_{point.split('.', 1)[1]}_{a}") for a in "xy"]
            elif ent in self.fw.nodes:
                out = self.of(self.placed[ent][1])
            else:
                at = self.rotate(ent, self.local(point))
                out = [a + b for a, b in zip(self.translation(ent), at, strict=True)]
            self.cache[point] = out
        return self.cache[point]

    def turn(self, body: str, p: Poly) -> Poly:
        """The derivative of p along body's angle: -s dp/dc + c dp/ds."""
        c, s = self.index[f"c_{body}"], self.index[f"s_{body}"]
        return self.symbol(f"c_{body}") * p.diff(s) - self.symbol(f"s_{body}") * p.diff(c)


def _dot(a: list[Poly], b: list[Poly]) -> Poly:
    return a[0] * b[0] + a[1] * b[1]


def _unknowns(fw: Framework, taut: tuple[str, ...]) -> tuple[list[str], list[str]]:
    """derive's unknowns on a torus: (c, s) of each body, then (d, w) of each pulling link with
    a free length; and their unit kinds."""
    zfl = set(fw.zero_free_length())
    variables = [f"{h}_{b}" for b in layout(fw).rotations for h in "cs"]
    kinds = ["rot"] * len(variables)
    for x in active_links(fw, taut):
        if x.name not in zfl:
            variables += [f"d_{x.name}", f"w_{x.name}"]
            kinds += ["len", "k"]
    for k in layout(fw).closing_pins:  # a closing pin's multipliers (derive._constraints)
        variables += [f"mu_pin{k + 1}_{a}" for a in "xy"]
        kinds += ["force", "force"]
    return variables, kinds


def _equations(alg: _Algebra, taut: tuple[str, ...]) -> tuple[list[Poly], list[str]]:
    """derive.equilibrium_equations on a torus: each body's moment and unit rotation, then each
    link's length and force law."""
    fw, half = alg.fw, Fraction(1, 2)
    zfl = set(fw.zero_free_length())
    E, laws, about = alg.number(0), [], []
    for x in active_links(fw, taut):
        r = [a - b for a, b in zip(alg.of(x.a), alg.of(x.b), strict=True)]
        k = alg.symbol(f"k_{x.name}")
        w = k
        if x.name not in zfl:
            w, d, L0 = (alg.symbol(f"{p}_{x.name}") for p in ("w", "d", "L0"))
            laws += [d * d - _dot(r, r), w * d - k * (d - L0)]
            about += [f"{x.kind} {x.name}: length", f"{x.kind} {x.name}: force law"]
        E = E + (w * _dot(r, r)).scale(half)
    for load in fw.loads:
        f = [alg.symbol(f"f_{load.name}_{a}") for a in "xy"]
        E = E - _dot(f, alg.of(load.point))
    for k, gap in _closing_gaps(alg):  # E + mu . gap, and gap = 0
        for a, g in zip("xy", gap, strict=True):
            E = E + alg.symbol(f"mu_pin{k + 1}_{a}") * g
            laws.append(g)
            about.append(f"pin {k + 1}: {a}")
    eqs, names = [], []
    for b in alg.lay.rotations:
        c, s = alg.symbol(f"c_{b}"), alg.symbol(f"s_{b}")
        eqs += [alg.turn(b, E), c * c + s * s - alg.number(1)]
        names += [f"body {b}: moment", f"body {b}: unit rotation"]
    return eqs + laws, names + about


def _closing_gaps(alg: _Algebra) -> list[tuple[int, list[Poly]]]:
    """(k, a - b) of each loop-closing pin k (derive._constraints)."""
    return [(k, [p - q for p, q in zip(alg.of(a), alg.of(b), strict=True)])
            for k in alg.lay.closing_pins for a, b in [alg.fw.pins[k]]]  # fmt: skip


def _constraint_code(alg: _Algebra) -> tuple[tuple, tuple]:
    """(code, outputs) of constraint_jacobian (each closing pin coordinate's derivative along
    each body's angle) and of constraint_values (the pins' gaps)."""
    jac, val = _Code(), _Code()
    gaps = [g for _, gap in _closing_gaps(alg) for g in gap]
    firsts = [jac.name(alg.turn(b, g)) for g in gaps for b in alg.lay.rotations]
    return (jac, firsts), (val, [val.name(g) for g in gaps])


def _parametric(alg: _Algebra, variables: list[str], names: tuple[str, ...],
                polys: list[Poly]) -> ParametricSystem:  # fmt: skip
    """The polynomials as symbolic.parametric_from_sympy writes them: terms in lex order of the
    variables and the slots used, a zero polynomial as one zero term, texts left empty."""
    nv = len(variables)
    slots = alg.gens[nv:]
    used = [k for k in range(len(slots)) if any(p.uses(nv + k) for p in polys)]
    var_exps, par_exps, coeffs = [], [], []
    for p in polys:
        keys = sorted(((m[:nv] + tuple(m[nv + k] for k in used), m) for m in p.terms),
                      reverse=True)  # fmt: skip
        rows = [(key, float(p.terms[m])) for key, m in keys] or [((0,) * (nv + len(used)), 0.0)]
        var_exps.append(np.array([key[:nv] for key, _ in rows], dtype=np.int64))
        par_exps.append(np.array([key[nv:] for key, _ in rows], dtype=np.int64))
        coeffs.append(np.array([c for _, c in rows], dtype=float))
    return ParametricSystem(
        tuple(variables), names, tuple(slots[k] for k in used), tuple(var_exps),
        tuple(par_exps), tuple(coeffs), (),
    )  # fmt: skip


class _Code:
    """Lines of generated source in which every distinct term, sum of leading terms and other
    text is computed once, as a temporary (symbolic.numpy_function's common subexpressions:
    the chain's points share their leading terms, as sympy's cse shares them)."""

    def __init__(self):
        self.lines: list[str] = []
        self.named: dict[str, str] = {}

    def let(self, text: str) -> str:
        """A temporary holding `text` (the one already made for it, if any)."""
        if text not in self.named:
            self.named[text] = f"_t{len(self.named)}"
            self.lines.append(f"    {self.named[text]} = {text}")
        return self.named[text]

    def expr(self, p: Poly) -> str | None:
        """p as an expression of temporaries (its terms in p.text's order), None if zero."""
        out, const = None, 0.0
        for m in sorted(p.terms, reverse=True):
            c = float(p.terms[m])
            if not any(m):
                const = c
                continue
            mono = "*".join(g if e == 1 else f"{g}**{e}" for g, e in zip(p.gens, m, strict=True)
                            if e)  # fmt: skip
            term = self.let(f"{abs(c)!r}*{mono}") if abs(c) != 1.0 else mono
            if out is None:
                out = term if c > 0 else self.let(f"-{term}")
            else:
                out = self.let(f"{out} {'+' if c > 0 else '-'} {term}")
        if out is None:
            return repr(const) if p.terms else None
        return out if not const else f"{out} {'+' if const > 0 else '-'} {abs(const)!r}"

    def name(self, p: Poly) -> str | None:
        """A temporary (or variable) holding p, None if zero."""
        text = self.expr(p)
        return text if text is None or text.isidentifier() else self.let(text)


def _sum_of_products(a: list[str | None], b: list[str | None]) -> str | None:
    """'a0*b0 + a1*b1 ...' over the pairs with no zero (None) factor; None if none is left."""
    terms = [f"{p}*{q}" for p, q in zip(a, b, strict=True) if p is not None and q is not None]
    return " + ".join(terms) or None


def _function(name: str, variables: list[str], slots: list[str], code: _Code,
              outputs: list[str | None]) -> str:  # fmt: skip
    """Source of `def name(X, P)` as symbolic.numpy_function writes it."""
    head = [f"def {name}(X, P):"]
    head += [f"    {v} = X[..., {k}]" for k, v in enumerate(variables)]
    head += [f"    {v} = P[..., {k}]" for k, v in enumerate(slots)]
    out = ", ".join(o or "0" for o in outputs) or "0"
    return "\n".join(head + code.lines + [f"    return [{out}]"]) + "\n"


def _slot_text(alg: _Algebra, name: str) -> str:
    return repr(float(alg.const[name])) if name in alg.const else name


def _link(alg: _Algebra, code: _Code, x) -> tuple[list, list, Poly]:
    """A link's r = a - b as temporaries, with its derivatives along each body's angle."""
    r = [a - b for a, b in zip(alg.of(x.a), alg.of(x.b), strict=True)]
    dr = [[code.name(alg.turn(b, p)) for p in r] for b in alg.lay.rotations]
    return [code.name(p) for p in r], dr, r


def _hessian(alg: _Algebra, taut: tuple[str, ...]) -> tuple[_Code, list[str]]:
    """Code and outputs of the Hessian of V in the body angles: per link k A_ij at zero free
    length, else k (1 - L0/d) A_ij + k L0 g_i g_j / d^3 (derive._link_hessian), less each
    load's F . x_ij."""
    bodies, code = alg.lay.rotations, _Code()
    n, zfl = len(bodies), set(alg.fw.zero_free_length())
    upper = [(i, j) for i in range(n) for j in range(i, n)]
    H: dict[tuple[int, int], list[str]] = {ij: [] for ij in upper}
    for x in active_links(alg.fw, taut):
        rn, dr, r = _link(alg, code, x)
        k = _slot_text(alg, f"k_{x.name}")
        if x.name not in zfl:
            d = code.let(f"sqrt({_sum_of_products(rn, rn) or '0'})")
            L0 = _slot_text(alg, f"L0_{x.name}")
            g = [_sum_of_products(rn, dr[i]) for i in range(n)]
            g = [None if t is None else code.let(t) for t in g]
            w = code.let(f"{k}*(1 - {L0}/{d})")  # the force density
            c = code.let(f"{k}*{L0}/{d}**3")
        for i, j in upper:
            ddr = [code.name(alg.turn(bodies[i], alg.turn(bodies[j], p))) for p in r]
            A = _sum_of_products(dr[i] + rn, dr[j] + ddr)
            if x.name in zfl:
                H[i, j] += [f"{k}*({A})"] if A else []
                continue
            H[i, j] += [f"{w}*({A})"] if A else []
            H[i, j] += [f"{c}*{g[i]}*{g[j]}"] if g[i] and g[j] else []
    for ld in alg.fw.loads:
        f = [alg.symbol(f"f_{ld.name}_{a}") for a in "xy"]
        for i, j in upper:
            work = -_dot(f, [alg.turn(bodies[i], alg.turn(bodies[j], p))
                             for p in alg.of(ld.point)])  # fmt: skip
            H[i, j] += [code.name(work)] if work.terms else []
    for k, gap in _closing_gaps(alg):  # the Lagrangian's: mu . gap_ij
        mu = [alg.symbol(f"mu_pin{k + 1}_{a}") for a in "xy"]
        for i, j in upper:
            work = _dot(mu, [alg.turn(bodies[i], alg.turn(bodies[j], g)) for g in gap])
            H[i, j] += [code.name(work)] if work.terms else []
    names = {ij: code.let(" + ".join(t)) if t else None for ij, t in H.items()}
    return code, [names[min(i, j), max(i, j)] for i in range(n) for j in range(n)]


def _first_order(alg: _Algebra, taut: tuple[str, ...]) -> tuple[_Code, list[str | None]]:
    """Each pulling link's r and dr/dangle (component by component), then the loads' energy
    gradient -sum F . dx/dangle (derive._second_order's first-order terms)."""
    bodies, code, out = alg.lay.rotations, _Code(), []
    for x in active_links(alg.fw, taut):
        rn, dr, _ = _link(alg, code, x)
        out += rn + [dr[i][c] for c in range(2) for i in range(len(bodies))]
    for b in bodies:
        grad = alg.number(0)
        for ld in alg.fw.loads:
            f = [alg.symbol(f"f_{ld.name}_{a}") for a in "xy"]
            grad = grad - _dot(f, [alg.turn(b, p) for p in alg.of(ld.point)])
        out.append(code.expr(grad))
    return code, out


def _cones(alg: _Algebra, taut: tuple[str, ...]) -> dict:
    """derive._cone_systems on a two-body torus: per link with a free length that both bodies
    move, the poses where it has zero length (r = 0 on the two unit circles)."""
    if len(alg.lay.rotations) != 2:
        return {}
    unknowns = [f"{h}_{b}" for b in alg.lay.rotations for h in "cs"]
    zfl, out = set(alg.fw.zero_free_length()), {}
    at = [alg.index[v] for v in unknowns]
    for x in active_links(alg.fw, taut):
        r = [a - b for a, b in zip(alg.of(x.a), alg.of(x.b), strict=True)]
        if x.name in zfl or not all(any(p.uses(k) for p in r) for k in at):
            continue  # on one body a spring collapses only for special values: no cone point
        circles = [alg.symbol(c) * alg.symbol(c) + alg.symbol(s) * alg.symbol(s) - alg.number(1)
                   for c, s in zip(unknowns[::2], unknowns[1::2], strict=True)]  # fmt: skip
        sub = _Algebra(alg.fw, unknowns)
        polys = [_moved(p, alg, sub) for p in r + circles]
        out[x.name] = _parametric(sub, unknowns, ("z1", "z2", "z3", "z4"), polys).to_json()
    return out


def _moved(p: Poly, src: _Algebra, dst: _Algebra) -> Poly:
    """p (with no generator that dst lacks) over dst's generators."""
    where = [dst.index.get(g) for g in src.gens]
    terms = {}
    for m, c in p.terms.items():
        key = [0] * len(dst.gens)
        for k, e in enumerate(m):
            if e:
                key[where[k]] = e
        terms[tuple(key)] = c
    return Poly(dst.gens, terms)


def derive_planar(fw: Framework, taut: tuple[str, ...]) -> Derived:
    """derive.derive for a framework that `planar_torus` covers, without sympy."""
    variables, kinds = _unknowns(fw, taut)
    alg = _Algebra(fw, variables)
    eqs, descriptions = _equations(alg, taut)
    free = [what for p, what in zip(eqs, descriptions, strict=True) if not p.terms]
    if not active_links(fw, taut) and not fw.loads:
        free.insert(0, "any motion (no spring, taut cable or load acts)")
    names = tuple(f"f{i + 1}" for i in range(len(eqs)))
    ps = _parametric(alg, variables, names, eqs)
    lay, slots = alg.lay, list(fw.slots())
    points = sorted(point_names(fw)) + list(lay.rotations)
    coords = [p for q in points[: -len(lay.rotations) or None] for p in alg.of(q)]
    coords += [p for b in lay.rotations for p in alg.translation(b)]
    at = _Code()
    jacobian, values = _constraint_code(alg)
    source = "\n".join([
        "from numpy import sqrt, sin, cos\n",
        _function("positions", variables, slots, at, [at.expr(p) for p in coords]),
        _function("hessian", variables, slots, *_hessian(alg, taut)),
        _function("constraint_jacobian", variables, slots, *jacobian),
        _function("first_order", variables, slots, *_first_order(alg, taut)),
        _function("constraint_values", variables, slots, *values),
    ])  # fmt: skip
    return Derived(ps.to_json(), kinds, descriptions, free, points, len(lay.rotations),
                   2 * len(lay.closing_pins), source, [x.name for x in active_links(fw, taut)],
                   _cones(alg, taut))  # fmt: skip
