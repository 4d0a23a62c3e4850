"""Fold curves, cusps and cable-switch curves of a framework on the real route (a torus of body
angles or a product of spheres), traced numerically in the landscape's chart angles
(continuation/charts.py): no polynomial system, no sympy expansion, no Bertini.

A curve is followed by pseudo-arclength continuation (catastrophe/curve_trace.py) in
z = (chart angles, x, y) from a seed (a point near it the grid driver found,
catastrophe/chart_grid.py):

- a fold: grad V = 0 and the minimally augmented fold function s, the last entry of the solution
  of [[H, b], [c^T, 0]] (v, s) = (0, 1) with b, c H's left and right singular vectors of its
  smallest singular value at the last accepted point: s = 0 exactly where H is singular, and
  ds/dz_k = -w^T (dH/dz_k) v (w from the transposed system; dH/dz by central differences);
- a cable switch: grad V = 0 and the cable's length minus its free length.

A sphere's chart degenerates at its poles (a spurious zero of s there), so a curve is traced in
pieces, each in one chart: a piece stops where the plane's rechart would move a node to another
chart, and the next starts at that point recharted, in the same direction (the pose's velocity
decides). A piece also stops where the taut set changes (a fold of one taut set ends on a switch;
a switch curve ends where another cable switches). Cusps are where a fold curve's image in the
plane turns back (framework_folds._cusps), confirmed by the vanishing of the cubic term
v . (d/de H(theta + e v)) v (v the unit null vector of the symmetric H; normalised units,
relative to the largest entry of H when that is above 1).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..analysis.framework_classify import framework_rows
from ..continuation.charts import FD, FD_ANGLE, ChartPlane, _distance
from ..errors import ParameterError
from ..model.framework.compiled import framework_system
from ..model.framework.spec import units
from ..progress import Progress
from ..settings import Tolerances
from .curve_trace import Equations, Window, newton, one_way, remembered, tangent
from .framework_folds import _cusps, _empty, _solution_columns

KINDS = ("fold", "cable_switch")
SPACING = 0.01  # consecutive points: at most this fraction of the window's diagonal apart
HMAX = 0.05  # largest step in z (rad and the parameters' units)
MAX_PIECES = 400  # pieces of one curve's end (a curve along a chart edge changes chart often)
ON_CURVE = 3  # a seed within this many spacings (plane) and HMAX steps (pose) of a curve is on it
CUSP_TOL = 1e-6  # |v . H_e v| / max(1, |H|) below this confirms a cusp (normalised units)
CUSP_HALVINGS = 32  # bisections refining a cusp: its bracket (two steps) to 1e-10 of it
NUDGE = 1e-7  # a switch's sides: this far (normalised length) into each
PITCHFORK = 1e-4  # a fold point whose parameters' pull along the null direction is below this
# (relative to their pull, _pull) is a pitchfork: the branch passes. Measured: 1e-17 on the
# spatial Zeeman machine's, 3e-8 to 3e-6 on prism_slack's; 0.33 and up at the X-module's folds


@dataclass(frozen=True, eq=False)
class Seed:
    """A point near a curve: kind "fold" or "cable_switch", z = (chart angles, x, y) in the
    parameters' own units, and the cable of a switch."""

    kind: str
    z: np.ndarray
    cable: str | None = None


@dataclass(frozen=True, eq=False)
class _Curve:
    """One traced curve: its segments (each in one chart, in order), how its ends stopped."""

    seed: Seed
    segments: list[np.ndarray]
    ends: tuple[str, str]
    pieces: int
    seconds: float
    eqs: Equations

    @property
    def points(self) -> np.ndarray:
        return np.vstack(self.segments)


