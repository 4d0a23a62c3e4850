"""Quasi-static moves (cb.move): a stable state of a solve followed along an actuator path, its
snaps and the energy each releases; the paper's mechanism or any framework, through one
follower (motion/follow.py)."""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..columns import reference
from ..errors import ParameterError
from ..fs import atomic_write_text, new_folder, write_csv, write_json
from ..motion.flows import flow_of
from ..motion.follow import LOCATE, Followed, follow
from ..motion.path import ActuatorPath, actuator_path
from ..params import Params
from ..settings import Settings
from .solutions import Solutions

DEFAULT_STEPS = 100  # recorded steps a segment of the path
PLAN_POINTS = 41  # a plan's map: grid points a side


@dataclass(frozen=True)
class Move:
    """A followed state: `table` (trajectory.csv: one row a step, and the rows on either side
    of each snap), `snaps` (snaps.csv), `record` (run.json); `ends_in`: the solution_id of the
    solve's minimum the move ends in, where the path returns to the solve's values."""

    params: object
    state: int
    path: ActuatorPath
    table: pd.DataFrame
    snaps: pd.DataFrame
    record: dict

    @property
    def status(self) -> str:
        """ok, or incomplete (a snap with no minimum to fall into, or an unexplained end)."""
        return self.record["status"]

    @property
    def ends_in(self) -> int | None:
        """The solve's stable solution_id the final state is (None: the path ends elsewhere,
        or the state is none of them)."""
        return self.record["ends_in"]

    @property
    def warnings(self) -> list[str]:
        """What went wrong, in words (empty when the status is ok)."""
        return self.record["warnings"]

    def plot(self, path: str | Path) -> list[Path]:
        """move.png/svg: the state against the path position, snaps marked (hysteresis)."""
        from ..plot.motion import plot_move

        return plot_move(self, path)

    def animate(self, path: str | Path, frames: int = 80) -> Path:
        """move.gif: the mechanism along the path, snaps marked."""
        from ..plot.motion import animate_move

        return animate_move(self, path, frames)

    def explore(self, path: str | Path) -> Path:
        """explore.html: the move in a browser, offline, a slider along its steps."""
        from ..plot.explore_pages import move_page

        return move_page(self, path)

    def save(self, folder: str | Path, plots: bool = True, html: bool = False) -> Path:
        """trajectory.csv, snaps.csv, columns.md, run.json [, move.png/svg, move.gif]
        [, explore.html] in a new folder, built under a hidden name and renamed when complete."""
        with new_folder(folder) as work:
            atomic_write_text(work / "columns.md", reference(_move_table(self.params), "snaps"))
            write_json(work / "run.json", self.record)
            self.write_into(work, plots)
            if html:
                self.explore(work / "explore.html")
        return Path(folder)

    def write_into(self, work: Path, plots: bool) -> None:
        """trajectory.csv, snaps.csv [, move.png/svg, move.gif] into a folder being built."""
        write_csv(work / "trajectory.csv", self.table)
        write_csv(work / "snaps.csv", self.snaps)
        if plots:
            self.plot(work / "move")
            self.animate(work / "move.gif")


def _move_table(model) -> str:
    """The columns.md table of a trajectory: the paper's or a framework's."""
    return "move" if isinstance(model, Params) else "framework_move"


