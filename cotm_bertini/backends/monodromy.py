"""Generic solution sets by monodromy, certified by the trace test (issue 28).

Bertini 2 has no monodromy, but it tracks parameter homotopies in process; this module builds
monodromy on them (as HomotopyContinuation.jl's monodromy_solve does). The mathematics, with
what each step relies on (the proof obligations):

1. F(x) = F(x; p0), p0 the generic start of `seed` (homotopy.generic_start: the random complex
   parameters of the total-degree route). The augmented family is G(x; c, e) = F(x) + c M x + e,
   M a random complex n x n matrix, c in C, e in C^n. Its solution variety
   {(x, c, e): e = -F(x) - c M x} is the graph of a polynomial map of (x, c), hence
   IRREDUCIBLE, so the monodromy group of its projection to (c, e) acts TRANSITIVELY on a
   generic fibre: loops in (c, e) reach every point of it from any one. (A slope of rank one,
   u a^T, adds fewer roots, 117 against 136 on the double pendulum, but some of modulus 4,000
   whose paths failed and whose trace stayed 3e-6 from affine: measured, not used.)
2. A start pair needs no solve: random complex x0, c0 = 1, e0 = -F(x0) - M x0. As M is
   random, c0 = 1 is as general as any c; x0 -> e0 is dominant, so e0 is general too.
3. Loops: a graph of two nodes, A = (c0, e0) and B = (c0, e0 + s1 u), joined by edges: edge 0
   the straight segment, each other one a smooth path through a random e at its middle with c
   round a loop 1 -> c1 -> c2 -> 1 (Duff et al. 2019, "Solving polynomial systems via homotopy
   continuation and monodromy"; `_detour` says why c must loop). A root tracked along one edge
   and back along another has gone round a loop; every root at either node is sent along every
   edge whose pairing of it is not yet known, so each path gives a candidate root at the other
   node (three times fewer paths a root than triangle loops). A path between random complex
   points misses the discriminant (real codimension 2) with probability one, so an edge pairs
   the two fibres one to one.
4. Completeness, the trace test (Leykin, Rodriguez & Sottile 2018): the fibre is X ∩ L with
   X = {(x, y): y = -F(x)} (irreducible, dimension n) and L = {y = -M x - e0}, a general affine
   space of codimension n for a random M (spaces of this form are dense among all of them).
   Moving e on the line e0 + s u (u random) moves L in a general pencil of parallel translates.
   (a) Complete => affine: the sum of the whole fibre's points is an entire function of s (no
   point escapes to infinity for a general pencil) growing at most linearly, so affine.
   (b) Incomplete => not affine: the pencil's curve is irreducible (Bertini's theorem), so a
   subset of its points whose trace is affine is all of them or none (the classical trace
   theorem for a curve). The test compares three slices on the line: A (s = 0), B (s = s1: its
   roots are A's continued along edge 0, which lies in the pencil, once edge 0 pairs them one
   to one) and C (s = s2, A's roots continued straight there): an affine function meets it
   exactly, any other fails it with probability one. The x part suffices (y = -M x - e is
   affine in x and s). Slices with M = 0 are NOT general: on Zeeman's machine and the double
   pendulum the complete fibre's trace fails (defect 0.35 and 0.42, measured): at finite s
   points escape to infinity.
5. The generic set: one parameter homotopy from (c0, e0) to (0, 0) with a random complex detour
   (the gamma trick), on a random patch of projective space (most of its paths go to
   infinity: `homotopy.parsed_system`), tracks the complete fibre to F(x; p0) = 0. By the
   parameter continuation theorem its endpoints include every isolated solution of F(x; p0);
   the finite nonsingular ones are the generic set, as the total-degree route keeps them. All
   paths go along one curve (paths along two curves may not be mixed: they differ by a
   monodromy permutation).
   A second run along another random detour checks the first: a path that jumps onto another
   path's way to infinity loses a root and shows nothing, but two runs would have to lose the
   same one; the set is complete only when both end at the same roots.

Stagnation (several fresh edges in a row with no new root) without a passing trace test is
reported as incomplete, never as complete; a path that fails is counted, never dropped
silently; a lost path of the final homotopy makes the set incomplete. The working state can
be written to a checkpoint as it goes, and a later call resumes from it (nothing found is lost
to an interrupt).

Cost: about (edges + 2) N'' paths, N'' the size of the augmented fibre (at least the finite
count of F; bench/monodromy.py compares it with the Bezout bound).
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import SolverError
from ..fs import atomic_write_text
from ..model.polynomial import ParametricSystem, PolySystem
from ..progress import Progress, say
from ..versions import bertini2_version
from .homotopy import (
    _SUCCESS,
    BERTINI_MAX_NORM,
    INFINITE_CODES,
    NEVER_TRACKED,
    START_CENTRE,
    GenericSet,
    coincident_rows,
    double_then_adaptive,
    generic_start,
    solver_errors,
)
from .neighbour import _newton
from .render import parametric_texts, render_parameter_homotopy, render_system

SALT = 28  # random stream of the augmented family (issue 28), apart from the start's
DISTINCT = 1e-7  # two roots closer than this (relative, as coincident_rows) are one
POLISHED = 1e-10  # a Newton-polished endpoint whose last step (relative) is above this: failed
TRACE_TOL = 1e-8  # the trace test passes when the relative defect of affinity is below this
MAX_STALL = 5  # fresh edges in a row that find no new root: stagnation (as HC.jl's default)
# ... or this long without the roots growing by STALL_GAIN: stagnation too (a large fibre whose
# edges each still find a root now and then: a rigid body on a ball joint sat at 1,578 to
# 1,584 roots for ten minutes, and the edge count never stalled)
STALL_SECONDS = 240.0
STALL_GAIN = 0.01
MAX_EDGES = 64  # edges at most, whatever happens
FIRST_EDGES = 3  # edges made at the start: the straight one and two detours (more are added
# when every root has been along every edge and the trace test still fails)
# Bertini's security max norm (1e5) on the edges and slices: a point of the augmented fibre may
# be larger (fourbar's are), and a path between general parameter values cannot diverge.
LOOP_MAX_NORM = 1e12
# Bertini's predictor on the edges and slices: RK4 instead of the default RKF45, 19-23 % less
# CPU on case 3, Zeeman and the double pendulum, the same roots and retracks (measured).
LOOP_PREDICTOR = "RK4"
# Newton iterations a corrector step may take on the edges and slices (Bertini's default 2):
# with 4 the steps are longer, 5-7 times fewer on prism_slack's detour edges (2.5-3 times less
# time), more paths end in double precision (fewer adaptive retracks), the same endpoints on
# every path both settings ended
# (measured, issue 29); with 5 or 6 some paths jumped to another root. A jump on an edge costs
# nothing but a path (every root found is a root, the trace test judges the whole fibre).
LOOP_NEWTON = 4
FINAL_MAX_NORM = BERTINI_MAX_NORM  # the final homotopy: its paths do go to infinity
FINAL_ATTEMPTS = 3  # the final homotopy with a new detour when a path of it is lost
PENCIL_STEP = 3.0  # |s1|, |s2| about this: node B (s1) far enough from A that a loop through
# edge 0 and another edge is a fat triangle, not a sliver (B near A: roots stopped coming)
CHECKPOINT_SECONDS = 10.0  # the working state is written at most this often
CHUNK = 128  # paths a Bertini call on an edge: the checkpoint and progress between them
M, E = "mono_m", "mono_e"  # parameter names of the augmented family (unlike any variable)
Slice = tuple[np.ndarray, np.ndarray]  # parameters (c, e): the slope's factor c and e
Edge = tuple[Slice, complex] | None  # an edge's (detour, twist of c); None: the straight one


@dataclass(frozen=True, eq=False)
class Augmented:
    """G(x; c, e) = F(x) + c M x + e around one start pair (at c = 1), and the trace test's
    pencil e0 + s u."""

    start: dict[str, complex]  # p0, the generic start parameters
    base: PolySystem  # F(x) = F(x; p0)
    matrices: np.ndarray  # the slope M, shape (1, n, n)
    x0: np.ndarray  # the constructed start root
    origin: Slice  # node A: ((1,), e0 = -F(x0) - M x0), the base of every edge
    direction: np.ndarray  # the pencil's direction u, scaled to e0's size
    steps: tuple[complex, complex]  # s1 (node B) and s2 (slice C)
    family: ParametricSystem  # parameters mono_m0, then mono_e{i}
    texts: tuple[str, ...]  # the family's functions as Bertini text

    def values(self, at: Slice) -> dict[str, complex]:
        """The family's parameter values at (c, e), by name."""
        return dict(zip(self.family.parameters, _vector(at), strict=True))

    def system(self, at: Slice) -> PolySystem:
        """G(x; c, e) as a numeric system."""
        return self.family.instantiate(_vector(at))

    def slice(self, k: int) -> Slice:
        """The points of the pencil: A = (c0, e0) for k = 0, B and C = (c0, e0 + s_k u)."""
        c0, e0 = self.origin
        return self.origin if k == 0 else (c0, e0 + self.steps[k - 1] * self.direction)

    @property
    def size(self) -> float:
        """The size of e0's entries (at least 1): the scale of the random e's."""
        return max(1.0, float(np.abs(self.origin[1]).max()))


