"""Generic solution sets by monodromy, certified by the trace test (issue 28).

Bertini 2 has no monodromy, but it tracks parameter homotopies in process; this module builds
monodromy on them (as HomotopyContinuation.jl's monodromy_solve does). The mathematics, with
what each step relies on (the proof obligations):

1. F(x) = F(x; p0), p0 the generic start of `seed` (homotopy.generic_start: the random complex
   parameters of the total-degree route). The augmented family is
   G(x; c, e) = F(x) + c M x + e, M a random complex n x n matrix, c in C, e in C^n (more
   generally sum_k c_k M_k over DIRECTIONS matrices; one is the cheapest, measured). Its
   solution variety {(x, c, e): e = -F(x) - c M x} is the graph of a polynomial map of (x, c),
   hence IRREDUCIBLE, so the monodromy group of its projection to (c, e) acts TRANSITIVELY on a
   generic fibre: loops in (c, e) reach every point of it from any one.
2. A start pair needs no solve: random complex x0, c0 = 1, e0 = -F(x0) - M x0. As M is
   random, c0 = 1 is as general as any c; x0 -> e0 is dominant, so e0 is general too.
3. Loops (c0, e0) -> (c_a, e_a) -> (c_b, e_b) -> (c0, e0) through random complex points
   (triangles), each side one Bertini parameter homotopy; every root found is sent round every
   loop. A segment between random complex points misses the discriminant (real codimension 2)
   with probability one, so a loop returns a permutation of the fibre. (Loops in e alone are
   transitive too, but were measured to stagnate: roots of size 20-30 exchange only at branch
   points far beyond loops of e0's size. Moving c moves them.)
4. Completeness, the trace test (Leykin, Rodriguez & Sottile 2018): the fibre is X ∩ L with
   X = {(x, y): y = -F(x)} (irreducible, dimension n) and L = {y = -M x - e0}, a general affine
   space of codimension n for a random M (spaces of this form are dense among all of them).
   Moving e on the line e0 + s u (u random) moves L in a general pencil of parallel translates
   (n - 1 fixed combinations of its equations, one translated). (a) Complete => affine: the
   sum of the whole fibre's points is an entire function of s (no point escapes to infinity
   for a general pencil) growing at most linearly, so affine. (b) Incomplete => not affine: the
   pencil's curve is irreducible (Bertini's theorem), so its monodromy is transitive; a subset
   W whose trace is affine is single-valued, so every image of W under that monodromy has the
   same trace, hence (distinct subsets of general points have distinct sums; M x breaks any
   symmetry of F) W is invariant, hence all. The test compares three slices s = 0, s1, s2 (s1,
   s2 random): an affine function meets it exactly, any other fails it with probability one.
   The x part suffices (y = -M x - e is affine in x and s). Slices with M = 0 are NOT general:
   on Zeeman's machine and the double pendulum the complete fibre's trace fails (defect 0.35
   and 0.42, measured): at finite s points escape to infinity, the rotation variables along
   the isotropic directions c = ±i s (c^2 + s^2 stays finite), other coordinates with them.
5. The generic set: one parameter homotopy from (c0, e0) to (0, 0) with a random complex detour
   (the gamma trick) tracks the complete fibre to F(x; p0) = 0. By the parameter continuation
   theorem its endpoints include every isolated solution of F(x; p0); the finite nonsingular
   ones are the generic set, as the total-degree route keeps them. All paths go along one
   curve (paths along two curves may not be mixed: they differ by a monodromy permutation).

Stagnation (several fresh loops in a row with no new root) without a passing trace test is
reported as incomplete, never as complete; a path that fails is counted, never dropped
silently; a lost path of the final homotopy makes the set incomplete.

Cost: about (3 loops + 3) N'' paths, N'' the size of the augmented fibre (the degree of X, at
least the finite count of F; see bench/monodromy.py for how it compares with the Bezout bound).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import SolverError
from ..model.polynomial import ParametricSystem, PolySystem
from ..progress import Progress
from ..versions import bertini2_version
from .homotopy import (
    _SUCCESS,
    DOUBLE_FINAL_TOLERANCE,
    DOUBLE_MAX_STEPS,
    GENERIC_MAX_STEPS,
    INFINITE_CODES,
    NEVER_TRACKED,
    START_CENTRE,
    GenericSet,
    _bertini,
    _code,
    _end_points,
    _twins,
    coincident_rows,
    generic_start,
    is_singular,
    solver_errors,
)
from .neighbour import _newton
from .render import parametric_texts, render_parameter_homotopy, render_system

SALT = 28  # random stream of the augmented family (issue 28), apart from the start's
DISTINCT = 1e-7  # two roots closer than this (relative, as coincident_rows) are one
POLISHED = 1e-10  # a Newton-polished endpoint whose last step (relative) is above this: failed
TRACE_TOL = 1e-8  # the trace test passes when the relative defect of affinity is below this
MAX_STALL = 5  # fresh loops in a row that find no new root: stagnation (as HC.jl's default)
MAX_LOOPS = 64  # loops at most, whatever happens
DIRECTIONS = 1  # matrices M_k spanning the slopes the loops move through (measured: 1 is the
# cheapest; 2 or 4 need no fewer loops, and their longer texts cost more a path)
# Bertini's security max norm (1e5) on the loops and slices: a point of the augmented fibre may
# be larger (fourbar's are), and a path between general parameter values cannot diverge.
LOOP_MAX_NORM = 1e12
FIRST_LOOPS = 2  # loops made at the start (more are added when every root has been round all)
FINAL_ATTEMPTS = 3  # the final homotopy with a new detour when a path of it is lost
M, E = "mono_m", "mono_e"  # parameter names of the augmented family (unlike any variable)
Slice = tuple[np.ndarray, np.ndarray]  # parameters (c, e): the slope sum_k c_k M_k and e


@dataclass(frozen=True, eq=False)
class Augmented:
    """G(x; c, e) = F(x) + sum_k c_k M_k x + e around one start pair (at c = (1, 0, ..), M =
    M_0), and the trace test's pencil."""

    start: dict[str, complex]  # p0, the generic start parameters
    base: PolySystem  # F(x) = F(x; p0)
    matrices: np.ndarray  # M_k, shape (DIRECTIONS, n, n)
    x0: np.ndarray  # the constructed start root
    origin: Slice  # ((1, 0, ..), e0 = -F(x0) - M_0 x0): the base of every loop
    direction: np.ndarray  # u: the trace test's slices are (c0, e0 + s u)
    steps: tuple[complex, complex]  # s1, s2
    family: ParametricSystem  # parameters mono_m{k}, then mono_e{i}
    texts: tuple[str, ...]  # the family's functions as Bertini text

    def values(self, at: Slice) -> dict[str, complex]:
        """The family's parameter values at (c, e), by name."""
        return dict(zip(self.family.parameters, _vector(at), strict=True))

    def system(self, at: Slice) -> PolySystem:
        """G(x; c, e) as a numeric system."""
        return self.family.instantiate(_vector(at))

    def slice(self, k: int) -> Slice:
        """The trace test's slices: (c0, e0) for k = 0, (c0, e0 + s_k u) for k = 1, 2."""
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
    matrices, x0, u = (_gaussian(rng, shape) for shape in ((DIRECTIONS, n, n), n, n))
    e0 = -(base.evaluate(x0)[0] + matrices[0] @ x0)
    # |s| about 1 with |u| the size of e0: slices far enough apart that a missing point's
    # curvature shows, near enough that the paths stay short.
    u *= max(1.0, float(np.abs(e0).max()))
    steps = tuple(complex(z) for z in _gaussian(rng, 2))
    family = _family(base, matrices)
    origin = (np.eye(DIRECTIONS, 1)[:, 0].astype(complex), e0)
    return Augmented(start, base, matrices, x0, origin, u, steps, family, parametric_texts(family))


