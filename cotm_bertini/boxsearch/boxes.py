"""Every critical point of V on a torus of angles, found and proved by one branch and bound over
boxes of angles, many boxes at a time (interval arithmetic on numpy arrays, model.intervals).

A `BoxLandscape` encloses grad V and its Hessian (a valid slope matrix where V is piecewise
smooth) over a batch of boxes, and the squared lengths of the springs with free lengths, where V
is not smooth at length 0. Each box is

- tested at a spring's cone (boxsearch.cones), where the landscape can (`cone_sets`) and the
  spring's least length over the box is small against its spread there: excluded, or proved
  to hold exactly one cone point (a critical point in Clarke's sense at zero length) and no
  other critical point;
- set aside, where a spring may be shorter than `short` and the box is no wider than
  `min_width` undecided (without cone tests also where it is shorter over the whole box; the
  statement bounds the spring length over these boxes);
- contracted, where the landscape can (`contract`: the spheres' bars along their pulls), to
  the part that can hold a critical point, kept no thinner than THIN of its widest side and
  off-centre (a halving line never through a symmetric point it was centred on); excluded
  where nothing is left;
- excluded, where the enclosure of some component of grad V misses 0 (a spring's term is
  enclosed through its cone too: finite where its length may be 0);
- decided by the Krawczyk operator K(X) = m - Y g(m) + (I - Y H(X)) (X - m), Y the inverse of
  the Hessian's midpoint: K(X) inside the interior of X proves exactly one critical point in X
  (it lies in K(X)), K(X) disjoint from X proves none;
- or split along its (at most two) widest sides; a box that reaches the smallest width
  undecided is listed.

A box with one critical point gives a root: Newton in double precision from the middle of
K(X) n X. Boxes are rows of two (B, n) arrays, lo and hi, in radians (a box listed in a result
is one row lo_1..lo_n, hi_1..hi_n); the domain is [offset, offset + 2 pi]^n, with an offset that
is no simple fraction of pi so that no symmetric pose falls on the edges of the first grid or of
its halvings.
"""

from __future__ import annotations

import contextlib
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from ..model.intervals import Interval
from ..progress import Progress
from .cones import cone_test, near_cone
from .cones import sub_landscape as _sub
from .krawczyk import krawczyk_step
from .stability import no_minimum

TWO_PI = 2 * math.pi
OFFSET = -0.0123456789  # radians: the domain's lower corner (see the module docstring)
BATCH = 4096  # boxes a step: large enough that numpy's loops, not Python, set the pace
KRAWCZYK_WIDTH = 0.2  # radians: wider boxes are split, not tested (the test rarely decides them)
SHORT = 1e-3  # length units: springs shorter than this are set aside (V has a cone point at 0)
MIN_WIDTH = 1e-4  # radians: the smallest box away from a critical point
NEAR_CONE = 10.0  # undecided where a spring may be shorter than this times SHORT: set aside
NEAR_CONDITION = 1e10  # a critical point worth splitting below MIN_WIDTH for is no worse than this
ROOT_FLOOR = 1e-10  # radians: boxes are not split below this, whatever a spring's length
MAX_CUTS = 2  # sides halved at a split (see _split)
THIN = 0.25  # a contracted box keeps each side at least this share of its widest (_inflated)
SKEW = 0.0731  # of a contracted box's half width: its middle moved off a symmetric point
KRAWCZYK_BATCH = 1024  # boxes for the Krawczyk test wait until this many are pending
# landscape.free's codes: an angle V is flat along, or may be, or no critical point in the box
FREE, EDGE, NONE = 2, 1, -1
EDGE_WIDTH = 0.05  # radians: a box at the edge of a free region this small is left undecided


