"""A design map of a framework on the real route by continuation in chart angles: anchors
searched, equilibria followed over the grid (chart_grid.py), fold and switch curves traced from
the seeds the grid lines met (chart_curves.py), every grid point classified as a solve's rows
and given the Morse check. For frameworks whose fold systems sympy cannot expand (a product of
spheres); its status says what is proved (module chart_grid's docstring, 3)."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..backends.pools import worker_pool
from ..continuation.charts import ChartPlane
from ..model.framework.spec import Framework
from ..progress import Progress, say
from ..settings import Settings, Tolerances
from .chart_curves import chart_fold_curves
from .chart_grid import ANCHORS, anchor_jobs, anchor_task, propagate

ANCHOR_SECONDS = 600.0  # an anchor's search budget where settings.timeout gives none
LISTED = 20  # run.json lists this many lost branches and Morse failures at most


@dataclass(frozen=True)
class ChartMap:
    """The map's pieces: fold rows, the grid's rows (a 2-D sweep's table: `point` the grid
    index, the second axis fastest) and the record."""

    folds: pd.DataFrame
    table: pd.DataFrame
    record: dict


def chart_map(fw: Framework, x: str, xs: np.ndarray, y: str, ys: np.ndarray,
              settings: Settings, workers: int = 1) -> ChartMap:  # fmt: skip
    """The map of `fw` over the grid xs x ys of its parameters x, y by continuation."""
    t0 = time.perf_counter()
    centre = fw.replace(**{x: float(xs[len(xs) // 2]), y: float(ys[len(ys) // 2])})
    plane = ChartPlane(centre, x, y)
    budget = settings.timeout or ANCHOR_SECONDS
    jobs = anchor_jobs(fw, x, xs, y, ys, ANCHORS, budget)
    say(f"map: {len(jobs)} anchor searches (the real route's proof at each)")
    with worker_pool(workers) as run:
        anchors = run(anchor_task, jobs)
    t1 = time.perf_counter()
    # Each pose once (a root in an overlap of two charts is found in both).
    empty = np.zeros((0, plane.n))
    known = {(i, j): plane.fresh(plane.rechart(a["roots"]), empty, (xs[i], ys[j]))
             for a in anchors for i, j in [a["key"]]}  # fmt: skip
    say(f"map: anchors searched in {t1 - t0:.0f} s; the equilibria followed over the grid")
    state = propagate(plane, xs, ys, known)
    t2 = time.perf_counter()
    say(f"map: {len(state.seeds)} fold and switch points on the grid lines; curves traced")
    folds, curve_record = chart_fold_curves(plane, state.seeds, (xs[0], xs[-1]), (ys[0], ys[-1]))
    t3 = time.perf_counter()
    table, morse_failed = _grid_rows(fw, plane, x, xs, y, ys, known, settings)
    t4 = time.perf_counter()
    proved = [a["key"] for a in anchors if a["proved"]]
    record = {
        "grid": "continuation",
        "anchors": [{k: (list(v) if k == "key" else v) for k, v in a.items() if k != "roots"}
                    | {"equilibria": len(a["roots"])} for a in anchors],
        "anchors_proved": len(proved),
        "propagation": {"line_passes": state.passes, "through_folds": state.throughs,
                        "seeds": len(state.seeds), "lost_branches": len(state.lost),
                        "lost": state.lost[:LISTED]},
        "morse_failed": len(morse_failed), "morse_failures": morse_failed[:LISTED],
        "curves": curve_record,
        "not_proved": _not_proved(len(xs) * len(ys), len(proved)),
        "timings": {"anchors": t1 - t0, "propagation": t2 - t1, "curves": t3 - t2,
                    "classify": t4 - t3},
    }  # fmt: skip
    return ChartMap(folds, table, record)


def _not_proved(points: int, proved: int) -> str:
    return (
        f"{points - proved} of {points} grid points were not searched: their rows are the "
        f"equilibria followed from the {proved} proved anchors along grid lines (through "
        "folds); a pair born and dying away from every followed branch would be missed"
    )


def _grid_rows(fw: Framework, plane: ChartPlane, x: str, xs, y: str, ys, known: dict,
               settings: Settings) -> tuple[pd.DataFrame, list]:  # fmt: skip
    """Each grid point's rows, classified as a solve's (routes.real.real_table), with its index and
    the swept values; and the grid points whose Morse sum fails."""
    from ..analysis.framework_checks import morse_count
    from ..routes.real import real_table

    frames, failed = [], []
    report = Progress("map: grid points classified", len(xs) * len(ys), "points")
    for i, xv in enumerate(xs):
        for j, yv in enumerate(ys):
            fwp = fw.replace(**{x: float(xv), y: float(yv)})
            pts = known.get((i, j), np.zeros((0, plane.n)))
            land = plane.land((xv, yv))
            table = real_table(fwp, land.endpoints(pts), Tolerances())
            morse = morse_count(fwp, table)
            if morse.get("applicable") and not morse["ok"]:
                failed.append({x: float(xv), y: float(yv), "sum": morse["euler_characteristic"],
                               "expected": morse["expected"]})  # fmt: skip
            frame = pd.DataFrame(table)
            frame.insert(0, y, float(yv))
            frame.insert(0, x, float(xv))
            frame.insert(0, "point", i * len(ys) + j)
            frames.append(frame)
            report.update(1)
    report.close()
    return pd.concat(frames, ignore_index=True), failed
