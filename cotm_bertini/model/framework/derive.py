"""The equilibrium equations of a framework, derived with sympy in reduced coordinates.

Unknowns: a rotation per body (planar: c, s with c^2 + s^2 = 1; spatial: a unit quaternion), the
translation of each body and the coordinates of each node that no pin places, a force density
w and a length d per spring or taut cable with a free length (w d = k (d - L0), d^2 = |r|^2), and
a multiplier per bar and per pin that closes a loop. Pins that attach a body or node to
something already placed are eliminated by substitution (an open chain pinned to the ground
has its rotations as its only unknowns). The balance equations are the gradient of
E = sum w/2 |r|^2 - sum F . x + sum mu g along every unknown direction: for a planar rotation
the moment -s dE/dc + c dE/ds, for a quaternion the three torques t_i . dE/dq with t_i = q e_i.

How it scales (issue 28: two spatial bodies once took more than 15 minutes): nothing is
simplified globally. The equations are expanded once, in a polynomial ring with exact
coefficients (_polynomials); the Hessian is assembled by the chain rule from each point's
derivatives at the solution (_Jets), which are small, instead of differentiating the energy
twice (sympy's diff(f, a, b) calls factor_terms on the result).
"""

from __future__ import annotations

import sympy as sp

from .spec import Framework, owner, point_names
from .structure import Derived, Layout, layout, rotation_names
from .structure import active_links as _active
from .units import constants

_AXES = "xyz"


def _rotation(dim: int, q: list) -> sp.Matrix:
    if dim == 2:
        c, s = q
        return sp.Matrix([[c, -s], [s, c]])
    w, x, y, z = q
    return sp.Matrix(
        [
            [w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z],
        ]
    )


def quaternion_product(a: list, b: list) -> list:
    """The Hamilton product a b of quaternions (w, x, y, z)."""
    a1, b1, c1, d1 = a
    a2, b2, c2, d2 = b
    return [
        a1 * a2 - b1 * b2 - c1 * c2 - d1 * d2,
        a1 * b2 + b1 * a2 + c1 * d2 - d1 * c2,
        a1 * c2 - b1 * d2 + c1 * a2 + d1 * b2,
        a1 * d2 + b1 * c2 - c1 * b2 + d1 * a2,
    ]


class _Positions:
    """World coordinates of every point as sympy expressions, given each body's rotation."""

    def __init__(self, fw: Framework, lay: Layout, rot: dict[str, sp.Matrix]):
        self.fw, self.lay, self.rot = fw, lay, rot
        self.placed = {e: (pt, src) for e, pt, src in lay.placed_by}
        self.cache: dict[str, sp.Matrix] = {}

    def local(self, point: str) -> sp.Matrix:
        body, name = point.split(".", 1)
        return sp.Matrix([sp.Symbol(f"b_{body}_{name}_{a}") for a in _AXES[: self.fw.dim]])

    def translation(self, body: str) -> sp.Matrix:
        if body in self.placed:
            pt, src = self.placed[body]
            return self.of(src) - self.rot[body] * self.local(pt)
        return sp.Matrix([sp.Symbol(f"t_{body}_{a}") for a in _AXES[: self.fw.dim]])

    def of(self, point: str) -> sp.Matrix:
        """The point's world coordinates."""
        if point not in self.cache:
            ent = owner(point)
            dim = self.fw.dim
            if ent == "ground":
                name = point.split(".", 1)[1]
                out = sp.Matrix([sp.Symbol(f"g_{name}_{a}") for a in _AXES[:dim]])
            elif ent in self.fw.nodes:
                if ent in self.placed:
                    out = self.of(self.placed[ent][1])
                else:
                    out = sp.Matrix([sp.Symbol(f"n_{ent}_{a}") for a in _AXES[:dim]])
            else:
                out = self.translation(ent) + self.rot[ent] * self.local(point)
            self.cache[point] = out
        return self.cache[point]


def _unknowns(fw: Framework, lay: Layout) -> tuple[list[str], list[str]]:
    """The configuration unknowns (rotations, free translations, free nodes) and their kinds."""
    dim, variables, kinds = fw.dim, [], []
    for b in lay.rotations:
        names = rotation_names(dim, b)
        variables += names
        kinds += ["rot"] * len(names)
    for b in lay.translations:
        variables += [f"t_{b}_{a}" for a in _AXES[:dim]]
    for n in lay.free_nodes:
        variables += [f"n_{n}_{a}" for a in _AXES[:dim]]
    return variables, kinds + ["len"] * (len(variables) - len(kinds))


