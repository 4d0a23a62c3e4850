"""A peer benchmark of the real route's branch and bound (boxsearch.boxes.search) against codac's
interval branch and contract, side by side in one run on one machine: every critical point of V
on the torus of body angles [OFFSET, OFFSET + 2 pi]^n of each example, by both.

grad V for codac is built here, independently of the package's derivation: each point's world
position from the parsed framework (its bodies, pins and slots in the file's own units; a body
turns by its absolute angle about the pin that places it), V = sum k/2 (d - L0)^2 over springs
+ sum k/2 max(d - L0, 0)^2 over cables - F . x over loads, differentiated by sympy (the
cables' max kept: codac evaluates max on intervals and differentiates it for its centered
form, so no taut and slack pieces), and written as a codac AnalyticFunction (sympy's common
subexpressions named, though codac evaluates each use again). It is checked against the
package's grad V (normalised units, scaled back by k_unit L_unit^2) at random angles before
any timing.

codac: CtcInverse(grad V, 0) (forward-backward contraction with the centered form, codac's
default; --fixpoint: CtcFixpoint of it) in codac's `pave` loop (codac2_pave.cpp: first in,
first out; a box is contracted, dropped when empty, kept when no wider than eps = MIN_WIDTH,
1e-4 rad, else bisected), written here so that it stops at a budget (pave's own time argument
did not stop it). A codac "box" is one contraction (a node of the paving tree; --fixpoint:
one fixpoint call, several contractions); its roots are
clusters of kept boxes closer than eps (an outer enclosure: no existence or uniqueness proof),
those where a spring is near zero length (CONE) counted apart as cone points. Ours:
search(landscape(fw), SHORT, MIN_WIDTH), one warm run timed; a "box" is a box the search
decided (excluded, proved to hold one critical point or none by the Krawczyk test, split, set
aside or left undecided); its roots come with existence and uniqueness proofs. codac runs on
one thread (nb_threads 1).

Usage: python bench/codac_peer.py [--only NAME ...] [--codac-budget S] [--ours-budget S]
[--fixpoint]
"""

from __future__ import annotations

import argparse
import datetime
import itertools
import math
import os
import sys
import time
from collections import deque
from dataclasses import dataclass
from importlib import metadata

import numpy as np
import pandas as pd
import sympy as sp
from benchlib import BENCH, show, write_csv

try:
    import codac
except ImportError:
    sys.exit("bench/codac_peer.py needs codac: pip install -e .[bench]")

import cotm_bertini as cb
from cotm_bertini.boxsearch.boxes import MIN_WIDTH, OFFSET, SHORT, TWO_PI, search
from cotm_bertini.boxsearch.real_route import landscape
from cotm_bertini.model.framework.spec import Framework, owner, units
from cotm_bertini.model.framework.structure import layout

ROOT = BENCH.parent
EXAMPLES = {
    "xmodule": ROOT / "examples" / "xmodule.toml",
    "chain3": ROOT / "examples" / "chain3.toml",
    "chain3_collapse": ROOT / "tests" / "fixtures" / "chain3_collapse.toml",
}
SPHERES = {"prism_slack": ROOT / "examples" / "prism_slack.toml"}  # in chart angles
CHART_B = 8.0  # boxsearch.spheres: chart B's first angle is stored 8 higher (a box says its chart)
POSE_TOL = 1e-3  # length units: codac clusters (and our roots) at poses this close are one
CHECK_POINTS = 20  # random angle vectors at which grad V is compared with the package's
CHECK_TOL = 1e-9  # largest allowed difference, relative to max(1, |grad V|)
CONE = 1e-2  # length units: a codac cluster whose hull's middle has a spring this short is at
# a cone point (V is not differentiable there), not a critical point


@dataclass
class Gradient:
    """grad V in the file's units: sympy expressions in the angles t_0 .. t_{n-1}, and the
    squared length of each spring with a free length (to tell cone points)."""

    angles: list[sp.Symbol]
    grad: list[sp.Expr]
    spring_dd: list[sp.Expr]

    @property
    def n(self) -> int:
        return len(self.angles)


