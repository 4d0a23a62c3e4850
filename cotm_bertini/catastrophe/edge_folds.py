"""The fold curves of a map of the stable states alone (`only="stable"`) of a framework in
space: seeded where a minimum vanishes between two grid neighbours, then traced in chart angles.

Every grid point's minima were searched and proved (a 2-D sweep). Between two neighbours whose
stable counts differ, each minimum of the richer point that has no match at the other meets its
(not searched) partner at a fold on that grid edge: the fold is located by Newton on the fold
system along the edge's parameter (continuation/fold_point.py), from the minimum or, where that
does not converge, from the minimum followed along the edge as far as it stays one; the curve
through it is traced by catastrophe/chart_curves.py. A fold Newton does not reach is seeded from
the minimum itself; one neither reaches leaves its count change unexplained, and the map's check
says so.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..continuation.charts import ChartPlane
from ..continuation.fold_point import fold_newton
from ..continuation.framework_events import new_rows, usable
from .chart_curves import Seed, chart_fold_curves


def stable_fold_curves(fw, columns: dict, x: str, xs, y: str, ys) -> tuple[pd.DataFrame, dict]:
    """The fold curves through every grid edge of the 2-D sweep `columns` (xs x ys, only the
    minima) where a minimum vanishes, and the record (edges, seeds located, the tracing's)."""
    part = _points(columns, len(xs) * len(ys))
    seeds, located, edges = [], 0, 0
    for a, b, along in _edges(len(xs), len(ys)):
        if not (usable(part[a]) and usable(part[b])):
            continue
        more, less = (a, b) if _minima(part[a]) > _minima(part[b]) else (b, a)
        gone = _minima(part[more]) - _minima(part[less])
        if gone == 0:
            continue
        edges += 1
        for z, newton in _edge_seeds(fw, part, (x, xs, y, ys), (more, less), along, gone):
            located += newton
            seeds.append(Seed("fold", z))
    centre = fw.replace(**{x: float(xs[len(xs) // 2]), y: float(ys[len(ys) // 2])})
    plane = ChartPlane(centre, x, y)
    folds, record = chart_fold_curves(plane, seeds, (xs[0], xs[-1]), (ys[0], ys[-1]))
    return folds, {"grid": "search", "edges_with_a_minimum_gone": edges, "seeds": len(seeds),
                   "seeds_located_by_fold_newton": located, "curves": record}  # fmt: skip


def _points(columns: dict, count: int) -> list[dict]:
    """Each grid point's rows as columns (the 2-D sweep's `point` index, param2 fastest)."""
    point = np.asarray(columns["point"])
    return [{n: np.asarray(v)[point == k] for n, v in columns.items()} for k in range(count)]


def _edges(nx: int, ny: int):
    """Every pair of grid neighbours (a, b) and the axis (0: x, 1: y) they differ along."""
    for i in range(nx):
        for j in range(ny):
            if i + 1 < nx:
                yield i * ny + j, (i + 1) * ny + j, 0
            if j + 1 < ny:
                yield i * ny + j, i * ny + j + 1, 1


def _minima(cols: dict) -> int:
    return int(np.asarray(cols["stable"], dtype=bool).sum())


def _edge_seeds(fw, part: list, grid: tuple, ends: tuple, along: int, gone: int) -> list:
    """[(z, located)]: a seed of each fold on the grid edge ends[0] -> ends[1] (`gone` minima
    of ends[0] vanish on it). Each minimum of ends[0] is followed along the edge; one that
    stops being a minimum before its end vanishes there, and Newton on the fold system from
    where it stopped locates its fold (located: True). Where the count of those is not
    `gone`, the minima farthest in pose from those of ends[1] are taken instead; a fold Newton
    does not reach is seeded from the minimum itself (False)."""
    x, xs, y, ys = grid
    (i, j), (k, m) = (divmod(e, len(ys)) for e in ends)
    here = np.array([xs[i], ys[j]], dtype=float)
    param, other = (x, y) if along == 0 else (y, x)
    p_from, p_to = float(here[along]), float((xs[k], ys[m])[along])
    line = ChartPlane(fw.replace(**{other: float(here[1 - along])}), param, param)
    cols = part[ends[0]]
    theta = line.land((p_from, p_from)).chart_points(cols)
    rows = np.flatnonzero(np.asarray(cols["stable"], dtype=bool))
    stops = {r: _approach(line, theta[r], p_from, p_to) for r in rows}
    vanish = [r for r in rows if stops[r][0][1] != p_to]
    # Two followed to one minimum at p_to: all but the steadiest jumped there from a branch
    # that vanished, at their largest step (the fold is just past the pose before it).
    for group in _same_pose(line, [r for r in rows if r not in vanish], stops, p_to):
        for r in sorted(group, key=lambda r: stops[r][2])[1:]:
            vanish.append(r)
            stops[r] = (stops[r][1], None, 0.0)
    if len(vanish) != gone:
        vanish = list(new_rows(fw, cols, part[ends[1]], gone))
    out = []
    for r in vanish:
        last = stops[r][0]
        fold = fold_newton(line, *last, p_to) if last[1] != p_to else None
        if fold is not None and min(p_from, p_to) < fold.value < max(p_from, p_to):
            at = here.copy()
            at[along] = fold.value
            out.append((np.concatenate([fold.theta, at]), True))
        else:
            out.append((np.concatenate([theta[r], here]), False))
    return out


# _approach: steps along the grid edge. Not continuation/charts.advance: it tries the whole
# edge in one predictor-corrector step first, and past a fold its corrector lands on the other
# minimum (same index, so its checks pass): measured on tests/test_stable_maps.py's fixture, 5
# of 12 vanishing minima were followed across. Small even steps and the largest-jump rule
# (_same_pose) catch that.
APPROACH_STEPS = 64


def _approach(line: ChartPlane, theta: np.ndarray, p_from: float, p_to: float) -> tuple:
    """(last, before, jump): the minimum at `theta`, p_from followed towards p_to by Newton on
    grad V = 0 in APPROACH_STEPS steps as far as it stays a minimum: `last` (theta, p) its
    last pose, `before` the pose before its largest step, `jump` that step's size (rad)."""
    last, before, jump = (theta, p_from), (theta, p_from), 0.0
    for k in range(1, APPROACH_STEPS + 1):
        p = p_from + (p_to - p_from) * k / APPROACH_STEPS
        at = np.array([p, p])
        x = begin = line.rechart(last[0][None])[0]  # each step in a chart regular there
        for _ in range(30):
            g, H = (m[0] for m in line.derivatives(x[None], at))
            try:
                move = np.linalg.solve(H, g)
            except np.linalg.LinAlgError:
                return last, before, jump
            x = x - move
            if np.abs(move).max() < 1e-12:
                break
        _, H = (m[0] for m in line.derivatives(x[None], at))
        step = float(np.abs(x - begin).max())
        if not (np.abs(move).max() < 1e-9 and step < 0.5 and np.linalg.eigvalsh(H)[0] > 0):
            return last, before, jump
        if step > jump:
            before, jump = last, step
        last = (x, p)
    return last, before, jump


def _same_pose(line: ChartPlane, rows: list, stops: dict, p: float) -> list[list]:
    """The groups of more than one of `rows` whose followed minima end at one pose at p."""
    groups: list[list] = []
    for r in rows:
        here = stops[r][0][0][None]
        for g in groups:
            if not len(line.fresh(here, stops[g[0]][0][0][None], (p, p))):
                g.append(r)
                break
        else:
            groups.append([r])
    return [g for g in groups if len(g) > 1]