def move(
    res: Solutions,
    state: int,
    path: Mapping[str, Sequence[float]],
    steps: int = DEFAULT_STEPS,
    progress: bool = False,
) -> Move:
    """Follow the stable state `state` (a solution_id of `res`) while the parameters move along
    `path` ({name: [v0, v1, ...]}, piecewise linear, v0 at the solve's values), `steps` recorded
    steps a segment; where the state ends (a fold, a cable switch), it snaps to the minimum it
    falls into, and the move goes on from there."""
    if isinstance(steps, bool) or not isinstance(steps, int | np.integer) or steps < 1:
        raise ParameterError(f"steps = {steps!r}: expected a whole number >= 1")
    model = res.params
    ap = actuator_path(path, model.as_dict())
    for k in range(len(ap.waypoints)):  # each waypoint's values valid, before any work
        model.replace(**ap.at(k))
    row = _stable_row(res, state)
    t0 = time.perf_counter()
    flow = flow_of(model, res.table)
    followed = follow(lambda v: flow.at(model.replace(**v)), ap, flow.state(row), int(steps),
                      progress)  # fmt: skip
    elapsed = time.perf_counter() - t0
    table = _trajectory(flow, model, ap, followed)
    snaps = _snaps(flow, model, ap, followed)
    ends_in = None
    if followed.s[-1] == ap.segments and np.allclose(ap.waypoints[-1], ap.waypoints[0]):
        ends_in = flow.match(followed.states[-1])
    record = _record(res, state, ap, followed, int(steps), ends_in, elapsed)
    return Move(model, int(state), ap, table, snaps, record)


def _stable_row(res: Solutions, state, what: str = "state") -> pd.Series:
    """The row of the stable solution `state`, or a one-line error naming the stable ids."""
    table = res.table
    stable = table[table.stable.astype(bool)]
    ids = " ".join(str(int(i)) for i in stable.solution_id) or "none"
    try:
        sid = int(state)
    except (TypeError, ValueError):
        sid = None
    hit = stable[stable.solution_id == sid]
    if sid is None or isinstance(state, bool) or sid != state or hit.empty:
        raise ParameterError(f"{what} = {state!r}: not a stable solution_id of the solve "
                             f"(stable: {ids})")  # fmt: skip
    return hit.iloc[0]


def _trajectory(flow, model, ap: ActuatorPath, f: Followed) -> pd.DataFrame:
    """trajectory.csv: path position, parameter values, event, then the state's columns."""
    parts = []
    for k, (s, x, event) in enumerate(zip(f.s, f.states, f.events, strict=True)):
        values = ap.at(s)
        here = flow.at(model.replace(**values))
        eig = here.eigh(x)[0]
        state = {name: col[0] for name, col in here.columns(x[None, :]).items()}
        softest = float(eig.min()) / here.hessian_unit if len(eig) else np.nan
        parts.append({"step": k, "s": s, **values, "event": event, **state,
                      "hess_min_eig": softest})  # fmt: skip
    return pd.DataFrame(parts)


def _snaps(flow, model, ap: ActuatorPath, f: Followed) -> pd.DataFrame:
    """snaps.csv: one row a snap, the poses before and after."""
    pose = [*_pose(model, flow), "energy"]
    sides = [f"{e}.{n}" for n in pose for e in ("before", "after")]
    columns = ["snap", "s", *ap.names, "kind", "released", "located_to", "softest_eig",
               "cable_gap", "landed", *sides]  # fmt: skip
    rows = []
    for k, sn in enumerate(f.snaps, start=1):
        values = ap.at(sn.s)
        here = flow.at(model.replace(**values))
        before = here.rows(sn.before[None, :]).iloc[0]
        after = here.rows(sn.after[None, :]).iloc[0] if sn.after is not None else None
        row = {"snap": k, "s": sn.s, **values, "kind": sn.kind, "released": sn.released,
               "located_to": (sn.s_after - sn.s) * _scale(ap, sn.s),
               "softest_eig": sn.softest, "cable_gap": sn.cable_gap,
               "landed": after is not None}  # fmt: skip
        for name in pose:
            row[f"before.{name}"] = before[name]
            row[f"after.{name}"] = after[name] if after is not None else math.nan
        rows.append(row)
    return pd.DataFrame(rows, columns=columns)


def _pose(model, flow) -> list[str]:
    """The columns that place the mechanism: its angles, or a framework's pose columns."""
    return ["gamma1_deg", "gamma2_deg"] if isinstance(model, Params) else flow.pose_names