def _gaussian(rng: np.random.Generator, shape) -> np.ndarray:
    """Standard complex normal numbers (E|z|^2 = 1)."""
    return (rng.normal(size=shape) + 1j * rng.normal(size=shape)) / np.sqrt(2)


def _random_slice(rng: np.random.Generator, n: int, size: float) -> Slice:
    """A random point (c, e): c of modulus 1 and random phase (a slope as large as M's: a
    small one makes the fibre's points huge, and their paths fail), e complex normal of the
    given size."""
    c = _gaussian(rng, DIRECTIONS)
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
) -> Tracked:
    """`points` tracked from (c, e) = `start` to `target` by Bertini's parameter homotopy
    (double precision; failures, crossings and, unless `singular_ok`, singular endpoints again
    in adaptive precision), then the nonsingular endpoints polished by Newton's method on the
    target system."""
    family = aug.family
    texts = (
        render_parameter_homotopy(family, aug.values(start), aug.values(target), detour, aug.texts),
        render_system(aug.system(target)),
    )
    points = np.asarray(points, dtype=complex)
    # The final homotopy (singular_ok) keeps Bertini's max norm: its paths do go to infinity.
    options = {} if singular_ok else {"max_norm": LOOP_MAX_NORM}
    with solver_errors(f"a monodromy path batch ({len(points)} paths)"):
        out = _double_then_adaptive(texts, points, singular_ok, options)
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