def _vector(at: Slice) -> np.ndarray:
    return np.concatenate(at).astype(complex)


def augmented_family(ps: ParametricSystem, seed: int, centre: dict | None = None) -> Augmented:
    """The augmented family of `ps` at `seed`'s generic start, with a constructed start pair."""
    start = generic_start(ps, seed, START_CENTRE if centre is None else centre)
    base = ps.instantiate([start[n] for n in ps.parameters])
    n = len(ps.variables)
    rng = np.random.default_rng((seed, SALT))
    matrices, x0, u = (_gaussian(rng, shape) for shape in ((1, n, n), n, n))
    e0 = -(base.evaluate(x0)[0] + matrices[0] @ x0)
    # The pencil's step the size of e0 (|s| about PENCIL_STEP): node B far enough from A that
    # its loops are fat, the slices far enough apart that a missing point's curvature shows.
    direction = u * max(1.0, float(np.abs(e0).max()))
    steps = tuple(complex(z) for z in PENCIL_STEP * _gaussian(rng, 2))
    family = _family(base, matrices)
    origin = (np.ones(1, dtype=complex), e0)
    return Augmented(
        start, base, matrices, x0, origin, direction, steps, family, parametric_texts(family)
    )


def _gaussian(rng: np.random.Generator, shape) -> np.ndarray:
    """Standard complex normal numbers (E|z|^2 = 1)."""
    return (rng.normal(size=shape) + 1j * rng.normal(size=shape)) / np.sqrt(2)