def _scale(ap: ActuatorPath, s: float) -> float:
    """The parameter change per unit path position in the segment of s (largest component)."""
    k = min(int(math.floor(s)), ap.segments - 1)
    return float(np.abs(ap.waypoints[k + 1] - ap.waypoints[k]).max())


def _record(res, state, ap, f: Followed, steps, ends_in, elapsed) -> dict:
    status = "ok" if not f.warnings else "incomplete"
    return {
        "command": sys.argv[:], "params": res.params.as_dict(), "state": int(state),
        "path": ap.as_dict(), "steps_per_segment": steps, "locate": LOCATE,
        "snaps": len(f.snaps), "ends_in": ends_in, "status": status,
        "warnings": list(f.warnings), "newton_solves": f.newton_solves,
        "refused_steps": f.refused, "timings": {"move": elapsed},
        "solve": {"status": res.status, "folder": str(res.folder)},
    }  # fmt: skip


@dataclass(frozen=True)
class Plan:
    """An actuator path from stable state `state` to `goal` over a map (`path`: plan.csv, one
    row a waypoint, starting and ending at the solve's values), and `move`, the move along it
    that checks it (None when no path was found). `status`: ok (the move ends in the goal),
    unreachable (no path within the window), or incomplete (a path whose move does not end in
    the goal: not a plan)."""

    params: object
    state: int
    goal: int
    map: object
    path: pd.DataFrame
    move: Move | None
    record: dict

    @property
    def status(self) -> str:
        """ok, unreachable or incomplete (see the class docstring)."""
        return self.record["status"]

    def plot(self, path: str | Path) -> list[Path]:
        """plan.png/svg: the map with the path drawn over it, snaps marked."""
        from ..plot.motion import plot_plan

        return plot_plan(self, path)

    def explore(self, path: str | Path) -> Path:
        """explore.html: the plan's map in a browser, offline, with the path drawn on it and a
        slider that walks the move along it."""
        from ..plot.explore_pages import map_page

        return map_page(self.map, path, route=self.path, move=self.move)

    def save(self, folder: str | Path, plots: bool = True, html: bool = False) -> Path:
        """plan.csv, run.json, columns.md [, plan.png/svg] [, explore.html: the map with the
        path] and the checking move's trajectory.csv, snaps.csv [, move.png/svg, move.gif],
        in a new folder."""
        with new_folder(folder) as work:
            write_csv(work / "plan.csv", self.path)
            tables = ("plan", _move_table(self.params), "snaps")
            atomic_write_text(work / "columns.md", reference(*tables))
            write_json(work / "run.json", self.record)
            if self.move is not None:
                self.move.write_into(work, plots)
            if plots:
                self.plot(work / "plan")
            if html:
                self.explore(work / "explore.html")
        return Path(folder)


