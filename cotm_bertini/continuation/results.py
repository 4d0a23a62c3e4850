"""Finish a sweep: sweep.csv with branches, events.csv, columns.md and run.json.

Everything here works on numpy columns (the points as the runner keeps them in memory, or as
the folder's store holds them): no pandas, no CSV read back.
"""

from __future__ import annotations

import json
import time
from collections import Counter
from pathlib import Path

import numpy as np

from ..columns import reference
from ..fs import atomic_write_text, write_json
from ..versions import versions
from .runner import assemble_columns, sweep_names
from .spec import SweepSpec
from .store import PointStore
from .tables import Columns, csv_text, rows_text, union_names


def finish_columns(
    spec: SweepSpec,
    folder: Path,
    stats: dict,
    workers: int = 1,
    scheduler: str | None = None,
    command: list[str] | None = None,
    store: PointStore | None = None,
) -> tuple[dict, Columns]:
    """Assemble sweep.csv (with branches for 1-D sweeps), events.csv and run.json: (the run
    record, the table as numpy columns, branch included). `store`: the folder's points, already
    in memory (default: read from disk)."""
    from ..params import Params
    from .events import event_columns, event_records
    from .matching import branch_ids

    t0 = time.perf_counter()
    store = PointStore(folder) if store is None else store
    table = assemble_columns(spec, folder, store)
    events: list[dict] = []
    names = event_columns(spec.param)
    tables = ("sweep", "events", "solutions")
    if spec.framework is not None:
        from .framework import match_coordinates
        from .framework_events import framework_event_columns, framework_event_records

        names = framework_event_columns(spec.model, spec.param)
        tables = ("framework_sweep", "framework_events", "framework")
        if spec.param2 is None:
            table["branch"] = branch_ids(table, spec.param, match_coordinates(spec.model, table))
            events = _kept_events(folder, store, lambda: framework_event_records(spec, table))
    elif spec.param2 is None:
        table["branch"] = branch_ids(table, spec.param)
        base = Params(**spec.base)
        events = _kept_events(
            folder, store, lambda: event_records(table, spec.param, base, spec.settings)
        )
    atomic_write_text(folder / "sweep.csv", _sweep_text(spec, store, table.get("branch")))
    atomic_write_text(folder / "events.csv", csv_text({n: [e[n] for e in events] for n in names}))
    atomic_write_text(folder / "columns.md", reference(*tables))
    record = _record(spec, table, len(events), stats, workers, scheduler, command)
    record["timings"] = {"solve": stats["seconds"], "finish": time.perf_counter() - t0}
    write_json(folder / "run.json", record)
    return record, table


EVENTS_KEPT = ".events.json"  # a sweep folder's refined events, with the points they are of


def _kept_events(folder: Path, store: PointStore, refine) -> list[dict]:
    """The events `refine()` finds (each a full solve per bisection probe: minutes on a large
    framework), kept in the folder with the size of its points' store: a finished sweep run
    again (resumed, say, to draw its page) reads them back instead of refining them again."""
    from .._version import __version__

    size = store.path.stat().st_size if store.path.is_file() else None
    stamp = {"store_bytes": size, "points": len(store), "version": __version__}
    kept = folder / EVENTS_KEPT
    if size is not None and kept.is_file():
        try:
            data = json.loads(kept.read_text())
            if data["stamp"] == stamp:
                return data["events"]
        except (ValueError, KeyError):
            pass
    events = refine()
    if size is not None:
        atomic_write_text(kept, json.dumps({"stamp": stamp, "events": events}, default=_plain))
    return events


def _plain(value):
    """numpy scalars and arrays as JSON."""
    return value.tolist() if hasattr(value, "tolist") else str(value)


def _sweep_text(spec: SweepSpec, store: PointStore, branch: np.ndarray | None) -> str:
    """sweep.csv: the header, then each point's lines (written by the workers under the
    columns `sweep_names` foresaw, else here), with the branch column for 1-D sweeps."""
    parts = [store.points[i] for i in range(spec.size())]
    names = union_names(parts)
    texts = store.texts if names == sweep_names(spec) else {}
    pieces = [",".join(names + (["branch"] if branch is not None else [])) + "\n"]
    row = 0
    for index, part in enumerate(parts):
        text = texts.get(index)
        text = rows_text(part, names) if text is None else text
        if branch is not None and text:
            lines = text.split("\n")[:-1]
            ids = branch[row : row + len(lines)].tolist()
            text = "".join(f"{line},{b}\n" for line, b in zip(lines, ids, strict=True))
            row += len(lines)
        pieces.append(text)
    return "".join(pieces)


def _record(spec: SweepSpec, table: Columns, events: int, stats, workers, scheduler, command):
    """run.json: the request, counts, status, methods and versions."""
    rows = len(table["point"]) if "point" in table else 0
    status = np.asarray(table.get("status", np.zeros(0)), dtype=object)
    point = np.asarray(table.get("point", np.zeros(0)), dtype=int)
    incomplete = sorted(set(point[status != "ok"].tolist())) if rows else []
    lost = 0
    if rows:
        per_point = np.asarray(table["lost_paths"], dtype=float)
        first = np.unique(point, return_index=True)[1]  # a point's rows share its lost_paths
        lost = int(np.nansum(per_point[first]))
    methods = dict(Counter(table["method"].tolist()).most_common()) if rows else {}
    return {
        "spec": spec.to_json(),
        "key": spec.key(),
        "command": command,
        "points": spec.size(),
        "rows": rows,
        "events": events,
        "status": "incomplete" if incomplete else "ok",
        "incomplete_points": [int(p) for p in incomplete],
        "stats": stats,
        "workers": workers,
        "scheduler": scheduler,
        "methods": methods,
        "lost_paths": lost,
        "versions": versions(),
        "figures": [],
    }