def _random_slice(rng: np.random.Generator, n: int, size: float) -> Slice:
    """A random point (c, e): c of modulus 1 and random phase (a slope as large as M's: a
    small one makes the fibre's points huge, and their paths fail), e complex normal of the
    given size."""
    c = _gaussian(rng, 1)
    return c / np.linalg.norm(c), size * _gaussian(rng, n)


def _family(base: PolySystem, matrices: np.ndarray) -> ParametricSystem:
    """F + sum_k c_k M_k x + e as terms: each F_i's own, the n K terms c_k (M_k)_ij x_j, one
    e_i; the parameters are c, then e."""
    k, n = len(matrices), len(base.variables)
    var_exps, par_exps, coeffs = [], [], []
    for i, (ex, cf) in enumerate(zip(base.exponents, base.coefficients, strict=True)):
        pe = np.zeros((len(ex) + k * n + 1, k + n), dtype=np.int64)
        pe[len(ex) + np.arange(k * n), np.repeat(np.arange(k), n)] = 1  # c_k (M_k)_ij x_j
        pe[-1, k + i] = 1  # e_i
        linear = np.tile(np.eye(n, dtype=np.int64), (k, 1))
        var_exps.append(np.vstack([ex, linear, np.zeros((1, n), np.int64)]))
        par_exps.append(pe)
        coeffs.append(np.concatenate([np.asarray(cf, dtype=complex), matrices[:, i].ravel(), [1]]))
    names = [f"{M}{j}" for j in range(k)] + [f"{E}{i}" for i in range(n)]
    return ParametricSystem(
        base.variables, base.names, tuple(names), tuple(var_exps), tuple(par_exps),
        tuple(coeffs), (),
    )  # fmt: skip


@dataclass(frozen=True)
class Tracked:
    """Endpoints of one batch of paths: Newton-polished points (NaN where a path failed)."""

    points: np.ndarray
    ok: np.ndarray  # bool per path: tracked to a finite, nonsingular, polished root
    codes: tuple[str, ...]
    finite: np.ndarray  # bool per path: Bertini's finite flag
    singular: np.ndarray  # bool per path: Bertini's singular flag (is_singular)
    retracked_adaptive: int
    cpu_seconds: float


def track_segment(
    aug: Augmented,
    points: np.ndarray,
    start: Slice,
    target: Slice,
    detour: dict[str, complex] | None = None,
    singular_ok: bool = False,
    twist: complex = 0j,
) -> Tracked:
    """`points` tracked from (c, e) = `start` to `target` by Bertini's parameter homotopy
    (double precision; failures, crossings and, unless `singular_ok`, singular endpoints again
    in adaptive precision), then the nonsingular endpoints polished by Newton's method on the
    target system."""
    family = aug.family
    texts = (
        render_parameter_homotopy(
            family,
            aug.values(start),
            aug.values(target),
            detour,
            aug.texts,
            {family.parameters[0]: twist} if twist else None,
        ),  # fmt: skip
        render_system(aug.system(target)),
    )
    points = np.asarray(points, dtype=complex)
    if singular_ok:  # the final homotopy, tracked in projective space: see homotopy.parsed_system
        # Bertini's 2 Newton iterations here: with 4 the four-bar's final homotopy ended 28
        # of its 30 roots (two paths jumped, to infinity: nothing to notice it by; measured)
        options = {"max_norm": FINAL_MAX_NORM, "projective": True}
    else:  # Bertini's endgame also calls a path past 1e5 GoingToInfinity: not on an edge
        options = {
            "max_norm": LOOP_MAX_NORM,
            "path_truncation_threshold": LOOP_MAX_NORM,
            "predictor": LOOP_PREDICTOR,
            "max_num_newton_iterations": LOOP_NEWTON,
        }
    with solver_errors(f"a monodromy path batch ({len(points)} paths)"):
        out = double_then_adaptive(texts, points, options, singular_ok)
    ok = np.array(
        [
            c == _SUCCESS and f and not s
            for c, f, s in zip(out["codes"], out["finite"], out["singular"], strict=True)
        ],
        dtype=bool,
    )
    pts = np.where(ok[:, None], out["points"], np.nan + 0j)
    if ok.any():
        pts[ok], ok[ok] = _polish(aug.system(target), pts[ok])
    finite, singular = (np.array(out[f], dtype=bool) for f in ("finite", "singular"))
    return Tracked(
        pts,
        ok,
        tuple(out["codes"]),
        finite,
        singular,
        out["retracked_adaptive"],
        out["cpu_seconds"],
    )


