"""The bifurcation diagram of a one-parameter sweep: the paper's Figs 5 and 6 in one figure."""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ..params import PARAM_NAMES, PARAM_UNITS, TABLE1
from .common import flag, param_label, save, set_title

# Styles of the bifurcation diagram: line width and style, marker size (points^2).
_SWEEP_LINE = {"stable": (2.6, "-"), "unstable": (1.1, (0, (5, 2.5))), "nonphysical": (0.7, "-")}
_NONPHYSICAL_COLOUR = "0.72"
EVENT_STYLE = {  # marker, colour, size, label
    "fold": ("x", "black", 50, "fold (two branches meet and turn complex)"),
    "stability_change": ("D", "black", 95, "stability change"),
    "physical_change": ("v", "0.35", 60, "physical change (a spring length crosses 0)"),
}
# Drawn over one another where they coincide (a stability change at a fold): the fold's cross
# stays visible on top of the stability change's diamond.
EVENT_ZORDER = {"fold": 8, "pitchfork": 8, "stability_change": 6, "physical_change": 7}
# Two consecutive samples of a branch further apart than this (short way round, deg) are not
# joined: the branch is poorly resolved there, and a long line would only mislead.
_MAX_STEP_DEG = 90.0
# Events where branches are born or end (two real branches meet there).
_MEETING_KINDS = ("fold", "pitchfork")


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
    """A colour per branch id: tab20 without its greys (kept for non-physical), 18 colours, so
    the branches of a sweep (a handful of physical ones) do not share one."""
    palette = [c for k, c in enumerate(matplotlib.colormaps["tab20"].colors) if k not in (14, 15)]
    return {b: palette[k % len(palette)] for k, b in enumerate(branches)}


def _physical_events(events: pd.DataFrame, sweep: pd.DataFrame, param: str) -> pd.DataFrame:
    """The events that happen on physical branches: a fold of two negative-d roots has no place
    on a plot of the physical equilibria. Events without branch ids are all kept."""
    if "branches" not in events or "branch" not in sweep:
        return events
    at = "value" if "value" in events else param
    keep = []
    for ev in events.itertuples(index=False):
        ev = ev._asdict()
        ids = [int(b) for b in str(ev["branches"]).split("+") if b.strip().lstrip("-").isdigit()]
        lo, hi = ev.get("lo", ev[at]), ev.get("hi", ev[at])
        rows = sweep[sweep["branch"].isin(ids) & sweep[param].between(lo, hi)]
        keep.append(bool(flag(rows, "physical").any()))
    return events[np.array(keep, dtype=bool)]


def _styled_rows(sweep: pd.DataFrame, show_all: bool) -> pd.DataFrame:
    """The rows to draw (physical, and the other real ones with show_all) with a `_style`."""
    keep = flag(sweep, "physical") | (flag(sweep, "is_real") & show_all)
    rows = sweep[keep]
    style = np.where(
        flag(rows, "stable"),
        "stable",
        np.where(flag(rows, "physical"), "unstable", "nonphysical"),
    )
    return rows.assign(_style=style)


def _draw_lines(
    ax, rows: pd.DataFrame, param: str, angle: str, rank_of: dict, colour_of: dict, events=None
):
    """Each branch's samples joined, one LineCollection per style; a branch born (or ending) at
    a fold of `events` is joined to the fold point itself."""
    pieces: dict[str, list] = {"stable": [], "unstable": [], "nonphysical": []}
    colours: dict[str, list] = {"stable": [], "unstable": [], "nonphysical": []}
    joined = rows.dropna(subset=["branch"])
    meetings = _meetings(events, param, angle)
    values = np.array(sorted(rank_of), dtype=float)
    for branch, grp in joined[joined["branch"] >= 0].groupby("branch", sort=True):
        grp = grp.sort_values(param, kind="stable")
        x = grp[param].to_numpy(dtype=float)
        y = grp[angle].to_numpy(dtype=float) % 360.0
        styles = list(grp["_style"])
        links = _branch_links(x, y, np.array([rank_of[v] for v in x]), styles)
        for at, fold_y in meetings.get(int(branch), []):
            links += _fold_link(at, fold_y, x, y, styles, values)
        for style_name, pts in links:
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


