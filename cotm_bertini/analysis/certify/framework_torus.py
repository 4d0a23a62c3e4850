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
        self.code = self._compile()
        self.kL0 = [None if L0 is None else k * L0 for _, k, L0, _ in self.links]
        self.free = [
            i for i, (_, _, L0, spring) in enumerate(self.links) if L0 is not None and spring
        ]
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

    def _compile(self) -> dict[bool, tuple[Callable, Callable]]:
        """first_order's entries f -> d^2 of each active link (`squares(f)`), and f and the
        links' weights w -> grad V = the loads' gradient + sum_i w_i r_i . dr_i/dangle
        (`gradient(f, w)`), as straight-line code: an entry that is a constant (the same number
        at every pose) enters as that ball, and a product with the constant 0 not at all. Two
        versions (key: tight): with ball products, and with the products and squares as the
        hulls of their ends' (`product_range`, `square_range`: tighter over a wide box, slower)."""
        code, X = self.pose(tuple(self.cables), tuple(arb(0.1 + j, 0.5) for j in range(self.m)))
        first = code.first_order(X, self.P)
        names = {"ZERO": ZERO, "square": square_range, "product": product_range}
        for e, v in enumerate(first):
            if type(v) is not arb:
                names[f"C{e}"] = arb(v)
        out = {}
        for tight, square, product in ((False, "{0} * {0}", "{0} * ({1})"),
                                       (True, "square({0})", "product({0}, {1})")):  # fmt: skip
            space = dict(names)
            source = self._source(first, square, product)
            exec(compile(source, "<framework_torus parts>", "exec"), space)
            out[tight] = (space["squares"], space["gradient"])
        return out

    def _source(self, first: list, square: str, product: str) -> str:
        """The source of `squares(f)` and `gradient(f, w)` (see _compile), squares and
        products written by the format strings `square` ({0}) and `product` ({0}, {1})."""
        entry = [f"f[{e}]" if type(v) is arb else f"C{e}" for e, v in enumerate(first)]
        dim, m, per = self.dim, self.m, self.dim + self.dim * self.m
        nonzero = [type(v) is arb or bool(v) for v in first]
        dds, grad = [], [[e] for e in entry[len(self.links) * per :]]
        for i in range(len(self.links)):
            r = [entry[i * per + c] for c in range(dim)]
            dds.append(" + ".join(square.format(x) for x in r))
            for j in range(m):
                at = [i * per + dim + c * m + j for c in range(dim)]
                terms = [product.format(r[c], entry[e]) for c, e in enumerate(at) if nonzero[e]]
                if terms:
                    grad[j].append(product.format(f"w[{i}]", " + ".join(terms)))
        sums = ", ".join(" + ".join(g) for g in grad)
        return (f"def squares(f):\n    return [{', '.join(dds)}]\n\n"
                f"def gradient(f, w):\n    return [{sums}]\n")  # fmt: skip

    def _box(self, balls) -> dict:
        """What this box's enclosures share: first_order's entries over it, whether its
        products are hulls, d^2 of each active link (kept until the next box)."""
        if self.memo.get("balls") is not balls:  # the same tuple (kept alive here: unique id)
            code, X = self.pose(tuple(self.cables), balls)
            tight = max(float(a.rad()) for a in balls) > TIGHT_RADIUS
            first = code.first_order(X, self.P)
            self.memo = {"balls": balls, "first": first, "tight": tight,
                         "dds": self.code[tight][0](first)}  # fmt: skip
        return self.memo

    def state(self, name: str, L0, dd) -> str:
        """'taut', 'slack' or 'either' for a link over the box (a spring is always taut)."""
        if name not in self.cables or L0 is None or dd > L0 * L0:
            return "taut"
        return "slack" if dd < L0 * L0 else "either"

    def weights(self, dds: list) -> tuple[list, dict]:
        """w of each active link over the box (0 for a slack cable), and each cable's state."""
        ws, states = [], {}
        for (name, k, L0, _), kL0, dd in zip(self.links, self.kL0, dds, strict=True):
            if L0 is None or name not in self.cables:  # k, or k - k L0 / d = k (1 - L0 / d)
                ws.append(k if L0 is None else k - kL0 / dd.sqrt())
                continue
            states[name] = self.state(name, L0, dd)
            if states[name] == "slack":
                ws.append(ZERO)
                continue
            w = k * (1 - L0 / dd.sqrt())
            if states[name] == "either":  # k max(1 - L0/d, 0), which lies in [0, k]
                w = arb(0).union(w) if w.is_finite() else k * arb(0.5, 0.5)
            ws.append(w)
        return ws, states

    def enclose(self, balls, hessian: bool = True) -> tuple:
        """(grad V over the box, its Hessian's enclosure or None)."""
        memo = self._box(balls)
        if "grad" not in memo:  # else this box's gradient, asked for again with the Hessian
            w, states = self.weights(memo["dds"])
            memo["grad"] = (self.code[memo["tight"]][1](memo["first"], w), states)
        grad, states = memo["grad"]
        return grad, self.hessian(balls, states) if hessian else None

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
        dds = self._box(balls)["dds"]
        return [dds[i] for i in self.free]