def _double_then_adaptive(
    texts: tuple[str, str], points: np.ndarray, singular_ok: bool, options: dict
) -> dict:
    """The homotopy texts[0] (target texts[1]) from `points` in double precision, then in
    adaptive precision every path that did not end at a finite point, that met another or
    (unless `singular_ok`) that ended singular: homotopy.track_chunk's policy, but (a) the final
    homotopy's singular endpoints (the d = 0 artefacts, say) are not tracked again: they are
    not part of the generic set, and a retrack costs ~0.15 s each for the same point; (b) a
    path's outcome is read before the endgame too (_bertini_paths). `options`: more settings."""
    cpu = time.process_time()
    out = _bertini_paths(texts, points, "double", options)
    fields = [out[f] for f in ("codes", "finite", "singular")]
    redo = {
        k
        for k, (c, f, sing) in enumerate(zip(*fields, strict=True))
        if c != _SUCCESS or not f or (sing and not singular_ok)
    }
    redo = sorted(redo | set(_twins(*fields, out["points"])))
    if redo:
        again = _bertini_paths(texts, points[redo], "adaptive", options)
        for f in ("codes", "finite", "singular"):
            for k, i in enumerate(redo):
                out[f][i] = again[f][k]
        out["points"][redo] = again["points"]
    return {**out, "retracked_adaptive": len(redo), "cpu_seconds": time.process_time() - cpu}


def _bertini_paths(texts: tuple[str, str], points: np.ndarray, mptype: str, options: dict) -> dict:
    """One HomotopySolver call on one thread with the step caps of homotopy._track_texts, each
    path's outcome the code it stopped with: Bertini leaves the endgame's code NeverStarted
    when a path stopped before the endgame, where GoingToInfinity is a path at infinity (seen
    on the double pendulum's final homotopy), not a lost one."""
    bertini = _bertini()
    from bertini import nag_algorithm as na

    hom, target = (bertini.parse.system(text) for text in texts)
    solver = na.HomotopySolver(hom, list(points), target, mptype=mptype)
    if mptype == "double":
        solver.set(final_tolerance=DOUBLE_FINAL_TOLERANCE, max_num_steps=DOUBLE_MAX_STEPS)
    else:
        solver.set(max_num_steps=GENERIC_MAX_STEPS)
    solver.set(num_threads=1, **options)
    solver.solve(show_progress=False)
    meta = solver.solution_metadata()
    return {
        "codes": [_code(m) for m in meta],
        "finite": [bool(m.is_finite) for m in meta],
        "singular": [is_singular(m) for m in meta],
        "points": _end_points(solver.all_solutions(), points.shape[1]),
    }


