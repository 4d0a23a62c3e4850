"""The map of a two-parameter sweep: the number of stable equilibria at each grid point."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from .common import flag, param_label, save, set_title


def sweep_counts(sweep: pd.DataFrame, params: list[str] | tuple[str, ...]) -> pd.DataFrame:
    """Per grid point: the swept values and the numbers of real, physical and stable rows."""
    table = sweep.assign(
        n_real=flag(sweep, "is_real"),
        n_physical=flag(sweep, "physical"),
        n_stable=flag(sweep, "stable"),
    )
    counts = table.groupby(list(params), sort=True)[["n_real", "n_physical", "n_stable"]].sum()
    return counts.astype(int).reset_index()


def _cell_edges(v: np.ndarray) -> np.ndarray:
    """Cell edges around sorted centres v: midpoints, the ends extended by half a step."""
    if len(v) == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    mid = (v[1:] + v[:-1]) / 2
    return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def sweep_counts_figure(
    sweep: pd.DataFrame, params: list[str] | tuple[str, ...], annotate: bool | None = None
) -> Figure:
    """Heat map of the number of stable equilibria over a 2-D grid of params[0] x params[1].

    Each cell is one grid point, coloured by its stable count (one colour per integer). With
    `annotate` (default: when the grid has at most 400 points) each cell prints "stable/physical";
    otherwise the physical count is drawn as labelled white contours ("≥ n phys." inside).

    The QuadMesh has gid `stable-count`; its array is the stable count with rows = values of
    params[1] ascending, columns = values of params[0] ascending (masked where a grid point is
    missing).
    """
    px, py = params
    counts = sweep_counts(sweep, params)
    xs = np.unique(counts[px].to_numpy(dtype=float))
    ys = np.unique(counts[py].to_numpy(dtype=float))
    stable = counts.pivot(index=py, columns=px, values="n_stable").reindex(index=ys, columns=xs)
    phys = counts.pivot(index=py, columns=px, values="n_physical").reindex(index=ys, columns=xs)
    S, P = stable.to_numpy(dtype=float), phys.to_numpy(dtype=float)
    if annotate is None:
        annotate = S.size <= 400

    top = int(np.nanmax(S)) if np.isfinite(S).any() else 0
    bounds = np.arange(-0.5, top + 1.5)
    cmap = matplotlib.colormaps["viridis"].resampled(len(bounds) - 1)
    norm = matplotlib.colors.BoundaryNorm(bounds, cmap.N)
    fig = Figure(figsize=(9.0, 7.2), layout="constrained")
    ax = fig.subplots()
    mesh = ax.pcolormesh(
        _cell_edges(xs),
        _cell_edges(ys),
        np.ma.masked_invalid(S),
        cmap=cmap,
        norm=norm,
        gid="stable-count",
    )
    bar = fig.colorbar(mesh, ax=ax, ticks=np.arange(top + 1))
    bar.set_label("number of stable equilibria")
    if annotate:
        for j, yv in enumerate(ys):
            for i, xv in enumerate(xs):
                if np.isfinite(S[j, i]):
                    ax.text(
                        xv,
                        yv,
                        f"{S[j, i]:.0f}/{P[j, i]:.0f}",
                        ha="center",
                        va="center",
                        fontsize=7 if max(len(xs), len(ys)) > 10 else 9,
                        color="white" if S[j, i] < 0.6 * max(top, 1) else "black",
                    )
        note = "cells: stable/physical"
    elif len(xs) > 1 and len(ys) > 1 and np.nanmax(P) > np.nanmin(P):
        ticks = matplotlib.ticker.MaxNLocator(nbins=6, integer=True).tick_values(
            np.nanmin(P) + 1, np.nanmax(P)
        )
        levels = [t - 0.5 for t in ticks if np.nanmin(P) < t <= np.nanmax(P)]
        cs = ax.contour(xs, ys, P, levels=levels, colors="white", linewidths=1.1)
        ax.clabel(cs, fmt=lambda v: f"≥ {v + 0.5:.0f} phys.", fontsize=7)
        note = "white contours: number of physical equilibria"
    else:
        note = f"physical: {np.nanmin(P):.0f}-{np.nanmax(P):.0f}"
    ax.set_xlabel(param_label(px))
    ax.set_ylabel(param_label(py))
    set_title(
        ax,
        f"Number of stable equilibria over {px} x {py}, {int(np.isfinite(S).sum())} points "
        f"({note})",
        fontsize=10,
    )
    return fig


def plot_sweep_counts(
    sweep: pd.DataFrame,
    params: list[str] | tuple[str, ...],
    path: str | Path,
    annotate: bool | None = None,
) -> list[Path]:
    """Stable-count heat map of a 2-D sweep (see sweep_counts_figure); write PNG and SVG."""
    return save(sweep_counts_figure(sweep, params, annotate=annotate), path)
