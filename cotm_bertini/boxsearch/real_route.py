"""The real route: a framework whose poses form a circle or torus solved on the reals, by the
branch and bound of `boxes` over its body angles, with no complex generic set (one whose nodes
hang by bars, a product of spheres, by boxsearch.spheres; a four-bar's loop by boxsearch.loops;
nodes held by springs and cables alone over their coordinates, boxsearch.free_nodes; bodies in
space on ball joints over quaternion charts, boxsearch.rotations: `covers` and `landscape` say
which).

V = sum k/2 (d - L0)^2 over springs + sum k/2 max(d - L0, 0)^2 over cables - the loads' work, so
grad V = sum w r . dr/dangle + the loads' gradient, w = k (1 - L0/d) for a spring (k at zero free
length) and k max(1 - L0/d, 0) for a cable. Both come from the derivation's generated
`first_order` of the structure with every cable taut, evaluated on interval arrays (the source
model.framework.ballcode runs on balls for the certificates); over a box where a cable may be at
its free length, w is enclosed by the hull of 0 and k (1 - L0/d), and the Hessian by the hull of
the generated Hessians of every taut set the box allows (grad V is Lipschitz and piecewise
smooth, so that hull holds every slope: the Krawczyk test stays valid across a switch).

Each critical point found becomes an endpoint of the polynomial system of the taut set its cables
hold there (c, s of each body, and each link's length d and force density w), classified by
analysis.framework_classify as the complex route's endpoints are.
"""

from __future__ import annotations

import copy
import itertools
from functools import cached_property, lru_cache

import numpy as np

from ..backends.endpoints import Endpoints
from ..model.framework.ballcode import ball_module
from ..model.framework.compiled import FrameworkSystem, framework_system, slot_vector
from ..model.framework.reach import cable_states, sphere_chain
from ..model.framework.spec import Framework, units
from ..model.framework.structure import layout
from ..model.framework.units import normalized_slots
from ..model.intervals import Interval, stack
from . import rotations
from .boxes import (
    distinct,
    initial_boxes,
)
from .cones import ConeParts
from .free_nodes import free_nodes_only, reach
from .links import (
    EITHER,
    SLACK,
    TAUT,
    add_diagonal,
    columns,
    cone_term,
    force_density,
    found_endpoints,
    interval_sum,
    link_terms,
    links,
    matrix,
    meet,
    scaled,
    squared_bounds,
    taut_groups,
)
from .loops import ClosingPin, single_loop
from .rotations import turning_bodies
from .spheres import SphereFramework

ONLY = ("all", "stable")  # what a search looks for: every critical point, or the minima
# Chart units: a turning body's boxes this narrow get the mean-value form too (examples/ball_joint
# and a random body: 0.1 took 7.0 and 18.1 s, 0.3 7.2 and 19.3 s, 0.03 8.2 and 37.2 s, none
# 7 and 80 s).
CENTRED = 0.1


def covers(fw: Framework) -> str:
    """'' where the real route covers the framework's configuration space (a circle or torus
    of planar bodies' angles, a four-bar's loop, a product of spheres of nodes hung on bars,
    nodes held by springs and cables alone, or bodies in space on ball joints), else why
    not."""
    why = free_nodes_only(fw)
    lay = layout(fw)
    if not why or (lay.free_nodes and not (lay.rotations or lay.translations or fw.bars)):
        return why  # nodes alone: covered, or why not
    if fw.dim == 3:
        return turning_bodies(fw) if lay.rotations else sphere_chain(fw)[1]
    if not lay.is_torus:
        return single_loop(fw)
    return ""


@lru_cache(maxsize=8)
def landscape(fw: Framework, only: str = "all") -> TorusFramework | SphereFramework:
    """V over boxes of the framework's configuration space (covers says which), built once a
    process: a worker searching several shares of its boxes (boxsearch.box_shares) rebuilds it
    once, and the solve that dealt them not again. `only`: "all" critical points are searched
    for, or the "stable" ones alone (boxes where V can have no local minimum are dropped:
    boxsearch.stability)."""
    if only not in ONLY:
        raise ValueError(f"only = {only!r}: expected one of {ONLY}")
    land = new_landscape(fw)
    land.only = only
    return land