def gradient(fw: Framework) -> Gradient:
    """grad V of a planar framework pinned in an open chain, from its parsed description."""
    lay = layout(fw)
    if not lay.is_torus or fw.dim != 2 or fw.bars:
        raise ValueError(f"{fw.name}: not a torus of planar body angles")
    slots = fw.slots()  # file units
    angles = list(sp.symbols(f"t0:{len(lay.rotations)}", real=True))
    turn = dict(zip(lay.rotations, angles, strict=True))
    placed = {body: (pt, src) for body, pt, src in lay.placed_by}

    def local(point: str) -> list[sp.Expr]:
        body, name = point.split(".", 1)
        return [sp.Float(slots[f"b_{body}_{name}_{a}"]) for a in "xy"]

    def rotate(body: str, v: list[sp.Expr]) -> list[sp.Expr]:
        c, s = sp.cos(turn[body]), sp.sin(turn[body])
        return [c * v[0] - s * v[1], s * v[0] + c * v[1]]

    def at(point: str) -> list[sp.Expr]:
        body = owner(point)
        if body == "ground":
            return [sp.Float(slots[f"g_{point.split('.', 1)[1]}_{a}"]) for a in "xy"]
        pin, src = placed[body]  # the body's pinned point sits at src
        base = [p - q for p, q in zip(at(src), rotate(body, local(pin)), strict=True)]
        return [p + q for p, q in zip(base, rotate(body, local(point)), strict=True)]

    V, spring_dd = sp.Integer(0), []
    for x in fw.links:
        r = [p - q for p, q in zip(at(x.a), at(x.b), strict=True)]
        dd = r[0] ** 2 + r[1] ** 2
        k, L0 = slots[f"k_{x.name}"], slots[f"L0_{x.name}"]
        stretch = sp.sqrt(dd) - L0
        if x.kind == "cable":
            V += k / 2 * sp.Max(stretch, 0) ** 2
        else:
            V += k / 2 * stretch**2
            if L0 != 0:
                spring_dd.append(dd)
    for load in fw.loads:
        pos = at(load.point)
        V -= sum(slots[f"f_{load.name}_{a}"] * p for a, p in zip("xy", pos, strict=True))
    # d/dx Max(x, 0)^2 = 2 Max(x, 0) Heaviside(x) = 2 Max(x, 0): the step is 1 wherever it counts
    grad = [sp.diff(V, t).replace(sp.Heaviside, lambda *a: sp.Integer(1)) for t in angles]
    return Gradient(angles, grad, spring_dd)


def numeric(g: Gradient):
    """grad V at points (R, n) in double precision (numpy)."""
    f = sp.lambdify(g.angles, g.grad, modules=[{"Max": np.maximum}, "numpy"])
    return lambda x: np.stack([np.broadcast_to(v, x.shape[:1]) for v in f(*x.T)], axis=1)


def check(fw: Framework, g: Gradient, seed: int = 1) -> float:
    """The largest difference between our grad V and the package's (scaled to file units by
    k_unit L_unit^2) at CHECK_POINTS random angle vectors, relative to max(1, |grad V|)."""
    x = OFFSET + TWO_PI * np.random.default_rng(seed).random((CHECK_POINTS, g.n))
    length, stiffness = units(fw)
    theirs = landscape(fw).derivatives(x)[0] * stiffness * length**2
    ours = numeric(g)(x)
    scale = np.maximum(1.0, np.abs(theirs).max(axis=1, keepdims=True))
    return float((np.abs(ours - theirs) / scale).max())


def to_codac(g: Gradient):
    """(the codac AnalyticFunction of grad V, its input variable)."""
    x = codac.VectorVar(g.n)
    names = {t: x[i] for i, t in enumerate(g.angles)}
    shared, reduced = sp.cse(g.grad, optimizations="basic")
    for sym, expr in shared:
        names[sym] = _expr(expr, names)
    return codac.AnalyticFunction([x], codac.vec(*[_expr(e, names) for e in reduced])), x