def _pseudo_energy(fw: Framework, lay: Layout, pos: _Positions, taut) -> tuple:
    """E (whose gradient is the force balance), the extra unknowns, their kinds, and the
    equations and descriptions of the springs' laws and of the constraints."""
    zfl = set(fw.zero_free_length())
    E, variables, kinds, equations, about = sp.Integer(0), [], [], [], []
    for x in _active(fw, taut):
        r = pos.of(x.a) - pos.of(x.b)
        k = sp.Symbol(f"k_{x.name}")
        w = k
        if x.name not in zfl:
            w, d, L0 = (sp.Symbol(f"{p}_{x.name}") for p in ("w", "d", "L0"))
            variables += [d.name, w.name]
            kinds += ["len", "k"]
            equations += [d * d - r.dot(r), w * d - k * (d - L0)]
            about += [f"{x.kind} {x.name}: length", f"{x.kind} {x.name}: force law"]
        E += w / 2 * r.dot(r)
    for load in fw.loads:
        f = sp.Matrix([sp.Symbol(f"f_{load.name}_{a}") for a in _AXES[: fw.dim]])
        E -= f.dot(pos.of(load.point))
    for g, name, kind, what in _constraints(fw, lay, pos):
        E += sp.Symbol(name) * g
        variables.append(name)
        kinds.append(kind)
        equations.append(g)
        about.append(what)
    return E, variables, kinds, equations, about


def equilibrium_equations(fw: Framework, taut: tuple[str, ...]) -> tuple:
    """(variables, their unit kinds, equations, descriptions) of the equilibrium system: sympy
    expressions in the variables and the non-constant slots (normalised units), expanded."""
    lay = layout(fw)
    rot_syms = {b: [sp.Symbol(n) for n in rotation_names(fw.dim, b)] for b in lay.rotations}
    pos = _Positions(fw, lay, {b: _rotation(fw.dim, q) for b, q in rot_syms.items()})
    config, kinds = _unknowns(fw, lay)
    E, extra, extra_kinds, laws, law_about = _pseudo_energy(fw, lay, pos, taut)
    ring, polys = _polynomials(fw, config + extra, [E, *laws])
    balance, about = _balance(polys[0], ring, fw.dim, lay, config)
    equations = [_as_expr(f) for f in balance + polys[1:]]
    return config + extra, kinds + extra_kinds, equations, about + law_about


_MARK = "_constant_"  # no name of the file starts with "_"


def _polynomials(fw: Framework, variables: list[str], exprs: list) -> tuple:
    """(ring, exprs as its elements): polynomials in the variables, the slots and a marker
    _MARK, with exact rational coefficients: each constant slot c enters as c (1 + _MARK), c the
    exact value of its double, so the terms without _MARK are the expansion itself and the
    others say which coefficients a constant contributed to (_as_expr).

    sympy's expand of the nested products took most of a derivation (4.5 s of the post and
    platform's equations, against 0.2 s here); exact coefficients also cancel exactly, where
    sympy's floats left terms of 1e-19 that mean 0."""
    mark = sp.Symbol(_MARK)
    const = {sp.Symbol(n): sp.Rational(v) * (1 + mark) for n, v in constants(fw).items() if v}
    const |= {sp.Symbol(n): sp.Integer(0) for n, v in constants(fw).items() if not v}
    exprs = [e.xreplace(const) for e in exprs]
    others = set().union(*(e.free_symbols for e in exprs)) - {sp.Symbol(v) for v in variables}
    others.discard(mark)
    gens = [sp.Symbol(v) for v in variables] + sorted(others, key=lambda x: x.name) + [mark]
    ring = sp.ring(gens, sp.QQ)[0]
    return ring, [ring.from_expr(e) for e in exprs]


def _as_expr(f) -> sp.Expr:
    """A polynomial of _polynomials as a sympy expression, written as sympy's expand of the
    equations with the constants as floats wrote it (the texts, and with them the generic sets'
    cache keys, stay those of that route): a coefficient a constant contributed to as the
    nearest double (1.0*x), the others exact (x, -1/2*x)."""
    gens = f.ring.symbols[:-1]
    value: dict[tuple, object] = {}
    floated: set[tuple] = set()
    for monom, c in f.terms():
        if monom[-1]:
            floated.add(monom[:-1])
        else:
            value[monom[:-1]] = c
    terms = []
    for monom, c in value.items():
        num, den = int(c.numerator), int(c.denominator)
        # int / int rounds correctly.
        coeff = sp.Float(num / den) if monom in floated else sp.Rational(num, den)
        terms.append(sp.Mul(coeff, *(g**e for g, e in zip(gens, monom, strict=True) if e)))
    return sp.Add(*terms)