def new_landscape(fw: Framework) -> TorusFramework | SphereFramework:
    """The landscape of `fw`, built now (uncached: continuation in chart angles builds one for
    each parameter value it visits, continuation/charts.py)."""
    spheres = fw.dim == 3 and not layout(fw).rotations and bool(free_nodes_only(fw))
    return SphereFramework(fw) if spheres else TorusFramework(fw)


def moved_landscape(land, fw: Framework, slots: dict):
    """`land` (a torus or spheres landscape) at other parameter values: a copy with the
    numbers replaced by `slots` (fw's normalised slots; 20x cheaper than a new landscape, for
    continuation's many values), its taut sets' systems kept; None where a free length is 0 in
    one and not the other (the structure differs: build one anew)."""
    for x in fw.links:
        if x.kind != "bar" and (slots[f"L0_{x.name}"] == 0) != (land.slots[f"L0_{x.name}"] == 0):
            return None
    out = copy.copy(land)
    out.fw = fw
    out.renumber(slots)
    out.__dict__.pop("hessian_sets", None)  # which taut sets occur may differ at these values
    return out


class TorusFramework:
    """V of a planar framework pinned in an open chain, over boxes of its body angles; or, for
    one closing a single loop (boxsearch.loops), the system F whose roots are V's critical points
    on the loop's curve of poses, in the same angles; or, for nodes held by springs and cables
    alone (boxsearch.free_nodes), V over boxes of their coordinates within a proved bound; or,
    for bodies in space on ball joints, V over boxes of their quaternion charts
    (boxsearch.rotations)."""

    only = "all"  # which critical points a search of it looks for (`landscape`)

    def __init__(self, fw: Framework):
        why = covers(fw)
        if why:
            raise ValueError(f"the real route does not cover {fw.name}: {why}")
        self.fw = fw
        self.cables = tuple(c.name for c in fw.cables)
        self.full = framework_system(fw, self.cables)
        self.n = self.full.local_size
        self.bodies = layout(fw).rotations
        self.nodes = () if self.bodies else layout(fw).free_nodes  # coordinates, not angles
        self.spatial = fw.dim == 3 and bool(self.bodies)  # chart coordinates: boxsearch.rotations
        self.renumber()
        self.free_springs = [i for i, x in enumerate(self.links) if x.L0 is not None
                             and not x.cable]  # fmt: skip
        # boxsearch.cones decides boxes through springs' cones (a spring's end moves in the
        # plane as the angles turn: two or more of them)
        self.loop = ClosingPin(self.full) if layout(fw).closing_pins else None
        # (cones: of grad V, not F; a spatial body's cones are not enclosed: such boxes are
        # left undecided, said as such)
        self.cone_sets = self.n >= fw.dim and self.loop is None and not self.spatial
        self.member: np.ndarray | None = None  # a family's view: each box's member (rows)
        self.family = None  # a family's view: its TorusFamily (boxsearch.families)

    def renumber(self, slots: dict | None = None) -> None:
        """The numbers taken from normalised `slots` (default: the framework's)."""
        self.slots = normalized_slots(self.fw) if slots is None else slots
        self.P = [float(v) for v in slot_vector(self.slots)]
        self.links = links(self.fw, self.full.active, self.slots)
        if self.nodes:  # the box that holds every equilibrium, at these numbers
            self.centre, self.radius = reach(self.fw, self.slots)

    def structure(self) -> tuple:
        """What a search's arithmetic depends on besides the numbers: frameworks of one
        structure can be searched together (boxsearch.families.TorusFamily)."""
        return (self.full.key, tuple((t, fs.key) for t, fs in self.hessian_sets), self.bodies,
                self.cables, tuple((x.name, x.cable, x.L0 is None) for x in self.links),
                len(self.P))  # fmt: skip

    def sub(self, rows: np.ndarray) -> TorusFramework:
        """The landscape over the boxes `rows` of a batch (a family's view: their members')."""
        return self if self.family is None else self.family.rows(self.member[rows])

    def _P_rows(self, rows: np.ndarray) -> list:
        """The slots of the boxes `rows` (a family's per-box values taken at those rows)."""
        return [v if np.ndim(v) == 0 else v[rows] for v in self.P]

    def _P_numeric(self, count: int) -> np.ndarray:
        """The slots as the numeric code takes them: (p,), or (count, p) per box."""
        if self.family is None:
            return np.asarray(self.P)
        return np.stack([np.broadcast_to(v, (count,)) for v in self.P], axis=1)

    @cached_property
    def hessian_sets(self) -> list[tuple[tuple[str, ...], FrameworkSystem]]:
        """Every taut set a pose may have (always-taut cables in all, never-taut in none)."""
        states = cable_states(self.fw)
        either = [c for c in self.cables if states[c] == "either"]
        always = {c for c in self.cables if states[c] == "taut"}
        out = []
        for combo in itertools.product((True, False), repeat=len(either)):
            on = always | {c for c, t in zip(either, combo, strict=True) if t}
            taut = tuple(c for c in self.cables if c in on)
            out.append((taut, framework_system(self.fw, taut)))
        return out

    def pose(self, fs: FrameworkSystem, trig: list) -> list:
        """The solver variables of `fs` over the boxes from each body's (sin, cos) (`trig`; the
        rest 0: the generated first_order and hessian of a torus read only the rotations), or
        each free node's coordinates."""
        index = {v: j for j, v in enumerate(fs.ps.variables)}
        X: list = [0.0] * len(fs.ps.variables)
        if self.spatial:
            for b, q in zip(self.bodies, trig, strict=True):
                for a, value in zip("wxyz", q, strict=True):
                    X[index[f"q{a}_{b}"]] = value
            return X
        if self.nodes:
            for v, coords in zip(self.nodes, trig, strict=True):
                for a, value in zip("xyz", coords, strict=False):
                    X[index[f"n_{v}_{a}"]] = value
            return X
        for b, (s, c) in zip(self.bodies, trig, strict=True):
            X[index[f"s_{b}"]], X[index[f"c_{b}"]] = s, c
        return X

    def trig(self, box: Interval) -> list:
        """(sin, cos) of each body's angle over the boxes (a free node's coordinates; a spatial
        body's quaternion)."""
        if self.spatial:
            return [tuple(rotations.quaternion(f)) for f in self.frames(box)]
        if self.nodes:
            d = self.fw.dim
            return [tuple(box[:, i * d + a] for a in range(d)) for i in range(len(self.nodes))]
        return [box[:, j].sin_cos() for j in range(len(self.bodies))]

    def domain(self, start: int) -> tuple[np.ndarray, np.ndarray]:
        """The boxes a search starts from: the torus grid, or for free nodes the cube about
        the centre that holds every equilibrium, at most start^2 boxes a node."""
        if self.spatial:  # the four chart cubes, halved once for a single body
            return rotations.domain(len(self.bodies), 2 if len(self.bodies) == 1 else 1)
        if not self.nodes:
            return initial_boxes(self.n, start)
        per = max(1, int(round((start ** (2 * len(self.nodes))) ** (1 / self.n))))
        lo = np.tile(self.centre - self.radius, len(self.nodes))
        edges = lo[None, :] + 2 * self.radius * np.arange(per + 1)[:, None] / per
        idx = np.indices((per,) * self.n).reshape(self.n, -1).T
        cols = np.arange(self.n)
        return edges[idx, cols], edges[idx + 1, cols]

    def parts(self, box: Interval) -> tuple[list, list, list, list, list]:
        """Per link its squared length and r . dr/dangle (n), the loads' gradient, and per link
        r (dim) and dr/dangle (dim x n, row by row)."""
        dim, m = self.fw.dim, self.n
        first = ball_module(self.full).first_order(self.pose(self.full, self.trig(box)), self.P)
        per, dds, slopes, rs, drs = dim + dim * m, [], [], [], []
        for i in range(len(self.links)):
            r, dr = first[i * per : i * per + dim], first[i * per + dim : (i + 1) * per]
            dds.append(interval_sum(Interval.of(c) * c for c in r))
            slopes.append(
                [interval_sum(r[c] * dr[c * m + j] for c in range(dim)) for j in range(m)]
            )
            rs.append(r)
            drs.append(dr)
        return dds, slopes, first[len(self.links) * per :], rs, drs

    def enclose(self, box: Interval) -> tuple[Interval, Interval, dict]:
        """(squared lengths of the free-length springs, grad V, the cables' states) per box; a
        loop's F in place of grad V (boxsearch.loops)."""
        lengths, grad, states = self.enclose_v(box)
        if self.spatial:
            grad = self._centred(box, grad, states)
        if self.loop is not None:
            X = self.pose(self.full, self.trig(box))
            grad = self.loop.enclose(ball_module(self.full), X, self.P, grad)
        return lengths, grad, states

    def enclose_v(self, box: Interval) -> tuple[Interval, Interval, dict]:
        """(squared lengths of the free-length springs, grad V, the cables' states) per box.
        A spring's term is also enclosed through its cone (cone_term): finite where its
        length may be 0, and the two enclosures met where both hold."""
        dds, slopes, loads, rs, drs = self.parts(box)
        shape = box.lo.shape[:1]
        grad = [Interval.of(np.broadcast_to(0.0, shape)) + g for g in loads]
        states = {}
        for x, dd, a, r, dr in zip(self.links, dds, slopes, rs, drs, strict=True):
            w, state = force_density(x, dd)
            if x.cable:
                states[x.name] = state
            terms = [w * aj for aj in a]
            if x.L0 is not None and not x.cable and (dd.lo < squared_bounds(x.L0)[1]).any():
                terms = [meet(t, c) for t, c in zip(terms, cone_term(x, dd, a, r, dr),
                                                     strict=True)]  # fmt: skip
            grad = [g + t for g, t in zip(grad, terms, strict=True)]
        lengths = stack([dds[i] for i in self.free_springs], axis=1) if self.free_springs else (
            Interval(np.zeros(shape + (0,))))  # fmt: skip
        return lengths, stack(grad, axis=1), states

    def _centred(self, box: Interval, grad_v: Interval, states: dict) -> Interval:
        """grad V in chart coordinates (from `grad_v`, in the generated code's coordinates) met
        with its mean-value form g(mid) + H(box) (box - mid) on the boxes no wider than CENTRED
        where it may vanish: the generated code's natural enclosure of a turning body's gradient
        is some 15 w wide on a box of width w, about five times the mean-value form's."""
        grad = self.to_chart(self.frames(box), grad_v)[0]
        rows = np.flatnonzero(grad.contains_zero().all(axis=1)
                              & ((box.hi - box.lo).max(axis=1) <= CENTRED))  # fmt: skip
        if not len(rows):
            return grad
        sub, mid, land = box[rows], box.mid[rows], self.sub(rows)  # (a family's: its members')
        _, at, _ = land.enclose_v(Interval(mid))
        at = land.to_chart(land.frames(Interval(mid)), at)[0]
        hess_v = land.hessian_v(sub, {c: v[rows] for c, v in states.items()})
        H = land.to_chart(land.frames(sub), grad_v[rows], hess_v)[1]  # grad_v: known, not again
        dev = sub - mid
        mv = stack([interval_sum([at[:, i]] + [H[:, i, j] * dev[:, j] for j in range(self.n)])
                    for i in range(self.n)], axis=1)  # fmt: skip
        lo, hi = grad.lo.copy(), grad.hi.copy()
        lo[rows], hi[rows] = np.maximum(lo[rows], mv.lo), np.minimum(hi[rows], mv.hi)
        return Interval(lo, hi)

    def cone_parts(self, box: Interval, spring: np.ndarray) -> ConeParts:
        """What boxsearch.cones needs of each box about its spring `spring` (an index into the
        free-length springs, per box) at zero length: V is A's potential minus k L0 d there.
        The Hessians are summed link by link (each link's r is a sum of its bodies' turned
        vectors, so d2r/dangle_j2 is dr/dangle_j a quarter turn on and the rest 0: read off
        the generated first derivatives at the box turned by pi/2, as the loads' are)."""
        dim, m, count = self.fw.dim, self.n, box.lo.shape[0]
        dds, slopes, loads, rs, drs = self.parts(box)
        if self.nodes:  # straight coordinates: r and the loads' work have no second derivative
            loads2, drs2 = [0.0] * m, [[0.0] * len(d) for d in drs]
        else:
            _, _, loads2, _, drs2 = self.parts(box + np.pi / 2)
        which = np.asarray(self.free_springs)[spring]
        A = matrix([loads], count)[:, 0]
        H = add_diagonal(Interval(np.zeros((count, m, m))), matrix([loads2], count)[:, 0])
        r_s, J_s, J2_s, kl0 = None, None, None, np.zeros(count)
        for i, (x, dd) in enumerate(zip(self.links, dds, strict=True)):
            r = matrix([rs[i]], count)[:, 0]
            J = matrix([drs[i][c * m : (c + 1) * m] for c in range(dim)], count)
            J2 = matrix([drs2[i][c * m : (c + 1) * m] for c in range(dim)], count)
            M = add_diagonal((J[:, :, :, None] * J[:, :, None, :]).isum(axis=1),
                             (r[:, :, None] * J2).isum(axis=1))  # fmt: skip
            a = matrix([slopes[i]], count)[:, 0]
            grad, hess = link_terms(x, dd, a, r, J, M)
            here = which == i
            if here.any():  # the spring at its cone: k/2 d^2 in A, -k L0 d apart
                k = np.broadcast_to(np.asarray(x.k, dtype=float), (count,))
                grad = Interval.where(here[:, None], scaled(a, k), grad)
                hess = Interval.where(here[:, None, None], scaled(M, k), hess)
                kl0 = np.where(here, k * np.asarray(x.L0, dtype=float), kl0)
                r_s = r if r_s is None else Interval.where(here[:, None], r, r_s)
                J_s = J if J_s is None else Interval.where(here[:, None, None], J, J_s)
                J2_s = J2 if J2_s is None else Interval.where(here[:, None, None], J2, J2_s)
            A, H = A + grad, H + hess
        lo, hi, idx = np.zeros((count, dim, m, m)), np.zeros((count, dim, m, m)), np.arange(m)
        lo[:, :, idx, idx], hi[:, :, idx, idx] = J2_s.lo, J2_s.hi
        return ConeParts(A, J_s, r_s, kl0, H, Interval(lo, hi))

    def hessian(self, box: Interval, states: dict) -> Interval:
        """The hull of the Hessians of every taut set each box allows (B, n, n); a loop's
        Jacobian of F (boxsearch.loops)."""
        hess = self.hessian_v(box, states)
        if self.spatial:
            return self.to_chart(self.frames(box), self.enclose_v(box)[1], hess)[1]
        if self.loop is None:
            return hess
        X = self.pose(self.full, self.trig(box))
        return self.loop.jacobian(ball_module(self.full), X, self.P, self.enclose_v(box)[1], hess)

    def hessian_v(self, box: Interval, states: dict) -> Interval:
        """The hull of V's Hessians of every taut set each box allows (B, n, n)."""
        m, count = self.n, box.lo.shape[0]
        trig = self.trig(box)
        lo, hi = np.full((count, m, m), np.inf), np.full((count, m, m), -np.inf)
        for taut, fs in self.hessian_sets:
            allowed = np.ones(count, dtype=bool)
            for c in self.cables:
                s = states.get(c, np.full(count, TAUT))
                allowed &= (s == EITHER) | (s == (TAUT if c in taut else SLACK))
            rows = np.flatnonzero(allowed)
            if not len(rows):
                continue
            part = len(rows) < count
            sub = [tuple(v[rows] for v in group) for group in trig] if part else trig
            h = ball_module(fs).hessian(self.pose(fs, sub), self._P_rows(rows) if part else self.P)
            h = stack([Interval.of(np.broadcast_to(0.0, (len(rows),))) + v for v in h], axis=1)
            lo[rows] = np.minimum(lo[rows], h.lo.reshape(-1, m, m))
            hi[rows] = np.maximum(hi[rows], h.hi.reshape(-1, m, m))
        return Interval(lo, hi)

    def derivatives(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """grad V and its Hessian at points (R, n angles) in double precision, from the
        generated numpy code (Newton's steps; each point's Hessian that of its taut set); a
        loop's F and its Jacobian."""
        grad, hess = self.derivatives_v(x)
        if self.spatial:
            return self.to_chart(self.frames(x), grad, hess)
        if self.loop is None:
            return grad, hess
        X = self._numeric_pose(self.full, x)
        return self.loop.numeric(X, self._P_numeric(len(x)), grad, hess)

    def derivatives_v(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """grad V and its Hessian at points (R, n angles) (`derivatives` of an open chain); NaN
        where a spring has zero length (a free node on its anchor), said by no warning."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return self._derivatives_v(x)

    def _derivatives_v(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        P = self._P_numeric(len(x))
        first = self.full.numeric.first_order(self._numeric_pose(self.full, x), P)
        dim, m, per = self.fw.dim, self.n, self.fw.dim + self.fw.dim * self.n
        grad = np.zeros((len(x), m))
        grad += columns(first[len(self.links) * per :], len(x)) if m else 0.0
        taut = np.ones((len(x), len(self.cables)), dtype=bool)
        for i, link in enumerate(self.links):
            block = columns(first[i * per : (i + 1) * per], len(x))
            r, dr = block[:, :dim], block[:, dim:]
            d = np.sqrt((r * r).sum(axis=1))
            a = np.einsum("nc,ncj->nj", r, dr.reshape(len(x), dim, m))
            w = np.full(len(x), link.k) if link.L0 is None else link.k * (1 - link.L0 / d)
            if link.cable and link.L0 is not None:
                on = d > link.L0
                taut[:, self.cables.index(link.name)] = on
                w = np.where(on, w, 0.0)
            grad += w[:, None] * a
        hess = np.zeros((len(x), m, m))
        for want in np.unique(taut, axis=0):  # each taut set present (any: values may move)
            on = tuple(c for c, t in zip(self.cables, want, strict=True) if t)
            fs = framework_system(self.fw, on)
            rows = np.flatnonzero((taut == want).all(axis=1))
            if len(rows):
                h = fs.numeric.hessian(self._numeric_pose(fs, x[rows]), P if P.ndim == 1 else
                                       P[rows])  # fmt: skip
                hess[rows] = columns(h, len(rows)).reshape(-1, m, m)
        return grad, hess

    def _multipliers(self, angles: np.ndarray) -> np.ndarray:
        """The closing pin's multipliers at poses on the loop (R, 2), V as its taut set there
        has it (the pin's Jacobian is the same in every taut set's system: the full one's)."""
        X = self._numeric_pose(self.full, angles)
        P = self._P_numeric(len(angles))
        grad, _ = self.derivatives_v(angles)
        return self.loop.pin_multipliers(X, P, grad)

    def _numeric_pose(self, fs: FrameworkSystem, x: np.ndarray) -> np.ndarray:
        index = {v: j for j, v in enumerate(fs.ps.variables)}
        X = np.zeros((len(x), len(fs.ps.variables)))
        if self.spatial:
            for b, q in zip(self.bodies, self.trig(x), strict=True):
                for a, value in zip("wxyz", q, strict=True):
                    X[:, index[f"q{a}_{b}"]] = value
            return X
        for i, v in enumerate(self.nodes):
            for a in range(self.fw.dim):
                X[:, index[f"n_{v}_{'xyz'[a]}"]] = x[:, i * self.fw.dim + a]
        for j, b in enumerate(self.bodies):
            X[:, index[f"s_{b}"]], X[:, index[f"c_{b}"]] = np.sin(x[:, j]), np.cos(x[:, j])
        return X

    def fresh(self, points: np.ndarray, known: np.ndarray) -> np.ndarray:
        """The points that are neither at a `known` one nor at an earlier one (fresh_points;
        free nodes' coordinates do not wrap)."""
        if self.spatial:
            return _fresh_rotations(self.quaternions(points), self.quaternions(known), points)
        return fresh_points(points, known, wrap=not self.nodes)

    def rechart(self, x: np.ndarray) -> np.ndarray:
        """Points (R, n) with each spatial body in the chart where it is most regular (others
        as they are)."""
        if not self.spatial:
            return x
        q = self.quaternions(x)
        return np.hstack([rotations.chart_points(q[:, j]) for j in range(len(self.bodies))])

    def frames(self, x) -> list[dict]:
        """Each spatial body's chart frame (boxsearch.rotations.frame) over boxes or at points."""
        return [rotations.frame(x[:, 3 * j : 3 * j + 3]) for j in range(len(self.bodies))]

    def quaternions(self, x: np.ndarray) -> np.ndarray:
        """Each spatial body's unit quaternion at points (R, bodies, 4)."""
        qs = [rotations.quaternion(f) for f in self.frames(x.reshape(-1, self.n))]
        return np.stack([np.stack(q, axis=1) for q in qs], axis=1).reshape(len(x), len(qs), 4)

    def to_chart(self, frames: list, grad, hess=None) -> tuple:
        """(grad V, its Hessian or None) from the generated code's local coordinates to the
        bodies' chart coordinates (boxsearch.rotations): an Interval (B, n) and (B, n, n) over
        boxes, or arrays at points."""
        Ds = [rotations.jacobian(f) for f in frames]
        g = [grad[:, i] for i in range(self.n)]
        out = [c for j, (f, D) in enumerate(zip(frames, Ds, strict=True))
               for c in rotations.gradient(D, g[3 * j : 3 * j + 3])]  # fmt: skip
        if hess is not None:
            hess = _chart_hessian(frames, Ds, out, hess)
        return (stack(out, axis=1) if isinstance(grad, Interval) else np.stack(out, axis=1)), hess

    def chart_points(self, cols: dict) -> np.ndarray:
        """The chart points (R, n body angles, or free nodes' coordinates in normalised units)
        of a solutions table's rows (`cols`: columns; a spatial body's chart coordinates)."""
        if self.spatial:
            return np.hstack([rotations.chart_points(np.stack(
                [np.asarray(cols[f"{b}.q{a}"], dtype=float) for a in "wxyz"], axis=1))
                for b in self.bodies])  # fmt: skip
        if self.nodes:
            scale = units(self.fw)[0]
            return np.stack(
                [
                    np.asarray(cols[f"{v}.{a}"], dtype=float) / scale
                    for v in self.nodes
                    for a in "xyz"[: self.fw.dim]
                ],
                axis=1,
            )
        angles = [np.asarray(cols[f"{b}.angle_deg"], dtype=float) for b in self.bodies]
        return np.radians(np.stack(angles, axis=1)).reshape(-1, self.n)

    def endpoints(self, roots: np.ndarray) -> dict[tuple[str, ...], Endpoints]:
        """The critical points (R, n angles) as endpoints of their taut sets' systems (a
        spatial body's rotation found in two charts' overlap once)."""
        if self.spatial:
            roots = self.fresh(roots, np.zeros((0, self.n)))
        d = self._lengths(roots)
        out = {}
        for names, rows in taut_groups(self.cables, self.links, d, len(roots)):
            out[names] = self._endpoints(framework_system(self.fw, names), roots[rows], d, rows)
        return out

    def endpoints_of(self, taut: tuple[str, ...], angles: np.ndarray) -> Endpoints:
        """Poses (R, n angles) as endpoints of taut set `taut`'s system whatever the cables'
        lengths there (a start for Newton on one smooth piece of V, followed past a switch)."""
        fs = framework_system(self.fw, taut)
        return self._endpoints(fs, angles, self._lengths(angles), np.arange(len(angles)))

    def cable_lengths(self, x: np.ndarray) -> dict[str, np.ndarray]:
        """Each link's length at points (R, n angles), normalised units as `links`' L0."""
        return self._lengths(x)

    def _lengths(self, angles: np.ndarray) -> dict[str, np.ndarray]:
        dds = self.parts(Interval(angles))[0]
        return {x.name: np.sqrt(np.maximum(dd.mid, 0.0)) for x, dd in zip(self.links, dds,
                                                                          strict=True)}  # fmt: skip

    def _endpoints(self, fs: FrameworkSystem, angles: np.ndarray, d: dict, rows) -> Endpoints:
        links = {x.name: x for x in self.links}
        values = np.zeros((len(rows), len(fs.ps.variables)), dtype=complex)
        q = self.quaternions(angles) if self.spatial else None
        for k, v in enumerate(fs.ps.variables):
            head, _, rest = v.partition("_")
            if q is not None and head in ("qw", "qx", "qy", "qz"):
                values[:, k] = q[:, self.bodies.index(rest), "wxyz".index(head[1])]
            elif head == "n":
                node, _, axis = rest.rpartition("_")
                values[:, k] = angles[:, self.nodes.index(node) * self.fw.dim + "xyz".index(axis)]
            elif head in ("c", "s"):
                a = angles[:, self.bodies.index(rest)]
                values[:, k] = np.cos(a) if head == "c" else np.sin(a)
            elif head == "d":
                values[:, k] = d[rest][rows]
            elif head == "w":
                x = links[rest]
                values[:, k] = x.k * (1.0 - x.L0 / d[rest][rows])
            elif head == "mu" and self.loop is not None:
                values[:, k] = self._multipliers(angles)[:, self.loop.multipliers.index(v)]
            else:
                raise ValueError(f"the real route has no value for unknown {v}")
        return found_endpoints(fs.ps.variables, values, rows)


def _chart_hessian(frames: list, Ds: list, g: list, hess) -> Interval | np.ndarray:
    """Hess_u V = D Hess_v V D^T + sum_a g_a W_a (boxsearch.rotations; D block diagonal, a block
    per body), from Hess_v V (`hess`: (B, n, n) Interval or (R, n, n) array) and the chart
    gradient's columns `g` (D grad_v V)."""
    n, boxes = len(g), isinstance(hess, Interval)
    add = interval_sum if boxes else sum
    rows: list[list] = [[None] * n for _ in range(n)]
    for j, Dj in enumerate(Ds):
        for k, Dk in enumerate(Ds):
            # (D_j H_jk) first, then times D_k^T: 54 products a block in place of 81
            left = [[add(Dj[p][a] * hess[:, 3 * j + a, 3 * k + b] for a in range(3))
                     for b in range(3)] for p in range(3)]  # fmt: skip
            for p in range(3):
                for r in range(3):
                    rows[3 * j + p][3 * k + r] = add(left[p][b] * Dk[r][b] for b in range(3))
        bend = rotations.curvature(frames[j], g[3 * j : 3 * j + 3])
        for p in range(3):
            for r in range(3):
                rows[3 * j + p][3 * j + r] = rows[3 * j + p][3 * j + r] + bend[p][r]
    if not boxes:
        return np.stack([np.stack(row, axis=1) for row in rows], axis=1)
    return stack([stack(row, axis=1) for row in rows], axis=1)


def _fresh_rotations(q: np.ndarray, known: np.ndarray, points: np.ndarray) -> np.ndarray:
    """The `points` whose bodies' quaternions `q` (R, bodies, 4) are neither a `known` pose's
    (up to each body's sign) nor an earlier point's."""
    seen = list(known)
    kept = []
    for x, p in zip(points, q, strict=True):
        if not any(rotations.same(p, s) for s in seen):
            kept.append(x)
            seen.append(p)
    return np.array(kept).reshape(-1, points.shape[1] if points.ndim == 2 else 0)


def fresh_points(points: np.ndarray, known: np.ndarray, apart: float = 1e-8,
                 wrap: bool = True) -> np.ndarray:  # fmt: skip
    """The points (R, n angles) that are neither within `apart` (rad, on the torus; without
    `wrap`, plain coordinates) of a `known` one nor of an earlier one of their own."""
    n = known.shape[1] if known.ndim == 2 else points.shape[1]
    both = np.vstack([known.reshape(-1, n), points.reshape(-1, n)])
    keep = distinct(both, apart, wrap)
    return both[keep[keep >= len(known)]]
