"""The equilibria drawn like the paper's Figs 2-4: one panel per physical equilibrium."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from ..model.kinematics import points
from ..params import Params
from .common import describe, fit_text, physical_rows, save, set_title

COLOURS = {
    "bottom": "tab:red",
    "top": "tab:blue",
    "rod": "tab:green",
    "spring": "tab:purple",
}
_THIN, _BOLD = 1.2, 3.0


def configuration_points(params: Params, gamma1_deg: float, gamma2_deg: float) -> dict:
    """Points 1-6 in frame B (metres) for real angles in degrees: {i: array([x, y])}."""
    g1, g2 = math.radians(gamma1_deg), math.radians(gamma2_deg)
    pts = points(params, math.cos(g1), math.sin(g1), math.cos(g2), math.sin(g2))
    return {i: np.array(xy, dtype=float) for i, xy in pts.items()}


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


def _no_equilibrium(params: Params) -> Figure:
    fig = Figure(figsize=(6.0, 3.0))
    fig.text(
        0.5,
        0.55,
        "No physical equilibrium\n(no real root with both spring lengths > 0)",
        ha="center",
        va="center",
        fontsize=13,
    )
    caption = fit_text(describe(params), fig.get_figwidth(), 8)
    fig.text(0.5, 0.15, caption, ha="center", va="top", fontsize=8)
    return fig


def _draw_mechanism(ax, sid: int, p: dict, lw: float, amplitude: float, span: float) -> None:
    """Bodies, rod, zigzag springs and numbered points of one configuration."""
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
    ax.plot(*xy.T, "o", color="black", ms=3.5 if lw == _BOLD else 2.5, zorder=4)
    for i in range(1, 7):
        off = p[i] - (p[1] + p[2] + p[3]) / 3 if i <= 3 else p[i] - (p[4] + p[5] + p[6]) / 3
        off = off / max(np.hypot(*off), 1e-12) * 0.045 * span
        ax.text(*(p[i] + off), str(i), fontsize=7, ha="center", va="center", color="0.25")


def _panel(ax, row, p: dict, view: tuple[np.ndarray, float]) -> None:
    """One equilibrium: the mechanism, a title with its angles and kind, bold if stable."""
    centre, half = view
    sid, stable = int(row.solution_id), bool(row.stable)
    ax.set_gid(f"solution-{sid}")
    _draw_mechanism(ax, sid, p, _BOLD if stable else _THIN, 0.044 * half, 2 * half)
    kind = row.kind or "?"
    label = f"{kind}, stable" if stable else kind
    set_title(
        ax,
        f"#{sid}: $\\gamma_1$ = {row.gamma1_deg:.2f}°, $\\gamma_2$ = {row.gamma2_deg:.2f}°"
        f"\n{label}",
        fontsize=9,
        fontweight="bold" if stable else "normal",
    )
    if stable:
        ax.text(
            0.04, 0.96, "stable", transform=ax.transAxes, ha="left", va="top", fontsize=10,
            fontweight="bold", color="black",
        )  # fmt: skip
        for spine in ax.spines.values():
            spine.set_linewidth(2.0)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.tick_params(labelsize=7)
    ax.grid(True, lw=0.3, alpha=0.5)


def _legend(fig: Figure, ncols: int) -> None:
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


def configurations_figure(params: Params, solutions: pd.DataFrame) -> Figure:
    """One panel per physical solution, in solution_id order, all with the same axis limits.

    Each panel's Axes has gid `solution-<id>`; its artists have gids `s<id>-bottom` (closed
    triangle 1-2-3-1), `s<id>-top` (4-5-6-4), `s<id>-rod` (1-4), `s<id>-spring1` (zigzag 2 to 6)
    and `s<id>-spring2` (zigzag 3 to 5), so the drawn coordinates can be read back.
    """
    phys = physical_rows(solutions)
    n = len(phys)
    if n == 0:
        return _no_equilibrium(params)
    pts = [configuration_points(params, r.gamma1_deg, r.gamma2_deg) for r in phys.itertuples()]
    allxy = np.array([xy for p in pts for xy in p.values()])
    lo, hi = allxy.min(axis=0), allxy.max(axis=0)
    view = ((lo + hi) / 2, 0.58 * (hi - lo).max())
    ncols = math.ceil(math.sqrt(n))
    nrows = math.ceil(n / ncols)
    fig = Figure(figsize=(3.3 * ncols, 3.55 * nrows + 0.9), layout="constrained")
    grid = fig.subplots(nrows, ncols, squeeze=False, sharex=True, sharey=True)
    for ax in grid.flat[n:]:
        fig.delaxes(ax)
    for ax, row, p in zip(grid.flat, phys.itertuples(), pts, strict=False):
        _panel(ax, row, p, view)
    # x tick labels and label on the lowest panel of each column (the one above a blank slot).
    for k, ax in enumerate(grid.flat[:n]):
        if k + ncols >= n:
            ax.tick_params(labelbottom=True)
            ax.set_xlabel("x (m)", fontsize=8)
    for ax in grid[:, 0]:
        ax.set_ylabel("y (m)", fontsize=8)
    _legend(fig, ncols)
    n_stable = int(phys["stable"].astype(bool).sum())
    set_title(fig, f"{n} physical equilibria ({n_stable} stable)\n{describe(params)}", fontsize=10)
    return fig


def plot_configurations(params: Params, solutions: pd.DataFrame, path: str | Path) -> list[Path]:
    """Draw every physical equilibrium (see configurations_figure); write PNG and SVG."""
    return save(configurations_figure(params, solutions), path)
