"""Figures of a run: the equilibria drawn like Figs. 2-4 of the paper, and the energy map.

matplotlib is imported here only, and used through its object-oriented API (`Figure`, no
pyplot): the global backend is never switched and no other module of the package needs it.
PNG output goes through Agg, SVG through matplotlib's SVG backend.
"""

from __future__ import annotations

import math
import os
import tempfile
from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from .equations import energy
from .geometry import Params

COLOURS = {
    "bottom": "tab:red",
    "top": "tab:blue",
    "rod": "tab:green",
    "spring": "tab:purple",
}
KIND_STYLE = {  # marker, face colour, size, label
    "min": ("o", "limegreen", 70, "min of V"),
    "saddle": ("^", "darkorange", 70, "saddle of V"),
    "max": ("s", "red", 60, "max of V"),
    "degenerate": ("D", "magenta", 50, "degenerate critical point"),
}
FORMATS = ("png", "svg")
_THIN, _BOLD = 1.2, 3.0


# --- geometry of the drawing ---------------------------------------------------------------


def configuration_points(params: Params, gamma1_deg: float, gamma2_deg: float) -> dict:
    """Points 1-6 in frame B (metres) for real angles in degrees: {i: array([x, y])}."""
    p = params
    g1, g2 = math.radians(gamma1_deg), math.radians(gamma2_deg)
    c2, s2 = math.cos(g2), math.sin(g2)
    p4 = np.array([p.L3 * math.cos(g1), p.L3 * math.sin(g1)])
    return {
        1: np.array([0.0, 0.0]),
        2: np.array([p.p2x, 0.0]),
        3: np.array([p.p3x, p.p3y]),
        4: p4,
        5: p4 + np.array([c2 * p.p5x - s2 * p.p5y, s2 * p.p5x + c2 * p.p5y]),
        6: p4 + np.array([c2 * p.p6x, s2 * p.p6x]),
    }


def zigzag(a: np.ndarray, b: np.ndarray, amplitude: float, coils: int = 6) -> np.ndarray:
    """Polyline of a zigzag spring from a to b (first point a, last point b), shape (n, 2).

    A straight lead takes 15 % of the length at each end; the zigzag between has `coils` full
    teeth of half-width `amplitude` (at most a quarter of the length, so a short spring stays
    readable). A spring of zero length is the single segment a-b.
    """
    a, b = np.asarray(a, float), np.asarray(b, float)
    vec = b - a
    length = float(np.hypot(*vec))
    if length < 1e-12:
        return np.array([a, b])
    u = vec / length
    n = np.array([-u[1], u[0]])
    amp = min(amplitude, 0.25 * length)
    t = np.linspace(0.15, 0.85, 2 * coils + 1)
    side = np.zeros_like(t)
    side[1:-1] = np.where(np.arange(1, 2 * coils) % 2 == 1, 1.0, -1.0)
    mid = a + np.outer(t * length, u) + np.outer(side * amp, n)
    return np.vstack([a, mid, b])


# --- writing -------------------------------------------------------------------------------


def _save(fig: Figure, path_stem: str | Path, dpi: int = 110) -> list[Path]:
    """Write `<stem>.png` and `<stem>.svg`, each via a temporary file and os.replace."""
    stem = Path(path_stem)
    stem.parent.mkdir(parents=True, exist_ok=True)
    out = []
    for fmt in FORMATS:
        path = stem.with_name(f"{stem.name}.{fmt}")
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
        os.close(fd)
        try:
            # Reproducible SVG: fixed id salt, no date stamp.
            with matplotlib.rc_context({"svg.hashsalt": "cotm-bertini"}):
                fig.savefig(tmp, format=fmt, dpi=dpi, metadata={"Date": None})
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
        out.append(path)
    return out


def _describe(params: Params) -> str:
    return (
        f"L3 = {params.L3:g} m, k1 = {params.k1:g} N/m, k2 = {params.k2:g} N/m, "
        f"L01 = {params.L01:g} m, L02 = {params.L02:g} m"
    )


# --- configurations ------------------------------------------------------------------------


def _physical(solutions: pd.DataFrame) -> pd.DataFrame:
    if len(solutions) == 0 or "physical" not in solutions:
        return solutions.iloc[0:0]
    return solutions[solutions["physical"].astype(bool)]