class BoxLandscape(Protocol):
    """V over batches of boxes (see the module docstring)."""

    n: int

    def enclose(self, box: Interval) -> tuple[Interval, Interval, object]:
        """Over each box: the squared lengths of the springs with free lengths (B, s), grad V
        (B, n), and what `hessian` needs of the box (its cables' states)."""

    def hessian(self, box: Interval, states: object) -> Interval:
        """A slope matrix of grad V over each box (B, n, n)."""

    def derivatives(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """grad V and its Hessian at points (R, n) in double precision."""

    # Optional: `domain(start) -> (lo, hi)`, the boxes that cover the configuration space
    # (charts of a sphere, say); without it the torus grid of `initial_boxes`.
    # Optional: `cone_sets` (True) and `cone_parts(box, spring) -> boxsearch.cones.ConeParts`:
    # boxes through a spring's zero-length poses are tested there (boxsearch.cones).
    # Optional: `free(box, states, grad) -> (code (B, n) int, slack)`: FREE for the angles along
    # which grad V is 0 at every critical point in the box whatever they are (a node with its
    # every element slack and no load), with the cables to take as slack there (`slack`, name
    # -> (B,) bool, for enclose(box, slack) and the states hessian reads); EDGE where that may
    # be so but is not proved; NONE where no critical point is in the box: see _step.
    # Optional: `contract(box) -> (lo, hi)`, called right after `enclose(box)`: each box shrunk
    # to a box that holds every critical point it holds (lo > hi: none).
    # Optional: `only` ("all"; "stable": a box where V can have no local minimum is dropped,
    # boxsearch.stability, so that the roots found include every minimum, not every saddle).


class BoxFamily(Protocol):
    """One landscape at several parameter values (`members`), searched together (search_each):
    `rows(member)` is the landscape over a batch whose box i belongs to member[i]; that
    landscape's `sub(rows)` is the one over the boxes `rows` of its batch."""

    n: int
    members: int

    def rows(self, member: np.ndarray) -> BoxLandscape:
        """The landscape over a batch of boxes, box i at member[i]'s parameter values."""


@dataclass
class BoxSearch:
    """What the search established: roots (one a box with exactly one critical point), boxes
    set aside at cone points, boxes left undecided (at the smallest width, or at the budget)."""

    roots: np.ndarray  # (R, n) angles in radians, in the domain
    root_boxes: np.ndarray  # (R, 2n): lo and hi of the box each root was proved alone in
    newton_failed: int  # 'one' boxes where Newton did not converge inside K(X) (kept: mid K)
    set_aside: int
    set_aside_bound: float  # every spring is at most this long somewhere in each box set aside
    set_aside_boxes: np.ndarray  # (A, 2n): where the cone points are (each lies in one)
    undecided: np.ndarray  # (U, 2n)
    boxes: int
    seconds: float
    shortest_length: float  # every spring with a free length is at least this long elsewhere
    budget_hit: str = ""
    notes: list[str] = field(default_factory=list)
    volume: float = 0.0  # of the domain searched (0: the torus, (2 pi)^n)
    cpu_seconds: float = 0.0  # in every process that searched (`seconds` is the wall time)
    shares: int = 1  # the shares of boxes searched apart (boxsearch.box_shares), merged here
    # Boxes where grad V is 0 along some angles whatever they are (a node whose every element
    # is slack, with no load: V is flat along it), each with exactly one critical point of the
    # other angles, the same for every value of the free ones: pieces of a region of
    # equilibria. (F, 2n) boxes, (F, n) their points (free angles: the box's middle), (F, n)
    # which angles are free.
    free_boxes: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    free_points: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    free_masks: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), dtype=bool))
    edge: int = 0  # of the undecided boxes, those at the edge of a free region (EDGE_WIDTH)
    # Cone points (boxsearch.cones): each a pose where a spring has zero length and V a critical
    # point in Clarke's sense, proved alone in its box, no smooth one there. (C, 3n + 3): the
    # angles, the spring (index among those with free lengths), |lambda| (the other elements'
    # pull there, against k L0), the index, the box (lo, hi).
    cones: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))

    @property
    def undecided_share(self) -> float:
        """The share of the domain's volume in undecided boxes."""
        if not len(self.undecided):
            return 0.0
        n = self.undecided.shape[1] // 2
        w = self.undecided[:, n:] - self.undecided[:, :n]
        return float(np.prod(w, axis=1).sum() / (self.volume or TWO_PI**n))


def initial_boxes(n: int, start: int) -> tuple[np.ndarray, np.ndarray]:
    """A start x ... x start grid over the domain: (lo, hi), each (start^n, n)."""
    edges = OFFSET + TWO_PI * np.arange(start + 1) / start
    idx = np.indices((start,) * n).reshape(n, -1).T
    return edges[idx], edges[idx + 1]


def domain(land: BoxLandscape, start: int) -> tuple[np.ndarray, np.ndarray]:
    """The boxes a search starts from: the landscape's own cover, or the torus grid."""
    cover = getattr(land, "domain", None)
    return cover(start) if cover is not None else initial_boxes(land.n, start)


def search(
    land: BoxLandscape,
    short: float,
    min_width: float,
    start: int = 8,
    max_boxes: int | None = None,
    max_seconds: float | None = None,
    label: str = "real search",
    boxes: tuple[np.ndarray, np.ndarray] | None = None,
    step: Callable[[float], None] | None = None,
) -> BoxSearch:
    """Decide every box of the domain (module docstring), or of `boxes` (lo, hi) where given
    (a share of it, for a worker); stop at `max_boxes` or `max_seconds` with the boxes not yet
    decided listed as undecided. `step`: told the share of the volume decided after each batch
    step (a worker's search reports through it)."""
    first = boxes if boxes is not None else domain(land, start)
    return _search(land, 1, first, short, min_width, max_boxes, max_seconds, label,
                   step=step)[0]  # fmt: skip


def search_each(
    family: BoxFamily,
    short: float,
    min_width: float,
    start: int = 8,
    max_boxes: int | None = None,
    max_seconds: float | None = None,
    label: str = "real search",
    boxes: tuple[np.ndarray, np.ndarray] | None = None,
) -> list[BoxSearch]:
    """`search` of each member of a family (one landscape at several parameter values) over
    the whole domain, or over `boxes` (lo, hi) where given (the rest of the domain known to
    hold no critical point of any member: `cover`), all in the same batches of boxes: each
    member's search takes the steps its own search of those boxes would (its boxes, roots and
    lists equal, in the same order), and a batch holds every member's step, so numpy's loops,
    not Python, set the pace. `max_boxes` is each member's; `max_seconds` each member's share
    of the time (all stop at members x max_seconds)."""
    lo, hi = domain(family, start)
    whole = float(np.prod(hi - lo, axis=1).sum())
    first = (lo, hi) if boxes is None else boxes
    return _search(family, family.members, first, short, min_width, max_boxes, max_seconds,
                   label, whole)  # fmt: skip


