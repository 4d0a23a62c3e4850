"""The design map: the number of stable equilibria over two parameters, the fold curves on top;
on the paper's (L01, L02) plane its case points marked, on a framework's map its fold curves
drawn as polylines (solid where they change the stable count) with the cusps."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ..params import CASES, Params
from .common import describe, param_label, save, set_title, values_line

FREE_LENGTHS = ("L01", "L02")


def map_figure(
    params, regions: pd.DataFrame, folds: pd.DataFrame, axes: tuple[str, str] = FREE_LENGTHS
) -> Figure:
    """Stable counts as coloured cells (gid `regions`), the fold curves and cusps (gid `cusps`)
    on top: for the paper, fold points (gids `fold-relaxed`, `fold-tensioned`) and its cases
    (gid `cases`); for a framework (cb.Framework), polylines (gids `fold-changes`,
    `fold-no-change`, `cable-switch`, `pitchfork`)."""
    fig = Figure(figsize=(8.4, 7.2), layout="constrained")
    ax = fig.subplots()
    xname, yname = axes
    x, y = np.unique(regions[xname]), np.unique(regions[yname])
    grid = regions.pivot(index=yname, columns=xname, values="stable").loc[y, x].to_numpy(float)
    top = int(np.nanmax(grid)) if np.isfinite(grid).any() else 0
    levels = max(top, 1) + 1  # one colour for each count 0 .. top
    cmap = ListedColormap(colormaps["Blues"](np.linspace(0.05, 0.95, levels)))
    norm = BoundaryNorm(np.arange(-0.5, levels), cmap.N)
    mesh = ax.pcolormesh(x, y, grid, cmap=cmap, norm=norm, shading="nearest", gid="regions")
    fig.colorbar(mesh, ax=ax, ticks=range(levels), label="stable equilibria")
    paper = isinstance(params, Params)
    handles = _paper_folds(ax, folds) if paper else _curves(ax, folds, axes, (x, y))
    cusp = folds[folds.kind == "cusp"]
    (marks,) = ax.plot(cusp[xname], cusp[yname], "kv", ms=6, mfc="white", gid="cusps",
                       label="cusp", zorder=5)  # fmt: skip
    handles.append(marks)
    ax.set_xlim(x.min(), x.max())
    ax.set_ylim(y.min(), y.max())
    ax.set_xlabel(param_label(xname))
    ax.set_ylabel(param_label(yname))
    if paper:
        _cases(ax)
        ax.set_aspect("equal")
        geometry = [s for s in describe(params).split(", ") if not s.startswith(FREE_LENGTHS)]
        title = "Stable equilibria over the free lengths, with the fold curves\n"
        title += ", ".join(geometry)
    else:
        others = values_line(params.as_dict(), leave_out=axes)
        title = f"{params.name}: stable equilibria over ({xname}, {yname}), with the fold curves"
        title += f"\n{others}" if others else ""
    set_title(ax, title, fontsize=10)
    ax.legend(handles=handles, loc="upper right", fontsize=8)
    return fig


def fold_subsets(params, folds: pd.DataFrame) -> list[tuple[str, pd.DataFrame, str, str]]:
    """(legend label, rows, colour, dash) of each kind of fold row: the paper's two families,
    or a framework's folds that change the stable count, those that do not, cable switches,
    pitchforks."""
    if isinstance(params, Params):
        families = (("relaxed", "#d95f02"), ("tensioned", "#e7298a"))
        return [(f"fold ({family} equilibria)",
                 folds[(folds.family == family) & (folds.kind == "fold")], colour, "solid")
                for family, colour in families]  # fmt: skip
    switch = (folds.kind == "cable_switch").to_numpy()
    pitch = (folds.kind == "pitchfork").to_numpy()
    changes = folds.changes_stable_count.to_numpy(bool) & ~switch & ~pitch
    subsets = {"changes": changes, "no_change": ~changes & ~switch & ~pitch, "switch": switch,
               "pitchfork": pitch}  # fmt: skip
    return [(label, folds[subsets[which]], style["color"], _DASH[style["ls"]])
            for which, _, style, label in _STYLES]  # fmt: skip


_DASH = {"-": "solid", "--": "dash", "-.": "dashdot"}


def _paper_folds(ax: Axes, folds: pd.DataFrame) -> list:
    """The paper's fold points, one colour per family (sampled along the parallel curve)."""
    handles = []
    for label, f, colour, _ in fold_subsets(Params(), folds):
        family = label.split("(")[1].split()[0]
        ax.plot(f.L01, f.L02, ".", ms=1.2, color=colour, gid=f"fold-{family}")
        handles.append(Line2D([], [], marker="o", ls="", ms=5, color=colour, label=label))
    return handles


def _cases(ax: Axes) -> None:
    for name, case in CASES.items():
        l01, l02 = case["L01"], case["L02"]
        ax.plot(l01, l02, "k*", ms=11, mfc="yellow", gid="cases")
        ax.annotate(name, (l01, l02), textcoords="offset points", xytext=(6, 6), fontsize=8)


# A framework's fold curves: (which rows, gid, line style, legend label).
_STYLES = (
    ("changes", "fold-changes", {"color": "#d95f02", "lw": 1.6, "ls": "-"},
     "fold changing the stable count"),
    ("no_change", "fold-no-change", {"color": "#7570b3", "lw": 0.9, "ls": "--", "alpha": 0.6},
     "fold of no consequence (stable count unchanged)"),
    ("switch", "cable-switch", {"color": "#1b9e77", "lw": 1.4, "ls": "-."},
     "cable switch (taut / slack)"),
    ("pitchfork", "pitchfork", {"color": "#e7298a", "lw": 1.6, "ls": "--"},
     "pitchfork (a symmetric state meets the mirror pair it splits into)"),
)  # fmt: skip


def _curves(ax: Axes, folds: pd.DataFrame, axes: tuple[str, str], grid: tuple) -> list:
    """A framework's fold curves as polylines by curve_id in order of arc."""
    from ..catastrophe.regions import polylines

    window = tuple((g.min(), g.max()) for g in grid)
    handles = []
    for (_, gid, style, label), (_, part, _, _) in zip(_STYLES, fold_subsets(None, folds),
                                                       strict=True):  # fmt: skip
        for line in polylines(part, *axes, window):
            rows = part.iloc[line]
            marker = "." if len(rows) == 1 else None
            ax.plot(rows[axes[0]], rows[axes[1]], marker=marker, gid=gid, **style)
        if len(part):
            handles.append(Line2D([], [], label=label, **style))
    return handles


def plot_map(
    params,
    regions: pd.DataFrame,
    folds: pd.DataFrame,
    path: str | Path,
    axes: tuple[str, str] = FREE_LENGTHS,
):
    """The design map as PNG and SVG (or the one suffix given)."""
    return save(map_figure(params, regions, folds, axes), path)