def derive(fw: Framework, taut: tuple[str, ...], step=None) -> Derived:
    """The equilibrium system of `fw` with the cables in `taut` taut and the others slack.
    `step(what)`, if given, hears which part is being derived (for progress lines)."""
    from ..symbolic import numpy_function, parametric_from_sympy

    step = step or (lambda what: None)
    step("the equilibrium equations")
    lay = layout(fw)
    const = {sp.Symbol(n): sp.Float(v, 17) for n, v in constants(fw).items()}
    rot_syms = {b: [sp.Symbol(n) for n in rotation_names(fw.dim, b)] for b in lay.rotations}
    pos = _Positions(fw, lay, {b: _rotation(fw.dim, q) for b, q in rot_syms.items()})
    config, _ = _unknowns(fw, lay)
    variables, kinds, equations, descriptions = equilibrium_equations(fw, taut)
    free = [descriptions[i] for i, f in enumerate(equations) if f == 0]
    if not _active(fw, taut) and not fw.loads:
        free.insert(0, "any motion (no spring, taut cable or load acts)")
    slots = [n for n in fw.slots()]
    ps = parametric_from_sympy(
        tuple(variables), tuple(f"f{i + 1}" for i in range(len(equations))),
        tuple(equations), tuple(slots),
    )  # fmt: skip
    step("the second-order terms")
    local, hess, cjac, firsts = _second_order(fw, lay, rot_syms, taut, config)
    # Named points, then each body's frame origin under the body's own name.
    points = sorted(point_names(fw)) + list(lay.rotations)
    coords = [c for p in points[: -len(lay.rotations) or None] for c in pos.of(p)]
    coords += [c for b in lay.rotations for c in pos.translation(b)]
    args = {"X": [sp.Symbol(v) for v in variables], "P": [sp.Symbol(n) for n in slots]}
    # constraint_values: the bars' and closing pins' residuals, which a gradient flow on the
    # constraint set (analysis/framework_flow.py) projects back to zero.
    functions = {"positions": coords, "hessian": hess, "constraint_jacobian": cjac,
                 "first_order": firsts,
                 "constraint_values": [g for g, *_ in _constraints(fw, lay, pos)]}  # fmt: skip
    parts = ["from numpy import sqrt, sin, cos\n"]
    for name, exprs in functions.items():
        step(f"the numeric code: {name}")
        parts.append(numpy_function(name, args, [e.xreplace(const) for e in exprs] or [sp.S(0)]))
    source = "\n".join(parts)
    step("the zero-length poses")
    cones = _cone_systems(fw, lay, pos, taut, slots, const)
    return Derived(ps.to_json(), kinds, descriptions, free, points, local,
                   len(cjac) // max(local, 1), source, [x.name for x in _active(fw, taut)],
                   cones)  # fmt: skip


def _cone_systems(fw: Framework, lay: Layout, pos: _Positions, taut, slots, const) -> dict:
    """Per spring with a free length (planar, two bodies, only rotations): the system whose
    roots are the poses where the spring has zero length (V has a cone point there)."""
    from ..symbolic import parametric_from_sympy

    if not (lay.is_torus and len(lay.rotations) == fw.dim == 2):
        return {}
    zfl, out = set(fw.zero_free_length()), {}
    unknowns = [n for b in lay.rotations for n in rotation_names(2, b)]
    for x in _active(fw, taut):
        r = (pos.of(x.a) - pos.of(x.b)).xreplace(const)
        moves = {s.name for s in r.free_symbols} & set(unknowns)
        if x.name in zfl or len(moves) < len(unknowns):
            # A spring on one body collapses only for special parameter values (two equations
            # on a circle): no cone point generically.
            continue
        eqs = [r[0], r[1]] + [
            sp.Symbol(c) ** 2 + sp.Symbol(s) ** 2 - 1
            for c, s in zip(unknowns[::2], unknowns[1::2], strict=True)
        ]
        ps = parametric_from_sympy(tuple(unknowns), ("z1", "z2", "z3", "z4"), tuple(eqs),
                                   tuple(slots))  # fmt: skip
        out[x.name] = ps.to_json()
    return out


