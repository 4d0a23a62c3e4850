"""A framework's barriers drawn as energy profiles: V along each saddle's two descents, against
arc length from the saddle (negative towards min_a, positive towards min_b)."""

from __future__ import annotations

import pandas as pd
from matplotlib.figure import Figure

from ..model.framework.spec import Framework
from .common import set_title, values_line
from .energy_map import KIND_STYLE


def barrier_profile_figure(fw: Framework, table: pd.DataFrame, paths: dict) -> Figure:
    """One curve per saddle (gid `descent-<saddle_id>`), the saddle and the minima marked
    (gids `saddle` and `min`: offsets (arc, V)), and each end labelled with its solution_id."""
    fig = Figure(figsize=(8.6, 5.6), layout="constrained")
    ax = fig.subplots()
    saddles, minima = [], []
    for saddle_id, (side_a, side_b) in paths.items():
        row = table.loc[saddle_id]
        arc = pd.concat([-side_a.arc[::-1], side_b.arc[1:]]).to_numpy()
        V = pd.concat([side_a.energy[::-1], side_b.energy[1:]]).to_numpy()
        label = f"saddle {saddle_id}" + (" (lowest)" if row.lowest else "")
        (line,) = ax.plot(arc, V, lw=1.4, gid=f"descent-{saddle_id}", label=label)
        saddles.append((0.0, float(side_a.energy.iloc[0])))
        for side, end, sign in ((side_a, row.min_a, -1), (side_b, row.min_b, 1)):
            point = (sign * float(side.arc.iloc[-1]), float(side.energy.iloc[-1]))
            minima.append(point)
            label = "?" if pd.isna(end) else str(int(end))
            ax.annotate(label, point, xytext=(0, -12), textcoords="offset points", fontsize=8,
                        ha="center", color=line.get_color())  # fmt: skip
    for kind, points in (("saddle", saddles), ("min", minima)):
        marker, colour, size, label = KIND_STYLE[kind]
        if points:
            ax.scatter(*zip(*points, strict=True), s=size, marker=marker, c=colour,
                       edgecolors="black", linewidths=0.9, zorder=5, gid=kind,
                       label=label)  # fmt: skip
    ax.axvline(0.0, color="0.7", lw=0.6, zorder=0)
    ax.set_xlabel("arc length from the saddle along the descent (rad and length units; "
                  "- towards min_a, + towards min_b)")  # fmt: skip
    ax.set_ylabel("V (J)")
    values = values_line(fw.as_dict())
    set_title(
        ax,
        f"Energy along the descents from each saddle ({fw.name}"
        + (f": {values}" if values else "") + ")\nminima labelled with their solution_id",
        fontsize=10,
    )  # fmt: skip
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8, loc="best")
    else:
        ax.text(0.5, 0.5, "no saddle of index 1", ha="center", va="center",
                transform=ax.transAxes)  # fmt: skip
    return fig