def configurations_figure(params: Params, solutions: pd.DataFrame) -> Figure:
    """One panel per physical solution, in solution_id order, all with the same axis limits.

    Each panel's Axes has gid `solution-<id>`; its artists have gids `s<id>-bottom` (closed
    triangle 1-2-3-1), `s<id>-top` (4-5-6-4), `s<id>-rod` (1-4), `s<id>-spring1` (zigzag 2 to 6)
    and `s<id>-spring2` (zigzag 3 to 5), so the drawn coordinates can be read back.
    """
    phys = _physical(solutions)
    n = len(phys)
    if n == 0:
        fig = Figure(figsize=(6, 3))
        fig.text(
            0.5,
            0.55,
            "No physical equilibrium\n(no real root with both spring lengths > 0)",
            ha="center",
            va="center",
            fontsize=13,
        )
        fig.text(0.5, 0.15, _describe(params), ha="center", fontsize=8)
        return fig

    pts = [configuration_points(params, r.gamma1_deg, r.gamma2_deg) for r in phys.itertuples()]
    allxy = np.array([xy for p in pts for xy in p.values()])
    lo, hi = allxy.min(axis=0), allxy.max(axis=0)
    centre = (lo + hi) / 2
    half = 0.58 * (hi - lo).max()
    span = 2 * half
    amplitude = 0.022 * span

    ncols = math.ceil(math.sqrt(n))
    nrows = math.ceil(n / ncols)
    fig = Figure(figsize=(3.3 * ncols, 3.55 * nrows + 0.9), layout="constrained")
    grid = fig.subplots(nrows, ncols, squeeze=False, sharex=True, sharey=True)
    for ax in grid.flat[n:]:
        fig.delaxes(ax)

    for ax, row, p in zip(grid.flat, phys.itertuples(), pts, strict=False):
        sid = int(row.solution_id)
        stable = bool(row.stable)
        lw = _BOLD if stable else _THIN
        ax.set_gid(f"solution-{sid}")
        bottom = np.array([p[1], p[2], p[3], p[1]])
        top = np.array([p[4], p[5], p[6], p[4]])
        ax.fill(*bottom.T, color=COLOURS["bottom"], alpha=0.15, lw=0)
        ax.fill(*top.T, color=COLOURS["top"], alpha=0.15, lw=0)
        ax.plot(*bottom.T, color=COLOURS["bottom"], lw=lw, gid=f"s{sid}-bottom")
        ax.plot(*top.T, color=COLOURS["top"], lw=lw, gid=f"s{sid}-top")
        ax.plot(*np.array([p[1], p[4]]).T, color=COLOURS["rod"], lw=lw + 0.8, gid=f"s{sid}-rod")
        for i, (a, b) in ((1, (2, 6)), (2, (3, 5))):
            z = zigzag(p[a], p[b], amplitude)
            ax.plot(*z.T, color=COLOURS["spring"], lw=0.7 * lw, gid=f"s{sid}-spring{i}", zorder=3)
        xy = np.array([p[i] for i in range(1, 7)])
        ax.plot(*xy.T, "o", color="black", ms=2.5 if not stable else 3.5, zorder=4)
        for i in range(1, 7):
            off = p[i] - (p[1] + p[2] + p[3]) / 3 if i <= 3 else p[i] - (p[4] + p[5] + p[6]) / 3
            off = off / max(np.hypot(*off), 1e-12) * 0.045 * span
            ax.text(*(p[i] + off), str(i), fontsize=7, ha="center", va="center", color="0.25")
        kind = row.kind or "?"
        label = f"{kind}, stable" if stable else kind
        ax.set_title(
            f"#{sid}: $\\gamma_1$ = {row.gamma1_deg:.2f}°, $\\gamma_2$ = {row.gamma2_deg:.2f}°"
            f"\n{label}",
            fontsize=9,
            fontweight="bold" if stable else "normal",
        )
        if stable:
            ax.text(
                0.04,
                0.96,
                "stable",
                transform=ax.transAxes,
                ha="left",
                va="top",
                fontsize=10,
                fontweight="bold",
                color="black",
            )
            for spine in ax.spines.values():
                spine.set_linewidth(2.0)
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - half, centre[1] + half)
        ax.tick_params(labelsize=7)
        ax.grid(True, lw=0.3, alpha=0.5)
    # x tick labels and label on the lowest panel of each column (the one above a blank slot).
    for k, ax in enumerate(grid.flat[:n]):
        if k + ncols >= n:
            ax.tick_params(labelbottom=True)
            ax.set_xlabel("x (m)", fontsize=8)
    for ax in grid[:, 0]:
        ax.set_ylabel("y (m)", fontsize=8)

    handles = [
        Patch(
            facecolor=COLOURS["bottom"],
            edgecolor=COLOURS["bottom"],
            alpha=0.6,
            label="bottom body 1-2-3 (fixed)",
        ),
        Patch(
            facecolor=COLOURS["top"], edgecolor=COLOURS["top"], alpha=0.6, label="top body 4-5-6"
        ),
        Line2D([], [], color=COLOURS["rod"], lw=2, label="rod 1-4"),
        Line2D([], [], color=COLOURS["spring"], lw=1, label="springs 2-6 and 3-5"),
        Line2D([], [], color="black", lw=_BOLD, label="bold: stable (min of V)"),
    ]
    fig.legend(
        handles=handles,
        loc="outside lower center",
        ncols=5 if ncols >= 3 else 3,
        fontsize=8,
        frameon=False,
    )
    n_stable = int(phys["stable"].astype(bool).sum())
    fig.suptitle(f"{n} physical equilibria ({n_stable} stable)\n{_describe(params)}", fontsize=10)
    return fig


