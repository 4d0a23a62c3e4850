"""V of a framework whose poses form a circle or torus, enclosed over a box of body angles in
ball arithmetic (python-flint's arb) for the certificate's completeness search (certify/torus).

grad V = sum w r . dr/dangle plus the loads' gradient, w = k (1 - L0 / |r|) for a spring (k at
zero free length) and k max(1 - L0 / |r|, 0) for a cable, from the generated `first_order` of
the system with every cable taut (model.framework.ballcode: the derivation's own source run on
balls); the Hessian from the generated `hessian` of each taut set a box allows (a cable taut,
slack, or either where its length may be L0: then the hull of both, a valid slope matrix since
grad V is Lipschitz and piecewise smooth).

The entries of `first_order` that are constants (the 0 of a point that does not move with an
angle, say) are found once, and the products r . dr/dangle written once as straight-line code
(`TorusV._compile`) without the products by 0; each taut set's module and the places of its
angles' sines and cosines are looked up once, not per box.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable

from flint import arb

from ...model.framework.ballcode import ball_module
from ...model.framework.compiled import framework_system
from ...model.framework.spec import Framework
from ...model.framework.structure import layout
from .torus import Landscape

ZERO = arb(0)
TIGHT_RADIUS = 0.1  # radians: over a box of a wider half-width products are their ends' hulls


def product_range(x, y):
    """A ball holding x * y over the balls x and y: the hull of the products of their ends (a
    ball product, m1 m2 +- (|m1| r2 + |m2| r1 + r1 r2), is wider by up to 2 r1 r2)."""
    a, b, c, d = x.lower(), x.upper(), y.lower(), y.upper()
    return (a * c).union(a * d).union(b * c).union(b * d)


def _times(x, y):
    return x * y


def square_range(x):
    """A ball holding x^2 over the ball x: the hull of its ends' squares, and of 0 if x holds
    it (x * x of (2 +- 1) is -1 .. 9; this is 1 .. 9)."""
    a, b = x.lower(), x.upper()
    out = (a * a).union(b * b)
    return out.union(ZERO) if x.contains(0) else out


def torus_landscape(fw: Framework, P: list) -> Landscape:
    """V of a framework whose poses form a torus (only body rotations), in the body angles."""
    v = TorusV(fw, P)
    return Landscape(v.m, v.enclose, v.lengths, 1.0)


def _ball(v):
    """A generated function's entry as a ball (its constant entries are plain numbers)."""
    return v if type(v) is arb else arb(v)


