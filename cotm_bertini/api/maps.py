"""Design maps over two parameters (cb.design_map): fold curves, stable-count regions. The
paper's mechanism over (L01, L02), or a framework (cb.Framework) over any two of its
parameters; one DesignMap for both."""

from __future__ import annotations

import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..columns import reference
from ..errors import ParameterError
from ..fs import atomic_write_text, link_tree, new_folder, write_csv, write_json
from ..params import Params
from ..progress import duration, say
from ..settings import Settings

FREE_LENGTHS = ("L01", "L02")
PAPER_WINDOW = (0.0, 14.0)  # the paper's map: both free lengths from 0 to 14 m
SWEEP_FOLDER = "sweep"  # in a saved map: the 2-D sweep behind regions.csv
UNEXPLAINED_LISTED = 20  # run.json lists this many unexplained count changes at most


@dataclass(frozen=True)
class DesignMap:
    """Fold points inside the window (`folds`), the grid of counts (`regions`, columns named
    as the two `axes`), timings; the 2-D sweep that counted them is in
    `record["sweep_folder"]`. `params`: the paper's Params or the cb.Framework mapped."""

    params: object
    folds: pd.DataFrame
    regions: pd.DataFrame
    record: dict
    axes: tuple[str, str] = FREE_LENGTHS

    @property
    def cusps(self) -> pd.DataFrame:
        """The cusp rows of `folds`."""
        return self.folds[self.folds.kind == "cusp"].reset_index(drop=True)

    @property
    def status(self) -> str:
        """ok, or incomplete (a sweep point failed a check, or a count change is unexplained)."""
        return self.record["status"]

    def plot(self, path: str | Path) -> list[Path]:
        """map.png/svg: stable counts coloured, fold curves on top (the paper's cases marked
        on the paper's map)."""
        from ..plot.design_map import plot_map

        return plot_map(self.params, self.regions, self.folds, path, self.axes)

    def save(self, folder: str | Path, plots: bool = True) -> Path:
        """folds.csv, regions.csv, columns.md, run.json [, map.png/svg] and sweep/ (the 2-D
        sweep behind regions.csv, hard-linked from where it was solved) in a new folder, built
        under a hidden name and renamed when complete."""
        source = Path(self.record["sweep_folder"])
        tables = ("folds", "regions") if isinstance(self.params, Params) else MAP_TABLES
        with new_folder(folder) as work:
            write_csv(work / "folds.csv", self.folds)
            write_csv(work / "regions.csv", self.regions)
            atomic_write_text(work / "columns.md", reference(*tables))
            if plots:
                self.plot(work / "map")
            link_tree(source, work / SWEEP_FOLDER)
            record = {**self.record, "sweep_folder": SWEEP_FOLDER, "sweep_solved_in": str(source)}
            write_json(work / "run.json", record)
        return Path(folder)


MAP_TABLES = ("framework_folds", "framework_regions")  # columns.md of a framework's map


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


def _axes(model, axes: tuple, l01, l02, points) -> tuple[tuple, tuple, int]:
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


def design_map(
    model,
    *axes,
    points: int | None = None,
    settings: Settings | None = None,
    workers: int = 1,
    progress: bool = False,
    l01: tuple[float, float] | None = None,
    l02: tuple[float, float] | None = None,
) -> DesignMap:
    """Fold curves in the window, and the number of physical and stable equilibria on a
    points x points grid of it (by a 2-D sweep: parameter homotopies).

    A framework: design_map(fw, "x", (-0.6, 0.8), "y", (-0.8, 0.2), points=101), any two of
    its parameters. The paper's mechanism: design_map(params, l01=(0, 14), l02=(0, 14),
    points=101) (or positionally design_map(params, (0, 14), (0, 14), 101))."""
    from .sweeps import sweep

    (x, xr), (y, yr), points = _axes(model, axes, l01, l02, points)
    for a in xr:  # the window's corners validated before any work is announced or done
        for b in yr:
            model.replace(**{x: a, y: b})
    t0 = time.perf_counter()
    say(f"map: fold curves in the window {x} {xr[0]:g}..{xr[1]:g}, {y} {yr[0]:g}..{yr[1]:g}")
    folds, fold_record = _fold_curves(model, x, xr, y, yr, settings, workers)
    t_folds = time.perf_counter() - t0
    inside = folds.physical.astype(bool) & folds[x].between(*xr) & folds[y].between(*yr)
    folds = folds[inside].reset_index(drop=True)
    xs, ys = grid_values(*xr, points), grid_values(*yr, points)
    say(f"map: {len(folds)} fold points in {duration(t_folds)}; now the stable counts on a "
        f"{points} x {points} grid (a 2-D sweep)")  # fmt: skip
    sw = sweep(model, x, xs, settings, param2=y, values2=ys, workers=workers, progress=progress)
    regions = _counts(sw.columns, xs, ys, (x, y))
    t_regions = time.perf_counter() - t0 - t_folds
    pieces = int(folds.curve_id[folds.curve_id >= 0].nunique())
    record = {
        "params": model.as_dict(), "window": {x: list(xr), y: list(yr)}, "axes": [x, y],
        "points": points, "fold_points": len(folds), "fold_curves": pieces,
        "cusps": int((folds.kind == "cusp").sum()),
        "timings": {"folds": t_folds, "regions": t_regions},
        "sweep_folder": str(sw.folder), "sweep_status": sw.status, "command": sys.argv[:],
    }  # fmt: skip
    if isinstance(model, Params):
        record.update(certificate=fold_record, status=sw.status)
    else:
        record.update(framework=model.name, fold_record=fold_record)
        record.update(_explained(regions, folds, (x, y), sw.status))
        record["timings"]["check"] = time.perf_counter() - t0 - t_folds - t_regions
    return DesignMap(model, folds, regions, record, (x, y))


def _fold_curves(model, x: str, xr, y: str, yr, settings, workers: int) -> tuple:
    """Every fold point (the paper's: closed form, proved; a framework's: by Bertini), with
    what was done."""
    if isinstance(model, Params):
        from ..analysis.design.fold_curves import fold_curves_proved

        return fold_curves_proved(model)
    from ..continuation.framework_folds import framework_fold_curves

    return framework_fold_curves(model, x, xr, y, yr, settings, workers=workers)


def _explained(regions: pd.DataFrame, folds: pd.DataFrame, axes, sweep_status: str) -> dict:
    """The map's completeness check: the stable-count changes between grid neighbours that no
    fold curve changing the count (or cable switch) crosses; incomplete if any."""
    from ..analysis.design.region_changes import count_changes, unexplained

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


def _counts(
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
