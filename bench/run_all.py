"""The benchmark suite (`make bench`): every table, bench/results/*.csv and the time/error plot.

1. reference equilibria (40-digit mpmath Newton, no Bertini)       bench/reference.py
2. run time against error over a grid of settings, cases 1-3        bench/settings_grid.py
3. formulations and start systems, cases 2-3                         bench/formulations.py
4. peers on case 3 (bertini2, PHCpack, Bertini 2 in-process)          bench/peers.py
5. stage profile of `make case3`                                      bench/stage_profile.py
6. the paper's 241-point sweep, and a summary of the headline figures

Benchmarks, not tests: nothing is asserted; targets are printed beside the measurements.
Timings are wall clock on whatever else the machine is doing: run it on a quiet machine.

Usage: .venv/bin/python bench/run_all.py [--quick]   (--quick: the slow case-3 settings skipped)
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
import traceback
from pathlib import Path

SWEEP_POINTS = 241


def sweep_time(points: int = SWEEP_POINTS) -> dict:
    """The paper's sweep (L01 0..12 m, L02 = 0, Table 1) as bench/sweep.py runs it, no plots."""
    from cotm_bertini.params import TABLE1
    from cotm_bertini.sweep import (
        SweepSpec,
        default_workers,
        prepare,
        run_points,
        warm_generic_sets,
    )

    spec = SweepSpec(dict(TABLE1), "L01", 0.0, 12.0, points)
    workers = default_workers()
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="bench-sweep-") as tmp:
        warm_generic_sets(spec)
        folder = prepare(spec, Path(tmp))
        stats = run_points(spec, folder, workers=workers)
    return {
        "points": stats["solved"],
        "workers": workers,
        "sweep_s": stats["seconds"],
        "wall_s": time.perf_counter() - start,
        "ms_per_point": 1e3 * stats["seconds"] / max(stats["solved"], 1),
        "lost_paths": stats["lost_paths"],
    }


def _pareto_settings(grid_table, column: str) -> dict[str, list[str]]:
    """Settings on each case's Pareto front of (wall time, error)."""
    import numpy as np
    from settings_grid import ERROR_FLOOR, pareto

    out = {}
    for case, group in grid_table.groupby("case"):
        err = group[column].to_numpy(dtype=float)
        err = np.where(np.isfinite(err), np.maximum(err, ERROR_FLOOR), 1e3)
        front = pareto(np.column_stack([group["wall_s"].to_numpy(dtype=float), err]))
        out[case] = list(group["setting"].to_numpy()[front])
    return out


def summary(results: dict, failed: list[str], elapsed: float) -> None:
    """Section 6: the headline figures against their targets; summary.csv."""
    import pandas as pd
    from benchlib import show, write_csv

    rows = []

    def add(metric: str, value: float, unit: str, target: str = "", met: object = "") -> None:
        rows.append({"metric": metric, "value": value, "unit": unit, "target": target, "met": met})

    peers = results.get("peers")
    if peers is not None:
        ours = float(peers.loc[0, "seconds"])
        add("case-3 end to end (cotm-bertini solve, median of 3)", ours, "s", "< 1 s", ours < 1)
        for label, key in (("bare bertini2", "bare bertini2"), ("PHCpack phc -b", "PHCpack")):
            row = peers[peers["solver"].str.startswith(key)]
            if len(row):
                add(
                    f"{label} / ours end to end (case 3)",
                    float(row["x_ours_end_to_end"].iloc[0]),
                    "x",
                )
                add(f"{label} time (case 3)", float(row["seconds"].iloc[0]), "s")
    grid = results.get("grid")
    if grid is not None:
        table = pd.DataFrame([o.row for o in grid.values()])
        default = table[table["setting"] == "homotopy"]
        worst = float(default["worst_err_deg"].max())
        add("worst angle error, default settings, cases 1-3", worst, "deg", "< 1e-9", worst < 1e-9)
        add("missed equilibria, default settings, cases 1-3", int(default["missed"].sum()), "")
    stages = results.get("stages")
    if stages is not None:
        get = dict(zip(stages["stage"], stages["median_s"], strict=True))
        add("make case3 (with plots) wall", get["wall"], "s")
        add("  of which plots", get["plot"], "s")
        add("  of which start-up and imports", get["startup_import"], "s")
    sweep = results.get("sweep")
    if sweep is not None:
        add(
            f"{sweep['points']}-point sweep ({sweep['workers']} workers)",
            sweep["sweep_s"],
            "s",
            "< 60 s",
            sweep["sweep_s"] < 60,
        )
        add("  per point", sweep["ms_per_point"], "ms")
        add("  lost paths", sweep["lost_paths"], "")
    add("bench wall time (run_all.py)", elapsed, "s", "< 600 s", elapsed < 600)
    frame = pd.DataFrame(rows)
    show("6. Summary", frame, {"value": ".4g"})
    if grid is not None:
        for column, what in (("worst_err_deg", "reported"), ("raw_err_deg", "raw endpoints")):
            fronts = _pareto_settings(table, column)
            text = "; ".join(f"{case}: {', '.join(s)}" for case, s in fronts.items())
            print(f"Pareto front ({what} error vs wall time): {text}")
        print(
            "note: the reported error is that of the package's double-precision Newton polish "
            "(~1e-14 to 1e-11 deg, set by conditioning), so differences between settings below "
            "1e-11 deg are not a property of the setting"
        )
    if failed:
        print("sections that failed: " + ", ".join(failed))
    write_csv(frame, "summary")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="skip the slow case-3 settings")
    args = ap.parse_args()
    start = time.perf_counter()

    import formulations
    import peers
    import reference
    import settings_grid
    import stage_profile

    results: dict = {}
    failed: list[str] = []

    def section(name: str, fn, *fargs, **fkwargs) -> None:
        t = time.perf_counter()
        try:
            results[name] = fn(*fargs, **fkwargs)
        except Exception:  # a benchmark reports a broken section and goes on
            traceback.print_exc()
            failed.append(name)
        print(f"[{name}: {time.perf_counter() - t:.1f} s]", flush=True)

    section("reference", reference.run)
    ref = results.get("reference")
    if ref is not None:
        section("grid", settings_grid.run, ref, quick=args.quick)
        section(
            "formulations",
            formulations.run,
            ref,
            results.get("grid"),
            cases=("case2",) if args.quick else formulations.FORMULATION_CASES,
        )
    section("peers", peers.run, ref)
    section("stages", stage_profile.run)
    section("stages_cli", stage_profile.run, engine="cli")  # what `make case3` runs
    section("sweep", sweep_time)
    if "sweep" in results:
        s = results["sweep"]
        print(
            f"\n== sweep: {s['points']} points (L01 0..12 m), {s['workers']} workers: "
            f"{s['sweep_s']:.2f} s solving ({s['ms_per_point']:.1f} ms per point), "
            f"{s['wall_s']:.2f} s with set-up; lost paths {s['lost_paths']} =="
        )
    summary(results, failed, time.perf_counter() - start)
    print(f"\nbench wall time: {time.perf_counter() - start:.1f} s")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
