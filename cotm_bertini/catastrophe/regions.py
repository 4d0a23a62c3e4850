"""The completeness check of a design map: every change of the stable count between neighbouring
grid points must be explained by a fold curve that changes the count (or a cable switch)
crossing the segment between them.

Distances are measured in window units (each axis divided by its window's width), so one
tolerance serves axes of any units. Fold curves are polylines: the rows of one `curve_id` in
order of `arc`, broken where consecutive points are further apart than `max_gap` (a curve that
leaves the window and comes back); a row with `curve_id` -1 is a point.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

MAX_GAP = 0.05  # window units: consecutive fold points further apart are not joined


def count_changes(regions: pd.DataFrame, x: str, y: str, column: str = "stable") -> pd.DataFrame:
    """Every pair of horizontal or vertical grid neighbours whose `column` differs: x0, y0, x1,
    y1 and the counts `before` (at x0, y0) and `after`."""
    grid = regions.pivot(index=y, columns=x, values=column).sort_index().sort_index(axis=1)
    xs, ys, g = grid.columns.to_numpy(float), grid.index.to_numpy(float), grid.to_numpy()
    rows = []
    for j, i in zip(*np.nonzero(g[:, 1:] != g[:, :-1]), strict=True):  # along x
        rows.append((xs[i], ys[j], xs[i + 1], ys[j], g[j, i], g[j, i + 1]))
    for j, i in zip(*np.nonzero(g[1:, :] != g[:-1, :]), strict=True):  # along y
        rows.append((xs[i], ys[j], xs[i], ys[j + 1], g[j, i], g[j + 1, i]))
    return pd.DataFrame(rows, columns=["x0", "y0", "x1", "y1", "before", "after"])


def explaining(folds: pd.DataFrame) -> np.ndarray:
    """The fold rows that can change the stable count: fold, cusp or pitchfork points flagged
    `changes_stable_count`, and every cable switch."""
    kind = folds["kind"].to_numpy()
    changes = folds["changes_stable_count"].to_numpy(bool)
    return (np.isin(kind, ("fold", "cusp", "pitchfork")) & changes) | (kind == "cable_switch")


def _window_units(folds: pd.DataFrame, x: str, y: str, window: tuple) -> np.ndarray:
    (x0, x1), (y0, y1) = window
    u = (folds[x].to_numpy(float) - x0) / (x1 - x0)
    return np.stack([u, (folds[y].to_numpy(float) - y0) / (y1 - y0)], axis=1)


def polylines(
    folds: pd.DataFrame, x: str, y: str, window: tuple, max_gap: float = MAX_GAP
) -> list[np.ndarray]:
    """The fold rows as polylines: positional indices of the rows of one `curve_id` in order of
    `arc`, broken where consecutive points are more than `max_gap` window units apart; each
    row of `curve_id` -1 alone."""
    pts = _window_units(folds, x, y, window)
    curve, arc = folds["curve_id"].to_numpy(int), folds["arc"].to_numpy(float)
    order = np.lexsort((arc, curve))
    p, c = pts[order], curve[order]
    joined = (c[1:] == c[:-1]) & (c[1:] >= 0) & (np.hypot(*(p[1:] - p[:-1]).T) <= max_gap)
    return np.split(order, np.flatnonzero(~joined) + 1) if len(order) else []


def fold_segments(
    folds: pd.DataFrame, x: str, y: str, window: tuple, max_gap: float = MAX_GAP
) -> np.ndarray:
    """The explaining fold curves as segments (k, 4) in window units: consecutive points of
    each polyline of the explaining rows; a polyline of one point as a segment of length 0."""
    keep = folds[explaining(folds)]
    pts = _window_units(keep, x, y, window)
    segs = [np.zeros((0, 4))]
    for line in polylines(keep, x, y, window, max_gap):
        q = pts[line]
        segs.append(np.hstack([q[:-1], q[1:]]) if len(q) > 1 else np.hstack([q, q]))
    return np.vstack(segs)


def _point_segment(p: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Distance from points p (n, 2) to segments s (n, 4)."""
    a, d = s[:, :2], s[:, 2:] - s[:, :2]
    dd = (d * d).sum(axis=1)
    t = np.clip(((p - a) * d).sum(axis=1) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
    return np.hypot(*(a + t[:, None] * d - p).T)


def segment_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance between segments a (n, 4) and b (n, 4), row by row: 0 where they cross."""

    def side(p, q, r):
        return np.sign(
            (q[:, 0] - p[:, 0]) * (r[:, 1] - p[:, 1]) - (q[:, 1] - p[:, 1]) * (r[:, 0] - p[:, 0])
        )

    p1, p2, q1, q2 = a[:, :2], a[:, 2:], b[:, :2], b[:, 2:]
    cross = (side(p1, p2, q1) * side(p1, p2, q2) < 0) & (side(q1, q2, p1) * side(q1, q2, p2) < 0)
    ends = np.minimum.reduce(
        [_point_segment(p1, b), _point_segment(p2, b), _point_segment(q1, a), _point_segment(q2, a)]
    )
    return np.where(cross, 0.0, ends)


def unexplained(
    regions: pd.DataFrame,
    folds: pd.DataFrame,
    x: str,
    y: str,
    tolerance: float | None = None,
    column: str = "stable",
) -> tuple[pd.DataFrame, float]:
    """The count changes between grid neighbours that no explaining fold curve crosses (within
    `tolerance` window units; default: the longest segment of the explaining curves, i.e. the
    fold spacing), and the tolerance used."""
    window = grid_window(regions, x, y)
    segs = fold_segments(folds, x, y, window)
    if tolerance is None:
        lengths = np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1])
        tolerance = float(lengths.max(initial=0.0))
    changes = count_changes(regions, x, y, column)
    return uncrossed(changes, segs, window, tolerance), tolerance


def grid_window(regions: pd.DataFrame, x: str, y: str) -> tuple:
    """((x0, x1), (y0, y1)): the ends of the grid."""
    return tuple((float(regions[a].min()), float(regions[a].max())) for a in (x, y))


def uncrossed(
    changes: pd.DataFrame, segments: np.ndarray, window: tuple, tolerance: float
) -> pd.DataFrame:
    """The rows of `changes` (count_changes) whose grid segment no segment of `segments` (k, 4,
    window units) comes within `tolerance` of."""
    (x0, x1), (y0, y1) = window
    origin, scale = np.array([x0, y0] * 2), np.array([x1 - x0, y1 - y0] * 2)
    grid = (changes[["x0", "y0", "x1", "y1"]].to_numpy(float) - origin) / scale
    lo_s, hi_s = (
        np.minimum(segments[:, :2], segments[:, 2:]),
        np.maximum(segments[:, :2], segments[:, 2:]),
    )
    missed = np.ones(len(grid), dtype=bool)
    for k, g in enumerate(grid):
        lo, hi = np.minimum(g[:2], g[2:]) - tolerance, np.maximum(g[:2], g[2:]) + tolerance
        near = segments[((hi_s >= lo) & (lo_s <= hi)).all(axis=1)]
        if len(near):
            missed[k] = segment_distance(np.broadcast_to(g, near.shape), near).min() > tolerance
    return changes[missed].reset_index(drop=True)
