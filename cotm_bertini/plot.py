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
from matplotlib.collections import LineCollection
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


# --- parameter sweeps ----------------------------------------------------------------------

# Styles of the bifurcation diagram: line width and style, marker size (points^2).
_SWEEP_LINE = {"stable": (2.6, "-"), "unstable": (1.1, (0, (5, 2.5))), "nonphysical": (0.7, "-")}
_NONPHYSICAL_COLOUR = "0.72"
EVENT_STYLE = {  # marker, colour, size, label
    "fold": ("x", "black", 50, "fold (two branches meet and turn complex)"),
    "stability_change": ("D", "black", 95, "stability change"),
    "physical_change": ("v", "0.35", 60, "physical change (a spring length crosses 0)"),
}
# Two consecutive samples of a branch further apart than this (short way round, deg) are not
# joined: the branch is poorly resolved there, and a long line would only mislead.
_MAX_STEP_DEG = 90.0


def _param_label(name: str) -> str:
    from .geometry import PARAM_UNITS

    unit = PARAM_UNITS.get(name)
    return f"{name} ({unit})" if unit else name


def _flag(table: pd.DataFrame, column: str) -> np.ndarray:
    """A boolean column as a numpy array (False where missing or NaN)."""
    if column not in table:
        return np.zeros(len(table), dtype=bool)
    return table[column].fillna(False).astype(bool).to_numpy()


def _branch_links(
    x: np.ndarray, y: np.ndarray, ranks: np.ndarray, styles: list[str]
) -> list[tuple[str, np.ndarray]]:
    """The drawable pieces of one branch, samples in parameter order: [(style, (n, 2) array)].

    Consecutive samples are joined when they sit at neighbouring parameter values (rank + 1)
    and their angles differ by at most _MAX_STEP_DEG the short way round; otherwise the branch
    has a gap there. A link between two styles (stable to unstable, physical to not) changes
    style at its midpoint. A link across 0/360 deg is cut at the edge and continues from the
    other edge, so no drawn piece ever jumps across the plot. Pieces of one style that follow
    each other are merged into one polyline (dashes then run on smoothly).
    """
    links: list[tuple[str, np.ndarray, np.ndarray]] = []
    for i in range(len(x) - 1):
        if ranks[i + 1] - ranks[i] != 1:
            continue
        step = (y[i + 1] - y[i] + 180.0) % 360.0 - 180.0
        if abs(step) > _MAX_STEP_DEG:
            continue
        a = np.array([x[i], y[i]])
        b = np.array([x[i + 1], y[i] + step])  # unwrapped end
        if styles[i] == styles[i + 1]:
            links.append((styles[i], a, b))
        else:
            m = (a + b) / 2
            links += [(styles[i], a, m), (styles[i + 1], m, b)]
    pieces: list[tuple[str, list[np.ndarray]]] = []
    for style, a, b in links:
        for sa, sb in _cut_at_edges(a, b):
            if pieces and pieces[-1][0] == style and np.allclose(pieces[-1][1][-1], sa, atol=1e-9):
                pieces[-1][1].append(sb)
            else:
                pieces.append((style, [sa, sb]))
    return [(style, np.array(pts)) for style, pts in pieces]


