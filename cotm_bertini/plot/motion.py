"""Pictures of a move: the followed state against the actuators (hysteresis, snaps marked) and
the mechanism moving (an animated GIF)."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ..fs import atomic_write_bytes
from ..params import Params
from .common import cube, param_label, save, set_title, values_line
from .configurations import _THIN, _draw_mechanism, configuration_points

SNAP_BACKGROUND = "#fff0f0"  # a frame on either side of a snap


def _coordinate(move) -> str:
    """The column drawn against the path: gamma1, or the framework's first pose column."""
    if isinstance(move.params, Params):
        return "gamma1_deg"
    from ..continuation.framework import pose_names

    return pose_names(move.params)[0]


def _against(move) -> tuple[str, np.ndarray]:
    """The horizontal axis: the one parameter a one-parameter path moves, else position s."""
    table = move.table
    if len(move.path.names) == 1:
        name = move.path.names[0]
        return param_label(name), table[name].to_numpy(float)
    return "path position s (1 a segment)", table["s"].to_numpy(float)


def snaps_text(move) -> str:
    """Each snap by its kind and the parameter values where it happens (`fold at y = -0.14462`),
    or `none`."""
    return "; ".join(f"{r.kind} at {move.path.values_text(r.s)}"
                     for r in move.snaps.itertuples()) or "none"  # fmt: skip


def plot_move(move, path: str | Path) -> list[Path]:
    """move.png/svg: see move_figure."""
    return save(move_figure(move), path)


def move_figure(move) -> Figure:
    """The state's coordinate and energy against the actuator (a hysteresis loop where the path
    returns), arrows at snaps; the title names each snap by its parameter values."""
    table = move.table
    name = _coordinate(move)
    label, h = _against(move)
    y = table[name].to_numpy(float)
    if name.endswith("_deg"):  # unwrapped along the move, so a turn past 360 is no jump
        y = np.degrees(np.unwrap(np.radians(y)))
    fig = Figure(figsize=(7.0, 6.0), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True)
    for ax, values, ylabel in ((top, y, name), (bottom, table["energy"].to_numpy(float), "V")):
        # One line a stretch between snaps: the jump itself is an arrow, not a drawn branch.
        cuts = np.flatnonzero(table.event.to_numpy() == "snap_to")
        for piece in np.split(np.arange(len(table)), cuts):
            ax.plot(h[piece], values[piece], color="tab:blue", lw=1.4)
        for k in cuts:
            ax.annotate("", xy=(h[k], values[k]), xytext=(h[k - 1], values[k - 1]),
                        arrowprops={"arrowstyle": "->", "color": "tab:red", "lw": 1.2})  # fmt: skip
        ax.set_ylabel(ylabel)
        ax.grid(True, lw=0.3, alpha=0.5)
    bottom.set_xlabel(label)
    fixed = values_line(move.params.as_dict(), move.path.names)
    set_title(fig, f"move of state #{move.state} along {move.path.text()}: snaps (red arrows): "
              f"{snaps_text(move)}\n{fixed}", fontsize=9)  # fmt: skip
    return fig


def animate_move(move, path: str | Path, frames: int = 80) -> Path:
    """An animated GIF of the mechanism along the move (every snap's two rows kept)."""
    from PIL import Image

    table = move.table
    pick = np.unique(np.concatenate([
        np.linspace(0, len(table) - 1, min(frames, len(table))).round().astype(int),
        np.flatnonzero(table.event.to_numpy() != "step"),
    ]))  # fmt: skip
    fig = Figure(figsize=(4.6, 4.6), dpi=80)
    FigureCanvasAgg(fig)
    kw = {"projection": "3d"} if getattr(move.params, "dim", 2) == 3 else {}
    ax = fig.add_subplot(1, 1, 1, **kw)
    for k in pick:  # a first pass over every frame: one view for all of them
        _frame(ax, move, table.iloc[k])
    limits = [getattr(ax, f"get_{a}lim")() for a in "xyz"[: 3 if kw else 2]]
    if kw:
        limits = cube(limits)
    images = []
    for k in pick:
        ax.clear()
        _frame(ax, move, table.iloc[k])
        for a, lim in zip("xyz", limits, strict=False):
            getattr(ax, f"set_{a}lim")(lim)
        if not kw:
            ax.set_aspect("equal", adjustable="box")
        row = table.iloc[k]
        note = {"snap_from": "  (snaps)", "snap_to": "  (after the snap)"}.get(row.event, "")
        set_title(ax, ", ".join(f"{n} = {row[n]:.4g}" for n in move.path.names) + note,
                  fontsize=9)  # fmt: skip
        fig.canvas.draw()
        images.append(Image.fromarray(np.asarray(fig.canvas.buffer_rgba())).convert("P"))
    buffer = io.BytesIO()
    images[0].save(buffer, format="GIF", save_all=True, append_images=images[1:], duration=80,
                   loop=0)  # fmt: skip
    out = Path(path)
    atomic_write_bytes(out, buffer.getvalue())
    return out


def _frame(ax, move, row: pd.Series) -> None:
    """The mechanism in one row of the trajectory, at that row's parameter values."""
    values = {n: float(row[n]) for n in move.path.names}
    model = move.params.replace(**values)
    if isinstance(model, Params):
        p = configuration_points(model, row.gamma1_deg, row.gamma2_deg)
        span = float(np.ptp(np.array(list(p.values())), axis=0).max())
        _draw_mechanism(ax, 0, p, _THIN if row.event == "snap_from" else 2.0, 0.022 * span, span)
        ax.set_facecolor("white" if row.event == "step" else SNAP_BACKGROUND)
    else:
        from .framework import _draw

        _draw(ax, model, row)
        if row.event != "step":
            ax.set_facecolor(SNAP_BACKGROUND)


def plot_plan(plan, path: str | Path) -> list[Path]:
    """The map (regions, fold curves) with the plan's path over it, its snaps marked."""
    from .design_map import map_figure

    dm = plan.map
    fig = map_figure(plan.params, dm.regions, dm.folds, dm.axes)
    ax = fig.axes[0]
    x, y = dm.axes
    if len(plan.path):
        ax.plot(plan.path[x], plan.path[y], "-o", color="black", lw=2.0, ms=4, zorder=6,
                label="plan")  # fmt: skip
        ax.plot(plan.path[x].iloc[:1], plan.path[y].iloc[:1], "*", color="gold", ms=16,
                mec="black", zorder=7, label="start and end")  # fmt: skip
    if plan.move is not None and len(plan.move.snaps):
        snaps = plan.move.snaps
        ax.plot(snaps[x], snaps[y], "X", color="tab:red", ms=11, mec="white", zorder=8,
                label="snaps")  # fmt: skip
    ax.legend(loc="best", fontsize=8)
    set_title(fig, f"plan from state #{plan.state} to #{plan.goal}: {plan.status}", fontsize=10)
    return save(fig, path)
