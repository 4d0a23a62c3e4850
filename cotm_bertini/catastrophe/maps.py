"""A design map's pieces: its window and axes (the paper's free lengths, or any two parameters
of a framework), every fold point in it, the stable counts on its grid, and its completeness
check (each change of the stable count between grid neighbours crossed by a fold curve or a
cable switch). cb.design_map (api.maps) runs the 2-D sweep between them."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from ..errors import ParameterError
from ..params import Params

FREE_LENGTHS = ("L01", "L02")
PAPER_WINDOW = (0.0, 14.0)  # the paper's map: both free lengths from 0 to 14 m
UNEXPLAINED_LISTED = 20  # run.json lists this many unexplained count changes at most


def _window(name: str, lo: float, hi: float, points: int, nonnegative: bool) -> None:
    for what, v in ((f"{name} from", lo), (f"{name} to", hi)):
        if not nonnegative and not math.isfinite(v):
            raise ParameterError(f"{what} {v!r}: must be finite")
        if nonnegative and not (math.isfinite(v) and v >= 0):
            raise ParameterError(f"{what} {v!r}: a free length must be finite and >= 0")
    if not hi > lo:
        raise ParameterError(f"{name}: the range {lo:g} to {hi:g} is empty (need from < to)")
    if isinstance(points, bool) or not isinstance(points, int | np.integer) or points < 2:
        raise ParameterError(f"points = {points!r}: a map needs at least 2 points a side")


def map_axes(model, axes: tuple, l01, l02, points) -> tuple[tuple, tuple, int]:
    """((x, xrange), (y, yrange), points) from design_map's arguments: (x, xrange, y, yrange
    [, points]), or for the paper (l01, l02 [, points]) or the keywords l01=, l02=."""
    paper = isinstance(model, Params)
    if axes and isinstance(axes[0], str):
        if len(axes) not in (4, 5) or l01 is not None or l02 is not None:
            raise ParameterError("design_map(model, x, (from, to), y, (from, to), points=...)")
        (x, xr, y, yr), extra = axes[:4], axes[4:]
    elif paper and len(axes) <= 3:
        given = list(axes[:2])
        for k, kw in enumerate((l01, l02)):
            if kw is not None and k < len(given):
                raise ParameterError(f"design_map: {FREE_LENGTHS[k]} given twice")
        xr = given[0] if given else (l01 or PAPER_WINDOW)
        yr = given[1] if len(given) > 1 else (l02 or PAPER_WINDOW)
        (x, y), extra = FREE_LENGTHS, axes[2:]
    else:
        raise ParameterError(
            "design_map: name the two parameters of the framework, "
            "design_map(fw, x, (from, to), y, (from, to), points=...)"
        )
    if extra:
        if points is not None:
            raise ParameterError("design_map: points given twice")
        points = extra[0]
    points = 101 if points is None else points
    if paper and {x, y} != set(FREE_LENGTHS):
        raise ParameterError(
            f"design_map: axes {x!r}, {y!r}: the paper's map is over the free lengths, L01 and L02"
        )
    if paper and x == "L02":  # the paper's map has L01 across
        (x, xr), (y, yr) = (y, yr), (x, xr)
    if not paper:
        from ..continuation.framework import check_param

        check_param(model, x, "x")
        check_param(model, y, "y")
        if x == y:
            raise ParameterError(f"design_map: y = {y!r} is the same parameter as x")
    xr, yr = _range(x, xr), _range(y, yr)
    _window(x, *xr, points, nonnegative=paper)
    _window(y, *yr, points, nonnegative=paper)
    return (x, xr), (y, yr), int(points)


def _range(name: str, r) -> tuple[float, float]:
    """A window's (from, to) as floats, or a one-line error naming the axis."""
    try:
        lo, hi = r
        return float(lo), float(hi)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}: the range {r!r} must be two numbers (from, to)") from None


def fold_points(model, x: str, xr, y: str, yr, settings, workers: int) -> tuple:
    """Every fold point (the paper's: closed form, proved; a framework's: by Bertini), with
    what was done."""
    if isinstance(model, Params):
        from .paper_folds import fold_curves_proved

        return fold_curves_proved(model)
    from .framework_folds import framework_fold_curves

    return framework_fold_curves(model, x, xr, y, yr, settings, workers=workers)


def explained(regions: pd.DataFrame, folds: pd.DataFrame, axes, sweep_status: str) -> dict:
    """The map's completeness check: the stable-count changes between grid neighbours that no
    fold curve changing the count (or cable switch) crosses; incomplete if any."""
    from .regions import count_changes, unexplained

    missed, tolerance = unexplained(regions, folds, *axes)
    listed = missed.head(UNEXPLAINED_LISTED)
    return {
        "count_changes": len(count_changes(regions, *axes)),
        "unexplained_changes": len(missed),
        "unexplained": listed.to_dict(orient="records"),
        "explain_tolerance": tolerance,
        "status": "ok" if sweep_status == "ok" and missed.empty else "incomplete",
    }


def grid_values(lo: float, hi: float, points: int) -> np.ndarray:
    """`points` evenly spaced values from lo to hi, each the double nearest the exact decimal
    value (computed in decimal arithmetic): 0 to 14 in 41 points gives 2.1, never the
    2.0999999999999996 of np.linspace."""
    from decimal import Decimal

    a, b = Decimal(repr(float(lo))), Decimal(repr(float(hi)))
    return np.array([float(a + (b - a) * k / (points - 1)) for k in range(points)])


def counts_on_grid(
    columns: dict[str, np.ndarray], xs: np.ndarray, ys: np.ndarray, axes=FREE_LENGTHS
) -> pd.DataFrame:
    """Physical and stable equilibria at each grid point (0 where a point has no row), from the
    2-D sweep's columns (its `point` is the grid index, the second axis varying fastest)."""
    size = len(xs) * len(ys)
    point = np.asarray(columns["point"], dtype=int)
    count = {
        name: np.bincount(point, weights=np.asarray(columns[name], dtype=bool), minlength=size)
        for name in ("physical", "stable")
    }
    return pd.DataFrame(
        {axes[0]: np.repeat(xs, len(ys)), axes[1]: np.tile(ys, len(xs)),
         **{name: c.astype(int) for name, c in count.items()}}
    )  # fmt: skip