def _cut_at_edges(a: np.ndarray, b: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """Segment a-b (b's angle unwrapped relative to a's in [0, 360)) as segments within [0, 360]."""
    shift = math.floor(b[1] / 360.0)
    if shift == 0 or b[1] == 360.0:
        return [(a, b)]
    edge = 360.0 if shift > 0 else 0.0
    t = (edge - a[1]) / (b[1] - a[1])
    xm = a[0] + t * (b[0] - a[0])
    return [(a, np.array([xm, edge])), (np.array([xm, 360.0 - edge]), b - [0.0, 360.0 * shift])]


def _branch_colours(branches: list) -> dict:
    """A colour per branch id, cycling through tab10 without its grey (kept for non-physical)."""
    palette = [c for k, c in enumerate(matplotlib.colormaps["tab10"].colors) if k != 7]
    return {b: palette[k % len(palette)] for k, b in enumerate(branches)}


def bifurcation_figure(
    sweep: pd.DataFrame,
    param: str,
    show_all: bool = False,
    events: pd.DataFrame | None = None,
) -> Figure:
    """gamma1 (top panel) and gamma2 (bottom panel) of the equilibria against `param`.

    The paper's Figs. 5 and 6 in one figure with a shared parameter axis. Physical equilibria
    only unless `show_all`, which adds the other real roots (negative d, d = 0 artefacts) in
    light grey. Every plotted row is a marker: stable ones filled circles, unstable ones small
    hollow circles, non-physical ones grey dots. With a `branch` column, the samples of a branch
    are joined by lines in the branch's colour (grey if not physical), thick and solid where
    stable, thin and dashed where unstable; never across 0/360 deg or a gap (see _branch_links).
    With branches and more than 60 parameter values the lines carry the picture: only the stable
    markers are drawn (small, on the thick lines). `events` (columns kind, value, gamma1_deg,
    gamma2_deg) are marked in both panels.

    Each panel's Axes has gid `gamma1` or `gamma2`. Its marker collections have gids `stable`,
    `unstable`, `nonphysical` (when drawn) and one per event kind, offsets (param value, angle in
    deg); its line collections have gids `stable-lines`, `unstable-lines`, `nonphysical-lines`.
    Rows whose branch is missing or negative are markers only. The events' parameter column is
    `value`, or else `param` itself.
    """
    real = _flag(sweep, "is_real")
    physical = _flag(sweep, "physical")
    keep = physical | (real & show_all)
    rows = sweep[keep]
    style = np.where(
        _flag(rows, "stable"),
        "stable",
        np.where(_flag(rows, "physical"), "unstable", "nonphysical"),
    )
    rows = rows.assign(_style=style)
    values = np.unique(sweep[param].to_numpy(dtype=float))
    rank_of = {v: k for k, v in enumerate(values)}
    has_branches = "branch" in rows and len(rows) > 0
    # Many samples: the lines carry the picture, the markers shrink to dots on them.
    dense = has_branches and len(values) > 60
    colour_of = {}
    if has_branches:
        phys_branches = rows.loc[rows["_style"] != "nonphysical", "branch"].dropna()
        phys_branches = phys_branches[phys_branches >= 0]
        colour_of = _branch_colours(sorted(phys_branches.unique()))

    fig = Figure(figsize=(10.5, 9.0), layout="constrained")
    axes = fig.subplots(2, 1, sharex=True)
    for ax, angle, name in zip(
        axes, ("gamma1_deg", "gamma2_deg"), ("gamma1", "gamma2"), strict=True
    ):
        ax.set_gid(name)
        if has_branches:
            pieces: dict[str, list] = {"stable": [], "unstable": [], "nonphysical": []}
            colours: dict[str, list] = {"stable": [], "unstable": [], "nonphysical": []}
            joined = rows.dropna(subset=["branch"])
            for branch, grp in joined[joined["branch"] >= 0].groupby("branch", sort=True):
                grp = grp.sort_values(param, kind="stable")
                x = grp[param].to_numpy(dtype=float)
                for style_name, pts in _branch_links(
                    x,
                    grp[angle].to_numpy(dtype=float) % 360.0,
                    np.array([rank_of[v] for v in x]),
                    list(grp["_style"]),
                ):
                    pieces[style_name].append(pts)
                    colours[style_name].append(
                        _NONPHYSICAL_COLOUR
                        if style_name == "nonphysical"
                        else colour_of.get(branch, "black")
                    )
            for style_name, (lw, ls) in _SWEEP_LINE.items():
                coll = LineCollection(
                    pieces[style_name],
                    colors=colours[style_name] or "black",
                    linewidths=lw,
                    linestyles=ls,
                    zorder={"nonphysical": 1, "unstable": 2, "stable": 3}[style_name],
                    gid=f"{style_name}-lines",
                    capstyle="round",
                    joinstyle="round",
                )
                ax.add_collection(coll)
        for style_name in ("nonphysical", "unstable", "stable"):
            if dense and style_name != "stable":
                continue  # the lines say it; beads of markers would hide the dashes
            sel = rows[rows["_style"] == style_name]
            x, y = sel[param].to_numpy(dtype=float), sel[angle].to_numpy(dtype=float) % 360.0
            if style_name == "nonphysical":
                kw = {"s": 5, "c": _NONPHYSICAL_COLOUR, "linewidths": 0, "zorder": 1}
            else:
                if has_branches:
                    colour = [colour_of.get(b, "black") for b in sel["branch"]]
                else:
                    colour = "black"
                if style_name == "stable":
                    kw = {"s": 6 if dense else 16, "c": colour, "zorder": 5}
                    kw |= {"linewidths": 0} if dense else {"edgecolors": "black", "linewidths": 0.4}
                else:
                    kw = {"s": 3 if dense else 10, "facecolors": "white", "edgecolors": colour}
                    kw |= {"linewidths": 0.4 if dense else 0.7, "zorder": 4}
            ax.scatter(x, y, gid=style_name, **kw)
        if events is not None and len(events):
            for kind, (marker, colour, size, _label) in EVENT_STYLE.items():
                ev = events[events["kind"] == kind]
                if len(ev) == 0:
                    continue
                at = "value" if "value" in ev else param
                filled = marker not in ("x", "+")
                ax.scatter(
                    ev[at].to_numpy(dtype=float),
                    ev[angle].to_numpy(dtype=float) % 360.0,
                    s=size,
                    marker=marker,
                    c="none" if filled else colour,
                    edgecolors=colour if filled else None,
                    linewidths=1.3 if filled else 1.6,
                    zorder=6,
                    gid=kind,
                )
        ax.set_ylim(0, 360)
        ax.set_yticks(np.arange(0, 361, 45))
        ax.set_ylabel(f"{name} (deg)")
        ax.grid(True, lw=0.3, alpha=0.6)
        ax.set_title(f"{name} of the equilibria against {param}", fontsize=10)
    if len(values):
        pad = 0.01 * (values[-1] - values[0]) if len(values) > 1 else 0.5
        axes[1].set_xlim(values[0] - pad, values[-1] + pad)
    axes[1].set_xlabel(_param_label(param))

    def entry(colour, style_name: str | None, label: str, **marker) -> Line2D:
        lw, ls = _SWEEP_LINE[style_name] if has_branches and style_name else (0, "")
        shown = marker if not dense or style_name is None else {}
        return Line2D([], [], color=colour, lw=lw, ls=ls, label=label, **shown)

    handles = [
        entry("black", "stable", "stable equilibrium (min of V)", marker="o", ms=4.5),
        entry(
            "black",
            "unstable",
            "unstable equilibrium (saddle or max of V)",
            marker="o",
            ms=3.5,
            mfc="white",
        ),
    ]
    if show_all:
        handles.append(
            entry(
                _NONPHYSICAL_COLOUR,
                "nonphysical",
                "real root, not physical (d < 0 or d = 0 artefact)",
                marker="o",
                ms=2.5,
                mew=0,
            )
        )
    if events is not None and len(events):
        for kind, (marker, colour, size, label) in EVENT_STYLE.items():
            if (events["kind"] == kind).any():
                handles.append(
                    entry(
                        colour, None, label, marker=marker, ms=math.sqrt(size), mfc="none", mew=1.4
                    )
                )
    fig.legend(handles=handles, loc="outside lower center", ncols=2, fontsize=8, frameon=False)

    n_points = sweep["point"].nunique() if "point" in sweep else len(values)
    lines_note = "colours: branches" if has_branches else "no branch column: samples only"
    fig.suptitle(
        f"Equilibria of the CoTM against {param}: {n_points} points, "
        f"{int(physical.sum())} physical rows, {int(_flag(sweep, 'stable').sum())} stable "
        f"({lines_note})",
        fontsize=10,
    )
    return fig


def plot_bifurcation(
    sweep: pd.DataFrame,
    param: str,
    path_stem: str | Path,
    show_all: bool = False,
    events: pd.DataFrame | None = None,
) -> list[Path]:
    """gamma1 and gamma2 against `param` in one two-panel figure (see bifurcation_figure).

    Writes `<stem>.png` and `<stem>.svg` (one file pair, both panels sharing the parameter axis).
    """
    return _save(bifurcation_figure(sweep, param, show_all=show_all, events=events), path_stem)


def sweep_counts(sweep: pd.DataFrame, params: list[str] | tuple[str, ...]) -> pd.DataFrame:
    """Per grid point: the swept values and the numbers of real, physical and stable rows."""
    table = sweep.assign(
        n_real=_flag(sweep, "is_real"),
        n_physical=_flag(sweep, "physical"),
        n_stable=_flag(sweep, "stable"),
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
    ax.set_xlabel(_param_label(px))
    ax.set_ylabel(_param_label(py))
    ax.set_title(
        f"Number of stable equilibria over {px} x {py}, {int(np.isfinite(S).sum())} points "
        f"({note})",
        fontsize=10,
    )
    return fig


def plot_sweep_counts(
    sweep: pd.DataFrame,
    params: list[str] | tuple[str, ...],
    path_stem: str | Path,
    annotate: bool | None = None,
) -> list[Path]:
    """Stable-count heat map of a 2-D sweep (see sweep_counts_figure); write PNG and SVG."""
    return _save(sweep_counts_figure(sweep, params, annotate=annotate), path_stem)