def _constraints(fw: Framework, lay: Layout, pos: _Positions) -> list[tuple]:
    """(g, multiplier name, unit kind, description) for every bar and loop-closing pin."""
    out = []
    for x in fw.bars:
        r = pos.of(x.a) - pos.of(x.b)
        g = (r.dot(r) - sp.Symbol(f"len_{x.name}") ** 2) / 2
        out.append((g, f"mu_{x.name}", "k", f"bar {x.name}: length"))
    for k in lay.closing_pins:
        a, b = fw.pins[k]
        gap = pos.of(a) - pos.of(b)
        for i in range(fw.dim):
            out.append((gap[i], f"mu_pin{k + 1}_{_AXES[i]}", "force", f"pin {k + 1}: {_AXES[i]}"))
    return out


def _balance(E, ring, dim: int, lay: Layout, config: list[str]) -> tuple[list, list]:
    """Stationarity of E (a polynomial of `ring`) along every unknown direction, plus the
    unit-rotation equations."""
    gen = dict(zip((g.name for g in ring.symbols), ring.gens, strict=True))
    eqs, about = [], []
    for b in lay.rotations:
        q = [gen[n] for n in rotation_names(dim, b)]
        grad = [E.diff(v) for v in q]
        if dim == 2:
            c, s = q
            eqs += [-s * grad[0] + c * grad[1], c * c + s * s - 1]
            about += [f"body {b}: moment", f"body {b}: unit rotation"]
        else:
            for axis, unit in zip("xyz", ([0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]), strict=True):
                t = quaternion_product(q, unit)
                eqs.append(sum((ti * gi for ti, gi in zip(t, grad, strict=True)), ring.zero))
                about.append(f"body {b}: moment about {axis}")
            eqs.append(sum((v * v for v in q), ring.zero) - 1)
            about.append(f"body {b}: unit quaternion")
    rotations = {n for b in lay.rotations for n in rotation_names(dim, b)}
    for v in config:
        if v not in rotations:
            eqs.append(E.diff(gen[v]))
            about.append(f"{v}: force balance")
    return eqs, about


def _upper(n: int) -> list[tuple[int, int]]:
    """The index pairs (i, j), i <= j, of an n x n symmetric matrix."""
    return [(i, j) for i in range(n) for j in range(i, n)]


def _turn(dim: int) -> tuple[list, dict]:
    """First and second derivatives at 0 of the local rotation R(delta) (planar) or
    R(sqrt(1 - |v|^2), v) (spatial) in its coordinates: constant matrices."""
    if dim == 2:
        u = [sp.Symbol("delta")]
        m = _rotation(2, [sp.cos(u[0]), sp.sin(u[0])])
    else:
        u = list(sp.symbols("vx vy vz"))
        m = _rotation(3, [sp.sqrt(1 - sum(t * t for t in u)), *u])
    at = {x: 0 for x in u}
    first = [m.diff(a) for a in u]
    return [f.xreplace(at) for f in first], {
        (i, j): first[i].diff(u[j]).xreplace(at) for i, j in _upper(len(u))}  # fmt: skip


