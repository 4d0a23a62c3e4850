"""The design map: the number of stable equilibria over the (L01, L02) plane, the fold curves on
top, the paper's case points marked."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib import colormaps
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ..params import CASES, Params
from .common import describe, save


def map_figure(params: Params, regions: pd.DataFrame, folds: pd.DataFrame) -> Figure:
    """Stable counts as coloured cells (gid `regions`), fold points (gids `fold-relaxed`,
    `fold-tensioned`), cusps (gid `cusps`) and the paper's cases (gid `cases`)."""
    fig = Figure(figsize=(8.4, 7.2), layout="constrained")
    ax = fig.subplots()
    x, y = np.unique(regions.L01), np.unique(regions.L02)
    grid = regions.pivot(index="L02", columns="L01", values="stable").loc[y, x].to_numpy(float)
    top = int(np.nanmax(grid)) if np.isfinite(grid).any() else 0
    levels = max(top, 1) + 1  # one colour for each count 0 .. top
    cmap = ListedColormap(colormaps["Blues"](np.linspace(0.05, 0.95, levels)))
    norm = BoundaryNorm(np.arange(-0.5, levels), cmap.N)
    mesh = ax.pcolormesh(x, y, grid, cmap=cmap, norm=norm, shading="nearest", gid="regions")
    fig.colorbar(mesh, ax=ax, ticks=range(levels), label="stable equilibria")
    handles = []
    for family, colour in (("relaxed", "#d95f02"), ("tensioned", "#e7298a")):
        f = folds[(folds.family == family) & (folds.kind == "fold")]
        ax.plot(f.L01, f.L02, ".", ms=1.2, color=colour, gid=f"fold-{family}")
        handles.append(Line2D([], [], marker="o", ls="", ms=5, color=colour,
                              label=f"fold ({family} equilibria)"))  # fmt: skip
    cusp = folds[folds.kind == "cusp"]
    (marks,) = ax.plot(cusp.L01, cusp.L02, "kv", ms=6, mfc="white", gid="cusps", label="cusp")
    handles.append(marks)
    for name, case in CASES.items():
        l01, l02 = case["L01"], case["L02"]
        ax.plot(l01, l02, "k*", ms=11, mfc="yellow", gid="cases")
        ax.annotate(name, (l01, l02), textcoords="offset points", xytext=(6, 6), fontsize=8)
    ax.set_xlim(x.min(), x.max())
    ax.set_ylim(y.min(), y.max())
    ax.set_xlabel("L01 (m)")
    ax.set_ylabel("L02 (m)")
    ax.set_aspect("equal")
    geometry = [s for s in describe(params).split(", ") if not s.startswith(("L01", "L02"))]
    ax.set_title("Stable equilibria over the free lengths, with the fold curves\n"
                 + ", ".join(geometry), fontsize=10)  # fmt: skip
    ax.legend(handles=handles, loc="upper right", fontsize=8)
    return fig


def plot_map(params: Params, regions: pd.DataFrame, folds: pd.DataFrame, path: str | Path):
    """The design map as PNG and SVG (or the one suffix given)."""
    return save(map_figure(params, regions, folds), path)