def _expr(e: sp.Expr, names: dict):
    """A sympy expression (+, *, integer and half powers, sin, cos, Max) as a codac one."""
    if e in names:
        return names[e]
    if e.is_Number:
        return codac.ScalarExpr(float(e))
    args = [_expr(a, names) for a in e.args]
    if e.is_Add:
        out = args[0]
        for a in args[1:]:
            out = out + a
        return out
    if e.is_Mul:
        coeff = [float(a) for a in e.args if a.is_Number]
        out = None
        for a, a_expr in zip(e.args, args, strict=True):
            if not a.is_Number:
                out = a_expr if out is None else out * a_expr
        return float(np.prod(coeff)) * out if coeff else out
    if e.is_Pow:
        base, p = args[0], e.exp
        if p == sp.Rational(1, 2):
            return codac.sqrt(base)
        if p == sp.Rational(-1, 2):
            return 1.0 / codac.sqrt(base)
        if p.is_Integer:
            out = codac.sqr(base) if abs(p) == 2 else base
            for _ in range(abs(int(p)) - (2 if abs(p) >= 2 else 1)):
                out = out * base
            return out if p > 0 else 1.0 / out
        if (2 * p).is_Integer:  # x^(m/2) = sqrt(x) x^((m-1)/2)
            return _expr(sp.sqrt(e.base) * e.base ** (p - sp.Rational(1, 2)), names)
    if isinstance(e, sp.sin):
        return codac.sin(args[0])
    if isinstance(e, sp.cos):
        return codac.cos(args[0])
    if isinstance(e, sp.Max) and len(args) == 2:
        return codac.max(args[0], args[1])
    raise ValueError(f"no codac form for {type(e).__name__}: {e}")


def sphere_gradient(fw: Framework, turned: tuple[bool, ...]) -> tuple[Gradient, list]:
    """(grad V in chart angles a_i, b_i of each free node, the nodes' positions as sympy
    expressions) of a spatial framework whose nodes hang by bars, each node in chart A (u =
    (sin a cos b, sin a sin b, cos a)) or, where `turned`, chart B (u = (cos a', sin a' cos b,
    sin a' sin b), a' = a - CHART_B): written from the charts' definitions, not the package."""
    slots = fw.slots()
    nodes = list(fw.nodes)
    angles = list(sp.symbols(f"t0:{2 * len(nodes)}", real=True))
    pos: dict[str, list] = {}
    for g in {p.split(".", 1)[1] for x in fw.links for p in (x.a, x.b) if owner(p) == "ground"}:
        pos[f"ground.{g}"] = [sp.Float(slots[f"g_{g}_{c}"]) for c in "xyz"]
    bars = [x for x in fw.links if x.kind == "bar"]
    while len(pos) < len(nodes) + sum(p.startswith("ground.") for p in pos):
        for x in bars:
            for top, node in ((x.a, x.b), (x.b, x.a)):
                if top in pos and node in nodes and node not in pos:
                    i = nodes.index(node)
                    a, b = angles[2 * i], angles[2 * i + 1]
                    if turned[i]:
                        a = a - CHART_B
                        u = [sp.cos(a), sp.sin(a) * sp.cos(b), sp.sin(a) * sp.sin(b)]
                    else:
                        u = [sp.sin(a) * sp.cos(b), sp.sin(a) * sp.sin(b), sp.cos(a)]
                    length = slots[f"len_{x.name}"]
                    pos[node] = [p + length * c for p, c in zip(pos[top], u, strict=True)]
    V, spring_dd = sp.Integer(0), []
    for x in (x for x in fw.links if x.kind != "bar"):
        r = [p - q for p, q in zip(pos[x.a], pos[x.b], strict=True)]
        dd = sum(c**2 for c in r)
        k, L0 = slots[f"k_{x.name}"], slots[f"L0_{x.name}"]
        stretch = sp.sqrt(dd) - L0
        V += k / 2 * (sp.Max(stretch, 0) ** 2 if x.kind == "cable" else stretch**2)
        if x.kind != "cable" and L0 != 0:
            spring_dd.append(dd)
    for load in fw.loads:
        at = pos[load.point]
        V -= sum(slots[f"f_{load.name}_{c}"] * p for c, p in zip("xyz", at, strict=True))
    grad = [sp.diff(V, t).replace(sp.Heaviside, lambda *a: sp.Integer(1)) for t in angles]
    return Gradient(angles, grad, spring_dd), [c for v in nodes for c in pos[v]]


