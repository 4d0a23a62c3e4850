"""Finish a sweep: sweep.csv with branches, events.csv, columns.md and run.json."""

from __future__ import annotations

import time
from pathlib import Path

import pandas as pd

from ..columns import reference
from ..fs import atomic_write_text, write_csv, write_json
from ..versions import versions
from .runner import assemble
from .spec import SweepSpec

EVENT_FRAME_COLUMNS = ["kind", "branches", "gamma1_deg", "gamma2_deg"]


def finish(
    spec: SweepSpec,
    folder: Path,
    stats: dict,
    workers: int = 1,
    scheduler: str | None = None,
    command: list[str] | None = None,
) -> dict:
    """Assemble sweep.csv (with branches for 1-D sweeps), events.csv and run.json."""
    from ..params import Params
    from .events import find_events
    from .matching import assign_branches

    t0 = time.perf_counter()
    table = assemble(spec, folder)
    events = pd.DataFrame(columns=EVENT_FRAME_COLUMNS[:2] + [spec.param] + EVENT_FRAME_COLUMNS[2:])
    if spec.param2 is None:
        table = assign_branches(table, spec.param)
        events = find_events(table, spec.param, Params(**spec.base), spec.settings)
    write_csv(folder / "sweep.csv", table)
    write_csv(folder / "events.csv", events)
    atomic_write_text(folder / "columns.md", reference("sweep", "events", "solutions"))
    incomplete = sorted(set(table.loc[table["status"] != "ok", "point"])) if len(table) else []
    record = {
        "spec": spec.to_json(),
        "key": spec.key(),
        "command": command,
        "points": spec.size(),
        "rows": len(table),
        "events": len(events),
        "status": "incomplete" if incomplete else "ok",
        "incomplete_points": [int(p) for p in incomplete],
        "stats": stats,
        "workers": workers,
        "scheduler": scheduler,
        "methods": table["method"].value_counts().to_dict() if len(table) else {},
        "lost_paths": int(table.groupby("point")["lost_paths"].max().sum()) if len(table) else 0,
        "versions": versions(),
        "figures": [],
        "timings": {"solve": stats["seconds"], "finish": time.perf_counter() - t0},
    }
    write_json(folder / "run.json", record)
    return record