def _meetings(events, param: str, angle: str) -> dict[int, list[tuple[float, float]]]:
    """For each branch, the (parameter, angle) of the folds (and pitchforks) it takes part in."""
    out: dict[int, list[tuple[float, float]]] = {}
    if events is None or not len(events) or "branches" not in events:
        return out
    at = "value" if "value" in events else param
    for ev in events[events["kind"].isin(_MEETING_KINDS)].itertuples(index=False):
        ev = ev._asdict()
        point = (float(ev[at]), float(ev[angle]) % 360.0)
        for b in str(ev["branches"]).split("+"):
            if b.strip().isdigit():
                out.setdefault(int(b), []).append(point)
    return out


def _fold_link(
    at: float, fold_y: float, x: np.ndarray, y: np.ndarray, styles: list[str], values: np.ndarray
) -> list[tuple[str, np.ndarray]]:
    """The branch's line from a fold point to its sample at the next parameter value on either
    side (the branch is real on one side of its fold only), in that sample's style; nothing if
    the branch has no sample there or the angle jumps."""
    k = int(np.searchsorted(values, at))
    near = {values[j] for j in (k - 1, k) if 0 <= j < len(values)}
    if at in near:
        near = {at}
    out = []
    for i in np.flatnonzero([v in near for v in x]):
        step = (y[i] - fold_y + 180.0) % 360.0 - 180.0
        if abs(step) > _MAX_STEP_DEG:
            continue
        a, b = np.array([at, fold_y]), np.array([x[i], fold_y + step])
        if b[0] < a[0]:  # left to right, the sample's angle as the start
            a, b = np.array([x[i], y[i]]), np.array([at, y[i] - step])
        out += [(styles[i], np.array(seg)) for seg in _cut_at_edges(a, b)]
    return out


def _draw_markers(ax, rows, param: str, angle: str, dense: bool, colour_of: dict | None) -> None:
    """A marker per row: stable filled, unstable hollow, non-physical grey dots."""
    for style_name in ("nonphysical", "unstable", "stable"):
        if dense and style_name != "stable":
            continue  # the lines say it; beads of markers would hide the dashes
        sel = rows[rows["_style"] == style_name]
        x, y = sel[param].to_numpy(dtype=float), sel[angle].to_numpy(dtype=float) % 360.0
        if style_name == "nonphysical":
            kw = {"s": 5, "c": _NONPHYSICAL_COLOUR, "linewidths": 0, "zorder": 1}
        else:
            if colour_of is not None:
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


def _draw_events(ax, events: pd.DataFrame | None, param: str, angle: str) -> None:
    if events is None or not len(events):
        return
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
            zorder=EVENT_ZORDER.get(kind, 6),
            gid=kind,
        )


def _legend(fig: Figure, lines: bool, dense: bool, show_all: bool, events) -> None:
    def entry(colour, style_name: str | None, label: str, **marker) -> Line2D:
        lw, ls = _SWEEP_LINE[style_name] if lines and style_name else (0, "")
        shown = marker if not dense or style_name is None else {}
        return Line2D([], [], color=colour, lw=lw, ls=ls, label=label, **shown)

    handles = [
        entry("black", "stable", "stable equilibrium (min of V)", marker="o", ms=4.5),
        entry(
            "black", "unstable", "unstable equilibrium (saddle or max of V)", marker="o",
            ms=3.5, mfc="white",
        ),
    ]  # fmt: skip
    if show_all:
        handles.append(
            entry(
                _NONPHYSICAL_COLOUR, "nonphysical",
                "real root, not physical (d < 0 or d = 0 artefact)", marker="o", ms=2.5, mew=0,
            )
        )  # fmt: skip
    if events is not None and len(events):
        for kind, (marker, colour, size, label) in EVENT_STYLE.items():
            if (events["kind"] == kind).any():
                handles.append(
                    entry(
                        colour, None, label, marker=marker, ms=math.sqrt(size), mfc="none", mew=1.4
                    )
                )
    fig.legend(handles=handles, loc="outside lower center", ncols=2, fontsize=8, frameon=False)


