"""The design map of the (L01, L02) plane (cb.design_map): fold curves, stable-count regions."""

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
from ..settings import Settings

FREE_LENGTHS = ("L01", "L02")
SWEEP_FOLDER = "sweep"  # in a saved map: the 2-D sweep behind regions.csv


@dataclass(frozen=True)
class DesignMap:
    """Fold points inside the window (`folds`), the grid of counts (`regions`), timings; the
    2-D sweep that counted them is in `record["sweep_folder"]`."""

    params: Params
    folds: pd.DataFrame
    regions: pd.DataFrame
    record: dict

    def plot(self, path: str | Path) -> list[Path]:
        """map.png/svg: stable counts coloured, fold curves on top, the paper's cases marked."""
        from ..plot.design_map import plot_map

        return plot_map(self.params, self.regions, self.folds, path)

    def save(self, folder: str | Path, plots: bool = True) -> Path:
        """folds.csv, regions.csv, columns.md, run.json [, map.png/svg] and sweep/ (the 2-D
        sweep behind regions.csv, hard-linked from where it was solved) in a new folder, built
        under a hidden name and renamed when complete."""
        source = Path(self.record["sweep_folder"])
        with new_folder(folder) as work:
            write_csv(work / "folds.csv", self.folds)
            write_csv(work / "regions.csv", self.regions)
            atomic_write_text(work / "columns.md", reference("folds", "regions"))
            if plots:
                self.plot(work / "map")
            link_tree(source, work / SWEEP_FOLDER)
            record = {**self.record, "sweep_folder": SWEEP_FOLDER, "sweep_solved_in": str(source)}
            write_json(work / "run.json", record)
        return Path(folder)


def _window(name: str, lo: float, hi: float, points: int) -> None:
    for what, v in ((f"{name} from", lo), (f"{name} to", hi)):
        if not math.isfinite(v) or v < 0:
            raise ParameterError(f"{what} {v!r}: a free length must be finite and >= 0")
    if not hi > lo:
        raise ParameterError(f"{name}: the range {lo:g} to {hi:g} is empty (need from < to)")
    if points < 2:
        raise ParameterError(f"points = {points!r}: a map needs at least 2 points a side")


def design_map(
    params: Params,
    l01: tuple[float, float] = (0.0, 14.0),
    l02: tuple[float, float] = (0.0, 14.0),
    points: int = 101,
    settings: Settings | None = None,
    workers: int = 1,
    progress: bool = False,
) -> DesignMap:
    """Fold curves in the window, and the number of physical and stable equilibria on a
    points x points grid of it (by a 2-D sweep: parameter homotopies)."""
    from ..analysis.fold_curves import fold_curves_proved
    from .sweeps import sweep

    _window("L01", *l01, points)
    _window("L02", *l02, points)
    t0 = time.perf_counter()
    folds, certificate = fold_curves_proved(params)
    t_folds = time.perf_counter() - t0
    inside = folds.physical & folds.L01.between(*l01) & folds.L02.between(*l02)
    folds = folds[inside].reset_index(drop=True)
    xs, ys = grid_values(*l01, points), grid_values(*l02, points)
    sw = sweep(params, "L01", xs, settings, param2="L02", values2=ys, workers=workers,
               progress=progress)  # fmt: skip
    regions = _counts(sw.columns, xs, ys)
    pieces = int(folds.curve_id[folds.curve_id >= 0].nunique())
    record = {
        "params": params.as_dict(), "window": {"L01": list(l01), "L02": list(l02)},
        "points": points, "fold_points": len(folds), "fold_curves": pieces,
        "cusps": int((folds.kind == "cusp").sum()), "certificate": certificate,
        "timings": {"folds": t_folds, "regions": time.perf_counter() - t0 - t_folds},
        "sweep_folder": str(sw.folder), "sweep_status": sw.status, "command": sys.argv[:],
    }  # fmt: skip
    return DesignMap(params, folds, regions, record)


def grid_values(lo: float, hi: float, points: int) -> np.ndarray:
    """`points` evenly spaced values from lo to hi, each the double nearest the exact decimal
    value (computed in decimal arithmetic): 0 to 14 in 41 points gives 2.1, never the
    2.0999999999999996 of np.linspace."""
    from decimal import Decimal

    a, b = Decimal(repr(float(lo))), Decimal(repr(float(hi)))
    return np.array([float(a + (b - a) * k / (points - 1)) for k in range(points)])


def _counts(columns: dict[str, np.ndarray], xs: np.ndarray, ys: np.ndarray) -> pd.DataFrame:
    """Physical and stable equilibria at each grid point (0 where a point has no row), from the
    2-D sweep's columns (its `point` is the grid index, L02 varying fastest)."""
    size = len(xs) * len(ys)
    point = np.asarray(columns["point"], dtype=int)
    count = {
        name: np.bincount(point, weights=np.asarray(columns[name], dtype=bool), minlength=size)
        for name in ("physical", "stable")
    }
    return pd.DataFrame(
        {"L01": np.repeat(xs, len(ys)), "L02": np.tile(ys, len(xs)),
         **{name: c.astype(int) for name, c in count.items()}}
    )  # fmt: skip