def fold_equations(plane: ChartPlane) -> Equations:
    """curve_trace Equations of the fold curves, z = (chart angles, x, y): grad V = 0 and the
    minimally augmented fold function (module docstring), bordered at zref."""
    n = plane.n
    borders: dict[bytes, tuple] = {}
    e = np.zeros(n + 1)
    e[-1] = 1.0

    def eqs(z: np.ndarray, zref: np.ndarray):
        key = zref.tobytes()
        if key not in borders:
            borders.clear()  # one zref at a time: the last accepted point
            _, H0 = plane.derivatives(zref[:n], zref[n:])
            u, _, vt = np.linalg.svd(H0[0])
            borders[key] = u[:, -1], vt[-1]
        b, c = borders[key]
        g, H, gp, dH = _jet(plane, z[:n], z[n:])
        M = np.block([[H, b[:, None]], [c[None, :], np.zeros((1, 1))]])
        v, w = np.linalg.solve(M, e), np.linalg.solve(M.T, e)
        ds = -np.einsum("i,kij,j->k", w[:n], dH, v[:n])
        return np.append(g, v[n]), np.vstack([np.hstack([H, gp]), ds])

    return remembered(eqs)


def _jet(plane: ChartPlane, theta: np.ndarray, p) -> tuple:
    """At one chart point: grad V (n,), H (n, n), d grad / d(x, y) (n, 2) and dH/dz (n + 2, n, n):
    central differences in the angles (their shifts in one call), forward differences in the
    parameters (step charts.FD * (1 + |p|): a landscape is built for each parameter value, the
    dearest part of an evaluation; the Jacobian's O(FD) error leaves Newton's fixed point, F = 0,
    as it is)."""
    n = plane.n
    shifts = np.vstack([theta, theta + FD_ANGLE * np.eye(n), theta - FD_ANGLE * np.eye(n)])
    g, H = plane.derivatives(shifts, p)
    dH = np.empty((n + 2, n, n))
    dH[:n] = (H[1 : n + 1] - H[n + 1 :]) / (2 * FD_ANGLE)
    gp = np.empty((n, 2))
    for k in range(2):
        h = FD * (1.0 + abs(p[k]))
        up = list(p)
        up[k] = p[k] + h
        gu, Hu = plane.derivatives(theta, up)
        gp[:, k] = (gu[0] - g[0]) / h
        dH[n + k] = (Hu[0] - H[0]) / h
    return g[0], H[0], gp, dH


def switch_equations(plane: ChartPlane, cable: str) -> Equations:
    """curve_trace Equations of `cable`'s switch curves: grad V = 0 and the cable's length minus
    its free length = 0 (its gradient by central differences)."""
    n, j = plane.n, plane.cables.index(cable)

    def eqs(z: np.ndarray, zref: np.ndarray):
        theta, p = z[:n], z[n:]
        g, H = plane.derivatives(theta, p)
        gp = plane.grad_p(theta, p)[0]
        shifts = np.vstack([theta, theta + FD_ANGLE * np.eye(n), theta - FD_ANGLE * np.eye(n)])
        m = plane.margins(shifts, p)[:, j]
        dm = np.empty(n + 2)
        dm[:n] = (m[1 : n + 1] - m[n + 1 :]) / (2 * FD_ANGLE)
        for k in range(2):
            h = FD * (1.0 + abs(p[k]))
            up, down = list(p), list(p)
            up[k], down[k] = p[k] + h, p[k] - h
            dm[n + k] = (plane.margins(theta, up)[0, j] - plane.margins(theta, down)[0, j]) / (
                2 * h
            )
        return np.append(g[0], m[0]), np.vstack([np.hstack([H[0], gp]), dm])

    return remembered(eqs)


def _equations(plane: ChartPlane, seed: Seed) -> Equations:
    return fold_equations(plane) if seed.kind == "fold" else switch_equations(plane, seed.cable)


def _check(plane: ChartPlane, seeds: list[Seed], xrange, yrange) -> None:
    """Refuse bad seeds or a bad window in one line naming the field and the value."""
    for name, (lo, hi) in ((plane.x, xrange), (plane.y, yrange)):
        if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
            raise ParameterError(f"{name}: window ({lo}, {hi}) must be finite with from < to")
    for s in seeds:
        if s.kind not in KINDS:
            raise ParameterError(f"seed kind: {s.kind!r} is not a curve kind ({', '.join(KINDS)})")
        if s.kind == "cable_switch" and s.cable not in plane.cables:
            raise ParameterError(f"seed cable: {s.cable!r} is not a cable of {plane.fw.name!r}")
        if np.shape(s.z) != (plane.n + 2,):
            raise ParameterError(f"seed z: shape {np.shape(s.z)}, not ({plane.n + 2},)")