def sphere_row(name: str, budgets: tuple[float, float]) -> dict:
    """prism_slack by both solvers over the search's chart boxes (27: each node's band and two
    caps): codac paves each box with the gradient of its charts; roots compared by pose (a pose
    in two overlapping charts is one)."""
    fw = cb.Framework.from_toml(SPHERES[name])
    land = landscape(fw)
    lo, hi = land.domain(0)
    length, stiffness = units(fw)
    found, boxes, seconds, left, err, n = [], 0, 0.0, [], 0.0, lo.shape[1]
    cache: dict = {}
    # Most chart boxes are emptied in seconds: each first gets an equal share of a tenth of the
    # budget, and those it does not finish are paved again from the start, in turn, each with
    # all the budget left (prism_slack: one chart box, every node in the band, holds the roots).
    todo, again = [(a, b, True) for a, b in zip(lo, hi, strict=True)], []
    while todo or again:
        b_lo, b_hi, early = todo.pop(0) if todo else (*again.pop(0), False)
        budget = budgets[0] / 10 / len(lo) if early else budgets[0] - seconds
        turned = tuple(bool(v >= CHART_B / 2) for v in b_lo[0::2])
        if turned not in cache:
            g, X = sphere_gradient(fw, turned)
            x = b_lo + np.random.default_rng(1).random((CHECK_POINTS, n)) * (b_hi - b_lo)
            theirs = land.derivatives(x)[0] * stiffness * length**2
            ours = numeric(g)(x)
            scale = np.maximum(1.0, np.abs(theirs).max(axis=1, keepdims=True))
            err = max(err, float((np.abs(ours - theirs) / scale).max()))
            cache[turned] = (g, sp.lambdify(g.angles, X, "numpy"))
        g, place = cache[turned]
        f = run_codac(g, MIN_WIDTH, budget, box=(b_lo, b_hi))
        boxes, seconds = boxes + f.boxes, seconds + f.seconds
        if f.complete:
            found += [np.array(place(*x), dtype=float) for x in f.roots]
        elif early:
            again.append((b_lo, b_hi))
        else:
            left.append(f.note)
    if err > CHECK_TOL:
        raise SystemExit(f"{name}: grad V differs from the package's by {err:.2e}")
    t0 = time.perf_counter()
    ours = search(land, SHORT, MIN_WIDTH, max_seconds=budgets[1])
    ours_s = time.perf_counter() - t0
    ours_pose = land.positions(ours.roots) * length
    theirs_pose = _distinct_poses(np.array(found).reshape(-1, 3 * len(fw.nodes)))
    gap = np.abs(theirs_pose[:, None, :] - ours_pose[None, :, :]).max(axis=2)
    matched = int((gap.min(axis=1) < POSE_TOL).sum()) if gap.size else 0
    done = not left and not ours.budget_hit
    return {"example": name + " (chart angles)", "n": n, "grad_check": err,
            "codac_roots": len(theirs_pose), "ours_roots": len(ours.roots), "codac_boxes": boxes,
            "ours_boxes": ours.boxes, "codac_s": seconds, "ours_s": ours_s,
            "codac_over_ours": seconds / ours_s,
            "agree": ("yes" if matched == len(theirs_pose) == len(ours.roots) else "no")
            if done else "partial: a budget hit",
            "codac_matched": matched,
            "notes": f"codac: {len(found)} clusters over 27 chart boxes, {len(theirs_pose)} poses"
            + "".join(f"; a chart box stopped: {note}" for note in left)}  # fmt: skip


def _distinct_poses(X: np.ndarray) -> np.ndarray:
    """The poses (R, 3 m) each once: those within POSE_TOL of an earlier one left out."""
    kept: list[np.ndarray] = []
    for p in X:
        if all(np.abs(p - q).max() >= POSE_TOL for q in kept):
            kept.append(p)
    return np.array(kept).reshape(-1, X.shape[1])


