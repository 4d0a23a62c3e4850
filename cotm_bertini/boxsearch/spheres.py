"""The real route on spheres: a spatial framework whose free nodes each hang by a bar from a
ground point or from a node hung before it (model.framework.reach.sphere_chain), so that its
poses form a product of 2-spheres, searched by boxsearch.boxes over charts of each sphere.

Charts. A node's direction u from the point it hangs from is given by two angles (a, b) in one of
two charts: A, u = (sin a cos b, sin a sin b, cos a), over a band of a that leaves out the poles
on the z axis; and B, u = (cos a, sin a cos b, sin a sin b), the same with the axes turned (poles
on the x axis), over two squares around +z (a = b = pi/2) and -z (a = pi/2, b = -pi/2) that hold
the caps the band leaves out, with a margin: a direction within angle t of +z has
|a - pi/2| = asin|u_x| <= t and |b - pi/2| = atan(|u_y| / u_z) <= t. Every box lies in one chart;
chart B's a is stored shifted by SHIFT so that a box says its chart. Both charts are regular
(sin a >= sin BAND), so a critical point of V in chart angles is one on the spheres; one in an
overlap of charts is found in both and kept once. The charts' edges are no simple fractions of
pi (a symmetric pose on the edge of a box is never proved alone in it).

V in chart angles: node positions X = parent + length u; grad V = J^T g, g the gradient in node
coordinates from the generated first_order of the structure with every cable taut (each cable's
force density enclosed as the torus route does, links.force_density). A node's two components
are length times u_a . G and u_b . G, G the pull on its bar end; since u_a and u_b are
orthogonal to u they are also enclosed with each link's r taken without the node's own swing
(a diagonal to the ground is then a constant vector), and the two enclosures are met. At a
critical point G, and that swing-free pull F, lie along the bar: `contract` shrinks each box to
the chart angles of the directions +-F/|F|. The Hessian is
J^T H J + sum_i g_i d2X_i, H the generated Hessian with each cable's stiffness the interval [0, k]
where the cable may be taut or slack over the box: H is linear in k, so that encloses the
Hessian of every taut set the box allows (the hull the torus route forms set by set).
"""

from __future__ import annotations

import math
from functools import cached_property

import numpy as np

from ..backends.endpoints import Endpoints
from ..model.framework.ballcode import ball_module
from ..model.framework.compiled import FrameworkSystem, framework_system, slot_vector
from ..model.framework.reach import sphere_chain
from ..model.framework.spec import Framework, owner, units
from ..model.framework.units import normalized_slots
from ..model.intervals import Interval, stack
from .boxes import EDGE, FREE, NONE, OFFSET
from .links import (
    EITHER,
    SLACK,
    TAUT,
    columns,
    force_density,
    found_endpoints,
    interval_sum,
    links,
    meet,
    taut_groups,
)

SHIFT = 8.0  # chart B's first angle is stored as a + SHIFT
BAND = 0.6107  # chart A covers a in [BAND + TILT, pi - BAND + TILT]
TILT = 0.0071  # moves the band's middle (pi/2) off the halving lines
CAP = BAND + 0.0731  # chart B's squares: half side (more than BAND + TILT + SKEW: overlap)
SKEW = 0.0173  # moves the squares' middles (+-z) off the halving lines
SECOND = (((0, 0), "uaa"), ((0, 1), "uab"), ((1, 0), "uab"), ((1, 1), "ubb"))
APART = 1e-8  # normalised length units: two critical points closer than this are one


def pieces() -> list[tuple[tuple[float, float], tuple[float, float]]]:
    """The chart boxes ((a lo, a hi), (b lo, b hi)) that cover one sphere: the band of chart A
    and chart B's two squares around the poles +z and -z."""
    band = ((BAND + TILT, math.pi - BAND + TILT), (OFFSET, OFFSET + 2 * math.pi))
    a = (SHIFT + math.pi / 2 - CAP + SKEW, SHIFT + math.pi / 2 + CAP + SKEW)
    squares = [(a, (s * math.pi / 2 - CAP + SKEW, s * math.pi / 2 + CAP + SKEW)) for s in (1, -1)]
    return [band, *squares]


def _trig(a):
    return a.sin_cos() if isinstance(a, Interval) else (np.sin(a), np.cos(a))


def _pick(mask: np.ndarray, a, b):
    if isinstance(a, Interval) or isinstance(b, Interval):
        return Interval.where(mask, a, b)
    return np.where(mask, a, b)


def directions(a, b, second: bool = True) -> dict[str, list]:
    """u and its derivatives in the chart angles (u_a, u_b, and with `second` u_aa, u_ab,
    u_bb), each three components (Intervals or arrays), for angles (a, b) of either chart
    (module docstring)."""
    lo = a.lo if isinstance(a, Interval) else a
    turned = lo >= SHIFT / 2
    (sa, ca), (sb, cb) = _trig(a - SHIFT * turned), _trig(b)
    zero = 0.0 * cb
    out = {
        "u": [sa * cb, sa * sb, ca],
        "ua": [ca * cb, ca * sb, -sa],
        "ub": [-(sa * sb), sa * cb, zero],
    }
    if second:
        out["uaa"] = [-c for c in out["u"]]
        out["uab"] = [-(ca * sb), ca * cb, zero]
        out["ubb"] = [-c for c in out["u"][:2]] + [zero]
    # Chart B is chart A with the axes turned: its (x, y, z) is A's (z, x, y).
    if not turned.any():
        return out
    return {k: [_pick(turned, v[p], v[c]) for c, p in enumerate((2, 0, 1))]
            for k, v in out.items()}  # fmt: skip


