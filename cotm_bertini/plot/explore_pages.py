"""The explorer's three pages (plot/explore.py draws their data): a map (click a grid point), a
sweep (a slider along the swept parameter) and a move (a slider along the path)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..params import Params
from .explore import axis_title, page_data, write_page
from .motion import snaps_text

# A map's stable counts as classes, one colour each: white for none, then ColorBrewer's Set3
# (light, so the fold curves stay readable over it; its grey swapped for a tan, its orange
# after the counts met most often, as the fold curves are orange): any two of these twelve
# differ by a CIELAB distance of at least 18.
COUNT_COLOURS = ("#ffffff", "#80b1d3", "#b3de69", "#fb8072", "#bebada", "#ffed6f", "#8dd3c7",
                 "#fdb462", "#bc80bd", "#fccde5", "#ccebc5", "#e5c494")  # fmt: skip


def count_colour(k: int) -> str:
    """The colour of a stable count k (past the twelfth class, the palette again in a darker
    shade: 12 is white's darker twin, a mid grey)."""
    base = COUNT_COLOURS[k % len(COUNT_COLOURS)]
    shade = 0.6 ** (k // len(COUNT_COLOURS))
    return "#" + "".join(f"{round(int(base[i : i + 2], 16) * shade):02x}" for i in (1, 3, 5))


def count_scale(top: int) -> tuple[list, dict]:
    """A stepped colour scale for counts 0..top over z in [-0.5, top + 0.5] (each count one
    flat band), and its colour bar: a tick at each count, labelled by it."""
    scale = []
    for k in range(top + 1):
        scale += [[k / (top + 1), count_colour(k)], [(k + 1) / (top + 1), count_colour(k)]]
    bar = {"title": {"text": "stable<br>states"}, "tickvals": list(range(top + 1)),
           "ticktext": [str(k) for k in range(top + 1)], "outlinewidth": 1,
           "outlinecolor": "#888"}  # fmt: skip
    return scale, bar


def map_page(dm, path: str | Path, route: pd.DataFrame | None = None, move=None) -> Path:
    """A map's page: stable counts (hover: both counts), fold curves, cusps and cable switches;
    a click draws the equilibria of the 2-D sweep at that grid point. `route` (a plan's
    waypoints) is drawn over it, and `move` (the move along it) walked by a slider."""
    import plotly.graph_objects as go

    from ..analysis.classify import read_table

    model, (x, y) = dm.params, dm.axes
    xs, ys = np.unique(dm.regions[x].to_numpy(float)), np.unique(dm.regions[y].to_numpy(float))
    grid = {c: dm.regions.pivot(index=y, columns=x, values=c).loc[ys, xs].to_numpy(int)
            for c in ("stable", "physical")}  # fmt: skip
    table = read_table(Path(dm.record["sweep_folder"]) / "sweep.csv")
    phys = table[table.physical.astype(bool)]
    data = page_data(model, phys, phys.point.to_numpy(int), len(xs) * len(ys))
    top = int(grid["stable"].max())
    scale, bar = count_scale(top)
    fig = go.Figure(go.Heatmap(
        x=xs, y=ys, z=grid["stable"], customdata=grid["physical"], colorscale=scale,
        zmin=-0.5, zmax=top + 0.5, colorbar=bar, name="stable count",
        hovertemplate=f"{x} = %{{x}}<br>{y} = %{{y}}<br>stable: %{{z}}<br>"
        "physical: %{customdata}<extra></extra>"))  # fmt: skip
    for trace in _fold_traces(dm, x, y, xs, ys):
        fig.add_trace(trace)
    if route is not None and len(route):
        fig.add_trace(go.Scatter(x=route[x], y=route[y], mode="lines+markers", name="plan",
                                 line={"color": "black", "width": 3}))  # fmt: skip
    fig.update_layout(xaxis_title=axis_title(x), yaxis_title=axis_title(y),
                      legend={"orientation": "h", "y": -0.15}, margin={"t": 30})  # fmt: skip
    values = model.as_dict()
    start = [min(max(values[n], g.min()), g.max()) for n, g in ((x, xs), (y, ys))]
    data.update(page="map", axes=[x, y], xs=xs.tolist(), ys=ys.tolist(), start_at=start,
                dot=[0.01 * np.ptp(xs), 0.01 * np.ptp(ys)],
                command=_move_command(model, (x, y)))  # fmt: skip
    name = getattr(model, "name", "the paper's mechanism")
    note = (f"{name}: click a grid point to draw its physical equilibria (from the map's own "
            f"2-D sweep, {len(xs)} x {len(ys)} points); hover for the counts.")  # fmt: skip
    slider = ""
    if move is not None:
        data["track"] = _track(move, (x, y))
        slider, note = "the plan's move", note + " The slider walks the plan's move."
    return write_page(path, f"{name}: map over ({x}, {y})", note, fig, data, slider=slider,
                      draw=True)  # fmt: skip


def _move_command(model, axes: tuple[str, str]) -> str:
    """The start of the command line that moves a state of this model: its values other than
    the map's axes (the paper's: those that are not Table 1's)."""
    values = {n: v for n, v in model.as_dict().items() if n not in axes}
    if isinstance(model, Params):
        table1 = Params().as_dict()
        head = ["cotm-bertini move"]
        values = {n: v for n, v in values.items() if v != table1[n]}
    else:
        head = ["cotm-bertini move --framework", model.source or f"{model.name}.toml"]
    return " ".join([*head, *(f"--set {n}={v:.12g}" for n, v in values.items())])


def _track(mv, axes: tuple[str, str]) -> dict:
    """A move's steps as drawable rows, one a step, with their labels and places on the map."""
    table = mv.table
    track = page_data(mv.params, table.assign(kind="min", stable=True), np.arange(len(table)),
                      len(table))  # fmt: skip
    track["labels"] = _step_labels(table, list(mv.path.names))
    track["at"] = table[list(axes)].to_numpy(float).tolist()
    return track


def _step_labels(table: pd.DataFrame, names: list[str]) -> list[str]:
    """Each step of a trajectory: its parameter values and event."""
    return [", ".join(f"{n} = {row[n]:.6g}" for n in names) + f" ({row.event})"
            for _, row in table.iterrows()]  # fmt: skip


def _fold_traces(dm, x: str, y: str, xs: np.ndarray, ys: np.ndarray) -> list:
    """The fold curves (the paper's: points by family; a framework's: polylines of the folds
    that change the stable count, those that do not, and cable switches), and the cusps."""
    import plotly.graph_objects as go

    from ..catastrophe.regions import polylines
    from .design_map import fold_subsets

    folds, out = dm.folds, []
    for label, rows, colour, dash in fold_subsets(dm.params, folds):
        if isinstance(dm.params, Params):
            dots = {"size": 2, "color": colour}
            out.append(go.Scatter(x=rows[x], y=rows[y], mode="markers", name=label,
                                  marker=dots, hoverinfo="skip"))  # fmt: skip
            continue
        px, py = [], []
        for line in polylines(rows, x, y, ((xs.min(), xs.max()), (ys.min(), ys.max()))):
            px += [*rows[x].iloc[line], None]
            py += [*rows[y].iloc[line], None]
        out.append(go.Scatter(x=px, y=py, mode="lines", name=label, hoverinfo="skip",
                              line={"color": colour, "dash": dash, "width": 2}))  # fmt: skip
    cusps = folds[folds.kind == "cusp"]
    out.append(go.Scatter(x=cusps[x], y=cusps[y], mode="markers", name="cusp",
                          marker={"symbol": "triangle-down", "size": 9, "color": "white",
                                  "line": {"color": "black", "width": 1}}))  # fmt: skip
    return out


def _coordinate(model) -> str:
    """The column a diagram draws: gamma1, or the framework's first pose column."""
    if isinstance(model, Params):
        return "gamma1_deg"
    from ..continuation.framework import pose_names

    return pose_names(model)[0]


def sweep_page(model, table: pd.DataFrame, param: str, values, path: str | Path) -> Path:
    """A one-parameter sweep's page: the bifurcation diagram (stable filled, the rest open) and
    a slider along the swept parameter that draws every physical equilibrium there."""
    import plotly.graph_objects as go

    phys = table[table.physical.astype(bool)]
    data = page_data(model, phys, phys.point.to_numpy(int), len(values))
    ycol = _coordinate(model)
    fig = go.Figure()
    for stable, label in ((True, "stable"), (False, "unstable")):
        part = phys[phys.stable.astype(bool) == stable]
        fig.add_trace(go.Scatter(x=part[param], y=part[ycol], mode="markers", name=label,
                                 marker={"size": 4, "symbol": "circle" if stable else
                                         "circle-open"}))  # fmt: skip
    fig.update_layout(xaxis_title=axis_title(param), yaxis_title=ycol, margin={"t": 30})
    labels = [f"{param} = {v:.6g}" for v in values]
    data.update(page="sweep", labels=labels, at=[float(v) for v in values])
    name = getattr(model, "name", "the paper's mechanism")
    note = f"{name}: move the slider to draw the physical equilibria at each sweep point."
    return write_page(path, f"{name}: sweep over {param}", note, fig, data, slider=param)


def move_page(mv, path: str | Path) -> Path:
    """A move's page: the followed state against the path (snaps marked) and a slider along
    the steps that draws the mechanism."""
    import plotly.graph_objects as go

    table, names = mv.table, list(mv.path.names)
    along = names[0] if len(names) == 1 else "s"
    ycol = _coordinate(mv.params)
    data = page_data(mv.params, table.assign(kind="min", stable=True), np.arange(len(table)),
                     len(table))  # fmt: skip
    fig = go.Figure(go.Scatter(x=table[along], y=table[ycol], mode="lines", name="state"))
    snaps = table[table.event == "snap_to"]
    fig.add_trace(go.Scatter(x=snaps[along], y=snaps[ycol], mode="markers", name="after a snap",
                             marker={"color": "red", "size": 9}))  # fmt: skip
    fig.update_layout(xaxis_title=axis_title(along), yaxis_title=ycol, margin={"t": 30})
    data.update(page="move", labels=_step_labels(table, names),
                at=table[along].astype(float).tolist())  # fmt: skip
    n = len(mv.snaps)
    note = (f"state #{mv.state} moved along {mv.path.text()}, {n} snap{'' if n == 1 else 's'}"
            + (f" ({snaps_text(mv)})." if n else "."))  # fmt: skip
    return write_page(path, f"move of state #{mv.state}", note, fig, data, slider="step")