@dataclass
class Found:
    """One solver's outcome over the domain."""

    roots: np.ndarray  # (R, n) a point of each root (codac: its cluster's hull's middle)
    widths: np.ndarray  # (R, n) codac: each cluster's hull's widths; ours: zeros
    boxes: int
    seconds: float
    note: str = ""
    cone: np.ndarray | None = None  # codac: whether each cluster is at a cone point
    complete: bool = True  # the whole domain decided (no budget hit)


def run_codac(g: Gradient, eps: float, budget: float, fixpoint: bool = False,
              box: tuple | None = None) -> Found:  # fmt: skip
    """codac's `pave` loop (codac2_pave.cpp: first in, first out; contract; drop an empty box,
    keep one no wider than eps, else bisect it), written here around CtcInverse(grad V, 0) so
    that it stops at `budget` seconds (wall) with the boxes left counted as undecided; the kept
    boxes grouped into clusters (`clusters`). `box`: (lo, hi) to pave, else the torus."""
    f, _ = to_codac(g)
    ctc = codac.CtcInverse(f, codac.IntervalVector([[0.0, 0.0]] * g.n))
    if fixpoint:
        ctc = codac.CtcFixpoint(ctc)
    start = [[OFFSET, OFFSET + TWO_PI]] * g.n if box is None else list(zip(*box, strict=True))
    todo = deque([codac.IntervalVector([[float(a), float(b)] for a, b in start])])
    kept, calls, inside = [], 0, 0.0
    t0 = time.perf_counter()
    while todo:
        if calls % 256 == 0 and time.perf_counter() - t0 > budget:
            break
        box = todo.popleft()
        c0 = time.perf_counter()
        box = ctc.contract(box)
        inside += time.perf_counter() - c0
        calls += 1
        if box.is_empty():
            continue
        if box.max_diam() <= eps:
            kept.append(box)
        else:
            todo.extend(box.bisect_largest(0.5))
    seconds = time.perf_counter() - t0
    lo = np.array([[b[i].lb() for i in range(g.n)] for b in kept]).reshape(-1, g.n)
    hi = np.array([[b[i].ub() for i in range(g.n)] for b in kept]).reshape(-1, g.n)
    label = clusters(lo, hi, eps)
    count = int(label.max()) + 1 if len(label) else 0
    c_lo = np.full((count, g.n), np.inf)
    c_hi = np.full((count, g.n), -np.inf)
    np.minimum.at(c_lo, label, lo)
    np.maximum.at(c_hi, label, hi)
    cone = np.zeros(count, dtype=bool)
    np.logical_or.at(cone, label, at_cone(g, 0.5 * (lo + hi)))
    note = f"{len(kept):,} boxes kept, {inside:.2f} s in contract"
    if todo:
        left = sum(math.prod(b[i].diam() for i in range(g.n)) for b in todo) / TWO_PI**g.n
        note += f"; stopped at {budget:g} s, {len(todo):,} undecided, {left:.2e} of the domain"
    return Found(0.5 * (c_lo + c_hi), c_hi - c_lo, calls, seconds, note, cone, not todo)


