"""The benchmark suite (`make bench`): every table, bench/results/*.csv and the time/error plot.

1. reference equilibria (40-digit mpmath Newton, no Bertini)       bench/reference.py
2. run time against error over a grid of settings, cases 1-3        bench/settings_grid.py
3. formulations and start systems, cases 2-3                         bench/formulations.py
4. peers on case 3 (bertini2, PHCpack, Bertini 2 in-process)          bench/peers.py
5. stage profile of `make case3`                                      bench/stage_profile.py
6. speed side by side: the paper's sweep by four routes, one solve, the 101 x 101 grid
                                                                     bench/speed.py
7. the cold solve of case 3 against bare bertini2 on case 3, interleaved
                                                                     bench/cold_solve.py
8. a summary of the headline figures

Benchmarks, not tests: nothing is asserted; targets are printed beside the measurements.
Timings are wall clock on whatever else the machine is doing: run it on a quiet machine.

Usage: .venv/bin/python bench/run_all.py [--quick]   (--quick: the slow case-3 settings and the
101 x 101 grid skipped)
"""

from __future__ import annotations

import argparse
import sys
import time
import traceback


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
    """Section 8: the headline figures against their targets; summary.csv."""
    import pandas as pd
    from benchlib import show, write_csv

    rows = []

    def add(metric: str, value: float, unit: str, target: str = "", met: object = "") -> None:
        rows.append({"metric": metric, "value": value, "unit": unit, "target": target, "met": met})

    peers = results.get("peers")
    if peers is not None:
        ours = float(peers.loc[0, "seconds"])
        add("case-3 end to end (cotm-bertini solve, median of 3)", ours, "s", "< 0.3 s", ours < 0.3)
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
        add("cotm-bertini solve case3 --no-cache (with plots) wall", get["wall"], "s")
        add("  of which plots", get["plot"], "s")
        add("  of which start-up and imports", get["startup_import"], "s")
    speed = results.get("speed")
    if speed is not None:
        row = speed[(speed["points"] == 241) & speed["route"].str.startswith("ours")].iloc[0]
        sweep_s = row["seconds"]
        add("241-point paper sweep (2 workers)", sweep_s, "s", "< 2.5 s", sweep_s < 2.5)
        add("  per point", row["ms_per_point"], "ms", "< 10 ms", row["ms_per_point"] < 10)
        add("  worst angle error at the sample points", row["worst_err_deg"], "deg")
        add("  lost paths", row["lost_paths"], "")
    solve = results.get("solve")
    if solve is not None:
        add("cotm-bertini solve case3 --no-cache --no-plots (median of 5)", solve["median_s"],
            "s", "< 0.3 s", solve["median_s"] < 0.3)  # fmt: skip
    grid = results.get("grid101")
    if grid is not None:
        add("101 x 101 grid (2 workers)", grid["seconds"], "s", "< 120 s", grid["seconds"] < 120)
        add("  lost paths", grid["lost_paths"], "")
    cold = results.get("cold")
    if cold is not None:
        add("cold solve case3 --no-cache --no-plots (fresh process, median of 5)",
            cold["cold solve case3 --no-cache --no-plots (s, median)"], "s")  # fmt: skip
        add("  / bare bertini2 case3 (same run)", cold["cold solve / bare bertini2"], "x")
        add("  sympy imported (1: yes, 0: no)", int(cold["sympy imported"]), "", "0",
            not cold["sympy imported"])  # fmt: skip
    add("bench wall time (run_all.py)", elapsed, "s", "< 600 s", elapsed < 600)
    frame = pd.DataFrame(rows)
    show("8. Summary", frame, {"value": ".4g"})
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

    import cold_solve
    import formulations
    import peers
    import reference
    import settings_grid
    import speed
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
    section("speed", speed.series, 8)
    if "speed" in results:
        speed.plot_series(results["speed"], speed.RESULTS / "speed.png")
    section("solve", speed.one_solve)
    section("cold", cold_solve.run)
    if not args.quick:
        section("grid101", speed.grid)
    summary(results, failed, time.perf_counter() - start)
    print(f"\nbench wall time: {time.perf_counter() - start:.1f} s")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