class _Jets:
    """Each point's position, first and second derivatives in the local coordinates at a
    solution (X as symbols): (x, {i: dx/du_i}, {(i, j): d2x/du_i du_j, i <= j}), zeros left out.

    A rotation is perturbed as R0 R(delta) or R(q0 (sqrt(1 - |v|^2), v)) = R0 R(u) (_local_frame),
    and a point of body b is its source's position plus R_b c (c a constant vector), so its
    derivatives are R0 R'(0) c and R0 R''(0) c: small expressions, where sympy's diff of the
    positions took minutes on two spatial bodies."""

    def __init__(self, fw: Framework, lay: Layout, rot_syms: dict, config: list[str]):
        self.fw = fw
        self.placed = {e: (pt, src) for e, pt, src in lay.placed_by}
        self.rot0 = {b: _rotation(fw.dim, q) for b, q in rot_syms.items()}
        self.turn = _turn(fw.dim)
        # The local coordinates: each body's rotation in turn, then translations and nodes.
        per = len(self.turn[0])
        self.start = {b: per * k for k, b in enumerate(lay.rotations)}
        rotations = {n for b in lay.rotations for n in rotation_names(fw.dim, b)}
        moves = [v for v in config if v not in rotations]
        self.index = {v: per * len(lay.rotations) + k for k, v in enumerate(moves)}
        self.size = per * len(lay.rotations) + len(moves)
        self.pos = _Positions(fw, lay, self.rot0)
        self.cache: dict[str, tuple] = {}

    def _symbols(self, names: list[str]) -> tuple:
        """The jet of unknown coordinates (a free translation or node): their own derivatives."""
        first = {}
        for k, name in enumerate(names):
            first[self.index[name]] = sp.Matrix([int(i == k) for i in range(len(names))])
        return sp.Matrix([sp.Symbol(n) for n in names]), first, {}

    def of(self, point: str) -> tuple:
        """The point's jet."""
        if point not in self.cache:
            self.cache[point] = self._of(point)
        return self.cache[point]

    def _of(self, point: str) -> tuple:
        ent, dim = owner(point), self.fw.dim
        if ent == "ground":
            return self.pos.of(point), {}, {}
        if ent in self.fw.nodes:
            if ent in self.placed:
                return self.of(self.placed[ent][1])
            return self._symbols([f"n_{ent}_{a}" for a in _AXES[:dim]])
        c = self.pos.local(point)
        if ent in self.placed:
            pt, src = self.placed[ent]
            x, first, second = self.of(src)
            c = c - self.pos.local(pt)
        else:
            x, first, second = self._symbols([f"t_{ent}_{a}" for a in _AXES[:dim]])
        first, second = dict(first), dict(second)
        r0, k = self.rot0[ent], self.start[ent]
        for i, d in enumerate(self.turn[0]):
            first[k + i] = first.get(k + i, sp.zeros(dim, 1)) + r0 * (d * c)
        for (i, j), d in self.turn[1].items():
            key = (k + i, k + j)
            second[key] = second.get(key, sp.zeros(dim, 1)) + r0 * (d * c)
        return x + r0 * c, first, second

    def full(self, point: str) -> tuple:
        """The point's jet with every derivative listed (zeros included)."""
        x, first, second = self.of(point)
        zero = sp.zeros(self.fw.dim, 1)
        return (x, [first.get(i, zero) for i in range(self.size)],
                {ij: second.get(ij, zero) for ij in _upper(self.size)})  # fmt: skip

    def link(self, a: str, b: str) -> tuple:
        """The jet of r = a - b (zeros included)."""
        (xa, ja, ha), (xb, jb, hb) = self.full(a), self.full(b)
        return xa - xb, [p - q for p, q in zip(ja, jb, strict=True)], {k: ha[k] - hb[k] for k in ha}


def _stretch(r, first: list, second: dict) -> tuple[list, dict]:
    """The derivatives of |r|^2 / 2: g_i = r . r_i and A_ij = r_i . r_j + r . r_ij."""
    return [r.dot(f) for f in first], {
        (i, j): first[i].dot(first[j]) + r.dot(h) for (i, j), h in second.items()}  # fmt: skip


def _link_hessian(x, jets: _Jets, zfl: set) -> dict:
    """{(i, j): d2V/du_i du_j} of a spring or taut cable, V = k/2 (|r| - L0)^2, by the chain rule:
    k (1 - L0/|r|) A_ij + k L0 g_i g_j / |r|^3 (k A_ij when L0 = 0; _stretch)."""
    r, first, second = jets.link(x.a, x.b)
    k, L0 = sp.Symbol(f"k_{x.name}"), sp.Symbol(f"L0_{x.name}")
    g, A = _stretch(r, first, second)
    if x.name in zfl:
        return {ij: k * a for ij, a in A.items()}
    d = sp.sqrt(r.dot(r))
    return {(i, j): k * (1 - L0 / d) * a + k * L0 * g[i] * g[j] / d**3 for (i, j), a in A.items()}


def _constraint_jets(fw: Framework, lay: Layout, jets: _Jets) -> list[tuple[list, dict]]:
    """([dg/du_i], {(i, j): d2g/du_i du_j}) of each constraint g of _constraints, in its order:
    a bar's (|r|^2 - length^2) / 2 (_stretch), a closing pin's gap per axis."""
    out = [_stretch(*jets.link(x.a, x.b)) for x in fw.bars]
    for k in lay.closing_pins:
        a, b = fw.pins[k]
        _, first, second = jets.link(a, b)
        for i in range(fw.dim):
            out.append(([f[i] for f in first], {ij: h[i] for ij, h in second.items()}))
    return out