def _taut(plane: ChartPlane, z: np.ndarray, cable: str | None) -> np.ndarray:
    """Which cables are taut at z (a switch's own cable left out: it is at its free length)."""
    taut = plane.margins(z[: plane.n], z[plane.n :])[0] > 0
    if cable is not None:
        taut[plane.cables.index(cable)] = False
    return taut


def _chart_moves(plane: ChartPlane, theta: np.ndarray) -> bool:
    """Whether rechart would move some node to another chart (an angle's turn by 2 pi is no
    move: the equations are periodic in it)."""
    moved = plane.rechart(theta[None])[0] - theta
    return bool((np.abs((moved + np.pi) % (2 * np.pi) - np.pi) > 1e-9).any())


def _near(plane: ChartPlane, a: np.ndarray, b: np.ndarray, win: Window, spacing: float,
          times: float) -> np.ndarray:  # fmt: skip
    """Rows of a within `times` spacings of b in the plane and `times` HMAX steps of its pose
    (node positions or angles mod 2 pi, at b's parameters)."""
    n = plane.n
    a = np.atleast_2d(a)
    out = win.xy_distance(a, b) <= times * spacing * win.diagonal
    if out.any():
        rows = np.flatnonzero(out)
        pose = _distance(plane, a[rows, :n], np.tile(b[:n], (len(rows), 1)), b[n:])
        out[rows] = pose <= times * HMAX
    return out


CURVE_POINTS = 6.0  # an end of a curve stops after this many points / spacing ("max_points")
CRAWL_POINTS, CRAWL = 40, 0.05  # ... or after 40 points whose mean step in the plane is below
# 0.05 of the spacing ("crawls": X-module switch curves moved 1e-4 of the window in 300 points)


def _guard(plane: ChartPlane, start: np.ndarray, seed: np.ndarray, cable, win: Window,
           spacing: float, left: int) -> tuple:  # fmt: skip
    """A piece's `keep` (curve_trace): False where the chart or the taut set changes, where
    the curve comes back to its seed after leaving it, or after `left` more points (a curve
    that crawls: a switch along a continuum of the slack side moved 1e-4 of the window in 300
    points); and the state that says which, where, and how many points it kept."""
    pattern = _taut(plane, start, cable)
    state: dict = {"why": None, "at": None, "away": False, "kept": 0, "plane": 0.0, "last": start}

    def keep(z: np.ndarray) -> bool:
        state["kept"] += 1
        state["plane"] += float(win.xy_distance(z, state["last"]))
        state["last"] = z
        if state["kept"] > left:
            state.update(why="max_points", at=z)
            return False
        if state["kept"] >= CRAWL_POINTS and (
            state["plane"] < CRAWL * spacing * win.diagonal * state["kept"]
        ):  # the pose moves, the parameters hardly: not a curve of the map's plane
            state.update(why="crawls", at=z)
            return False
        if _chart_moves(plane, z[: plane.n]):
            state.update(why="chart", at=z)
            return False
        if (_taut(plane, z, cable) != pattern).any():
            state.update(why="taut_set", at=z)
            return False
        if not state["away"]:
            state["away"] = not _near(plane, z, seed, win, spacing, 3)[0]
        elif _near(plane, z, seed, win, spacing, 1)[0]:
            state.update(why="closed", at=z)
            return False
        return True

    return keep, state