def plan(
    res: Solutions,
    state: int,
    goal: int,
    over: tuple,
    points: int | None = None,
    design_map=None,
    settings: Settings | None = None,
    workers: int | None = None,
    progress: bool = False,
) -> Plan:
    """An actuator path over two parameters, `over` = (x, (from, to), y, (from, to)), that
    takes the mechanism from the stable state `state` to the stable state `goal` (solution_ids
    of `res`) and returns the actuators to the solve's values: fewest snaps, then shortest, over
    the grid of a map (`design_map`, a cb.DesignMap over the same window, or made here with
    `points` a side, default PLAN_POINTS, `settings` and `workers` as for cb.design_map);
    checked by cb.move along it."""
    from ..catastrophe.maps import map_axes
    from ..motion.plan import plan_path
    from .maps import design_map as make_map

    model = res.params
    given = design_map is not None
    if given and (points, settings, workers) != (None, None, None):
        raise ParameterError("plan: points, settings and workers make a map; a design_map "
                             "given is used as it is")  # fmt: skip
    points = PLAN_POINTS if points is None and not given else points
    (x, xr), (y, yr), points = map_axes(model, tuple(over), None, None, points)
    if given and design_map.record["window"] != {x: list(xr), y: list(yr)}:
        raise ParameterError(f"design_map: its window {design_map.record['window']} is not "
                             f"the plan's {({x: list(xr), y: list(yr)})}")  # fmt: skip
    start = _inside(model, (x, xr), (y, yr))
    row, target = _stable_row(res, state), _stable_row(res, goal, "goal")
    if int(row.solution_id) == int(target.solution_id):
        raise ParameterError(f"goal = {goal!r}: the state the mechanism is in already")
    t0 = time.perf_counter()
    dm = design_map
    if dm is None:
        dm = make_map(model, x, xr, y, yr, points=points, settings=settings,
                      workers=workers or 1, progress=progress)  # fmt: skip
    t1 = time.perf_counter()
    grid = _grid(model, dm, (x, y))
    flow = flow_of(model, res.table)
    found = plan_path(lambda v: flow.at(model.replace(**v)), grid, start, flow.state(row),
                      lambda s: flow.match(s) == int(target.solution_id), progress)  # fmt: skip
    t2 = time.perf_counter()
    path = pd.DataFrame(found.waypoints, columns=[x, y])
    checked = None
    if found.waypoints:
        checked = move(res, int(state), {x: path[x].tolist(), y: path[y].tolist()})
    timings = {"map": t1 - t0, "search": t2 - t1, "check": time.perf_counter() - t2}
    status = "unreachable"
    if checked is not None:
        status = "ok" if checked.ends_in == int(goal) and checked.status == "ok" else "incomplete"
    record = {
        "command": sys.argv[:], "params": model.as_dict(), "state": int(state), "goal": int(goal),
        "window": {x: list(xr), y: list(yr)}, "points": len(grid.xs), "status": status,
        "snaps": found.snaps if found.waypoints else None, "travel": found.travel,
        "waypoints": len(found.waypoints), "states_expanded": found.expanded,
        "steps_simulated": found.steps_simulated, "states_not_in_map": found.unlisted,
        "map_status": dm.status, "map_reused": bool(dm.record.get("reused")),
        "move_status": checked.status if checked else None,
        "move_ends_in": checked.ends_in if checked else None,
        "timings": timings,
    }  # fmt: skip
    return Plan(model, int(state), int(goal), dm, path, checked, record)


def _inside(model, xa: tuple, ya: tuple) -> dict[str, float]:
    """The solve's values, refused unless inside the window on both axes."""
    values = model.as_dict()
    for name, (lo, hi) in (xa, ya):
        if not lo <= values[name] <= hi:
            raise ParameterError(f"{name} = {values[name]:g}: the solve lies outside the plan's "
                                 f"window {lo:g} to {hi:g}")  # fmt: skip
    return {xa[0]: float(values[xa[0]]), ya[0]: float(values[ya[0]])}


def _grid(model, dm, axes: tuple[str, str]):
    """The plan's grid: the map's, with its 2-D sweep's stable rows by grid index."""
    from ..analysis.classify import read_table
    from ..continuation.framework import pose_names
    from ..model.framework.spec import units
    from ..motion.plan import Grid

    x, y = axes
    if tuple(dm.axes) != (x, y):
        raise ParameterError(f"design_map: its axes {tuple(dm.axes)} are not the plan's {axes}")
    xs, ys = np.unique(dm.regions[x].to_numpy(float)), np.unique(dm.regions[y].to_numpy(float))
    table = read_table(Path(dm.record["sweep_folder"]) / "sweep.csv")
    stable = table[table.stable.astype(bool)]
    by_point = {int(k): rows for k, rows in stable.groupby("point")}
    if isinstance(model, Params):
        return Grid((x, y), xs, ys, by_point, ["gamma1_deg", "gamma2_deg"], model.L3)
    return Grid((x, y), xs, ys, by_point, pose_names(model), units(model)[0])