def plot_configurations(
    params: Params, solutions: pd.DataFrame, path_stem: str | Path
) -> list[Path]:
    """Draw every physical equilibrium (see configurations_figure); write PNG and SVG."""
    return _save(configurations_figure(params, solutions), path_stem)


# --- energy map ----------------------------------------------------------------------------


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


def energy_map_figure(params: Params, solutions: pd.DataFrame, n: int = 300) -> Figure:
    """Filled contours and contour lines of V over the torus, with the equilibria marked.

    The marker collections have gids `min`, `saddle`, `max`, `degenerate` (physical rows by
    kind), `negative_d` and `zero_length_spring`; their offsets are (gamma1, gamma2) in degrees.
    """
    g1, g2, V = energy_grid(params, n)
    fig = Figure(figsize=(8.6, 7.2), layout="constrained")
    ax = fig.subplots()
    # Levels equally spaced in sqrt(V - Vmin): the low-energy basins, where the minima and
    # most saddles sit, get as much colour resolution as the high ridges.
    vmin, vmax = float(V.min()), float(V.max())
    levels = vmin + (vmax - vmin) * np.linspace(0.0, 1.0, 31) ** 2
    filled = ax.contourf(g1, g2, V, levels=levels, cmap="viridis")
    filled.set_rasterized(True)  # keeps the SVG small; lines and markers stay vector
    ax.contour(g1, g2, V, levels=levels[1::2], colors="white", linewidths=0.4, alpha=0.6)
    bar = fig.colorbar(filled, ax=ax, shrink=0.9, ticks=levels[::3], format="%.3g")
    bar.set_label("V (J)")

    neg = _real_rows(solutions, "negative_d")
    if len(neg):
        ax.scatter(
            neg["gamma1_deg"],
            neg["gamma2_deg"],
            s=14,
            c="0.75",
            edgecolors="0.3",
            linewidths=0.5,
            zorder=3,
            gid="negative_d",
            label="real root with a d < 0 (not physical)",
        )
    zero = _real_rows(solutions, "zero_length_spring")
    if len(zero):
        ax.scatter(
            zero["gamma1_deg"],
            zero["gamma2_deg"],
            s=150,
            marker="*",
            c="white",
            edgecolors="black",
            linewidths=0.9,
            zorder=4,
            gid="zero_length_spring",
            label="spring of zero length (cusp max of V)",
        )
    phys = _physical(solutions)
    for kind, (marker, colour, size, label) in KIND_STYLE.items():
        rows = phys[phys["kind"] == kind] if len(phys) else phys
        if len(rows) == 0:
            continue
        ax.scatter(
            rows["gamma1_deg"],
            rows["gamma2_deg"],
            s=size,
            marker=marker,
            c=colour,
            edgecolors="black",
            linewidths=0.9,
            zorder=5,
            gid=kind,
            label=label,
        )
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
    ax.set_xlim(0, 360)
    ax.set_ylim(0, 360)
    ax.set_xticks(np.arange(0, 361, 45))
    ax.set_yticks(np.arange(0, 361, 45))
    ax.set_aspect("equal")
    ax.set_xlabel("gamma1 (deg)")
    ax.set_ylabel("gamma2 (deg)")
    ax.set_title(
        "Potential energy V(gamma1, gamma2) on the torus "
        "(contour levels equally spaced in sqrt(V - min V))\n" + _describe(params),
        fontsize=10,
    )
    if ax.get_legend_handles_labels()[0]:
        fig.legend(loc="outside lower center", ncols=3, fontsize=8, frameon=True)
    return fig


def plot_energy_map(params: Params, solutions: pd.DataFrame, path_stem: str | Path) -> list[Path]:
    """Energy contours with the equilibria (see energy_map_figure); write PNG and SVG."""
    return _save(energy_map_figure(params, solutions), path_stem)


def plot_run(params: Params, solutions: pd.DataFrame, folder: str | Path) -> list[Path]:
    """Both figures into a run folder: configurations.{png,svg} and energy_map.{png,svg}."""
    folder = Path(folder)
    return plot_configurations(params, solutions, folder / "configurations") + plot_energy_map(
        params, solutions, folder / "energy_map"
    )