def clusters(lo: np.ndarray, hi: np.ndarray, gap: float) -> np.ndarray:
    """A cluster label for each box: boxes closer than `gap` (each side) are in one cluster
    (codac's connected_subsets asks them to touch, but a contracted box no longer touches its
    neighbours: one root then shows as several pieces)."""
    n = lo.shape[1]
    parent = list(range(len(lo)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    cells: dict[tuple, list[int]] = {}
    keys = np.floor(0.5 * (lo + hi) / (2 * gap)).astype(np.int64)
    for i, key in enumerate(map(tuple, keys)):
        cells.setdefault(key, []).append(i)
    steps = list(itertools.product((-1, 0, 1), repeat=n))
    for key, members in cells.items():
        for step in steps:
            near = cells.get(tuple(k + s for k, s in zip(key, step, strict=True)), ())
            for i in members:
                for j in near:
                    if j < i and (np.maximum(lo[i], lo[j]) - np.minimum(hi[i], hi[j]) <= gap).all():
                        parent[find(i)] = find(j)
    roots = np.array([find(i) for i in range(len(lo))], dtype=np.int64)
    return np.unique(roots, return_inverse=True)[1].reshape(-1)


def at_cone(g: Gradient, x: np.ndarray) -> np.ndarray:
    """Whether a spring with a free length is shorter than CONE at each point (R, n)."""
    out = np.zeros(len(x), dtype=bool)
    for e in g.spring_dd:
        dd = sp.lambdify(g.angles, e, "numpy")(*x.T)
        out |= np.sqrt(np.abs(np.broadcast_to(dd, len(x)))) < CONE
    return out


def run_ours(fw: Framework, budget: float) -> Found:
    """search(landscape(fw), SHORT, MIN_WIDTH, max_seconds=budget), warm (derivations done,
    one run with a budget of at most 10 s before), wall time of one run."""
    land = landscape(fw)
    _ = land.hessian_sets
    search(land, SHORT, MIN_WIDTH, max_seconds=min(budget, 10.0))  # warm up
    t0 = time.perf_counter()
    found = search(land, SHORT, MIN_WIDTH, max_seconds=budget)
    seconds = time.perf_counter() - t0
    note = []
    if found.budget_hit:
        note.append(f"{found.budget_hit}, undecided {found.undecided_share:.2%}")
    elif len(found.undecided):
        note.append(f"{len(found.undecided):,} undecided at the smallest width")
    if found.set_aside:
        note.append(f"{found.set_aside:,} set aside (a spring under {SHORT:g})")
    roots = found.roots
    return Found(roots, np.zeros_like(roots), found.boxes, seconds, "; ".join(note),
                 complete=not found.budget_hit)  # fmt: skip


def torus_gap(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|a - b| per angle modulo 2 pi: (len(a), len(b), n)."""
    d = np.abs(a[:, None, :] - b[None, :, :]) % TWO_PI
    return np.minimum(d, TWO_PI - d)


def agree(theirs: Found, ours: Found) -> dict:
    """Each codac cluster matched to our roots within its hull's width per angle (mod 2 pi);
    clusters at a cone point (a spring shorter than CONE at one of their boxes' middles) apart.
    The sets agree when every other cluster holds exactly one of our roots and each of our
    roots is in exactly one cluster."""
    gap = torus_gap(theirs.roots, ours.roots)
    inside = (gap <= np.maximum(theirs.widths, 1e-9)[:, None, :]).all(axis=2)  # (C, R)
    cone = theirs.cone
    per_cluster, per_root = inside.sum(axis=1), inside.sum(axis=0)
    clean = bool((per_cluster[~cone] == 1).all() and (per_root == 1).all())
    if not (theirs.complete and ours.complete):
        verdict = "partial: " + ", ".join(
            w for w, done in (("codac", theirs.complete), ("ours", ours.complete)) if not done
        ) + " stopped"  # fmt: skip
    else:
        verdict = "yes" if clean else "no"
    return {"codac_cone": int(cone.sum()), "codac_matched": int(((per_cluster == 1) & ~cone).sum()),
            "ours_in_codac": int((per_root >= 1).sum()),
            "widest_root_cluster": float(theirs.widths[~cone].max()) if (~cone).any() else 0.0,
            "agree": verdict}  # fmt: skip


def newton_roots(fw: Framework, theirs: Found) -> np.ndarray:
    """Whether Newton (the package's grad V and Hessian, double precision, least-squares
    steps) from the middle of each codac cluster ends at a critical point (|grad V| < 1e-10,
    normalised units) inside the cluster's hull widened by its width on each side."""
    land = landscape(fw)
    x = theirs.roots.copy()
    if not len(x):
        return np.zeros(0, dtype=bool)
    with np.errstate(all="ignore"):
        for _ in range(30):
            g, h = land.derivatives(x)
            x = x - np.einsum("nij,nj->ni", np.linalg.pinv(h, rcond=1e-12), g)
        g, _ = land.derivatives(x)
    close = (torus_gap(x, theirs.roots)[np.arange(len(x)), np.arange(len(x))]
             <= 1.5 * theirs.widths + 1e-9).all(axis=1)  # fmt: skip
    return np.isfinite(g).all(axis=1) & (np.abs(g).max(axis=1) < 1e-10) & close


def row(name: str, budgets: tuple[float, float], fixpoint: bool) -> dict:
    """One example by both solvers (`budgets`: codac's and ours, seconds)."""
    fw = cb.Framework.from_toml(EXAMPLES[name])
    g = gradient(fw)
    err = check(fw, g)
    print(
        f"{name}: our grad V against the package's at {CHECK_POINTS} random points: "
        f"largest difference {err:.1e} (relative to max(1, |grad V|))"
    )
    if err > CHECK_TOL:
        raise SystemExit(f"{name}: grad V differs from the package's by {err:.2e}")
    theirs = run_codac(g, MIN_WIDTH, budgets[0], fixpoint)
    ours = run_ours(fw, budgets[1])
    out = {"example": name, "n": g.n, "grad_check": err,
           "codac_roots": int((~theirs.cone).sum()), "ours_roots": len(ours.roots),
           "codac_boxes": theirs.boxes, "ours_boxes": ours.boxes, "codac_s": theirs.seconds,
           "ours_s": ours.seconds, "codac_over_ours": theirs.seconds / ours.seconds}  # fmt: skip
    out |= agree(theirs, ours)
    out["codac_newton"] = int((newton_roots(fw, theirs) & ~theirs.cone).sum())
    extra = ~theirs.cone & (torus_gap(theirs.roots, ours.roots) > np.maximum(
        theirs.widths, 1e-9)[:, None, :]).any(axis=2).all(axis=1)  # fmt: skip
    if extra.any() and len(ours.roots):
        near = torus_gap(theirs.roots[extra], ours.roots).max(axis=2).min(axis=1)
        theirs.note += (f"; {int(extra.sum())} clusters hold none of our roots: the nearest "
                        f"{near.min():.1e} to {near.max():.1e} rad from one")  # fmt: skip
    notes = (("codac", theirs.note), ("ours", ours.note))
    out["notes"] = " | ".join(f"{who}: {note}" for who, note in notes if note)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    names = list(EXAMPLES) + list(SPHERES)
    ap.add_argument("--only", nargs="*", default=names, choices=names)
    ap.add_argument("--codac-budget", type=float, default=180.0, help="seconds, each example")
    ap.add_argument("--ours-budget", type=float, default=60.0, help="seconds, each example")
    ap.add_argument("--fixpoint", action="store_true", help="codac: CtcFixpoint(CtcInverse)")
    args = ap.parse_args()
    print(
        f"{datetime.date.today()}, {os.cpu_count()} cores, load average "
        f"{os.getloadavg()[0]:.1f}, codac {metadata.version('codac')} "
        f"({codac.nb_threads()} thread), numpy {np.__version__}"
    )
    budgets = (args.codac_budget, args.ours_budget)
    rows = [sphere_row(name, budgets) if name in SPHERES else row(name, budgets, args.fixpoint)
            for name in args.only]  # fmt: skip
    frame = pd.DataFrame(rows)
    kind = "CtcFixpoint(CtcInverse)" if args.fixpoint else "CtcInverse"
    show(f"codac (pave loop, {kind}, eps {MIN_WIDTH:g}) against the real route's search "
         f"(SHORT {SHORT:g}, MIN_WIDTH {MIN_WIDTH:g})", frame,
         {"grad_check": ".1e", "codac_s": ".3f", "ours_s": ".3f", "codac_over_ours": ".1f",
          "widest_root_cluster": ".1e"})  # fmt: skip
    print(
        "codac box: one contraction (a node of the paving tree); ours: one box decided "
        "(excluded, Krawczyk-tested, split, set aside or left undecided)"
    )
    write_csv(frame, "codac_peer_fixpoint" if args.fixpoint else "codac_peer")


if __name__ == "__main__":
    main()
