"""A sweep's folds located on their fold systems against the bisection by full solves, same
run: the 4-link chain (tests/fixtures/chain4.toml) swept over L0 from 1.6 to 2.0, both ways;
seconds (points, events), the solves the events took, and the events' values side by side.
Usage: python bench/sweep_folds.py [--points N] [--only all|stable]."""

from __future__ import annotations

import argparse
import tempfile
import time

import numpy as np
import pandas as pd
from benchlib import BENCH, show, write_csv

ROOT = BENCH.parent


def run(points: int, only: str, located: bool) -> tuple[dict, pd.DataFrame]:
    """One sweep: its row of the table, and its events."""
    import cotm_bertini as cb
    import cotm_bertini.continuation.framework_events as fe
    import cotm_bertini.point as point

    solves, pinned, solve = [0], fe._pinned, point.solve_framework_point

    def counted(*args, **kwargs):
        solves[0] += 1
        return solve(*args, **kwargs)

    point.solve_framework_point = counted  # the events' probes (the points use the batch call)
    fe._pinned = pinned if located else (lambda *a, **k: None)
    try:
        fw = cb.Framework.from_toml(ROOT / "tests" / "fixtures" / "chain4.toml")
        t0 = time.perf_counter()
        sw = cb.sweep(fw, "L0", np.linspace(1.6, 2.0, points), workers=2, only=only,
                      out=tempfile.mkdtemp())  # fmt: skip
        seconds = time.perf_counter() - t0
    finally:
        point.solve_framework_point, fe._pinned = solve, pinned
    timings = sw.record.get("timings", {})
    return {"folds": "located" if located else "bisected", "points": points, "seconds": seconds,
            "points_s": timings.get("solve"), "events_s": timings.get("finish"),
            "event_solves": solves[0], "events": len(sw.events)}, sw.events  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=101)
    ap.add_argument("--only", choices=("all", "stable"), default="all")
    args = ap.parse_args()
    rows, events = [], []
    for located in (True, False):
        row, ev = run(args.points, args.only, located)
        rows.append(row)
        events.append(ev)
    frame = pd.DataFrame(rows)
    frame["ratio"] = frame["seconds"] / frame["seconds"].iloc[-1]
    show("a sweep's folds: located on their systems against bisected", frame,
         {"seconds": ".1f", "points_s": ".1f", "events_s": ".1f", "ratio": ".3f"})  # fmt: skip
    a, b = events
    same = len(a) == len(b) and list(a["kind"]) == list(b["kind"])
    gap = float(np.abs(a["L0"].to_numpy() - b["L0"].to_numpy()).max()) if same and len(a) else None
    print(f"same events: {same}; largest difference of the values: {gap}")
    write_csv(frame, "sweep_folds")


if __name__ == "__main__":
    main()