def _polish(system: PolySystem, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Newton-polished points and which converged (below POLISHED)."""
    polished, size = _newton(system, x.copy())
    if polished is None:  # a singular Jacobian: keep Bertini's endpoints, flag none
        return x, np.isfinite(x).all(axis=1)
    return polished, (size < POLISHED) & np.isfinite(polished).all(axis=1)


def _known(roots: np.ndarray, x: np.ndarray, tol: float = DISTINCT) -> np.ndarray:
    """Whether each row of x is one of `roots`: the metric of coincident_rows (largest
    coordinate difference relative to 1 + the larger norm), vectorised over both sets."""
    if len(roots) == 0 or len(x) == 0:
        return np.zeros(len(x), dtype=bool)
    gap = np.abs(x[:, None, :] - roots[None, :, :]).max(axis=2)
    scale = np.maximum.outer(1 + np.abs(x).max(axis=1), 1 + np.abs(roots).max(axis=1))
    return (gap / scale < tol).any(axis=1)


@dataclass
class _Fibre:
    """The monodromy's working state (mutable, private): roots found at e0, in the order found;
    each loop's count of roots already pushed through it; the roots' points on the slices."""

    roots: np.ndarray
    loops: list[tuple[Slice, Slice]] = field(default_factory=list)
    sent: list[int] = field(default_factory=list)
    slices: list[np.ndarray] = field(default_factory=list)  # roots continued to s1, s2
    paths: int = 0
    failed: int = 0
    retracked: int = 0
    idle: int = 0  # fresh loops in a row that found no new root
    notes: list[str] = field(default_factory=list)

    def count(self, batch: Tracked, what: str) -> None:
        """Book one batch of paths: tracked, failed (with their codes), retracked."""
        self.paths += len(batch.ok)
        self.retracked += batch.retracked_adaptive
        bad = [batch.codes[k] for k in np.flatnonzero(~batch.ok)]
        if bad:
            self.failed += len(bad)
            self.notes.append(f"{what}: {len(bad)} paths failed ({', '.join(sorted(set(bad)))})")


def slice_points(aug: Augmented, roots: np.ndarray) -> tuple[list[np.ndarray], list[Tracked]]:
    """`roots` (at e0) continued to the trace test's two slices e0 + s1 u, e0 + s2 u (NaN
    rows where a path failed), and the two batches."""
    batches = [track_segment(aug, roots, aug.origin, aug.slice(k)) for k in (1, 2)]
    return [b.points for b in batches], batches


def trace_residual(aug: Augmented, fibres: list[np.ndarray]) -> tuple[float, str]:
    """The trace test on the same points at e0 and on the two slices: the defect of affinity
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
    """The trace test's relative defect for `roots` (points of the fibre at e0): below
    TRACE_TOL iff they are the whole fibre (with probability one)."""
    slices, _ = slice_points(aug, roots)
    return trace_residual(aug, [roots, *slices])[0]


def _trace(aug: Augmented, fib: _Fibre) -> tuple[float, str]:
    """The trace test on every root found: the roots not yet on the slices continued there."""
    new = fib.roots[len(fib.slices[0]) :]
    if len(new):
        slices, batches = slice_points(aug, new)
        for k, (pts, batch) in enumerate(zip(slices, batches, strict=True)):
            fib.count(batch, f"trace slice {k + 1}")
            fib.slices[k] = np.vstack([fib.slices[k], pts])
    return trace_residual(aug, [fib.roots, *fib.slices])


def _add(fib: _Fibre, x: np.ndarray) -> int:
    """Add the rows of x that are new roots (distinct from the known and from each other)."""
    fresh: list[np.ndarray] = []
    for p in x[~_known(fib.roots, x)]:
        if not fresh or not _known(np.array(fresh), p[None, :])[0]:
            fresh.append(p)
    if fresh:
        fib.roots = np.vstack([fib.roots, fresh])
    return len(fresh)


def _push(aug: Augmented, fib: _Fibre, k: int) -> int:
    """The roots not yet sent through loop k sent round it (e0 -> e_a -> e_b -> e0); returns
    how many new roots came back."""
    ea, eb = fib.loops[k]
    x = fib.roots[fib.sent[k] :]
    fib.sent[k] = len(fib.roots)
    for a, b in ((aug.origin, ea), (ea, eb), (eb, aug.origin)):
        batch = track_segment(aug, x, a, b)
        fib.count(batch, f"loop {k + 1}")
        x = batch.points[batch.ok]
        if not len(x):
            return 0
    return _add(fib, x)