class TorusV:
    """grad V, its Hessian and the springs' squared lengths over a box of body angles (see the
    module docstring); `balls`: a tuple of arb balls, one per body angle."""

    def __init__(self, fw: Framework, P: list):
        self.fw, self.P, self.dim = fw, P, fw.dim
        self.cables = [c.name for c in fw.cables]
        self.bodies = layout(fw).rotations
        self.systems: dict[tuple, tuple] = {}  # taut set -> (module, angle slots, size)
        full = framework_system(fw, tuple(self.cables))
        self.m = full.local_size
        slot = dict(zip(fw.slots(), P, strict=True))
        zfl = set(fw.zero_free_length())
        springs = {x.name for x in fw.springs}
        self.links = [(x, slot[f"k_{x}"], None if x in zfl else slot[f"L0_{x}"], x in springs)
                      for x in full.active]  # fmt: skip
        self.split, self.split_tight = self._compile()
        self.memo: dict = {}  # the last box's parts: the search asks for them twice

    def _system(self, taut: tuple) -> tuple:
        """(ball module, (sine slot, cosine slot) per body, variable count) of a taut set."""
        if taut not in self.systems:
            fs = framework_system(self.fw, taut)
            index = {v: j for j, v in enumerate(fs.ps.variables)}
            slots = [(index[f"s_{b}"], index[f"c_{b}"]) for b in self.bodies]
            self.systems[taut] = (ball_module(fs), slots, len(fs.ps.variables))
        return self.systems[taut]

    def pose(self, taut: tuple, balls) -> tuple:
        """(the taut set's ball module, its variables at the box: sines and cosines, 0 else)."""
        code, slots, size = self._system(taut)
        X = [ZERO] * size
        for (s, c), a in zip(slots, balls, strict=True):
            X[s], X[c] = a.sin_cos()
        return code, X

    def _compile(self) -> tuple[Callable, Callable]:
        """first_order's entries -> (d^2 of each active link, r . dr/dangle_j of each, the
        loads' gradient) as straight-line code: an entry that is a constant (the same number at
        every pose) enters as that ball, and a product with the constant 0 not at all. Two
        versions: with ball products, and with the products and squares as the hulls of their
        ends' (`product_range`, `square_range`: tighter over a wide box, slower)."""
        code, X = self.pose(tuple(self.cables), tuple(arb(0.1 + j, 0.5) for j in range(self.m)))
        first = code.first_order(X, self.P)
        names = {"ZERO": ZERO, "square": square_range, "product": product_range}
        for e, v in enumerate(first):
            if type(v) is not arb:
                names[f"C{e}"] = arb(v)
        out = []
        for square, product in (("{0} * {0}", "{0} * {1}"), ("square({0})", "product({0}, {1})")):
            source = self._source(first, square, product)
            space = dict(names)
            exec(compile(source, "<framework_torus parts>", "exec"), space)
            out.append(space["parts"])
        return out[0], out[1]

    def _source(self, first: list, square: str, product: str) -> str:
        """The source of `parts(f)` (see _compile), squares and products written by the
        format strings `square` ({0}) and `product` ({0}, {1})."""
        entry = [f"f[{e}]" if type(v) is arb else f"C{e}" for e, v in enumerate(first)]
        dim, m, per = self.dim, self.m, self.dim + self.dim * self.m
        dds, dots = [], []
        for i in range(len(self.links)):
            r = [entry[i * per + c] for c in range(dim)]
            dds.append(" + ".join(square.format(x) for x in r))
            base = i * per + dim
            row = []
            for j in range(m):
                at = [base + c * m + j for c in range(dim)]
                terms = [product.format(r[c], entry[e]) for c, e in enumerate(at)
                         if type(first[e]) is arb or first[e]]  # fmt: skip
                row.append(" + ".join(terms) or "ZERO")
            dots.append(f"[{', '.join(row)}]")
        loads = entry[len(self.links) * per :]
        return (f"def parts(f):\n    return [{', '.join(dds)}], [{', '.join(dots)}], "
                f"[{', '.join(loads)}]\n")  # fmt: skip

    def parts(self, balls) -> tuple:
        """(per active link (name, k, L0 or None, is a spring, d^2, r . dr/dangle), the loads'
        gradient) over the box."""
        if self.memo.get("balls") is balls:  # the same tuple (kept alive here: its id is unique)
            return self.memo["parts"]
        code, X = self.pose(tuple(self.cables), balls)
        tight = max(float(a.rad()) for a in balls) > TIGHT_RADIUS
        dds, dots, loads = (self.split_tight if tight else self.split)(code.first_order(X, self.P))
        out = [(*link, dd, a) for link, dd, a in zip(self.links, dds, dots, strict=True)]
        self.memo = {"balls": balls, "parts": (out, loads), "tight": tight}
        return self.memo["parts"]

    def state(self, name: str, L0, dd) -> str:
        """'taut', 'slack' or 'either' for a link over the box (a spring is always taut)."""
        if name not in self.cables or L0 is None or dd > L0 * L0:
            return "taut"
        return "slack" if dd < L0 * L0 else "either"

    def enclose(self, balls, hessian: bool = True) -> tuple:
        """(grad V over the box, its Hessian's enclosure or None)."""
        links, loads = self.parts(balls)
        if "grad" in self.memo:  # this box's gradient, asked for again with the Hessian
            grad, states = self.memo["grad"]
            return grad, self.hessian(balls, states) if hessian else None
        grad, states = list(loads), {}
        times = product_range if self.memo["tight"] else _times
        for name, k, L0, _, dd, a in links:
            states[name] = self.state(name, L0, dd)
            if states[name] == "slack":
                continue
            w = k if L0 is None else k * (1 - L0 / dd.sqrt())
            if states[name] == "either":  # k max(1 - L0/d, 0), which lies in [0, k]
                w = arb(0).union(w) if w.is_finite() else k * arb(0.5, 0.5)
            grad = [g + times(w, aj) for g, aj in zip(grad, a, strict=True)]
        self.memo["grad"] = (grad, states)
        if not hessian:
            return grad, None
        return grad, self.hessian(balls, states)

    def hessian(self, balls, states: dict) -> list:
        """The hull of the Hessians of every taut set the box allows."""
        options = [(True,) if states.get(c, "taut") == "taut" else (False,)
                   if states[c] == "slack" else (True, False) for c in self.cables]  # fmt: skip
        hull = None
        for combo in itertools.product(*options):
            taut = tuple(c for c, on in zip(self.cables, combo, strict=True) if on)
            code, X = self.pose(taut, balls)
            h = [_ball(v) for v in code.hessian(X, self.P)]
            hull = h if hull is None else [x.union(y) for x, y in zip(hull, h, strict=True)]
        m = self.m
        return [hull[i * m : (i + 1) * m] for i in range(m)]

    def lengths(self, balls) -> list:
        """d^2 of every spring with a free length (V has a cone point where one is 0)."""
        return [dd for _, _, L0, spring, dd, _ in self.parts(balls)[0]
                if L0 is not None and spring]  # fmt: skip
