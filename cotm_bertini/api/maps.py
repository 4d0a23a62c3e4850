"""Design maps over two parameters (cb.design_map): fold curves, stable-count regions. The
paper's mechanism over (L01, L02), or a framework (cb.Framework) over any two of its
parameters; one DesignMap for both."""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from ..catastrophe.maps import (
    FREE_LENGTHS,
    counts_on_grid,
    explained,
    fold_points,
    grid_values,
    map_axes,
)
from ..columns import reference
from ..fs import atomic_write_text, link_tree, new_folder, write_csv, write_json
from ..params import Params
from ..progress import duration, say
from ..settings import Settings

SWEEP_FOLDER = "sweep"  # in a saved map: the 2-D sweep behind regions.csv


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

    def explore(self, path: str | Path) -> Path:
        """explore.html: the map in a browser, offline; a click on a grid point draws its
        equilibria (from the map's 2-D sweep)."""
        from ..plot.explore_pages import map_page

        return map_page(self, path)

    def save(self, folder: str | Path, plots: bool = True, html: bool = False) -> Path:
        """folds.csv, regions.csv, columns.md, run.json [, map.png/svg] [, explore.html] and
        sweep/ (the 2-D sweep behind regions.csv, hard-linked from where it was solved) in a
        new folder, built under a hidden name and renamed when complete."""
        source = Path(self.record["sweep_folder"])
        tables = ("folds", "regions") if isinstance(self.params, Params) else MAP_TABLES
        with new_folder(folder) as work:
            write_csv(work / "folds.csv", self.folds)
            write_csv(work / "regions.csv", self.regions)
            atomic_write_text(work / "columns.md", reference(*tables))
            if plots:
                self.plot(work / "map")
            if html:
                self.explore(work / "explore.html")
            link_tree(source, work / SWEEP_FOLDER)
            record = {**self.record, "sweep_folder": SWEEP_FOLDER, "sweep_solved_in": str(source)}
            write_json(work / "run.json", record)
        return Path(folder)


MAP_TABLES = ("framework_folds", "framework_regions")  # columns.md of a framework's map


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

    (x, xr), (y, yr), points = map_axes(model, axes, l01, l02, points)
    for a in xr:  # the window's corners validated before any work is announced or done
        for b in yr:
            model.replace(**{x: a, y: b})
    t0 = time.perf_counter()
    say(f"map: fold curves in the window {x} {xr[0]:g}..{xr[1]:g}, {y} {yr[0]:g}..{yr[1]:g}")
    folds, fold_record = fold_points(model, x, xr, y, yr, settings, workers)
    t_folds = time.perf_counter() - t0
    inside = folds.physical.astype(bool) & folds[x].between(*xr) & folds[y].between(*yr)
    folds = folds[inside].reset_index(drop=True)
    xs, ys = grid_values(*xr, points), grid_values(*yr, points)
    say(f"map: {len(folds)} fold points in {duration(t_folds)}; now the stable counts on a "
        f"{points} x {points} grid (a 2-D sweep)")  # fmt: skip
    sw = sweep(model, x, xs, settings, param2=y, values2=ys, workers=workers, progress=progress)
    regions = counts_on_grid(sw.columns, xs, ys, (x, y))
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
        record.update(explained(regions, folds, (x, y), sw.status))
        record["timings"]["check"] = time.perf_counter() - t0 - t_folds - t_regions
    return DesignMap(model, folds, regions, record, (x, y))