def cover(land: BoxLandscape, first: tuple[np.ndarray, np.ndarray], stop: float = 0.2,
          ) -> tuple[tuple[np.ndarray, np.ndarray], int]:  # fmt: skip
    """The boxes of `first` (lo, hi) that the enclosure of grad V does not exclude, halved (as
    `_split`) until no wider than `stop`, and the boxes looked at. Over a family's hull
    (TorusFamily.hull: every number an interval holding each member's) a box excluded holds
    no critical point of any member, so their searches start from what is left."""
    todo, keep, count = [first], [], 0
    while todo:
        lo, hi = _take(todo, BATCH)
        count += len(lo)
        _, grad, _ = land.enclose(Interval(lo, hi))
        live = grad.contains_zero().all(axis=1)
        lo, hi = lo[live], hi[live]
        small = (hi - lo).max(axis=1) <= stop
        keep.append((lo[small], hi[small]))
        if (~small).any():
            a, b, _ = _split(lo[~small], hi[~small], np.arange(int((~small).sum())))
            todo.append((a, b))
    n = first[0].shape[1]
    return (_rows([a for a, _ in keep], n), _rows([b for _, b in keep], n)), count


@dataclass
class _Member:
    """One search's state: its stack of boxes to decide and what it established so far."""

    stack: list
    deferred: list = field(default_factory=list)  # boxes waiting for the Krawczyk test
    roots: list = field(default_factory=list)
    root_boxes: list = field(default_factory=list)
    undecided: list = field(default_factory=list)
    aside_boxes: list = field(default_factory=list)
    boxes: int = 0
    aside: int = 0
    bound: float = 0.0
    shortest: float = math.inf
    failed: int = 0
    budget: str = ""
    free: list = field(default_factory=list)  # (box, point, mask) rows of free pieces
    edge: int = 0
    peaks: list = field(default_factory=list)  # cone points' rows (_Outcome.peaks)

    def stop(self, why: str) -> None:
        """Every box not yet decided listed as undecided (the next batch first), with why the
        search stopped."""
        self.budget = why
        self.undecided += [np.hstack([a, b]) for a, b in self.stack + self.deferred]
        self.stack, self.deferred = [], []

    def live(self) -> bool:
        return bool(self.stack or self.deferred)

    def next_batch(self) -> tuple[np.ndarray, np.ndarray, bool]:
        """(lo, hi, for the Krawczyk test): the boxes waiting for the test once KRAWCZYK_BATCH
        of them are (or nothing else is), else the next BATCH from the stack. The test's slope
        matrix costs the same per call for 10 boxes as for 1,000 (prism_slack: a third of the
        search went in 332 small calls)."""
        if not self.stack or sum(len(d[0]) for d in self.deferred) >= KRAWCZYK_BATCH:
            lo = np.vstack([d[0] for d in self.deferred])
            hi = np.vstack([d[1] for d in self.deferred])
            self.deferred = []
            return lo, hi, True
        return (*_take(self.stack, BATCH), False)

    def result(self, n: int, clocks: tuple, volume: float) -> BoxSearch:
        """The record (`clocks`: this search's wall and CPU seconds)."""
        free = _rows(self.free, 4 * n)
        return BoxSearch(
            _rows(self.roots, n), _rows(self.root_boxes, 2 * n), self.failed,
            self.aside, self.bound, _rows(self.aside_boxes, 2 * n), _rows(self.undecided, 2 * n),
            self.boxes, clocks[0], self.shortest, self.budget, volume=volume,
            cpu_seconds=clocks[1], free_boxes=free[:, : 2 * n], free_points=free[:, 2 * n : 3 * n],
            free_masks=free[:, 3 * n :] > 0.5, edge=self.edge,
            cones=_rows(self.peaks, 3 * n + 3),
        )  # fmt: skip


def _search(land, members: int, first: tuple, short, min_width, max_boxes, max_seconds, label,
            whole: float | None = None, step=None):  # fmt: skip
    """The members' searches in lockstep: each step takes every live member's next batch (as
    its own search would) into one call of `_step`, and hands each its rows of the outcome.
    `whole`: the volume of the domain where `first` is only the part left to search."""
    t0, c0 = time.perf_counter(), time.process_time()
    n = first[0].shape[1]
    volume = float(np.prod(first[1] - first[0], axis=1).sum())
    group = [_Member([first]) for _ in range(members)]
    pending = float(members)
    report = Progress(label, 1.0, "of the poses decided")
    while True:
        elapsed = time.perf_counter() - t0
        for m in group:
            if m.live() and ((max_boxes and m.boxes >= max_boxes) or (
                    max_seconds and elapsed > max_seconds * members)):  # fmt: skip
                m.stop(f"stopped at {m.boxes:,} boxes after {elapsed:.1f} s")
        live = [k for k, m in enumerate(group) if m.live()]
        if not live:
            break
        takes = [group[k].next_batch() for k in live]
        sizes = np.array([len(a) for a, _, _ in takes])
        lo = takes[0][0] if len(takes) == 1 else np.vstack([a for a, _, _ in takes])
        hi = takes[0][1] if len(takes) == 1 else np.vstack([b for _, b, _ in takes])
        testing = np.repeat([t for _, _, t in takes], sizes)
        view = land.rows(np.repeat(live, sizes)) if hasattr(land, "rows") else land
        out = _step(view, lo, hi, short, min_width, testing)
        ends = np.cumsum(sizes)
        for k, part, (_, _, tested) in zip(live, out.parts(ends), takes, strict=True):
            part.record(group[k], counted=tested)
        decided = float(np.prod(hi - lo, axis=1).sum())
        for a, b in (out.split, out.later):
            decided -= float(np.prod(b - a, axis=1).sum())
        pending -= decided / volume
        report.set(1.0 - pending / members, note=f"{sum(m.boxes for m in group):,} boxes")
        if step is not None:
            step(1.0 - pending / members)
    report.close()
    clocks = ((time.perf_counter() - t0) / members, (time.process_time() - c0) / members)
    return [m.result(n, clocks, whole or volume) for m in group]