def _polish(system: PolySystem, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Newton-polished points and which converged (below POLISHED)."""
    polished, size = _newton(system, x.copy())
    if polished is None:  # a singular Jacobian: keep Bertini's endpoints, flag none
        return x, np.isfinite(x).all(axis=1)
    return polished, (size < POLISHED) & np.isfinite(polished).all(axis=1)


def _index(roots: np.ndarray, x: np.ndarray, tol: float = DISTINCT) -> np.ndarray:
    """For each row of x, the index of the root it is (the metric of coincident_rows: largest
    coordinate difference relative to 1 + the larger norm), or -1; vectorised over both."""
    if len(roots) == 0 or len(x) == 0:
        return np.full(len(x), -1)
    gap = np.abs(x[:, None, :] - roots[None, :, :]).max(axis=2)
    scale = np.maximum.outer(1 + np.abs(x).max(axis=1), 1 + np.abs(roots).max(axis=1))
    rel = gap / scale
    best = rel.argmin(axis=1)
    return np.where(rel[np.arange(len(x)), best] < tol, best, -1)


@dataclass
class _Graph:
    """The monodromy's working state (mutable, private): the roots at nodes A and B in the
    order found; per edge its detour (None: edge 0, the straight segment in the pencil) and the
    pairings it has shown, links[k][side][i] = j (root i at node `side` goes along edge k to
    root j at the other node; -1: that path failed); A's roots continued to slice C."""

    nodes: list[np.ndarray]
    detours: list[Edge]
    links: list[tuple[dict[int, int], dict[int, int]]]
    beyond: np.ndarray
    paths: int = 0
    failed: int = 0
    retracked: int = 0
    idle: int = 0  # fresh edges in a row that found no new root
    resumed: int = 0  # roots read from a checkpoint
    mark: tuple[int, float] = (0, 0.0)  # (roots, when): the last time they grew by STALL_GAIN
    notes: list[str] = field(default_factory=list)

    def count(self, batch: Tracked, what: str) -> None:
        """Book one batch of paths: tracked, failed (with their codes), retracked."""
        self.paths += len(batch.ok)
        self.retracked += batch.retracked_adaptive
        bad = [batch.codes[k] for k in np.flatnonzero(~batch.ok)]
        if bad:
            self.failed += len(bad)
            self.notes.append(f"{what}: {len(bad)} paths failed ({', '.join(sorted(set(bad)))})")

    def add_edge(self, detour: Edge) -> None:
        """A new edge between A and B (no pairing known yet)."""
        self.detours.append(detour)
        self.links.append(({}, {}))

    def pending(self, k: int, side: int) -> list[int]:
        """The roots at node `side` not yet sent along edge k."""
        return [i for i in range(len(self.nodes[side])) if i not in self.links[k][side]]


def _new_graph(aug: Augmented, seed: int) -> _Graph:
    """The graph at the start: x0 at A, edge 0 and FIRST_EDGES - 1 random detours."""
    n = len(aug.x0)
    g = _Graph([aug.x0[None, :].copy(), np.zeros((0, n), complex)], [], [], np.zeros((0, n)))
    for k in range(FIRST_EDGES):
        g.add_edge(_detour(aug, seed, k))
    return g


def _detour(aug: Augmented, seed: int, k: int, reach: float = 1.0) -> Edge:
    """Edge k's path: none for edge 0 (straight); else (detour, twist) taking e through a
    random point of size `reach` times e0's at the edge's middle, and the slope factor c round
    a loop 1 -> c1 -> c2 -> 1 (c1, c2 of modulus `reach`, random phases, at t = 2/3 and 1/3):
    c(t) = 1 + t (1 - t) (d + w t). A loop made of two edges then winds round c = 0 as a
    triangle of random points does, and the roots that go to infinity there are exchanged (on
    the double pendulum, edges whose c only went out and back along a segment never reached
    two roots of modulus 4,000, measured). Its own random stream: a resumed run makes the same
    edges."""
    if k == 0:
        return None
    rng = np.random.default_rng((seed, SALT, 2, k))
    _, e = _random_slice(rng, len(aug.x0), aug.size)
    c1, c2 = reach * np.exp(2j * np.pi * rng.random(2))
    (_, ea), (_, eb) = aug.origin, aug.slice(1)
    w = 13.5 * (c1 - c2)  # from c(2/3) = c1, c(1/3) = c2, t (1 - t) = 2/9 at both
    d = 4.5 * (2 * c2 - 1 - c1)
    return (np.array([d]), 4 * (reach * e - (ea + eb) / 2)), complex(w)


def _sweep(aug: Augmented, g: _Graph, k: int, side: int, after=None) -> int:
    """Every root at node `side` not yet sent along edge k sent along it, CHUNK paths a Bertini
    call, `after(g, paths)` called after each (the checkpoint and the progress line: one call
    of thousands of paths took 30 min on a 16-unknown chain, measured); returns how many new
    roots it found."""
    todo, new = g.pending(k, side), 0
    for at in range(0, len(todo), CHUNK):
        new += _sweep_chunk(aug, g, k, side, todo[at : at + CHUNK])
        if after is not None:
            after(g, len(todo[at : at + CHUNK]))
    return new


def _sweep_chunk(aug: Augmented, g: _Graph, k: int, side: int, todo: list[int]) -> int:
    """These roots at node `side` sent along edge k; the pairings recorded (a path that lands
    on a root already paired along this edge with another is counted failed: two paths cannot
    meet on an edge); returns how many new roots they found."""
    ends = (aug.origin, aug.slice(1))
    detour, twist = None, 0j
    if g.detours[k] is not None:
        (dc, de), twist = g.detours[k]
        if side == 1:  # the same curve backwards: c's d t(1-t) + w t^2(1-t) becomes this
            dc, twist = dc + twist, -twist
        detour = aug.values((dc, de))
    pts = g.nodes[side][todo]
    batch = track_segment(aug, pts, ends[side], ends[1 - side], detour, twist=twist)
    g.count(batch, f"edge {k}")
    there, new, met = 1 - side, 0, 0
    for i, ok, x in zip(todo, batch.ok, batch.points, strict=True):
        j = int(_index(g.nodes[there], x[None, :])[0]) if ok else -1
        if ok and j < 0:
            g.nodes[there] = np.vstack([g.nodes[there], x])
            j, new = len(g.nodes[there]) - 1, new + 1
        elif ok and g.links[k][there].get(j, i) != i:
            j, met = -1, met + 1
        g.links[k][side][i] = j
        if j >= 0:
            g.links[k][there][j] = i
    if met:
        g.failed += met
        g.notes.append(f"edge {k}: {met} paths met another path's root")
    return new


def _trace(aug: Augmented, g: _Graph) -> tuple[float, str]:
    """The trace test on A's roots, B's and C's, once edge 0 pairs A's and B's one to one
    (then B's are A's continued in the pencil); A's new roots continued straight to C."""
    a, b = g.nodes
    paired = sorted(v for v in g.links[0][0].values() if v >= 0)
    if len(a) != len(b) or paired != list(range(len(b))):
        return np.inf, "edge 0 does not yet pair the roots at A and B one to one"
    new = a[len(g.beyond) :]
    if len(new):
        batch = track_segment(aug, new, aug.origin, aug.slice(2))
        g.count(batch, "trace slice C")
        g.beyond = np.vstack([g.beyond, batch.points])
    return trace_residual(aug, [a, b, g.beyond])


def slice_points(aug: Augmented, roots: np.ndarray) -> list[np.ndarray]:
    """`roots` (at A) continued straight to B and C (NaN rows where a path failed)."""
    return [track_segment(aug, roots, aug.origin, aug.slice(k)).points for k in (1, 2)]


def trace_residual(aug: Augmented, fibres: list[np.ndarray]) -> tuple[float, str]:
    """The trace test on A's, B's and C's points: the defect of affinity
    |tr(s1) - tr(0) - s1/s2 (tr(s2) - tr(0))|, each coordinate relative to its own scale (the
    largest sum over a slice of the coordinate's moduli, at least 1: a coordinate of size 1e6
    in a few points does not hide a missing point of size 1 in another), the largest of them;
    and why it is infinite ('' if it is not)."""
    if any(not np.isfinite(f).all() for f in fibres):
        return np.inf, "a path to a trace slice failed"
    if any(coincident_rows(f, DISTINCT) for f in fibres):
        return np.inf, "two roots met on a trace slice"
    tr = [f.sum(axis=0) for f in fibres]
    s1, s2 = aug.steps
    defect = tr[1] - tr[0] - (s1 / s2) * (tr[2] - tr[0])
    scale = np.maximum(1.0, np.max([np.abs(f).sum(axis=0) for f in fibres], axis=0))
    return float((np.abs(defect) / scale).max()), ""


def trace_test(aug: Augmented, roots: np.ndarray) -> float:
    """The trace test's relative defect for `roots` (points of the fibre at A): below
    TRACE_TOL iff they are the whole fibre (with probability one)."""
    return trace_residual(aug, [roots, *slice_points(aug, roots)])[0]


def _explore(
    aug: Augmented, g: _Graph, seed: int, limits: tuple[int, int, float], report, save
) -> tuple[float, bool, str]:
    """Monodromy on the graph until the trace test passes: (trace residual, complete, reason).
    `limits`: (max_stall, max_edges, trace_tol). A round sends every unpaired root along every
    edge; a fresh edge is added when nothing is unpaired and the test still fails; `max_stall`
    fresh edges in a row without a new root is stagnation, and so are STALL_SECONDS without
    STALL_GAIN more roots: reported incomplete (the caller falls back or stops, and says so).
    `save(g)` is called after every chunk of paths and every round (the checkpoint)."""

    def after(graph: _Graph, paths: int) -> None:
        save(graph)
        note = (f"{len(graph.nodes[0])} roots, {len(graph.detours)} edges; time left not known "
                "(it ends when the trace test passes, or when the roots stop coming)")  # fmt: skip
        report.update(paths, note=note)
        stalled = _stalled(graph)
        if stalled:
            raise _Stalled(stalled)

    try:
        return _rounds(aug, g, seed, limits, report, save, after)
    except _Stalled as why:
        save(g)
        return float("nan"), False, f"{why} (the trace test not run again)"


class _Stalled(Exception):
    """The roots stopped growing for STALL_SECONDS: stagnation, said why."""


def _stalled(g: _Graph) -> str:
    """Why the monodromy is stagnating ('' while its roots still grow by STALL_GAIN within
    STALL_SECONDS)."""
    n, now = len(g.nodes[0]), time.perf_counter()
    roots, since = g.mark
    if not since or n >= roots * (1.0 + STALL_GAIN) + 1:
        g.mark = (n, now)
        return ""
    if now - since <= STALL_SECONDS:
        return ""
    return (f"stagnation: {n - roots} roots gained in the last {now - since:.0f} s "
            f"({n} in all; less than {STALL_GAIN:.0%} more)")  # fmt: skip


def _rounds(aug: Augmented, g: _Graph, seed: int, limits: tuple, report, save, after) -> tuple:
    """_explore's rounds (see there): (trace residual, complete, reason)."""
    max_stall, max_edges, tol = limits
    while True:
        before, found = g.paths, 0
        for k in range(len(g.detours)):
            found += sum(_sweep(aug, g, k, side, after) for side in (0, 1))
        swept = g.paths - before
        residual, why = _trace(aug, g)
        save(g)
        report.update(g.paths - before - swept, note=f"{len(g.nodes[0])} roots")
        if residual <= tol:
            return residual, True, f"trace test passed (defect {residual:.1e})"
        if found:
            g.idle = 0
        if any(g.pending(k, side) for k in range(len(g.detours)) for side in (0, 1)):
            continue
        failing = why or f"the trace test fails (defect {residual:.1e})"
        if g.idle >= max_stall:
            stall = f"stagnation: {g.idle} fresh edges in a row found no new root"
            return residual, False, f"{stall} and {failing}"
        if len(g.detours) >= max_edges:
            return residual, False, f"the edge budget ({max_edges} edges) is spent and {failing}"
        g.idle += 1
        # Each fresh edge that finds nothing reaches twice as far: a root of large modulus is
        # exchanged only at branch points far from A (case 2's last root, measured).
        g.add_edge(_detour(aug, seed, len(g.detours), 2.0**g.idle))


def _state(g: _Graph) -> dict:
    """The graph as JSON (complex numbers as [re, im] pairs)."""

    def pairs(x: np.ndarray) -> list:
        return np.stack([x.real, x.imag], axis=-1).tolist()

    return {
        "nodes": [pairs(x) for x in g.nodes],
        "detours": [
            None if d is None else [pairs(d[0][0]), pairs(d[0][1]), pairs(np.array([d[1]]))]
            for d in g.detours
        ],
        "links": [[sorted(side.items()) for side in link] for link in g.links],
        "beyond": pairs(g.beyond),
        "counts": [g.paths, g.failed, g.retracked, g.idle],
        "notes": g.notes,
    }


def _from_state(d: dict, n: int) -> _Graph:
    """Inverse of _state (ValueError, KeyError or TypeError if damaged)."""

    def points(x: list) -> np.ndarray:
        a = np.asarray(x, dtype=float).reshape(-1, n, 2)
        return a[..., 0] + 1j * a[..., 1]

    def vector(x: list) -> np.ndarray:
        a = np.asarray(x, dtype=float).reshape(-1, 2)
        return a[:, 0] + 1j * a[:, 1]

    g = _Graph(
        [points(x) for x in d["nodes"]],
        [
            None if e is None else ((vector(e[0]), vector(e[1])), complex(vector(e[2])[0]))
            for e in d["detours"]
        ],
        [tuple({int(i): int(j) for i, j in side} for side in link) for link in d["links"]],
        points(d["beyond"]),
        *(int(c) for c in d["counts"]),
        notes=list(d["notes"]),
    )
    if len(g.links) != len(g.detours) or len(g.nodes) != 2:
        raise ValueError("inconsistent monodromy checkpoint")
    g.resumed = len(g.nodes[0])
    return g


def load_checkpoint(path: Path | None, aug: Augmented, seed: int) -> _Graph:
    """The graph saved at `path` (a resumed run), or a new one (no file, or a damaged one:
    a checkpoint only saves work, it is never trusted for a result: the trace test is)."""
    if path is not None and path.is_file():
        try:
            g = _from_state(json.loads(path.read_text()), len(aug.x0))
            if np.abs(aug.system(aug.origin).evaluate(g.nodes[0])[0]).max(initial=0) < 1e-6:
                return g
        except (ValueError, KeyError, TypeError):
            pass
        path.unlink(missing_ok=True)
    return _new_graph(aug, seed)


ROUTE = "monodromy"  # GenericSet.route["route"] of a set found here


@dataclass(frozen=True)
class MonodromySet:
    """A generic solution set found by monodromy on the augmented family, trace-tested."""

    seed: int
    start: dict[str, complex]  # p0: the same generic start as the total-degree route
    points: np.ndarray  # finite nonsingular solutions of F(x; p0)
    augmented_points: np.ndarray  # the augmented fibre at node A (N'' points)
    edges: int
    paths: int  # every path tracked: edges, trace slice and the final homotopy
    failed_paths: int  # paths of the edges and slice that reached no nonsingular root
    finite_endpoints: int  # of the final homotopy (nonsingular and singular)
    singular_endpoints: int
    lost_endpoints: int  # final paths neither finite nor on their way to infinity
    retracked_adaptive: int
    trace_residual: float
    complete: bool
    reason: str
    seconds: float
    cpu_seconds: float
    resumed: int = 0  # roots read from a checkpoint (an interrupted run resumed)
    notes: tuple[str, ...] = ()

    @property
    def augmented(self) -> int:
        """N'': the size of the augmented fibre (the paths of the final homotopy)."""
        return len(self.augmented_points)

    def route(self) -> dict:
        """How the set was found (GenericSet.route), with its completeness evidence."""
        return {
            "route": ROUTE,
            "method": "monodromy on F + c M x + e: two nodes, a straight edge and looping ones",
            "augmented_count": self.augmented,
            "edges": self.edges,
            "paths_tracked": self.paths,
            "failed_paths": self.failed_paths,
            "lost_endpoints": self.lost_endpoints,
            "retracked_adaptive": self.retracked_adaptive,
            "trace_residual": self.trace_residual,
            "complete": self.complete,
            "evidence": ["trace test"] if self.complete else [],
            "reason": self.reason,
            "resumed_roots": self.resumed,
            "seconds": round(self.seconds, 3),
            "cpu_seconds": round(self.cpu_seconds, 3),
            "notes": "; ".join(self.notes),
        }

    def generic_set(self, key: str, incomplete_ok: bool = False) -> GenericSet:
        """As a GenericSet (its `paths`: the final homotopy's, N'', so that paths - finite
        endpoints still counts the endpoints at infinity; every path tracked is in `route`).
        An incomplete set is refused (SolverError with the reason) unless `incomplete_ok`: then
        its route says complete = False, and whoever uses it must report that."""
        if not self.complete and not incomplete_ok:
            raise SolverError(f"the monodromy generic set (seed {self.seed}): {self.reason}")
        return GenericSet(
            key, self.seed, dict(self.start), self.points, self.augmented,
            self.finite_endpoints, self.singular_endpoints, self.seconds, bertini2_version(),
            self.route(),
        )  # fmt: skip


def _descend(aug: Augmented, g: _Graph, seed: int) -> tuple[Tracked, str]:
    """The augmented fibre tracked from (c0, e0) to (0, 0), i.e. to F(x; p0) = 0, with a random
    complex detour of the parameters (the gamma trick). A lost path sends every path along a
    new detour: the endpoints of one curve are all the isolated roots, but paths along two
    curves may not be mixed (they differ by a monodromy permutation). Then the same along one
    more detour, as a check: a path that jumps onto another's way to infinity leaves nothing to
    see in its own endpoints (the four-bar lost 2 of 30 roots so with 4 Newton iterations a
    step, measured), but two detours would have to lose the same root. Returns the endpoints
    and, when the check ended at another set of roots, what differed ("" if nothing)."""
    n = len(aug.x0)
    zero = (np.zeros(1), np.zeros(n))
    rng = np.random.default_rng((seed, SALT, 1))
    runs = []
    for attempt in range(FINAL_ATTEMPTS + 1):
        detour = aug.values(_random_slice(rng, n, aug.size))
        final = track_segment(aug, g.nodes[0], aug.origin, zero, detour, singular_ok=True)
        g.paths += len(final.ok)
        g.retracked += final.retracked_adaptive
        lost = int(_lost(final).sum())
        if lost:
            g.notes.append(f"final homotopy, detour {attempt + 1}: {lost} paths lost")
        else:
            runs.append(final)
        if len(runs) == 2 or attempt + 1 - len(runs) == FINAL_ATTEMPTS:
            break
    if len(runs) < 2:  # no run without a lost path (the verdict says so), or no check made
        if runs:
            g.notes.append("final homotopy: the check along a second detour lost paths")
        return (runs[0] if runs else final), ""
    a, b = (r.points[r.ok] for r in runs)
    unmatched = int((_index(b, a) < 0).sum() + (_index(a, b) < 0).sum())
    if unmatched or len(a) != len(b):
        return runs[0], (f"the final homotopy along two detours ended at different roots "
                         f"({len(a)} and {len(b)}, {unmatched} unmatched)")  # fmt: skip
    return runs[0], ""


def _lost(final: Tracked) -> np.ndarray:
    """Paths neither at a finite endpoint nor on their way to infinity (as track() sorts)."""
    done = np.array([c == _SUCCESS for c in final.codes], dtype=bool) & final.finite
    away = [
        c in INFINITE_CODES or (c not in NEVER_TRACKED and not f)
        for c, f in zip(final.codes, final.finite, strict=True)
    ]
    return ~done & ~np.array(away, dtype=bool)


def monodromy_generic(
    ps: ParametricSystem,
    seed: int = 1,
    centre: dict[str, float] | None = None,
    *,
    max_stall: int = MAX_STALL,
    max_edges: int = MAX_EDGES,
    trace_tol: float = TRACE_TOL,
    checkpoint: Path | None = None,
) -> MonodromySet:
    """The generic solution set of `ps` at `seed`'s start parameters (centre + START_SPREAD
    noise, as generic_set) by monodromy on F + c M x + e, trace-tested, then one
    parameter homotopy to F; `complete` only when the trace test passed and no final path was
    lost. With `checkpoint` (a file) the working state is written there as it goes and read
    back by a later call (an interrupted run resumes); it is removed when the set is done."""
    t0, cpu0 = time.perf_counter(), time.process_time()
    aug = augmented_family(ps, seed, centre)
    g = load_checkpoint(checkpoint, aug, seed)
    saved = [time.perf_counter()]

    def save(graph: _Graph, force: bool = False) -> None:
        if checkpoint is not None and (
            force or time.perf_counter() - saved[0] > CHECKPOINT_SECONDS
        ):
            atomic_write_text(checkpoint, json.dumps(_state(graph)))
            saved[0] = time.perf_counter()

    limits = (max_stall, max_edges, trace_tol)
    with Progress(f"monodromy generic set (seed {seed})", None, "paths") as report:
        if g.resumed:
            say(f"cotm-bertini: resumed from {checkpoint}: {g.resumed} roots already found")
        try:
            verdict = _explore(aug, g, seed, limits, report, save)
        except KeyboardInterrupt:
            save(g, force=True)
            raise
        save(g, force=True)
        final, mismatch = _descend(aug, g, seed)
        report.update(len(final.ok))
    result = _result(aug, g, final, (*verdict, mismatch), (t0, cpu0), seed)
    if checkpoint is not None and result.complete:
        checkpoint.unlink(missing_ok=True)
    return result


def _result(
    aug: Augmented,
    g: _Graph,
    final: Tracked,
    verdict: tuple[float, bool, str, str],
    clocks: tuple[float, float],
    seed: int,
) -> MonodromySet:
    """The MonodromySet: the final homotopy's endpoints sorted as track() sorts them (finite,
    at infinity, lost), the verdict downgraded when a final path was lost, two met or the
    check along a second detour disagreed (verdict's last item)."""
    residual, complete, reason, mismatch = verdict
    done = np.array([c == _SUCCESS for c in final.codes], dtype=bool) & final.finite
    lost = int(_lost(final).sum())
    points = final.points[final.ok]
    unpolished = int((done & ~final.singular & ~final.ok).sum())
    notes = list(g.notes)
    if unpolished:
        notes.append(f"final homotopy: {unpolished} nonsingular endpoints failed Newton's method")
    problems = []
    if lost or unpolished:
        problems.append(f"{lost + unpolished} paths of the final homotopy lost")
    if coincident_rows(points, DISTINCT):
        problems.append("two paths of the final homotopy met")
    if mismatch:
        problems.append(mismatch)
    if problems:
        complete, reason = False, "; ".join([reason, *problems])
    return MonodromySet(
        seed, dict(aug.start), points, g.nodes[0], len(g.detours), g.paths, g.failed,
        int(done.sum()), int((done & final.singular).sum()), lost, g.retracked, residual,
        complete, reason, time.perf_counter() - clocks[0], time.process_time() - clocks[1],
        g.resumed, tuple(notes),
    )  # fmt: skip