class SphereFramework:
    """V of a spatial framework whose nodes hang from the ground by bars, over chart boxes."""

    only = "all"  # which critical points a search of it looks for (real_route.landscape)

    def __init__(self, fw: Framework):
        chain, why = sphere_chain(fw)
        if why:
            raise ValueError(f"the real route does not cover {fw.name}: {why}")
        self.fw = fw
        self.cables = tuple(c.name for c in fw.cables)
        self.full = framework_system(fw, self.cables)
        self.chain = chain
        self.nodes = tuple(n for n, _, _ in chain)
        self.parent = {n: top for n, top, _ in chain}
        self.renumber()
        self.n = 2 * len(self.nodes)
        self.bodies = ()  # no body angles (routes.real.along_continua)
        names = list(self.full.ps.variables)
        self.coords = [names.index(f"n_{v}_{c}") for v in self.nodes for c in "xyz"]
        # The generated code's local coordinates are the nodes' coordinates, in this order.
        if self.coords != list(range(self.full.local_size)):
            raise ValueError(f"{fw.name}: node coordinates are not the local coordinates")
        self.stencil = self._stencil()
        # Each link's ends that are nodes: (node index, +1 for end a / -1 for end b).
        self.ends = [[(j, int(np.sign(st[0, 3 * j]))) for j in range(len(self.nodes))
                      if st[0, 3 * j]] for st in self.stencil]  # fmt: skip

    def renumber(self, slots: dict | None = None) -> None:
        """The numbers taken from normalised `slots` (default: the framework's): the
        generated code's parameters, links, bar lengths."""
        self.slots = normalized_slots(self.fw) if slots is None else slots
        self.__dict__.pop("_constants", None)  # numbers read off the generated code
        self.P = [float(v) for v in slot_vector(self.slots)]
        self.links = links(self.fw, self.full.active, self.slots)
        self.length = {n: self.slots[f"len_{bar}"] for n, _, bar in self.chain}

    @cached_property
    def hessian_sets(self) -> list[tuple[tuple[str, ...], FrameworkSystem]]:
        """The systems whose generated code the search evaluates (every cable taut)."""
        return [(self.cables, self.full)]

    def domain(self, start: int) -> tuple[np.ndarray, np.ndarray]:
        """The product of each node's chart boxes: 3^nodes boxes (lo, hi), each (count, n)
        (`start`, the torus grid's divisions, has no part here: the charts are the start)."""
        parts = pieces()
        idx = np.indices((len(parts),) * len(self.nodes)).reshape(len(self.nodes), -1).T
        lo = np.array([[v for i in row for v in (parts[i][0][0], parts[i][1][0])] for row in idx])
        hi = np.array([[v for i in row for v in (parts[i][0][1], parts[i][1][1])] for row in idx])
        return lo, hi

    def free(self, box: Interval, states: dict, grad: Interval) -> tuple[np.ndarray, dict]:
        """(code (B, n), slack) over boxes. A node with no load on what hangs from it feels the
        rest only through the cables joining the two; where each is slack over a box, grad V
        is 0 along the node's two angles whatever they are (code FREE: V is flat there). Where
        some may be taut, a critical point in the box has them all slack, or a taut one
        balanced by the others (sum w_c v_c = 0, w_c >= 0, v_c the pull of cable c in the
        node's angles); where one direction has every such v_c on its positive side the
        second cannot be: with none certainly taut every critical point has the node's cables
        slack, and the box is FREE with them taken as slack (`slack`: name -> (B,) bool);
        with one certainly taut no critical point is in the box (code NONE: near the edge of
        a free region the pulls are weak, and the enclosure of grad V alone would exclude such
        boxes only when they are very small). Else EDGE where none is certainly taut. The test
        runs where the node's components of `grad` (the box's enclosure) both hold 0."""
        count = box.lo.shape[0]
        code, slack = np.zeros((count, self.n), dtype=np.int8), {}
        floating = self.floating()
        marks, todo = {}, {}
        for i, cables in floating.items():
            certain, loose = np.ones(count, dtype=bool), np.ones(count, dtype=bool)
            for c in cables:
                certain &= states[c] == SLACK
                loose &= states[c] != TAUT
            near = grad[:, 2 * i].contains_zero() & grad[:, 2 * i + 1].contains_zero()
            marks[i], todo[i] = (certain, loose), np.flatnonzero(~certain & near)
        rows = np.unique(np.concatenate([np.zeros(0, dtype=np.int64), *todo.values()]))
        if len(rows):
            last = getattr(self, "_last", (None,))
            if last[0] is box.lo:  # the box `enclose` just saw: its positions and directions
                positions = [_rows_of(p, rows) for p in last[1]]
                dirs = [{k: [_rows_of(c, rows) for c in v] for k, v in d.items()} for d in last[2]]
            else:
                positions, dirs = self.kinematics(box[rows], second=False)
            first = ball_module(self.full).first_order(self.pose(positions, len(rows)), self.P)
        for i, cables in floating.items():
            (certain, loose), at = marks[i], todo[i]
            none = np.zeros(count, dtype=bool)
            if len(at):
                loc = np.searchsorted(rows, at)
                one_side = at[self._unbalanced(first, dirs, loc, i, cables, states, at)]
                none[one_side[~loose[one_side]]] = True
                certain[one_side[loose[one_side]]] = True
            code[:, 2 * i : 2 * i + 2] = np.where(
                none, NONE, np.where(certain, FREE, np.where(loose, EDGE, 0)))[:, None]  # fmt: skip
            if certain.any():
                for c in cables:
                    slack[c] = slack.get(c, np.zeros(count, dtype=bool)) | certain
        return code, slack

    def _unbalanced(self, first, dirs, loc, i: int, cables, states: dict, at) -> np.ndarray:
        """Per box `at` (rows `loc` of `first` and `dirs`, the generated first_order and the
        directions there): whether the pulls in node i's angles of its cables that may be
        taut lie strictly on one side of a line (no taut balance: `free`). A crossing cable's
        pull is the gradient of |r|^2 / 2 there: +-r (its end below node i) along u_a, u_b."""
        per, v = 3 + 3 * len(self.coords), self.nodes[i]
        below = set(self.subtree(v))
        free_of = self.place(dirs, skip=i)
        pulls = []
        for k, x in enumerate(self.links):
            on = states[x.name][at] != SLACK if x.name in cables else None
            if on is None or not on.any():
                continue
            sign = next(sg for j, sg in self.ends[k] if j in below)
            r = [_rows_of(first[k * per + c], loc) for c in range(3)]
            q = [_rows_of(c, loc) for c in self.link_vector(free_of, k)]  # r less the swing
            u = {key: [_rows_of(dirs[i][key][c], loc) for c in range(3)] for key in ("ua", "ub")}
            pull = [meet(_dot(u[key], r), _dot(u[key], q)) * (sign * self.length[v])
                    for key in ("ua", "ub")]  # fmt: skip
            pulls.append((on, pull))
        if not pulls:
            return np.ones(len(loc), dtype=bool)
        e = sum(np.where(on[:, None], np.stack([p[0].mid, p[1].mid], 1), 0.0) for on, p in pulls)
        ok = np.ones(len(loc), dtype=bool)
        for on, p in pulls:
            side = p[0] * e[:, 0] + p[1] * e[:, 1]
            ok &= ~on | (side.lo > 0)
        return ok

    def floating(self) -> dict[int, list[str]]:
        """Per node that can float: the cables whose slackness frees it (module `free`)."""
        touches = [set(np.flatnonzero(np.abs(s).sum(axis=0)) // 3) for s in self.stencil]
        loaded = {ld.point for ld in self.fw.loads
                  if any(self.slots[f"f_{ld.name}_{c}"] for c in "xyz")}  # fmt: skip
        out = {}
        for i, v in enumerate(self.nodes):
            hang = set(self.subtree(v))
            if loaded & {self.nodes[j] for j in hang}:
                continue
            crossing = [x for x, t in zip(self.links, touches, strict=True)
                        if t & hang and (len(t) == 1 or not t <= hang)]  # fmt: skip
            if all(x.cable and x.L0 is not None for x in crossing):
                out[i] = [x.name for x in crossing]
        return out

    def subtree(self, node: str) -> list[int]:
        """Indices of the nodes that hang from `node` (itself included)."""
        out = []
        for i, v in enumerate(self.nodes):
            while v != node and v in self.parent:
                v = self.parent[v]
            if v == node:
                out.append(i)
        return out

    def swing_free_pull(self, dirs: list, i: int, ws: list) -> list:
        """The pull of `pull` on node i, each link's r taken at the positions without node i's
        own swing: u_a and u_b are orthogonal to u, so u_a . r is the same with or without it,
        and r is enclosed without its widest term (a diagonal to the ground: a constant)."""
        below = set(self.subtree(self.nodes[i]))
        X = self.place(dirs, skip=i)
        F = list(self._constants[1][3 * i : 3 * i + 3])
        for k, w in enumerate(ws):
            side = sum(s for j, s in self.ends[k] if j in below)
            if not side:  # no end below node i, or both: no net pull on what hangs there
                continue
            F = [f + (w * rc) * side for f, rc in zip(F, self.link_vector(X, k), strict=True)]
        return F

    def link_vector(self, X: list, k: int) -> list:
        """Link k's r (three components) at node coordinates X, from its ends' signs and its
        ground end (`_constants`): X may leave a node's swing out (`place`), the generated
        code's r cannot."""
        ends, offset = self.ends[k], self._constants[0][k]
        return [_total([offset[c]] + [s * X[3 * j + c] for j, s in ends]) for c in range(3)]

    @cached_property
    def _constants(self) -> tuple[list, list]:
        """(each link's r at every node at the origin: its ground end's part, so that r = that
        + the signed positions of its node ends; the loads' part of `pull`, three per node,
        summed down the chain) from the generated code, enclosed (dropped by `renumber`)."""
        count, per = 1, 3 + 3 * len(self.coords)
        zero = [Interval(np.zeros(count))] * len(self.coords)
        first = ball_module(self.full).first_order(self.pose(zero, count), self.P)
        offset = [[Interval(np.zeros(1)) + first[k * per + c] for c in range(3)]
                  for k in range(len(self.links))]  # fmt: skip
        tail = [Interval(np.zeros(1)) + v for v in first[len(self.links) * per :]]
        return offset, [c for v in self.nodes for c in self.pull(tail, v)]

    def pull(self, g: list, node: str) -> list:
        """The force on `node`'s bar end: the gradient (in node coordinates) of every node
        hanging from it, summed (three components)."""
        return [_total([g[3 * j + c] for j in self.subtree(node)]) for c in range(3)]

    def kinematics(self, x, second: bool = True) -> tuple[list, list]:
        """(positions: three per node, directions per node, with their second derivatives if
        `second`) at boxes (Interval) or points."""
        dirs = [directions(x[:, 2 * i], x[:, 2 * i + 1], second) for i in range(len(self.nodes))]
        return self.place(dirs), dirs

    def place(self, dirs: list, skip: int | None = None) -> list:
        """Node coordinates (three per node) from each node's direction; with `skip`, that
        node's own swing (length times u) left out of its position and of every node's below."""
        pos: dict[str, list] = {}
        for i, v in enumerate(self.nodes):
            top = self.parent[v]
            if owner(top) == "ground":
                g = top.split(".", 1)[1]
                base = [self.slots[f"g_{g}_{c}"] for c in "xyz"]
            else:
                base = pos[top]
            pos[v] = (
                list(base)
                if i == skip
                else [b + self.length[v] * u for b, u in zip(base, dirs[i]["u"], strict=True)]
            )
        return [c for v in self.nodes for c in pos[v]]

    def pose(self, positions: list, count: int) -> list:
        """The generated code's arguments: the node coordinates, the rest 0 (read by nothing)."""
        X: list = [0.0] * len(self.full.ps.variables)
        for j, p in zip(self.coords, positions, strict=True):
            X[j] = p
        return X

    def node_gradient(self, positions: list, count: int, slack: dict | None = None):
        """(g in node coordinates, squared lengths per link, cable states, force densities per
        link) over boxes; the cables of `slack` (name: (B,) bool) taken slack where it says so
        (see `free`)."""
        first = ball_module(self.full).first_order(self.pose(positions, count), self.P)
        m, per = len(positions), 3 + 3 * len(positions)
        g = [Interval(np.zeros(count)) + v for v in first[len(self.links) * per :]]
        dds, states, ws = [], {}, []
        for i, x in enumerate(self.links):
            r, dr = first[i * per : i * per + 3], first[i * per + 3 : (i + 1) * per]
            dd = interval_sum(Interval.of(c) * c for c in r)
            w, state = force_density(x, dd)
            if slack and x.name in slack:
                off = slack[x.name]
                w = Interval(np.where(off, 0.0, w.lo), np.where(off, 0.0, w.hi))
                state = np.where(off, SLACK, state)
            if x.cable:
                states[x.name] = state
            wr = [w * c for c in r]  # w r once: dr/dX of a node's coordinate is +-1 or 0
            for j in range(m):
                terms = [wr[c] * dr[c * m + j] for c in range(3) if not _zero(dr[c * m + j])]
                if terms:
                    g[j] = g[j] + interval_sum(terms)
            dds.append(dd)
            ws.append(w)
        return g, dds, states, ws

    def enclose(self, box: Interval, slack: dict | None = None) -> tuple:
        """(squared lengths of the free-length springs, grad V in chart angles, cable states),
        the cables of `slack` taken slack where it says so."""
        count = box.lo.shape[0]
        positions, dirs = self.kinematics(box, second=False)
        self._last = (box.lo, positions, dirs)  # for `free`, called next on the same box
        g, dds, states, ws = self.node_gradient(positions, count, slack)
        grad, pulls = [], []
        for i, v in enumerate(self.nodes):
            G, F = self.pull(g, v), self.swing_free_pull(dirs, i, ws)
            grad += [meet(_dot(dirs[i][key], G), _dot(dirs[i][key], F)) * self.length[v]
                     for key in ("ua", "ub")]  # fmt: skip
            pulls.append(F)
        self._pulls = (box.lo, pulls)  # for `contract`, called next on the same box
        springs = [dd for x, dd in zip(self.links, dds, strict=True) if x.L0 is not None
                   and not x.cable]  # fmt: skip
        lengths = stack(springs, axis=1) if springs else Interval(np.zeros((count, 0)))
        return lengths, stack(grad, axis=1), states

    def contract(self, box: Interval) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi) of each box shrunk to where a critical point can be (lo > hi somewhere:
        none), from the pulls `enclose` just found over it. At a critical point each node's
        pull G (on its bar end, from everything hanging there) is along the bar, and so is the
        swing-free pull F = G - c u (`swing_free_pull`): u = +-F / |F|, and where F's
        enclosure misses 0 that confines the node's two chart angles (_directions_along)."""
        lo, hi = box.lo.copy(), box.hi.copy()
        at, pulls = getattr(self, "_pulls", (None, None))
        if at is not box.lo:
            raise ValueError("contract wants the boxes that enclose saw last")
        for i, G in enumerate(pulls):
            a, b = slice(2 * i, 2 * i + 1), slice(2 * i + 1, 2 * i + 2)
            (a_lo, a_hi), (b_lo, b_hi) = _directions_along(
                G, lo[:, a][:, 0], hi[:, a][:, 0], lo[:, b][:, 0], hi[:, b][:, 0]
            )
            lo[:, 2 * i], hi[:, 2 * i] = a_lo, a_hi
            lo[:, 2 * i + 1], hi[:, 2 * i + 1] = b_lo, b_hi
        return lo, hi

    def jacobian(self, dirs: list, count: int) -> list:
        """dX/d(angles) as rows (3 per node) of columns (2 per node): Intervals or arrays."""
        zero = np.zeros(count)
        J = [[zero] * self.n for _ in range(3 * len(self.nodes))]
        for i, v in enumerate(self.nodes):
            for j in self.subtree(v):
                for c in range(3):
                    J[3 * j + c][2 * i] = self.length[v] * dirs[i]["ua"][c]
                    J[3 * j + c][2 * i + 1] = self.length[v] * dirs[i]["ub"][c]
        return J

    def hessian(self, box: Interval, states: dict) -> Interval:
        """A slope matrix of grad V over each box (B, n, n) (module docstring)."""
        count = box.lo.shape[0]
        positions, dirs = self.kinematics(box)
        g = self.node_gradient(positions, count, _slack_of(states))[0]
        H = self.node_hessian(positions, count, states)
        J = stack([stack(row, axis=1) for row in self.jacobian(dirs, count)], axis=1)
        JT = Interval(np.swapaxes(J.lo, 1, 2), np.swapaxes(J.hi, 1, 2))
        HJ = (H[:, :, :, None] * J[:, None, :, :]).isum(axis=2)
        out = (JT[:, :, :, None] * HJ[:, None, :, :]).isum(axis=2)
        return self._curvature(out, g, dirs, count)

    def _stencil(self) -> np.ndarray:
        """(links, 3, node coordinates): dr/dX of each link's r = a - b, constant (its ends are
        nodes and ground points); read from the generated code at two poses, checked equal."""
        m, per = len(self.coords), 3 + 3 * len(self.coords)
        rng, P = np.random.default_rng(0), np.tile(np.asarray(self.P), (2, 1))
        X = np.zeros((2, len(self.full.ps.variables)))
        X[:, self.coords] = rng.normal(size=(2, m))
        first = columns(self.full.numeric.first_order(X, P), 2)
        dr = np.stack([first[:, i * per + 3 : (i + 1) * per] for i in range(len(self.links))], 1)
        if not np.array_equal(dr[0], dr[1]):
            raise ValueError(f"{self.fw.name}: a link's ends move other than as nodes")
        return dr[0].reshape(len(self.links), 3, m)

    def node_hessian(self, positions: list, count: int, states: dict) -> Interval:
        """The Hessian of V in node coordinates over boxes (B, m, m), summed link by link from
        each link's r and its state there: a slack cable adds nothing, one that may be either
        the hull of nothing and its taut term. (The generated Hessian has every cable taut,
        with stiffnesses that no parameter sets folded in as numbers: no slot can switch a
        cable off.) Loads are linear in X and bars are the charts: neither adds a term."""
        first = ball_module(self.full).first_order(self.pose(positions, count), self.P)
        m, per = len(positions), 3 + 3 * len(positions)
        blocks: dict[tuple[int, int], Interval] = {}
        for i, x in enumerate(self.links):
            r = stack([Interval(np.zeros(count)) + first[i * per + c] for c in range(3)], axis=1)
            M = _link_block(x, r, states.get(x.name))
            for j, sj in self.ends[i]:
                for q, sq in self.ends[i]:
                    t = M if sj == sq else -M
                    blocks[j, q] = t if (j, q) not in blocks else blocks[j, q] + t
        lo, hi = np.zeros((count, m, m)), np.zeros((count, m, m))
        for (j, q), t in blocks.items():
            lo[:, 3 * j : 3 * j + 3, 3 * q : 3 * q + 3] = t.lo
            hi[:, 3 * j : 3 * j + 3, 3 * q : 3 * q + 3] = t.hi
        return Interval(lo, hi)

    def _curvature(self, out, g: list, dirs: list, count: int):
        """Add sum_i g_i d2X_i/d(angles)^2: each node's own 2 x 2 block, length times the
        gradient of everything hanging from it along u's second derivatives."""
        lo, hi = out.lo.copy(), out.hi.copy()
        for i, v in enumerate(self.nodes):
            G = self.pull(g, v)
            for (p, q), key in SECOND:
                t = Interval(np.zeros(count)) + self.length[v] * _dot(dirs[i][key], G)
                a, b = 2 * i + p, 2 * i + q
                lo[:, a, b] += t.lo
                hi[:, a, b] += t.hi
        # The additions above are rounded to nearest: widen by their error bound.
        pad = 4 * np.finfo(float).eps * (np.abs(lo) + np.abs(hi)) + 1e-300
        return Interval(lo - pad, hi + pad)

    def derivatives(self, x: np.ndarray, slack: dict | None = None) -> tuple:
        """grad V and its Hessian at points (R, n chart angles) in double precision (each
        point's Hessian that of its taut set: a slack cable adds nothing; the cables of
        `slack`, name -> (R,) bool, taken slack where it says so)."""
        count = len(x)
        g, H, _, dirs, _ = self._numeric(x, slack)
        J = np.stack([np.stack(row, axis=1) for row in self.jacobian(dirs, count)], axis=1)
        hess = np.einsum("nia,nij,njb->nab", J, H, J)
        for i, v in enumerate(self.nodes):
            G = self.pull(list(g.T), v)
            for (p, q), key in SECOND:
                hess[:, 2 * i + p, 2 * i + q] += self.length[v] * _dot(dirs[i][key], G)
        return np.einsum("nia,ni->na", J, g), hess

    def _numeric(self, x: np.ndarray, slack: dict | None = None) -> tuple:
        """At points (R, n chart angles): grad V and its Hessian in node coordinates (each
        point's taut set), the node coordinates, the directions with their derivatives, and
        each spring's and cable's length."""
        count = len(x)
        positions, dirs = self.kinematics(x)
        X = np.zeros((count, len(self.full.ps.variables)))
        X[:, self.coords] = np.stack(positions, axis=1)
        first = self.full.numeric.first_order(X, np.tile(np.asarray(self.P), (count, 1)))
        m, per = len(positions), 3 + 3 * len(positions)
        g, lengths = columns(first[len(self.links) * per :], count), {}
        H = np.zeros((count, m, m))
        for i, link in enumerate(self.links):
            r = columns(first[i * per : i * per + 3], count)
            d = lengths[link.name] = np.sqrt((r * r).sum(axis=1))
            w, M = np.full(count, link.k), np.zeros((count, 3, 3))
            if link.L0 is not None:
                w = link.k * (1 - link.L0 / d)
                M = np.einsum("n,nc,ne->nce", link.k * link.L0 / d**3, r, r)
                if link.cable:
                    taut = d > link.L0
                    if slack and link.name in slack:
                        taut &= ~slack[link.name]
                    w, M = np.where(taut, w, 0.0), M * taut[:, None, None]
            M = M + w[:, None, None] * np.eye(3)  # the Hessian of the link's energy in r
            D = self.stencil[i]
            g += np.einsum("n,nc,cj->nj", w, r, D)
            H += np.einsum("cj,nce,eq->njq", D, M, D)
        return g, H, X[:, self.coords], dirs, lengths

    def cable_lengths(self, x: np.ndarray) -> dict[str, np.ndarray]:
        """Each link's length at points (R, n chart angles), normalised units as `links`' L0."""
        return self._numeric(x)[4]

    def energy(self, x: np.ndarray, slack: tuple[str, ...] = ()) -> np.ndarray:
        """V at points (R, n chart angles), normalised units: the springs' and taut cables'
        energies less the loads' work; the cables `slack` left out (taken slack)."""
        X, d = self.positions(x), self._numeric(x)[4]
        V = np.zeros(len(x))
        for link in (x for x in self.links if x.name not in slack):
            stretch = d[link.name] - (link.L0 or 0.0)
            if link.cable:
                stretch = np.maximum(stretch, 0.0)
            V += 0.5 * link.k * stretch**2
        for load in self.fw.loads:
            if load.point in self.nodes:
                i = self.nodes.index(load.point)
                F = [self.slots[f"f_{load.name}_{c}"] for c in "xyz"]
                V -= X[:, 3 * i : 3 * i + 3] @ np.asarray(F)
        return V

    def positions(self, x: np.ndarray) -> np.ndarray:
        """Node coordinates (R, 3 per node) at points (R, n chart angles)."""
        return np.stack(self.kinematics(x)[0], axis=1)

    def chart_points(self, cols: dict) -> np.ndarray:
        """The chart points (R, n chart angles) of a solutions table's rows (`cols`: columns,
        node positions in the file's units), each node in its most regular chart."""
        scale = units(self.fw)[0]
        rows = len(np.asarray(cols[f"{self.nodes[0]}.x"]))
        x = np.empty((rows, self.n))
        for i, v in enumerate(self.nodes):
            top = self.parent[v]
            if owner(top) == "ground":
                g = top.split(".", 1)[1]
                base = np.array([self.slots[f"g_{g}_{c}"] for c in "xyz"])[None, :]
            else:
                base = np.stack([np.asarray(cols[f"{top}.{c}"], float) for c in "xyz"], 1) / scale
            u = np.stack([np.asarray(cols[f"{v}.{c}"], float) for c in "xyz"], 1) / scale - base
            u /= np.linalg.norm(u, axis=1)[:, None]
            b = np.arctan2(u[:, 1], u[:, 0])
            x[:, 2 * i] = np.arccos(np.clip(u[:, 2], -1.0, 1.0))  # chart A, then the best one
            x[:, 2 * i + 1] = np.where(b < OFFSET, b + 2 * math.pi, b)
        return self.rechart(x)

    def rechart(self, x: np.ndarray) -> np.ndarray:
        """Points (R, n chart angles) with each node in the chart where it is most regular:
        chart A unless its direction lies within BAND of the z axis (then chart B, whose
        squares hold it), by the inverse charts."""
        out = np.empty_like(x)
        for i in range(len(self.nodes)):
            u = np.stack(directions(x[:, 2 * i], x[:, 2 * i + 1], False)["u"], axis=1)
            u /= np.linalg.norm(u, axis=1)[:, None]
            polar = np.abs(u[:, 2]) > math.cos(BAND)
            b = np.arctan2(u[:, 1], u[:, 0])
            b = np.where(b < OFFSET, b + 2 * math.pi, b)
            out[:, 2 * i] = np.where(polar, np.arccos(np.clip(u[:, 0], -1, 1)) + SHIFT,
                                     np.arccos(np.clip(u[:, 2], -1, 1)))  # fmt: skip
            out[:, 2 * i + 1] = np.where(polar, np.arctan2(u[:, 2], u[:, 1]), b)
        return out

    def fresh(self, points: np.ndarray, known: np.ndarray) -> np.ndarray:
        """The points that are neither at the pose of a `known` one nor of an earlier one."""
        kept: list[np.ndarray] = []
        seen = list(self.positions(known)) if len(known) else []
        for x, p in zip(points, self.positions(points) if len(points) else [], strict=True):
            if all(np.abs(p - q).max() > APART for q in seen):
                kept.append(x)
                seen.append(p)
        return np.array(kept).reshape(-1, self.n)

    def endpoints(self, roots: np.ndarray) -> dict[tuple[str, ...], Endpoints]:
        """The critical points (chart angles), each pose once, as endpoints of their taut
        sets' systems (node coordinates, each link's d and w, each bar's multiplier)."""
        roots = self.fresh(roots, np.zeros((0, self.n)))
        grad, _, X, _, d = self._numeric(roots)
        out = {}
        for names, rows in taut_groups(self.cables, self.links, d, len(roots)):
            fs = framework_system(self.fw, names)
            out[names] = self._endpoints(fs, X[rows], {k: v[rows] for k, v in d.items()},
                                         grad[rows])  # fmt: skip
        return out

    def bar_gradients(self, X: np.ndarray) -> np.ndarray:
        """(R, bars, node coordinates): the gradient of each bar's (|r|^2 - length^2) / 2."""
        out = np.zeros((len(X), len(self.nodes), len(self.coords)))
        for b, v in enumerate(self.nodes):
            i, top = self.nodes.index(v), self.parent[v]
            r = X[:, 3 * i : 3 * i + 3] - (
                np.array([self.slots[f"g_{top.split('.', 1)[1]}_{c}"] for c in "xyz"])
                if owner(top) == "ground" else X[:, 3 * self.nodes.index(top) :][:, :3]
            )  # fmt: skip
            out[:, b, 3 * i : 3 * i + 3] = r
            if owner(top) != "ground":
                j = self.nodes.index(top)
                out[:, b, 3 * j : 3 * j + 3] = -r
        return out

    def _endpoints(self, fs: FrameworkSystem, X: np.ndarray, d: dict, grad: np.ndarray):
        """Endpoints of `fs` at poses X: node coordinates, d and w of each link, and each bar's
        multiplier from grad V + sum mu grad g = 0 (least squares; exact at a critical point)."""
        A = self.bar_gradients(X)
        mu = np.stack(
            [np.linalg.lstsq(a.T, -g, rcond=None)[0] for a, g in zip(A, grad, strict=True)]
        )
        links_by = {x.name: x for x in self.links}
        bars = {bar: self.nodes.index(v) for v, _, bar in sphere_chain(self.fw)[0]}
        values = np.zeros((len(X), len(fs.ps.variables)), dtype=complex)
        for k, v in enumerate(fs.ps.variables):
            head, _, rest = v.partition("_")
            if head == "n":
                node, axis = rest.rsplit("_", 1)
                values[:, k] = X[:, 3 * self.nodes.index(node) + "xyz".index(axis)]
            elif head == "d":
                values[:, k] = d[rest]
            elif head == "w":
                x = links_by[rest]
                values[:, k] = x.k * (1.0 - x.L0 / d[rest])
            elif head == "mu":
                values[:, k] = mu[:, bars[rest]]
            else:
                raise ValueError(f"the real route has no value for unknown {v}")
        return found_endpoints(fs.ps.variables, values, np.arange(len(X)))


def _directions_along(G: list, a_lo, a_hi, b_lo, b_hi) -> tuple:
    """The chart angles (a, b) of a box (each (B,) lo and hi) shrunk to the directions u =
    +-G/|G| (G three Intervals (B,)): ((a lo, a hi), (b lo, b hi)), lo > hi where neither
    direction is in the box; the box as it was where G may be 0 or is not finite. In chart A
    a = acos(u_z) and b is the argument of u_x + i u_y; chart B is A with (x, y, z) -> (z, x, y)
    (`directions`)."""
    norm = interval_sum([c.square() for c in G]).sqrt()
    ok = (norm.lo > 0) & np.isfinite(norm.hi) & np.all([c.finite() for c in G], axis=0)
    safe = Interval(np.where(ok, norm.lo, 1.0), np.where(ok, norm.hi, 1.0))
    U = [Interval(np.clip(q.lo, -1, 1), np.clip(q.hi, -1, 1)) for q in (c / safe for c in G)]
    turned = a_lo >= SHIFT / 2
    shift = np.where(turned, SHIFT, 0.0)
    # chart A: (axis, plane x, plane y) = (z, x, y); chart B: (x, y, z)
    axis = Interval.where(turned, U[0], U[2])
    px, py = Interval.where(turned, U[1], U[0]), Interval.where(turned, U[2], U[1])
    outs = []
    for sign in (1.0, -1.0):
        z, x, y = axis * sign, px * sign, py * sign
        # acos is decreasing; libm's acos (an ulp or two) and the shift's addition (half an
        # ulp of 11) are not exact: padded
        lo_a = np.arccos(np.clip(z.hi, -1, 1)) - 1e-14 + shift
        hi_a = np.arccos(np.clip(z.lo, -1, 1)) + 1e-14 + shift
        outs.append(((np.maximum(a_lo, lo_a), np.minimum(a_hi, hi_a)),
                     _arguments(x, y, b_lo, b_hi)))  # fmt: skip
    (a1, b1), (a2, b2) = outs
    empty1 = (a1[0] > a1[1]) | (b1[0] > b1[1])
    empty2 = (a2[0] > a2[1]) | (b2[0] > b2[1])
    out = []
    for p, q, keep in ((a1, a2, (a_lo, a_hi)), (b1, b2, (b_lo, b_hi))):
        lo = np.where(empty1, q[0], np.where(empty2, p[0], np.minimum(p[0], q[0])))
        hi = np.where(empty1, q[1], np.where(empty2, p[1], np.maximum(p[1], q[1])))
        out.append((np.where(ok, lo, keep[0]), np.where(ok, hi, keep[1])))
    return tuple(out)


def _arguments(x: Interval, y: Interval, b_lo, b_hi) -> tuple[np.ndarray, np.ndarray]:
    """[b lo, b hi] shrunk to the arguments of x + i y over the box (x, y); unchanged where the
    box is half a turn or wider or (x, y) may be 0, lo > hi where none lies in [b lo, b hi]."""
    mid = 0.5 * (b_lo + b_hi)
    c, s = Interval(mid).cos(), Interval(mid).sin()
    p, q = x * c + y * s, y * c - x * s  # x + i y turned by -mid: its argument less mid
    narrow = (b_hi - b_lo) < math.pi - 1e-9  # within (mid - pi/2, mid + pi/2)
    behind = p.hi <= 0  # every argument at least pi/2 from mid: none in the box
    around = p.contains_zero() & q.contains_zero()
    corners = np.stack([np.arctan2(q_, p_) for p_ in (p.lo, p.hi) for q_ in (q.lo, q.hi)])
    lo = mid + corners.min(axis=0) - 1e-12  # arctan2 is not correctly rounded: padded
    hi = mid + corners.max(axis=0) + 1e-12
    use = narrow & ~around & ~behind
    lo, hi = np.where(use, np.maximum(b_lo, lo), b_lo), np.where(use, np.minimum(b_hi, hi), b_hi)
    gone = narrow & behind
    return np.where(gone, 1.0, lo), np.where(gone, 0.0, hi)


def _link_block(x, r: Interval, state=None) -> Interval:
    """The Hessian of a link's energy in its r = a - b over boxes (B, 3) -> (B, 3, 3): k I
    without a free length; else w I + k L0 r r^T / d^3, w the force density; a cable's terms
    hulled with 0 where it may be slack, 0 where it is (`state`: the box's, where given: a
    cable the search takes as slack (see SphereFramework.free) is slack)."""
    eye = np.eye(3)[None]
    if x.L0 is None:
        return Interval(np.broadcast_to(x.k * eye, (r.lo.shape[0], 3, 3)).copy())
    dd = r.square().isum(axis=1)
    w, own = force_density(x, dd)
    if state is None:
        state = own
    elif (off := (state == SLACK) & (own != SLACK)).any():
        w = Interval(np.where(off, 0.0, w.lo), np.where(off, 0.0, w.hi))
    t = (x.k * x.L0) / (dd.sqrt() * dd)
    outer = Interval(r.lo[:, :, None], r.hi[:, :, None]) * Interval(
        r.lo[:, None, :], r.hi[:, None, :]
    )
    diag = r.square()  # tighter than r_c r_c
    ii = np.arange(3)
    outer.lo[:, ii, ii], outer.hi[:, ii, ii] = diag.lo, diag.hi
    T = outer * Interval(t.lo[:, None, None], t.hi[:, None, None])
    if x.cable:
        slack, either = (state == SLACK)[:, None, None], (state == EITHER)[:, None, None]
        T = Interval(
            np.where(slack, 0.0, np.where(either, np.minimum(T.lo, 0.0), T.lo)),
            np.where(slack, 0.0, np.where(either, np.maximum(T.hi, 0.0), T.hi)),
        )
    return T + Interval(w.lo[:, None, None] * eye, w.hi[:, None, None] * eye)


def _rows_of(v, loc: np.ndarray) -> Interval:
    """Rows `loc` of a generated value over boxes (an Interval, or a constant for them all)."""
    if isinstance(v, Interval):
        if np.ndim(v.lo) and len(v.lo) > 1:
            return v[loc]
        return Interval(np.full(len(loc), v.lo.ravel()[0]), np.full(len(loc), v.hi.ravel()[0]))
    return Interval(np.full(len(loc), float(v)))


def _slack_of(states: dict) -> dict:
    """The cables' slack masks from their states (what `free` takes as slack is SLACK)."""
    return {c: v == SLACK for c, v in states.items()}


def _dot(u: list, v: list):
    """u . v for three components (Intervals or arrays)."""
    return _total([a * b for a, b in zip(u, v, strict=True)])


def _total(items: list):
    """A sum of Intervals (rounded outwards) or of arrays."""
    return interval_sum(items) if any(isinstance(t, Interval) for t in items) else sum(items)


def _zero(v) -> bool:
    return not isinstance(v, Interval) and np.ndim(v) == 0 and v == 0