def _velocity(plane: ChartPlane, z: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The pose's and parameters' velocity along tangent t at z (chart-independent)."""
    n = plane.n
    land = plane.land(z[n:])
    if not hasattr(land, "positions"):
        return t
    h = 1e-6
    moved = land.positions(np.stack([z[:n] + h * t[:n], z[:n] - h * t[:n]]))
    return np.concatenate([(moved[0] - moved[1]) / (2 * h), t[n:]])


def _across(plane: ChartPlane, eqs: Equations, last: np.ndarray, at: np.ndarray) -> tuple:
    """The point `at` (where a piece left its chart, coming from `last`) recharted, with the
    tangent there that goes on the same way."""
    n = plane.n
    t_old = tangent(eqs, at, at)
    t_old = t_old if t_old @ (at - last) > 0 else -t_old
    z = at.copy()
    z[:n] = plane.rechart(at[None, :n])[0]
    t_new = tangent(eqs, z, z)
    same = _velocity(plane, z, t_new) @ _velocity(plane, at, t_old) > 0
    return z, t_new if same else -t_new


def _trace_on(plane: ChartPlane, eqs: Equations, z0: np.ndarray, t0: np.ndarray, win: Window,
              spacing: float, cable) -> tuple[list[np.ndarray], str]:  # fmt: skip
    """One end of a curve from its seed z0 along t0, in pieces (module docstring): the pieces
    (each in one chart; after the first each starts at the point recharted) and how it ended
    (curve_trace's ends, "taut_set", "closed", or "max_pieces")."""
    pieces, z, t, first = [], z0, t0, np.zeros((0, len(z0)))
    left = int(CURVE_POINTS / spacing)
    for _ in range(MAX_PIECES):
        keep, state = _guard(plane, z, z0, cable, win, spacing, left)
        pts, end = one_way(eqs, z, t, win, spacing, HMAX, keep)
        left -= state["kept"]
        pieces.append(np.vstack([first, pts]))
        if end != "left":
            return pieces, end
        if state["why"] != "chart":
            return pieces, state["why"]
        z, t = _across(plane, eqs, pts[-1] if len(pts) else z, state["at"])
        first = z[None]
    return pieces, "max_pieces"


def _trace(plane: ChartPlane, seed: Seed, z0: np.ndarray, win: Window, spacing: float) -> _Curve:
    """The curve through z0 both ways, its pieces joined in order."""
    started = time.perf_counter()
    eqs = _equations(plane, seed)
    t0 = tangent(eqs, z0, z0)
    fwd, end_f = _trace_on(plane, eqs, z0, t0, win, spacing, seed.cable)
    back, end_b = ([], "closed") if end_f == "closed" else _trace_on(
        plane, eqs, z0, -t0, win, spacing, seed.cable)  # fmt: skip
    back = back or [np.zeros((0, len(z0)))]
    middle = np.vstack([back[0][::-1], z0[None], fwd[0]])
    segments = [b[::-1] for b in back[:0:-1]] + [middle] + fwd[1:]
    if end_f == "closed":
        segments.append(z0[None])  # the polyline closes
    segments = [s for s in segments if len(s)]
    return _Curve(seed, segments, (end_b, end_f), len(fwd) + len(back),
                  time.perf_counter() - started, eqs)  # fmt: skip


def _polish(plane: ChartPlane, seed: Seed, eqs: Equations) -> np.ndarray | None:
    """The seed recharted and brought onto its curve (Newton across the curve)."""
    n = plane.n
    z = np.asarray(seed.z, float).copy()
    z[:n] = plane.rechart(z[None, :n])[0]
    t = tangent(eqs, z, z)
    return newton(eqs, z, z, lambda w: (t @ (w - z), t))


def chart_fold_curves(plane: ChartPlane, seeds, xrange: tuple[float, float],
                      yrange: tuple[float, float],
                      spacing: float = SPACING) -> tuple[pd.DataFrame, dict]:  # fmt: skip
    """Fold curves (with their cusps) and cable-switch curves through `seeds` in the window
    xrange x yrange of the plane's parameters: one row a point (the framework folds table,
    docs/columns.md), and the record (curves, their ends, points and seconds; seeds skipped)."""
    started = time.perf_counter()
    seeds = list(seeds)
    _check(plane, seeds, xrange, yrange)
    n = plane.n
    win = Window(n, n + 1, (xrange[0], yrange[0]), (xrange[1], yrange[1]), (1.0, 1.0))
    curves: list[_Curve] = []
    counts = {"seeds_on_traced": 0, "seeds_outside": 0, "seeds_not_refined": 0}
    # A curve's trace can take tens of seconds: a heartbeat between seeds (silent if short).
    with Progress("map: curves traced from the seeds", len(seeds), "seeds",
                  heartbeat=True) as report:  # fmt: skip
        for seed in seeds:
            z = _polish(plane, seed, _equations(plane, seed))
            same = [c for c in curves if (c.seed.kind, c.seed.cable) == (seed.kind, seed.cable)]
            if z is None:
                counts["seeds_not_refined"] += 1
            elif not win.inside(z, 1e-9):
                counts["seeds_outside"] += 1
            elif any(_near(plane, c.points, z, win, spacing, ON_CURVE).any() for c in same):
                counts["seeds_on_traced"] += 1
            else:
                curves.append(_trace(plane, seed, z, win, spacing))
            report.update(1, f"{len(curves)} curves")
    traced = time.perf_counter()
    table, about = _rows(plane, curves, win)
    warnings = [f"{counts['seeds_not_refined']} seeds did not converge onto a curve"] * bool(
        counts["seeds_not_refined"]) + about.pop("warnings")  # fmt: skip
    stops = ("max_points", "stalled", "max_pieces", "crawls")
    short = sum(end in stops for c in curves for end in c.ends)
    warnings += [f"{short} curve ends stopped before the window's edge ({', '.join(stops)}: "
                 "the curve's record)"] * bool(short)  # fmt: skip
    record = {
        "window": {plane.x: list(xrange), plane.y: list(yrange)}, "spacing": spacing,
        "seeds": len(seeds), **counts, "warnings": warnings,
        "curves": [{"curve_id": i, "kind": c.seed.kind, "cable": c.seed.cable,
                    "points": len(c.points), "pieces": c.pieces, "ends": list(c.ends),
                    "seconds": c.seconds} for i, c in enumerate(curves)],
        "trace_seconds": traced - started, "classify_seconds": time.perf_counter() - traced,
        "seconds": time.perf_counter() - started, **about,
        "counts": {k: int((table["kind"] == k).sum())
                   for k in ("fold", "cusp", "cable_switch", "pitchfork")},
    }  # fmt: skip
    return table, record


def _rows(plane: ChartPlane, curves: list[_Curve], win: Window) -> tuple[pd.DataFrame, dict]:
    """The table of the curves' points and cusps (physical points only) and counts."""
    about: dict = {"cusps": 0, "unconfirmed_turns": 0, "nonphysical_points": 0,
                   "unsided_switches": 0, "classified_points": 0}  # fmt: skip
    rows = []
    for cid, curve in enumerate(curves):
        pts = curve.points
        arc = np.concatenate([[0.0], np.cumsum(win.xy_distance(pts[1:], pts[:-1]))])
        arc /= win.diagonal
        kind = curve.seed.kind
        for z, a in zip(pts, arc, strict=True):
            here = "pitchfork" if kind == "fold" and _pull(plane, z) < PITCHFORK else kind
            rows.append({**_point(plane, z, curve.seed, about), "curve_id": cid, "arc": a,
                         "kind": here})  # fmt: skip
        offset = 0
        for seg in curve.segments if kind == "fold" else []:
            for k, z in _cusps(curve.eqs, seg, win, CUSP_HALVINGS):
                row = _point(plane, z, curve.seed, about)
                if row["null_cubic"] <= CUSP_TOL:
                    about["cusps"] += 1
                    rows.append({**row, "curve_id": cid, "arc": arc[offset + k], "kind": "cusp"})
                else:
                    about["unconfirmed_turns"] += 1
            offset += len(seg)
    columns = list(_empty(plane.fw, plane.x, plane.y).columns)
    frame = pd.DataFrame(rows) if rows else _empty(plane.fw, plane.x, plane.y)
    about["nonphysical_points"] = int((~frame["physical"].astype(bool)).sum())
    frame = frame[frame["physical"].astype(bool)].reset_index(drop=True)
    about["warnings"] = [f"{about[k]} {what}" for k, what in (
        ("unconfirmed_turns", "turns of a fold curve's image with a cubic term not 0 (no cusp)"),
        ("unsided_switches", "switch points whose two sides could not be told apart"),
        ("nonphysical_points", "points not physical (left out)"),
    ) if about[k]]  # fmt: skip
    return frame[columns], about


def _point(plane: ChartPlane, z: np.ndarray, seed: Seed, about: dict) -> dict:
    """One point's row: its solution columns (framework_classify), physical, taut set,
    changes_stable_count and (folds) null_cubic."""
    if seed.kind == "fold":
        changes, cubic = _fold_stability(plane, z)
        at = z
    else:
        changes, at = _switch_stability(plane, z, seed.cable)
        cubic = np.nan
        if changes is None:
            about["unsided_switches"] += 1
    about["classified_points"] += 1
    row = _solution_row(plane, at)
    row.update({plane.x: z[plane.n], plane.y: z[plane.n + 1], "changes_stable_count": changes,
                "null_cubic": cubic})  # fmt: skip
    return row


def _solution_row(plane: ChartPlane, z: np.ndarray) -> dict:
    """The framework's solution columns of the equilibrium at z (chart angles, x, y), whether
    it is physical, and its taut set."""
    n = plane.n
    land = plane.land(z[n:])
    ((taut, ends),) = land.endpoints(z[None, :n]).items()
    fs = framework_system(land.fw, taut)
    cols, _ = framework_rows(land.fw, fs, ends, units(plane.fw), Tolerances())
    row = {c: cols[c][0] for c in _solution_columns(plane.fw)}
    return {**row, "physical": bool(cols["physical"][0]), "taut": " ".join(fs.taut) or "none"}


def _fold_stability(plane: ChartPlane, z: np.ndarray) -> tuple[bool, float]:
    """At a fold point: whether a minimum meets an index-1 saddle (no negative eigenvalue
    besides the one nearest 0) and the null direction's cubic term (module docstring)."""
    n = plane.n
    _, H = plane.derivatives(z[:n], z[n:])
    eig, vec = np.linalg.eigh(H[0])
    k = int(np.argmin(np.abs(eig)))
    v = vec[:, k]
    _, Hs = plane.derivatives(np.stack([z[:n] + FD_ANGLE * v, z[:n] - FD_ANGLE * v]), z[n:])
    cubic = float(abs(v @ (Hs[0] - Hs[1]) @ v) / (2 * FD_ANGLE) / max(1.0, np.abs(H).max()))
    return bool((np.delete(eig, k) < 0).sum() == 0), cubic


def _pull(plane: ChartPlane, z: np.ndarray) -> float:
    """|v . dgrad/d(x, y)| / |dgrad/d(x, y)| at a point of the fold system (v the unit null
    direction of H): 0 where the parameters cannot move the equilibria along v, so the branch
    passes instead of turning (a pitchfork: by a symmetry, e.g. the mirror of a flat pose)."""
    n = plane.n
    _, H = plane.derivatives(z[:n], z[n:])
    eig, vec = np.linalg.eigh(H[0])
    v = vec[:, int(np.argmin(np.abs(eig)))]
    gp = plane.grad_p(z[:n], z[n:])[0]
    return float(np.abs(v @ gp).max() / max(np.abs(gp).max(), 1e-300))


def _switch_stability(plane: ChartPlane, z: np.ndarray, cable: str) -> tuple:
    """At a switch point: whether a stable taut branch ends there (framework_folds._classify:
    index 0 with the cable taut, >= 1 with it slack; None where the sides are not told apart),
    and the point NUDGE into the taut side (classified as the taut set's)."""
    n, j = plane.n, plane.cables.index(cable)
    dm = switch_equations(plane, cable)(z, z)[1][-1, :n]
    step = NUDGE * dm / max(float(dm @ dm), 1e-300)
    sides = np.stack([z[:n] + step, z[:n] - step])
    m = plane.margins(sides, z[n:])[:, j]
    taut_side = np.concatenate([sides[0], z[n:]])
    if not (m[0] > 0 > m[1]):
        return None, z
    _, H = plane.derivatives(sides, z[n:])
    index = (np.linalg.eigvalsh(H) < 0).sum(axis=1)
    # With the cable slack the Hessian loses the cable's positive rank-one term: the same index
    # (the equilibrium passes between taut sets) or one more (two branches end together here).
    return bool(index[0] == 0 and index[1] >= 1), taut_side