def _second_order(fw: Framework, lay: Layout, rot_syms: dict, taut: tuple[str, ...],
                  config: list[str]) -> tuple[int, list, list, list]:  # fmt: skip
    """The Lagrangian's Hessian and the constraints' Jacobian in local coordinates (the
    derivatives of _local_frame's positions at the solution)."""
    jets = _Jets(fw, lay, rot_syms, config)
    n, zfl = jets.size, set(fw.zero_free_length())
    H = {ij: sp.Integer(0) for ij in _upper(n)}
    for x in _active(fw, taut):
        for ij, h in _link_hessian(x, jets, zfl).items():
            H[ij] += h
    cons = _constraint_jets(fw, lay, jets)
    for (_, name, _, _), (_, second) in zip(_constraints(fw, lay, jets.pos), cons, strict=True):
        for ij, h in second.items():
            H[ij] += sp.Symbol(name) * h
    # V has -F . x per load.
    loads = [(sp.Matrix([sp.Symbol(f"f_{ld.name}_{a}") for a in _AXES[: fw.dim]]),
              jets.full(ld.point)) for ld in fw.loads]  # fmt: skip
    for f, (_, _, second) in loads:
        for ij, h in second.items():
            H[ij] -= f.dot(h)
    hess = [H[min(i, j), max(i, j)] for i in range(n) for j in range(n)]
    cjac = [d for first, _ in cons for d in first]
    # First order, for cone points: each active link's vector r and dr/dlocal, and the loads'
    # energy gradient.
    firsts = []
    for x in _active(fw, taut):
        r, first, _ = jets.link(x.a, x.b)
        firsts += list(r) + [first[a][i] for i in range(fw.dim) for a in range(n)]
    firsts += [-sum((f.dot(first[i]) for f, (_, first, _) in loads), sp.Integer(0))
               for i in range(n)]  # fmt: skip
    return n, hess, cjac, firsts


def _load_energy(fw: Framework, pos: _Positions):
    """sum F . x over the loads (V has it with a minus sign)."""
    return sum(
        (sp.Matrix([sp.Symbol(f"f_{ld.name}_{a}") for a in _AXES[: fw.dim]]).dot(pos.of(ld.point))
         for ld in fw.loads), sp.Integer(0))  # fmt: skip


def local_frame(fw: Framework) -> tuple[list, dict, _Positions, list, list]:
    """(local coordinates, their values at the solution, positions as functions of them, the
    constraints (g, multiplier, kind, description), the loads' energy sum F . x): the second-order
    terms of the energy at a solution (X as symbols) are derivatives in the local coordinates."""
    lay = layout(fw)
    rot_syms = {b: [sp.Symbol(n) for n in rotation_names(fw.dim, b)] for b in lay.rotations}
    config, _ = _unknowns(fw, lay)
    local, at, pos = _local_frame(fw, lay, rot_syms, config)
    return local, at, pos, _constraints(fw, lay, pos), _load_energy(fw, pos)


def _local_frame(fw: Framework, lay: Layout, rot_syms: dict, config: list[str]) -> tuple:
    """Local coordinates around a solution, the values that put them at it, and the positions.

    A rotation is perturbed as R0 R(delta) (planar) or q0 (sqrt(1 - |v|^2), v) (spatial), so the
    unit-length constraints are built in; translations and nodes are their own coordinates."""
    dim = fw.dim
    local, rot = [], {}
    for b in lay.rotations:
        q0 = rot_syms[b]
        if dim == 2:
            dl = sp.Symbol(f"delta_{b}")
            local.append(dl)
            rot[b] = _rotation(2, q0) * _rotation(2, [sp.cos(dl), sp.sin(dl)])
        else:
            v = [sp.Symbol(f"v{a}_{b}") for a in "xyz"]
            local += v
            unit = [sp.sqrt(1 - sum(t * t for t in v)), *v]
            rot[b] = _rotation(3, quaternion_product(q0, unit))
    trans = [sp.Symbol(v) for v in config if not any(v in rotation_names(dim, b)
                                                    for b in lay.rotations)]  # fmt: skip
    local += trans
    at = {s: 0 for s in local[: len(local) - len(trans)]}
    return local, at, _Positions(fw, lay, rot)