def spread(
    land: BoxLandscape, first: tuple[np.ndarray, np.ndarray], short: float, min_width: float,
    want: int, steps: int,
) -> tuple[tuple[np.ndarray, np.ndarray], BoxSearch]:  # fmt: skip
    """Breadth-first batch steps over the boxes `first` (lo, hi) until at least `want` are
    left to decide, or for at most `steps`: (the boxes left, what the steps decided, over the
    volume of `first`). Their fate is what `search` gives them: a box's is its own."""
    t0, c0 = time.perf_counter(), time.process_time()
    volume = float(np.prod(first[1] - first[0], axis=1).sum())
    (lo, hi), m = first, _Member([])
    for _ in range(steps):
        if not len(lo) or len(lo) >= want:
            break
        out = _step(land, lo, hi, short, min_width, np.ones(len(lo), dtype=bool))
        out.parts(np.array([len(lo)]))[0].record(m, counted=False)
        lo, hi = m.stack.pop() if m.stack else (lo[:0], hi[:0])
    clocks = (time.perf_counter() - t0, time.process_time() - c0)
    return (lo, hi), m.result(lo.shape[1], clocks, volume)


def merged(parts: list[BoxSearch], volume: float, seconds: float, apart: float = 1e-8):
    """One record of searches over disjoint parts of a domain of `volume` (`seconds`: the wall
    time of them all): counts summed, boxes listed together, the bounds combined, each root
    once (two within `apart` rad of each other, angles taken modulo 2 pi, are one: a root on
    the face two parts' boxes share)."""
    n = parts[0].roots.shape[1]
    roots = np.vstack([p.roots for p in parts])
    keep = distinct(roots, apart)
    keep = keep[_ordered(roots[keep])]
    hits = [p.budget_hit for p in parts if p.budget_hit]
    shares = sum(p.shares for p in parts)
    notes = [x for p in parts for x in p.notes]
    if len(keep) < len(roots):
        notes.append(f"{len(roots) - len(keep)} roots proved in two shares' boxes kept once")
    total = lambda name: sum(getattr(p, name) for p in parts)  # noqa: E731
    boxes = lambda name: _rows([getattr(p, name) for p in parts], 2 * n)  # noqa: E731
    free = [p for p in parts if p.free_boxes.size]
    return BoxSearch(
        roots[keep], boxes("root_boxes")[keep], total("newton_failed"), total("set_aside"),
        max(p.set_aside_bound for p in parts), boxes("set_aside_boxes"), boxes("undecided"),
        total("boxes"), seconds, min(p.shortest_length for p in parts),
        f"{len(hits)} of {shares} shares {hits[0]}" if hits else "", notes, volume,
        total("cpu_seconds"), shares, _rows([p.free_boxes for p in free], 2 * n),
        _rows([p.free_points for p in free], n),
        _rows([p.free_masks for p in free], n).astype(bool), total("edge"),
        _rows([p.cones for p in parts if p.cones.size], 3 * n + 3),
    )  # fmt: skip


def _ordered(roots: np.ndarray) -> np.ndarray:
    """The roots' order by their angles (first, then second, ...): one order whichever shares
    came back first (the search in one process keeps the order it found them in: fold seeds
    follow it)."""
    return np.lexsort(roots.T[::-1]) if len(roots) else np.zeros(0, dtype=np.int64)


def distinct(points: np.ndarray, apart: float, wrap: bool = True) -> np.ndarray:
    """The indices of the points (R, n angles) not within `apart` rad (on the torus: angles
    modulo 2 pi; without `wrap`, plain coordinates) of an earlier one."""
    period = TWO_PI if wrap else np.inf
    keep: list[int] = []
    for i in range(len(points)):
        if not keep:
            keep.append(i)
            continue
        diff = points[keep] - points[i]
        gap = np.abs((diff + math.pi) % period - math.pi if wrap else diff).max(axis=1)
        if gap.min() > apart:
            keep.append(i)
    return np.array(keep, dtype=np.int64)


def _rows(parts: list, width: int) -> np.ndarray:
    return np.vstack(parts).reshape(-1, width) if parts else np.zeros((0, width))


