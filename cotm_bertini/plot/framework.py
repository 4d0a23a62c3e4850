"""Pictures of a framework's equilibria: every physical one drawn in its pose."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from ..model.framework.spec import Framework, owner
from .common import cube, physical_rows, save, set_title, values_line

_AXES = "xyz"
_STYLE = {
    "spring": {"color": "tab:blue", "lw": 1.4},
    "cable": {"color": "tab:green", "lw": 1.0, "ls": "--"},
    "bar": {"color": "black", "lw": 3.0},
}
LOAD_COLOUR = "tab:red"


def _point(fw: Framework, row: pd.Series, name: str) -> np.ndarray:
    """A point's world coordinates in this row (ground points from the framework's values)."""
    dims = range(fw.dim)
    if owner(name) == "ground":
        slots = fw.slots()
        return np.array([slots[f"g_{name.split('.', 1)[1]}_{_AXES[a]}"] for a in dims])
    return np.array([row[f"{name}.{_AXES[a]}"] for a in dims])


def _draw(ax, fw: Framework, row: pd.Series) -> None:
    """One pose: bodies, links, pins, ground points, nodes, and loads as arrows."""

    def line(a, b, **style):
        pts = np.array([_point(fw, row, a), _point(fw, row, b)]).T
        ax.plot(*pts, **style)

    for body, pts in fw.bodies:
        xy = np.array([_point(fw, row, f"{body}.{p}") for p, _ in pts])
        closed = np.vstack([xy, xy[:1]]).T
        ax.plot(*closed, color="tab:orange", lw=2.2)
    for x in fw.links:
        style = dict(_STYLE[x.kind])
        if x.kind == "cable" and not bool(row.get(f"{x.name}.taut", True)):
            style.update(color="0.6", ls=":")
        line(x.a, x.b, **style)
    for a, _ in fw.pins:
        ax.scatter(*_point(fw, row, a), s=18, color="white", edgecolor="black", zorder=5)
    ground = np.array([_point(fw, row, f"ground.{g}") for g, _ in fw.ground])
    if len(ground):
        ax.scatter(*ground.T, marker="^", s=30, color="0.3", zorder=4)
    for node in fw.nodes:
        ax.scatter(*_point(fw, row, node), s=14, color="black", zorder=5)
    _draw_loads(ax, fw, row)


def _draw_loads(ax, fw: Framework, row: pd.Series) -> None:
    """Each load: an arrow along its force whose head is at the loaded point, a fifth of the
    pose's size long, labelled by its name and size (gid `load-<name>`)."""
    if not fw.loads:
        return
    names = [f"{b}.{p}" for b, pts in fw.bodies for p, _ in pts] + list(fw.nodes)
    names += [f"ground.{g}" for g, _ in fw.ground]
    xyz = np.array([_point(fw, row, n) for n in names])
    length = 0.2 * max(float(np.ptp(xyz, axis=0).max()), 1e-9)
    slots = fw.slots()
    for load in fw.loads:
        force = np.array([slots[f"f_{load.name}_{_AXES[a]}"] for a in range(fw.dim)])
        size = float(np.linalg.norm(force))
        if size == 0:
            continue
        head = _point(fw, row, load.point)
        tail = head - length * force / size
        if fw.dim == 2:
            arrow = {"arrowstyle": "-|>", "color": LOAD_COLOUR, "lw": 1.6}
            ax.annotate(f"{load.name} {size:.3g}", xy=head, xytext=tail, fontsize=7,
                        color=LOAD_COLOUR, ha="center", va="center", gid=f"load-{load.name}",
                        arrowprops=arrow)  # fmt: skip
            ax.update_datalim([tail])  # the arrow's tail inside the view
        else:
            ax.quiver(*tail, *(head - tail), color=LOAD_COLOUR, arrow_length_ratio=0.3,
                      gid=f"load-{load.name}")  # fmt: skip


def plot_framework(fw: Framework, solutions: pd.DataFrame, path: str | Path) -> list[Path]:
    """configurations.{png,svg}: see framework_figure."""
    return save(framework_figure(fw, solutions), path)


def framework_figure(fw: Framework, solutions: pd.DataFrame) -> Figure:
    """One panel per physical equilibrium, stable ones marked, loads drawn as arrows."""
    rows = physical_rows(solutions)
    n = max(len(rows), 1)
    cols = min(4, n)
    nrows = math.ceil(n / cols)
    # At least two panels wide: room for the title over a single pose.
    fig = Figure(figsize=(3.2 * max(cols, 2), 3.0 * nrows + 0.6))
    kw = {"projection": "3d"} if fw.dim == 3 else {}
    for k, (_, row) in enumerate(rows.iterrows()):
        ax = fig.add_subplot(nrows, cols, k + 1, **kw)
        _draw(ax, fw, row)
        if fw.dim == 2:
            ax.set_aspect("equal", adjustable="datalim")
        else:
            for a, lim in zip("xyz", cube([getattr(ax, f"get_{a}lim")() for a in "xyz"]),
                              strict=True):  # fmt: skip
                getattr(ax, f"set_{a}lim")(lim)
        mark = "stable" if bool(row["stable"]) else str(row["kind"])
        set_title(ax, f"#{int(row['solution_id'])}: {mark}, V = {row['energy']:.4g}", fontsize=9)
        ax.tick_params(labelsize=7)
    if not len(rows):
        fig.add_subplot(1, 1, 1).text(0.5, 0.5, "no physical equilibrium", ha="center")
    values = values_line(fw.values)
    loads = ", red arrows: loads" if fw.loads else ""
    set_title(
        fig,
        f"{fw.name}: every physical equilibrium (orange: bodies, blue: springs, green dashed: "
        f"taut cables, grey dotted: slack, black: bars{loads})" + (f"\n{values}" if values else ""),
        fontsize=9,
    )
    fig.tight_layout()
    return fig