def _explore(
    aug: Augmented, rng: np.random.Generator, limits: tuple[int, int, float], report: Progress
) -> tuple[_Fibre, float, bool, str]:
    """Monodromy from the start pair until the trace test passes: (state, trace residual,
    complete, reason). `limits`: (max_stall, max_loops, trace_tol). FIRST_LOOPS loops to begin
    with; a fresh one is added when every root has been round every loop; `max_stall` fresh
    loops in a row without a new root and the trace test still failing is stagnation:
    reported incomplete."""
    max_stall, max_loops, tol = limits
    n = len(aug.x0)
    fib = _Fibre(aug.x0[None, :].copy(), slices=[np.zeros((0, n), complex)] * 2)
    for _ in range(min(FIRST_LOOPS, max_loops)):
        fib.loops.append((_random_slice(rng, n, aug.size), _random_slice(rng, n, aug.size)))
        fib.sent.append(0)
    while True:
        residual, why = _trace(aug, fib)
        if residual <= tol:
            return fib, residual, True, f"trace test passed (defect {residual:.1e})"
        # The loop with the most roots still to send round it: the batches grow geometrically
        # (fewer Bertini calls) instead of walking one loop's cycles a root at a time.
        pending = [len(fib.roots) - sent for sent in fib.sent]
        k = int(np.argmax(pending)) if pending and max(pending) else None
        if k is None:
            failing = why or f"the trace test fails (defect {residual:.1e})"
            if fib.idle >= max_stall:
                stall = f"stagnation: {fib.idle} fresh loops in a row found no new root"
                return fib, residual, False, f"{stall} and {failing}"
            if len(fib.loops) >= max_loops:
                spent = f"the loop budget ({max_loops} loops) is spent"
                return fib, residual, False, f"{spent} and {failing}"
            fib.loops.append((_random_slice(rng, n, aug.size), _random_slice(rng, n, aug.size)))
            fib.sent.append(0)
            fib.idle, k = fib.idle + 1, len(fib.loops) - 1
        before = fib.paths
        if _push(aug, fib, k):
            fib.idle = 0
        report.update(fib.paths - before, note=f"{len(fib.roots)} roots, {len(fib.loops)} loops")


@dataclass(frozen=True)
class MonodromySet:
    """A generic solution set found by monodromy on the augmented family, trace-tested."""

    seed: int
    start: dict[str, complex]  # p0: the same generic start as the total-degree route
    points: np.ndarray  # finite nonsingular solutions of F(x; p0)
    augmented_points: np.ndarray  # the augmented fibre at e0 (N'' points)
    loops: int
    paths: int  # every path tracked: loops, trace slices and the final homotopy
    failed_paths: int  # paths of the loops and slices that reached no nonsingular root
    finite_endpoints: int  # of the final homotopy (nonsingular and singular)
    singular_endpoints: int
    lost_endpoints: int  # final paths neither finite nor on their way to infinity
    retracked_adaptive: int
    trace_residual: float
    complete: bool
    reason: str
    seconds: float
    cpu_seconds: float
    notes: tuple[str, ...] = ()

    @property
    def augmented(self) -> int:
        """N'': the size of the augmented fibre (the paths of the final homotopy)."""
        return len(self.augmented_points)

    def route(self) -> dict:
        """How the set was found (GenericSet.route)."""
        return {
            "method": "monodromy on the augmented family F + c M x + e, trace-tested",
            "augmented_count": self.augmented,
            "loops": self.loops,
            "paths_tracked": self.paths,
            "failed_paths": self.failed_paths,
            "lost_endpoints": self.lost_endpoints,
            "retracked_adaptive": self.retracked_adaptive,
            "trace_residual": self.trace_residual,
            "complete": self.complete,
            "reason": self.reason,
            "cpu_seconds": round(self.cpu_seconds, 3),
            "notes": "; ".join(self.notes),
        }

    def generic_set(self, key: str) -> GenericSet:
        """As a GenericSet (its `paths`: the final homotopy's, N'', so that paths - finite
        endpoints still counts the endpoints at infinity; every path tracked is in `route`).
        An incomplete set is refused (SolverError with the reason): never used as complete."""
        if not self.complete:
            raise SolverError(f"the monodromy generic set (seed {self.seed}): {self.reason}")
        return GenericSet(
            key, self.seed, dict(self.start), self.points, self.augmented,
            self.finite_endpoints, self.singular_endpoints, self.seconds, bertini2_version(),
            self.route(),
        )  # fmt: skip