def _take(stack: list, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Up to `count` boxes from the top of the stack (depth first keeps it short), from as
    many of its entries as it takes: a step of few boxes costs numpy's overhead all the same."""
    los, his, have = [], [], 0
    while stack and have < count:
        lo, hi = stack.pop()
        if have + len(lo) > count:
            cut = len(lo) - (count - have)
            stack.append((lo[:cut], hi[:cut]))
            lo, hi = lo[cut:], hi[cut:]
        los.append(lo)
        his.append(hi)
        have += len(lo)
    if len(los) == 1:
        return los[0], his[0]
    return np.vstack(los), np.vstack(his)


@dataclass
class _Outcome:
    """One batch's verdicts, by row of the batch (each `*_rows` ascending): the boxes set
    aside (`aside`: those short or at the smallest width, then `cone`: next to a cone point),
    with the bound of each; the leaves' shortest spring; the roots; the boxes left undecided;
    the boxes to split (lo, hi) with the row each came from (`parent`)."""

    rows: int
    aside_rows: np.ndarray
    aside: np.ndarray  # (k, 2n + 1): lo, hi, the spring bound
    cone_rows: np.ndarray
    cone: np.ndarray
    leaf_rows: np.ndarray
    leaf_short: np.ndarray
    root_rows: np.ndarray
    roots: np.ndarray  # (r, n)
    root_boxes: np.ndarray  # (r, 2n)
    root_good: np.ndarray  # (r,): Newton converged inside K n X
    left_rows: np.ndarray
    left: np.ndarray
    split: tuple[np.ndarray, np.ndarray]
    parent: np.ndarray
    later_rows: np.ndarray
    later: tuple[np.ndarray, np.ndarray]  # boxes for the Krawczyk test, handed back
    free_rows: np.ndarray
    free: np.ndarray  # (f, 4n): lo, hi, the point, the free angles (1.0) of each free piece
    edge_rows: np.ndarray  # of the boxes left, those at the edge of a free region
    peak_rows: np.ndarray
    peaks: np.ndarray  # (c, 3n + 3): a cone point's angles, spring, |lambda|, index, lo, hi

    def parts(self, ends: np.ndarray) -> list[_Part]:
        """Each member's share of the outcome (the members' rows end at `ends`)."""
        if len(ends) == 1:
            return [_Part(int(ends[0]), self.aside, self.cone, self.leaf_short, self.roots,
                          self.root_boxes, self.root_good, self.left, self.split,
                          self.later, self.free, len(self.edge_rows), self.peaks)]  # fmt: skip
        cut = lambda rows, *arrays: [np.split(a, np.searchsorted(rows, ends[:-1]))  # noqa: E731
                                     for a in arrays]  # fmt: skip
        aside, cone = cut(self.aside_rows, self.aside)[0], cut(self.cone_rows, self.cone)[0]
        (short,) = cut(self.leaf_rows, self.leaf_short)
        roots, boxes, good = cut(self.root_rows, self.roots, self.root_boxes, self.root_good)
        (left,) = cut(self.left_rows, self.left)
        (free,) = cut(self.free_rows, self.free)
        (peaks,) = cut(self.peak_rows, self.peaks)
        edge = np.diff(np.searchsorted(self.edge_rows, ends), prepend=0)
        later = zip(*cut(self.later_rows, *self.later), strict=True)
        member = np.searchsorted(ends, self.parent, side="right")
        order = np.argsort(member, kind="stable")  # each member's children in their order
        at = np.searchsorted(member[order], np.arange(1, len(ends)))
        lo, hi = (np.split(a[order], at) for a in self.split)
        sizes = np.diff(ends, prepend=0)
        return [_Part(*v) for v in zip(sizes, aside, cone, short, roots, boxes, good, left,
                                        zip(lo, hi, strict=True), later, free, edge,
                                        peaks, strict=True)]  # fmt: skip


@dataclass
class _Part:
    """One member's share of a batch's outcome (see _Outcome)."""

    boxes: int
    aside: np.ndarray
    cone: np.ndarray
    leaf_short: np.ndarray
    roots: np.ndarray
    root_boxes: np.ndarray
    root_good: np.ndarray
    left: np.ndarray
    split: tuple[np.ndarray, np.ndarray]
    later: tuple[np.ndarray, np.ndarray]
    free: np.ndarray
    edge: int
    peaks: np.ndarray

    def record(self, m: _Member, counted: bool) -> None:
        """Into the member's search: counts (the boxes unless `counted` when first taken),
        bounds, lists, the boxes to split pushed and those for the Krawczyk test kept."""
        m.boxes += 0 if counted else int(self.boxes)
        for rows in (self.aside, self.cone):
            if len(rows):
                m.aside += len(rows)
                m.aside_boxes.append(rows[:, :-1])
                m.bound = max(m.bound, float(rows[:, -1].max()))
        if len(self.leaf_short):
            m.shortest = min(m.shortest, float(self.leaf_short.min()))
        if len(self.roots):
            m.roots.append(self.roots)
            m.root_boxes.append(self.root_boxes)
            m.failed += int((~self.root_good).sum())
        if len(self.left):
            m.undecided.append(self.left)
        if len(self.free):
            m.free.append(self.free)
        m.edge += int(self.edge)
        if len(self.peaks):
            m.peaks.append(self.peaks)
        if len(self.split[0]):
            m.stack.append(self.split)
        if len(self.later[0]):
            m.deferred.append(self.later)


def _step(land: BoxLandscape, lo, hi, short: float, min_width: float, testing) -> _Outcome:
    """One batch: each box set aside, excluded, proved to hold one root, left, split, or (a
    box small enough for the Krawczyk test, where `testing` is False) handed back for it."""
    rows = np.arange(len(lo))
    dd, grad, states, code, slack, (lo, hi, gone) = _enclosed(land, Interval(lo, hi))
    free = code == FREE
    width = np.where(free, 0.0, hi - lo).max(axis=1)
    # At the edge of a free region (a node's cables may all be slack) every box holds
    # equilibria of the region, and halving cannot decide it: left undecided, counted apart.
    edge = (code == EDGE).any(axis=1) & (width <= EDGE_WIDTH)
    aside, smooth = np.zeros(len(lo), dtype=bool), np.ones(len(lo), dtype=bool)
    floor = np.full(len(lo), float(min_width))
    springs = dd.lo.shape[1] > 0
    cones = springs and getattr(land, "cone_sets", False)
    near = np.zeros(len(lo), dtype=bool)
    if springs:
        smooth = ~(dd.lo <= short * short).any(axis=1)
        aside = ~smooth & (width <= min_width)
        if not cones:  # no test through a cone: a box all shorter than `short` is set aside
            aside |= (dd.hi < short * short).any(axis=1)
        floor = _floor(dd, min_width)
    if cones:  # boxes through a spring's cone: tested there (boxsearch.cones), not smoothly
        near, which = near_cone(dd)
        shortest = np.argmin(dd.lo, axis=1)  # a spring shorter than `short`: its cone rules
        which = np.where(smooth, which, shortest)
        near = (near | ~smooth) & ~aside & ~free.any(axis=1)
    decided, later = np.zeros(len(lo), dtype=bool), np.zeros(len(lo), dtype=bool)
    decided[gone] = True
    off = _off_loop(land, grad)
    decided |= off
    aside &= ~off
    test = np.flatnonzero(~aside & (smooth | cones) & ~gone & ~off)  # grad V finite through cones
    n = lo.shape[1]
    found = (rows[:0], np.zeros((0, n)), np.zeros((0, 2 * n)), np.zeros(0, dtype=bool))
    pieces = (rows[:0], np.zeros((0, 4 * n)))
    peaks = (rows[:0], np.zeros((0, 3 * n + 3)))
    if len(test):
        zero = grad[test].contains_zero().all(axis=1) & ~(code[test] == NONE).any(axis=1)
        decided[test[~zero]] = True
        cand = test[zero & (width[test] <= KRAWCZYK_WIDTH)]
        if cones:
            at = cand[near[cand]]
            cand = cand[~near[cand] & (dd.lo[cand] > 0).all(axis=1)]
            if len(at):
                verdict, peaks = _cone_tested(land, lo, hi, at, which[at])
                decided[at[verdict != 0]] = True
        later[cand[~testing[cand]]] = True
        cand = cand[testing[cand]]
        if len(cand):
            verdict, found, pieces = _tested(land, lo, hi, cand, states, free, slack)
            decided[cand[verdict != 0]] = True
    leaf = ~aside & (decided | ~smooth) if springs else np.zeros(len(lo), dtype=bool)
    rest = ~aside & ~decided & ~later
    small = rest & ((width <= floor) | edge)
    if small.any():  # a root in or next to the box: split on (Krawczyk wants small boxes there)
        at = np.flatnonzero(small)
        near = _root_near(_sub(land, at), lo[at], hi[at])
        small[at[near & (width[at] > ROOT_FLOOR)]] = False
    cone = np.zeros(len(lo), dtype=bool)
    if small.any() and springs:
        # Next to a cone point the 1/d terms keep the enclosures too wide to decide: such a
        # box is set aside as the short ones are (its spring bound counted), not undecided.
        cone = small & (dd.lo < (NEAR_CONE * short) ** 2).any(axis=1)
        small &= ~cone
        rest &= ~cone  # set aside: not split as well
    # Next to a cone point (a spring may be short) nothing is tested until the boxes are set
    # aside at the smallest width: two halvings at once there save a batch step each.
    deep = rest & ~small & ~smooth & (width > 4 * min_width) & (not cones)
    plain = rest & ~small & ~deep
    once = _split(lo[plain], hi[plain], rows[plain], free)
    twice = _split(*_split(lo[deep], hi[deep], rows[deep], free), free)
    bound = lambda m: np.hstack([lo[m], hi[m], _spring_bound(dd.hi[m])[:, None]])  # noqa: E731
    low = np.sqrt(np.maximum(dd.lo[leaf].min(axis=1), 0.0)) if springs else np.zeros(0)
    return _Outcome(
        len(lo), rows[aside], bound(aside), rows[cone], bound(cone), rows[leaf], low, *found,
        rows[small], np.hstack([lo[small], hi[small]]), (np.vstack([once[0], twice[0]]),
        np.vstack([once[1], twice[1]])), np.concatenate([once[2], twice[2]]),
        rows[later], (lo[later], hi[later]), *pieces, rows[small & edge], *peaks,
    )  # fmt: skip


def _off_loop(land: BoxLandscape, grad: Interval) -> np.ndarray:
    """The boxes a loop's closure excludes (boxsearch.loops: F's first components are the
    closing pin's mismatch, finite where a spring's 1/d makes the rest unbounded): off the
    loop's curve of poses, whether a spring may be short there or not."""
    loop = getattr(land, "loop", None)
    if loop is None:
        return np.zeros(len(grad.lo), dtype=bool)
    return ~grad[:, : loop.constraints].contains_zero().all(axis=1)


def _enclosed(land: BoxLandscape, box: Interval) -> tuple:
    """(dd, grad, states, code, slack, (lo, hi, gone)) of a batch: the enclosures, `free`'s
    verdict (the enclosures redone with the cables it finds slack), the contracted boxes."""
    dd, grad, states = land.enclose(box)
    # Along free angles grad V is 0 whatever they are: the box is searched in the others.
    code, slack = _free(land, box, states, grad)
    if slack:  # those boxes' critical points have these cables slack: V as it is there
        dd, grad, states = land.enclose(box, slack=slack)
    return dd, grad, states, code, slack, _contracted(land, box)


def _contracted(land: BoxLandscape, box: Interval) -> tuple:
    """(lo, hi, gone): the boxes shrunk by the landscape's `contract` where it has one (to the
    part that can hold a critical point; the enclosures over the whole box hold over it), and
    which ones it emptied (left as they were: excluded)."""
    rule = getattr(land, "contract", None)
    if rule is None:
        return box.lo, box.hi, np.zeros(len(box.lo), dtype=bool)
    lo, hi = rule(box)
    gone = (lo > hi).any(axis=1)
    lo, hi = _inflated(lo, hi, box.lo, box.hi)
    return np.where(gone[:, None], box.lo, lo), np.where(gone[:, None], box.hi, hi), gone


def _inflated(lo, hi, outer_lo, outer_hi) -> tuple:
    """Boxes (lo, hi) each side widened by a tenth of its width each way, and to at least THIN
    times the widest side of its box `outer` (that it was contracted from), within that box:
    K(X) inside X cannot be proved on a box thin in some side (a contraction can pin an angle
    to rounding error) nor with the root on its edge (where a contraction may leave it), and
    the widened box holds no critical point the contracted one does not. Its middle is moved
    off the contracted box's (SKEW of its half width): a contraction can centre a box on a
    symmetric critical point, and a halving would then put that point on an edge."""
    floor = 0.5 * THIN * (outer_hi - outer_lo).max(axis=1, keepdims=True)
    half = np.maximum(0.6 * (hi - lo), floor)
    mid = 0.5 * (lo + hi) + SKEW * half
    return np.maximum(outer_lo, mid - half), np.minimum(outer_hi, mid + half)


def _tested(land, lo, hi, cand, states, free, slack) -> tuple:
    """The Krawczyk test of the batch's boxes `cand`: (verdict, the roots found as _roots
    gives them, the free pieces (rows, lo hi point mask)). Looking for minima alone (`only`),
    a box where V can have none (boxsearch.stability, on the test's own slope matrix) is
    excluded first."""
    h = _sub(land, cand).hessian(Interval(lo[cand], hi[cand]), _subset(states, cand))
    keep = np.ones(len(cand), dtype=bool)
    if getattr(land, "only", "all") == "stable":
        keep = ~no_minimum(h) | free[cand].any(axis=1)
    verdict = np.full(len(cand), -1, dtype=np.int8)
    k_lo, k_hi = lo[cand], hi[cand]
    if keep.any():
        at = cand[keep]
        verdict[keep], k_lo[keep], k_hi[keep] = krawczyk(
            _sub(land, at),
            lo[at],
            hi[at],
            _subset(states, at),
            free[at],
            _subset(slack, at),
            Interval(h.lo[keep], h.hi[keep]),
        )
    n = lo.shape[1]
    found = (cand[:0], np.zeros((0, n)), np.zeros((0, 2 * n)), np.zeros(0, dtype=bool))
    pieces = (cand[:0], np.zeros((0, 4 * n)))
    flat = free[cand].any(axis=1)
    one = (verdict == 1) & ~flat
    if one.any():
        at = cand[one]
        found = (at, *_roots(_sub(land, at), lo[at], hi[at], k_lo[one], k_hi[one]))
    one = (verdict == 1) & flat
    if one.any():
        at = cand[one]
        x = _free_points(_sub(land, at), lo[at], hi[at], k_lo[one], k_hi[one], free[at],
                         _subset(slack, at))  # fmt: skip
        pieces = (at, np.hstack([lo[at], hi[at], x, free[at]]))
    return verdict, found, pieces


def _cone_tested(land, lo, hi, at, spring) -> tuple:
    """boxsearch.cones' test of the batch's boxes `at`, each at its spring's cone: (verdict, the
    cone points as (rows, angles spring |lambda| index lo hi))."""
    verdict, (x, lam, index), one = cone_test(_sub(land, at), lo[at], hi[at], spring)
    rows = at[one]
    pull = np.sqrt((lam * lam).sum(axis=1))
    return verdict, (rows, np.hstack([x, spring[one][:, None], pull[:, None], index[:, None],
                                      lo[rows], hi[rows]]))  # fmt: skip


def _spring_bound(dd_hi: np.ndarray) -> np.ndarray:
    """In each box set aside some spring with a free length is at most this long."""
    return np.sqrt(np.maximum(dd_hi.min(axis=1), 0.0)) if dd_hi.shape[1] else np.zeros(len(dd_hi))


def _root_near(land: BoxLandscape, lo: np.ndarray, hi: np.ndarray, steps: int = 8) -> np.ndarray:
    """Whether Newton from each box's middle ends within one box width of it at an isolated
    critical point (its Hessian's condition below NEAR_CONDITION: one on an edge or merely
    badly conditioned): such boxes are split further. A point of a continuum (a singular
    Hessian) is not: boxes along a curve of critical points stop at the smallest width."""
    x, w = 0.5 * (lo + hi), hi - lo
    ok = np.ones(len(x), dtype=bool)
    for _ in range(steps):
        g, h = point_derivatives(land, x)
        with np.errstate(all="ignore"):
            ok = np.isfinite(h).all(axis=(1, 2)) & (np.abs(np.linalg.det(h)) > 1e-300)
            dx = np.zeros_like(x)
            if ok.any():
                dx[ok] = np.linalg.solve(h[ok], g[ok][..., None])[..., 0]
        x = x - np.where(ok[:, None], dx, 0.0)
    with np.errstate(all="ignore"):
        ok &= np.linalg.cond(np.where(ok[:, None, None], h, np.eye(x.shape[1]))) < NEAR_CONDITION
    return ok & ((x >= lo - w) & (x <= hi + w)).all(axis=1) & np.isfinite(x).all(axis=1)


def _subset(states, rows: np.ndarray):
    """The landscape's per-box states of the boxes `rows` (indices into the batch)."""
    if isinstance(states, dict):
        return {k: v[rows] for k, v in states.items()}
    return states


def _floor(dd: Interval, min_width: float) -> np.ndarray:
    """The smallest width worth splitting to: `min_width`, or less where a spring is short (the
    enclosures of its 1/d terms widen like width / d): a hundredth of d."""
    shortest = np.sqrt(np.maximum(dd.lo.min(axis=1), 0.0))
    return np.maximum(np.minimum(min_width, 0.01 * shortest), ROOT_FLOOR)


def _split(lo: np.ndarray, hi: np.ndarray, parent: np.ndarray, free=None) -> tuple:
    """Each box halved along its MAX_CUTS widest sides (those at least half as wide as its
    widest): (lo, hi, the `parent` of each half's box). In six or eight dimensions a box cut
    along every side makes 64 or 256 boxes where the first halvings would often have excluded
    half of them (prism_slack: 15.8 million boxes -> 2.6 million). A free angle of the
    batch's box `parent` (`free`, (batch, n)) is never halved: grad V is 0 along it."""
    if not len(lo):
        return lo, hi, parent
    w = hi - lo if free is None else np.where(free[parent], 0.0, hi - lo)
    widest = np.argsort(-w, axis=1, kind="stable")[:, :MAX_CUTS]
    cut = np.zeros(w.shape, dtype=bool)
    np.put_along_axis(cut, widest, True, axis=1)
    cut &= (w >= 0.5 * w.max(axis=1, keepdims=True)) & (w > 0)
    for j in range(lo.shape[1]):
        c = cut[:, j]
        mid = 0.5 * (lo[c, j] + hi[c, j])
        upper_lo, upper_hi = lo[c].copy(), hi[c].copy()
        upper_lo[:, j] = mid
        hi = hi.copy()
        hi[np.flatnonzero(c), j] = mid
        lo, hi = np.vstack([lo, upper_lo]), np.vstack([hi, upper_hi])
        parent = np.concatenate([parent, parent[c]])
        cut = np.vstack([cut, cut[c]])
    return lo, hi, parent


def krawczyk(land: BoxLandscape, lo, hi, states, free=None, slack=None, h=None) -> tuple:
    """(verdict, K lo, K hi) per box: 1 exactly one critical point (in K), -1 none, 0 unknown.
    Along `free` angles ((B, n) bool) grad V is 0 whatever they are: the test is that of the
    other components in the other angles (their gradient does not depend on the free ones over
    the box), and a 1 says each value of the free angles has exactly one critical point of the
    others, the same one (the free angles of K are the box's middle). `slack`: the cables
    the landscape takes as slack over each box (its `free`), at the middle too. `h`: the slope
    matrix over the boxes, where already made."""
    n = lo.shape[1]
    mid = 0.5 * (lo + hi)
    _, g_mid, _ = land.enclose(Interval(mid), slack=slack) if slack else land.enclose(Interval(mid))
    h = land.hessian(Interval(lo, hi), states) if h is None else h
    if free is None or not free.any():
        return krawczyk_step(lo, hi, g_mid, h)
    both = ~free[:, :, None] & ~free[:, None, :]
    eye = np.broadcast_to(np.eye(n), both.shape)
    h = Interval(np.where(both, h.lo, eye), np.where(both, h.hi, eye))
    g_mid = Interval(np.where(free, 0.0, g_mid.lo), np.where(free, 0.0, g_mid.hi))
    return krawczyk_step(lo, hi, g_mid, h, free)


def _roots(land: BoxLandscape, lo, hi, k_lo, k_hi, steps: int = 40) -> tuple:
    """Newton from the middle of K n X to the critical point each box holds alone: (roots,
    their boxes (lo, hi), whether each ended inside K n X)."""
    a, b = np.maximum(lo, k_lo), np.minimum(hi, k_hi)
    x = 0.5 * (a + b)
    done = np.zeros(len(x), dtype=bool)
    for _ in range(steps):
        live = np.flatnonzero(~done)
        if not len(live):
            break
        g, h = point_derivatives(_sub(land, live), x[live])
        dx = _newton_steps(h, g)
        new = x[live] - dx
        inside = ((new >= a[live]) & (new <= b[live])).all(axis=1)
        x[live] = np.where(inside[:, None], new, x[live])
        small = np.abs(dx).max(axis=1) <= 1e-15 * (1 + np.abs(new).max(axis=1))
        done[live[small | ~inside]] = True
    good = ((x >= a) & (x <= b)).all(axis=1)
    return x, np.hstack([lo, hi]), good


def _free(land, box: Interval, states, grad: Interval) -> tuple[np.ndarray, dict]:
    """(code (B, n), slack) of landscape.free over each box (none free without it)."""
    rule = getattr(land, "free", None)
    if rule is None:
        return np.zeros(box.lo.shape, dtype=np.int8), {}
    code, slack = rule(box, states, grad)
    return code, {c: m for c, m in slack.items() if m.any()}


def _free_points(land, lo, hi, k_lo, k_hi, free, slack, steps: int = 40) -> np.ndarray:
    """The critical point of the other angles each free box holds alone (Newton on them from
    the middle of K n X, the cables of `slack` slack), the free angles at the box's middle."""
    a, b = np.maximum(lo, k_lo), np.minimum(hi, k_hi)
    x = np.where(free, 0.5 * (lo + hi), 0.5 * (a + b))
    n = lo.shape[1]
    both = ~free[:, :, None] & ~free[:, None, :]
    for _ in range(steps):
        g, h = land.derivatives(x, slack) if slack else point_derivatives(land, x)
        h = np.where(both, h, np.eye(n))
        new = x - np.nan_to_num(_newton_steps(h, np.where(free, 0.0, g)))
        inside = ((new >= a) & (new <= b)).all(axis=1)
        x = np.where(inside[:, None], new, x)
    return x


def _newton_steps(h: np.ndarray, g: np.ndarray) -> np.ndarray:
    """H^-1 g for each point; NaN where its Hessian is singular (that point's Newton stops,
    not the batch's)."""
    try:
        return np.linalg.solve(h, g[..., None])[..., 0]
    except np.linalg.LinAlgError:
        out = np.full_like(g, np.nan)
        for i in range(len(g)):
            with contextlib.suppress(np.linalg.LinAlgError):
                out[i] = np.linalg.solve(h[i], g[i])
        return out


def point_derivatives(land: BoxLandscape, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """grad V and its Hessian at points (R, n) in double precision (for Newton only: what is
    proved comes from the enclosures)."""
    return land.derivatives(x)