def bifurcation_figure(
    sweep: pd.DataFrame,
    param: str,
    show_all: bool = False,
    events: pd.DataFrame | None = None,
    fixed: Mapping[str, float] | None = None,
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
    gamma2_deg) are marked in both panels, a fold's cross above a stability change's diamond;
    with their `branches` column (a+b), the branches that meet at a fold are drawn from the fold
    point itself to their first sample. `fixed`: the parameters held fixed, stated in the title.

    Each panel's Axes has gid `gamma1` or `gamma2`. Its marker collections have gids `stable`,
    `unstable`, `nonphysical` (when drawn) and one per event kind, offsets (param value, angle in
    deg); its line collections have gids `stable-lines`, `unstable-lines`, `nonphysical-lines`.
    Rows whose branch is missing or negative are markers only. The events' parameter column is
    `value`, or else `param` itself.
    """
    rows = _styled_rows(sweep, show_all)
    if events is not None and len(events) and not show_all:
        events = _physical_events(events, sweep, param)
    values = np.unique(sweep[param].to_numpy(dtype=float))
    rank_of = {v: k for k, v in enumerate(values)}
    has_branches = "branch" in rows and len(rows) > 0
    # Many samples: the lines carry the picture, the markers shrink to dots on them.
    dense = has_branches and len(values) > 60
    colour_of = None
    if has_branches:
        phys_branches = rows.loc[rows["_style"] != "nonphysical", "branch"].dropna()
        colour_of = _branch_colours(sorted(phys_branches[phys_branches >= 0].unique()))
    fig = Figure(figsize=(10.5, 9.0), layout="constrained")
    axes = fig.subplots(2, 1, sharex=True)
    for ax, name in zip(axes, ("gamma1", "gamma2"), strict=True):
        angle = f"{name}_deg"
        ax.set_gid(name)
        if has_branches:
            _draw_lines(ax, rows, param, angle, rank_of, colour_of, events)
        _draw_markers(ax, rows, param, angle, dense, colour_of)
        _draw_events(ax, events, param, angle)
        ax.set_ylim(0, 360)
        ax.set_yticks(np.arange(0, 361, 45))
        ax.set_ylabel(f"{name} (deg)")
        ax.grid(True, lw=0.3, alpha=0.6)
        set_title(ax, f"{name} of the equilibria against {param}", fontsize=10)
    if len(values):
        pad = 0.01 * (values[-1] - values[0]) if len(values) > 1 else 0.5
        axes[1].set_xlim(values[0] - pad, values[-1] + pad)
    axes[1].set_xlabel(param_label(param))
    _legend(fig, has_branches, dense, show_all, events)
    title = _title(sweep, param, values, has_branches)
    set_title(fig, title + _fixed_line(fixed, param), fontsize=10)
    return fig


def _fixed_line(fixed: Mapping[str, float] | None, param: str) -> str:
    """A second title line: the free lengths held fixed, then every other parameter that is not
    Table 1's (the rest are said to be)."""
    if not fixed:
        return ""
    names = [n for n in ("L01", "L02") if n in fixed and n != param]
    names += [
        n
        for n in PARAM_NAMES
        if n in fixed and n not in names and n != param and fixed[n] != TABLE1.get(n)
    ]
    items = ", ".join(f"{n} = {float(fixed[n]):g} {PARAM_UNITS.get(n, '')}".rstrip() for n in names)
    listed = set(names) | {param}
    rest = [n for n in PARAM_NAMES if n not in listed]
    tail = "; the other parameters as in Table 1" if rest else ""
    return f"\nfixed: {items}{tail}" if items else "\nfixed: every other parameter as in Table 1"


def _title(sweep: pd.DataFrame, param: str, values: np.ndarray, has_branches: bool) -> str:
    """What a reader needs: the points, and how many equilibria (stable ones) a point has."""
    key = "point" if "point" in sweep else param
    per = sweep.assign(_p=flag(sweep, "physical"), _s=flag(sweep, "stable")).groupby(key)
    phys, stable = per["_p"].sum(), per["_s"].sum()

    def span(counts) -> str:
        lo, hi = int(counts.min()), int(counts.max())
        return f"{lo}" if lo == hi else f"{lo} to {hi}"

    note = "colours: branches" if has_branches else "no branch column: samples only"
    return (
        f"Equilibria of the CoTM against {param} ({len(values)} values): "
        f"{span(phys)} physical equilibria a point, {span(stable)} of them stable ({note})"
    )


def plot_bifurcation(
    sweep: pd.DataFrame,
    param: str,
    path: str | Path,
    show_all: bool = False,
    events: pd.DataFrame | None = None,
    fixed: Mapping[str, float] | None = None,
) -> list[Path]:
    """gamma1 and gamma2 against `param` in one two-panel figure (see bifurcation_figure).

    Writes `<path>.png` and `<path>.svg`, or only `path` if it ends in .png, .svg or .pdf.
    """
    figure = bifurcation_figure(sweep, param, show_all=show_all, events=events, fixed=fixed)
    return save(figure, path)
