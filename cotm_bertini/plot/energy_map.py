"""The energy map: contours of V over the torus of angles, with every real root marked."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from ..model.compiled import energy
from ..params import Params
from .common import describe, physical_rows, save, set_title

KIND_STYLE = {  # marker, face colour, size, label
    "min": ("o", "limegreen", 70, "min of V"),
    "saddle": ("^", "darkorange", 70, "saddle of V"),
    "max": ("s", "red", 60, "max of V"),
    "degenerate": ("D", "magenta", 50, "degenerate critical point"),
}
MARKER_WORDS = {"o": "circle", "^": "triangle", "s": "square", "D": "diamond"}
PATH_COLOUR = "white"  # the descent paths on the barrier map


def marker_words(kind: str) -> str:
    """How a title names the marker of a kind of equilibrium: 'orange triangles'."""
    marker, colour = KIND_STYLE[kind][:2]
    return f"{colour.removeprefix('dark').removeprefix('lime')} {MARKER_WORDS[marker]}s"


def energy_grid(params: Params, n: int = 300) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """V on an n x n grid of (gamma1, gamma2) covering [0, 360] deg: (g1_deg, g2_deg, V)."""
    g = np.linspace(0.0, 360.0, n)
    g1, g2 = np.meshgrid(g, g, indexing="xy")  # rows: gamma2, columns: gamma1
    # equations.energy works on flat arrays: evaluate flat, then reshape.
    V = energy(params, np.radians(g1.ravel()), np.radians(g2.ravel())).reshape(g1.shape)
    return g, g, V


def _real_rows(solutions: pd.DataFrame, reason: str) -> pd.DataFrame:
    if len(solutions) == 0 or "reason" not in solutions:
        return solutions.iloc[0:0]
    mask = solutions["is_real"].astype(bool) & (solutions["reason"] == reason)
    return solutions[mask]


def _contours(fig: Figure, ax, params: Params, n: int) -> None:
    g1, g2, V = energy_grid(params, n)
    # Levels equally spaced in sqrt(V - Vmin): the low-energy basins, where the minima and
    # most saddles sit, get as much colour resolution as the high ridges.
    vmin, vmax = float(V.min()), float(V.max())
    levels = vmin + (vmax - vmin) * np.linspace(0.0, 1.0, 31) ** 2
    filled = ax.contourf(g1, g2, V, levels=levels, cmap="viridis")
    filled.set_rasterized(True)  # keeps the SVG small; lines and markers stay vector
    ax.contour(g1, g2, V, levels=levels[1::2], colors="white", linewidths=0.4, alpha=0.6)
    bar = fig.colorbar(filled, ax=ax, shrink=0.9, ticks=levels[::3], format="%.3g")
    bar.set_label("V (J)")


def _nonphysical_markers(ax, solutions: pd.DataFrame) -> None:
    neg = _real_rows(solutions, "negative_d")
    if len(neg):
        ax.scatter(
            neg["gamma1_deg"], neg["gamma2_deg"], s=14, c="0.75", edgecolors="0.3",
            linewidths=0.5, zorder=3, gid="negative_d",
            label="real root with a d < 0 (not physical)",
        )  # fmt: skip
    zero = _real_rows(solutions, "zero_length_spring")
    if len(zero):
        ax.scatter(
            zero["gamma1_deg"], zero["gamma2_deg"], s=150, marker="*", c="white",
            edgecolors="black", linewidths=0.9, zorder=4, gid="zero_length_spring",
            label="spring of zero length (cusp max of V)",
        )  # fmt: skip


def _equilibrium_markers(ax, solutions: pd.DataFrame) -> None:
    phys = physical_rows(solutions)
    for kind, (marker, colour, size, label) in KIND_STYLE.items():
        rows = phys[phys["kind"] == kind] if len(phys) else phys
        if len(rows) == 0:
            continue
        ax.scatter(
            rows["gamma1_deg"], rows["gamma2_deg"], s=size, marker=marker, c=colour,
            edgecolors="black", linewidths=0.9, zorder=5, gid=kind, label=label,
        )  # fmt: skip
    for r in phys.itertuples():
        ax.annotate(
            f"{int(r.solution_id)}" + (" (stable)" if r.stable else ""),
            (r.gamma1_deg, r.gamma2_deg),
            xytext=(6, 5),
            textcoords="offset points",
            fontsize=8,
            fontweight="bold" if r.stable else "normal",
            color="black",
            bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.75},
            zorder=6,
        )


def energy_map_figure(params: Params, solutions: pd.DataFrame, n: int = 300) -> Figure:
    """Filled contours and contour lines of V over the torus, with the equilibria marked.

    The marker collections have gids `min`, `saddle`, `max`, `degenerate` (physical rows by
    kind), `negative_d` and `zero_length_spring`; their offsets are (gamma1, gamma2) in degrees.
    """
    fig = Figure(figsize=(8.6, 7.2), layout="constrained")
    ax = fig.subplots()
    _contours(fig, ax, params, n)
    _nonphysical_markers(ax, solutions)
    _equilibrium_markers(ax, solutions)
    ax.set_xlim(0, 360)
    ax.set_ylim(0, 360)
    ax.set_xticks(np.arange(0, 361, 45))
    ax.set_yticks(np.arange(0, 361, 45))
    ax.set_aspect("equal")
    ax.set_xlabel("gamma1 (deg)")
    ax.set_ylabel("gamma2 (deg)")
    set_title(
        ax,
        "Potential energy V(gamma1, gamma2) on the torus "
        "(contour levels equally spaced in sqrt(V - min V))\n" + describe(params),
        fontsize=10,
    )
    if ax.get_legend_handles_labels()[0]:
        fig.legend(loc="outside lower center", ncols=3, fontsize=8, frameon=True)
    return fig


def plot_energy_map(params: Params, solutions: pd.DataFrame, path: str | Path) -> list[Path]:
    """Energy contours with the equilibria (see energy_map_figure); write PNG and SVG."""
    return save(energy_map_figure(params, solutions), path)


def barrier_figure(params: Params, solutions: pd.DataFrame, paths: dict, n: int = 300) -> Figure:
    """The energy map with each saddle's two descent paths (gid `descent-<saddle_id>`), drawn
    modulo 360 deg with a break where a path wraps."""
    fig = energy_map_figure(params, solutions, n)
    ax = fig.axes[0]
    label = "descent path from a saddle"
    for saddle, halves in paths.items():
        for path in halves:
            wrapped = np.mod(path, 360.0)
            jumps = np.abs(np.diff(wrapped, axis=0)).max(axis=1) > 180.0
            xy = np.insert(wrapped, np.flatnonzero(jumps) + 1, np.nan, axis=0)
            ax.plot(*xy.T, color=PATH_COLOUR, lw=1.4, gid=f"descent-{saddle}", label=label)
            label = "_nolegend_"  # one legend entry for all the paths
    set_title(
        ax,
        f"Descent paths ({PATH_COLOUR} lines) from each saddle ({marker_words('saddle')}) to "
        f"the minima ({marker_words('min')}), down V\n" + describe(params),
        fontsize=10,
    )
    for legend in list(fig.legends):  # redrawn with the paths in it
        legend.remove()
    if ax.get_legend_handles_labels()[0]:
        fig.legend(loc="outside lower center", ncols=3, fontsize=8, frameon=True)
    return fig