def _descend(aug: Augmented, fib: _Fibre, rng: np.random.Generator) -> Tracked:
    """The augmented fibre tracked from (c0, e0) to (0, 0), i.e. to F(x; p0) = 0, with a random
    complex detour of the parameters (the gamma trick). A lost path sends every path along a
    new detour: the endpoints of one curve are all the isolated roots, but paths along two
    curves may not be mixed (they differ by a monodromy permutation)."""
    n = len(aug.x0)
    zero = (np.zeros(DIRECTIONS), np.zeros(n))
    for attempt in range(FINAL_ATTEMPTS):
        detour = aug.values(_random_slice(rng, n, aug.size))
        final = track_segment(aug, fib.roots, aug.origin, zero, detour, singular_ok=True)
        fib.paths += len(final.ok)
        fib.retracked += final.retracked_adaptive
        lost = int(_lost(final).sum())
        if not lost:
            break
        fib.notes.append(f"final homotopy, detour {attempt + 1}: {lost} paths lost")
    return final


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
    max_loops: int = MAX_LOOPS,
    trace_tol: float = TRACE_TOL,
) -> MonodromySet:
    """The generic solution set of `ps` at `seed`'s start parameters (centre + START_SPREAD
    noise, as generic_set) by monodromy on F + M x + e, trace-tested, then one parameter
    homotopy to F; `complete` only when the trace test passed and no final path was lost."""
    t0, cpu0 = time.perf_counter(), time.process_time()
    aug = augmented_family(ps, seed, centre)
    rng = np.random.default_rng((seed, SALT, 1))
    with Progress(f"monodromy generic set (seed {seed})", None, "paths") as report:
        fib, residual, complete, reason = _explore(
            aug, rng, (max_stall, max_loops, trace_tol), report
        )
        final = _descend(aug, fib, rng)
        report.update(len(final.ok))
    return _result(aug, fib, final, (residual, complete, reason), (t0, cpu0), seed)


def _result(
    aug: Augmented,
    fib: _Fibre,
    final: Tracked,
    verdict: tuple[float, bool, str],
    clocks: tuple[float, float],
    seed: int,
) -> MonodromySet:
    """The MonodromySet: the final homotopy's endpoints sorted as track() sorts them (finite,
    at infinity, lost), the verdict downgraded when a final path was lost or two met."""
    residual, complete, reason = verdict
    done = np.array([c == _SUCCESS for c in final.codes], dtype=bool) & final.finite
    lost = int(_lost(final).sum())
    points = final.points[final.ok]
    unpolished = int((done & ~final.singular & ~final.ok).sum())
    notes = list(fib.notes)
    if unpolished:
        notes.append(f"final homotopy: {unpolished} nonsingular endpoints failed Newton's method")
    problems = []
    if lost or unpolished:
        problems.append(f"{lost + unpolished} paths of the final homotopy lost")
    if coincident_rows(points, DISTINCT):
        problems.append("two paths of the final homotopy met")
    if problems:
        complete, reason = False, "; ".join([reason, *problems])
    return MonodromySet(
        seed, dict(aug.start), points, fib.roots, len(fib.loops), fib.paths, fib.failed,
        int(done.sum()), int((done & final.singular).sum()), lost, fib.retracked, residual,
        complete, reason,
        time.perf_counter() - clocks[0], time.process_time() - clocks[1], tuple(notes),
    )  # fmt: skip
