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
from .solutions import Solutions

DEFAULT_STEPS = 100  # recorded steps a segment of the path


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

    def save(self, folder: str | Path, plots: bool = True) -> Path:
        """trajectory.csv, snaps.csv, columns.md, run.json [, move.png/svg, move.gif] in a new
        folder, built under a hidden name and renamed when complete."""
        tables = ("move", "snaps") if isinstance(self.params, Params) else (
            "framework_move", "snaps")  # fmt: skip
        with new_folder(folder) as work:
            write_csv(work / "trajectory.csv", self.table)
            write_csv(work / "snaps.csv", self.snaps)
            atomic_write_text(work / "columns.md", reference(*tables))
            write_json(work / "run.json", self.record)
            if plots:
                self.plot(work / "move")
                self.animate(work / "move.gif")
        return Path(folder)


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


def _stable_row(res: Solutions, state) -> pd.Series:
    """The row of the stable solution `state`, or a one-line error naming the stable ids."""
    table = res.table
    stable = table[table.stable.astype(bool)]
    ids = " ".join(str(int(i)) for i in stable.solution_id) or "none"
    try:
        sid = int(state)
    except (TypeError, ValueError):
        raise ParameterError(f"state = {state!r}: expected a solution_id (stable: {ids})") from None
    hit = stable[stable.solution_id == sid]
    if isinstance(state, bool) or sid != state or hit.empty:
        raise ParameterError(f"state = {state!r}: not a stable solution_id of the solve "
                             f"(stable: {ids})")  # fmt: skip
    return hit.iloc[0]


def _trajectory(flow, model, ap: ActuatorPath, f: Followed) -> pd.DataFrame:
    """trajectory.csv: path position, parameter values, event, then the state's columns."""
    parts = []
    for k, (s, x, event) in enumerate(zip(f.s, f.states, f.events, strict=True)):
        values = ap.at(s)
        here = flow.at(model.replace(**values))
        eig = here.eigh(x)[0]
        head = {"step": k, "s": s, **values, "event": event}
        tail = {"hess_min_eig": float(eig.min()) / here.hessian_unit if len(eig) else np.nan}
        parts.append({**head, **here.rows(x[None, :]).iloc[0].to_dict(), **tail})
    return pd.DataFrame(parts)


def _snaps(flow, model, ap: ActuatorPath, f: Followed) -> pd.DataFrame:
    """snaps.csv: one row a snap, the poses before and after."""
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
        for name in [*_pose(model, flow), "energy"]:
            row[f"before.{name}"] = before[name]
            row[f"after.{name}"] = after[name] if after is not None else math.nan
        rows.append(row)
    return pd.DataFrame(rows)


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
