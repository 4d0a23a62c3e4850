"""The real route on products of spheres (issue 41): each spatial example's first solve on the
command line (a fresh cache: equations derived, then the branch and bound over chart angles)
within a time budget, with what its run.json says: the search's boxes, the share of the
configuration space left undecided, rows, stable ones, the Morse sum against the Euler
characteristic 2^nodes, the status. Usage: python bench/spatial_route.py [--only NAME ...]
[--workers N | --dask N] [--budget NAME=SECONDS ...] (defaults: prism_slack 600 s, prism4
900 s, tower 600 s; a solve stopped by its budget is `incomplete` and says how much is left;
--dask N starts a local Dask cluster of N one-thread worker processes and solves on it with
--scheduler: boxes a second against N, the scale-out a cluster of machines would give).
--map: instead, prism_slack's 41 x 41 map over (L0t, h) in the window L0t 0.2..0.8, h 1.2..1.6
on the command line (fresh cache, --workers, default 2): its stages' times and its checks."""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd
from benchlib import BENCH, show, write_csv

ROOT = BENCH.parent
BUDGETS = {"prism_slack": 600.0, "prism4": 900.0, "tower": 600.0}


def _solve(name: str, budget: float, workers: int, scheduler: str = "") -> dict:
    """One first solve (fresh cache) on the command line and its run.json's figures."""
    cli = str(Path(sys.executable).with_name("cotm-bertini"))
    out = Path(tempfile.mkdtemp(prefix="cotm-bench-spatial-"))
    env = {**os.environ, "COTM_CACHE": str(out / "cache")}
    args = [
        cli,
        "solve",
        "--framework",
        str(ROOT / "examples" / f"{name}.toml"),
        "--timeout",
        str(budget),
        "--out",
        str(out / "runs"),
        "--no-cache",
        "--no-plots",
        "--quiet",
    ]
    args += ["--scheduler", scheduler] if scheduler else ["--workers", str(workers)]
    t0 = time.perf_counter()
    done = subprocess.run(args, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if done.returncode not in (0, 5):  # 5: incomplete, a stated outcome
        raise SystemExit(f"{name}: exit {done.returncode}\n{done.stderr[-2000:]}")
    record = json.loads((out / "runs" / "latest" / "run.json").read_text())
    search, morse, counts = record["details"]["real_search"], record["morse"], record["counts"]
    return {
        "example": name,
        "space": morse.get("manifold", ""),
        "workers": workers,
        "dask": bool(scheduler),
        "budget_s": budget,
        "first_solve_s": wall,
        "search_s": search["seconds"],
        "boxes": search["boxes"],
        "boxes_per_s": search["boxes"] / max(search["seconds"], 1e-9),
        "undecided_share": search["undecided_share"],
        "rows": counts["physical"],
        "stable": counts["stable"],
        "morse_sum": morse.get("euler_characteristic"),
        "euler": morse.get("expected"),
        "status": record["status"],
    }


MAP = ["--param", "L0t", "--from", "0.2", "--to", "0.8", "--param2", "h", "--from2", "1.2",
       "--to2", "1.6", "--points", "41"]  # fmt: skip


def _map(workers: int) -> dict:
    """prism_slack's 41 x 41 map (fresh cache) on the command line and its run.json's figures."""
    cli = str(Path(sys.executable).with_name("cotm-bertini"))
    out = Path(tempfile.mkdtemp(prefix="cotm-bench-spatial-map-"))
    env = {**os.environ, "COTM_CACHE": str(out / "cache")}
    args = [cli, "map", "--framework", str(ROOT / "examples" / "prism_slack.toml"), *MAP,
            "--workers", str(workers), "--out", str(out / "runs"), "--no-plots",
            "--quiet"]  # fmt: skip
    t0 = time.perf_counter()
    done = subprocess.run(args, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if done.returncode not in (0, 5):
        raise SystemExit(f"map: exit {done.returncode}\n{done.stderr[-2000:]}")
    record = json.loads((out / "runs" / "latest" / "run.json").read_text())
    chart = record["chart"]
    return {
        "map": "prism_slack 41 x 41", "workers": workers, "wall_s": wall,
        **{f"{k}_s": v for k, v in chart["timings"].items()},
        "anchors_proved": chart["anchors_proved"], "lost": chart["propagation"]["lost_branches"],
        "morse_failed": chart["morse_failed"], "curves": record["fold_curves"],
        "count_changes": record["count_changes"], "unexplained": record["unexplained_changes"],
        "status": record["status"],
    }  # fmt: skip


def main() -> None:
    """Solve each example within its budget; print and keep the table."""
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--only", nargs="*", default=list(BUDGETS), choices=list(BUDGETS))
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--dask", type=int, default=0, metavar="N")
    ap.add_argument("--budget", nargs="*", default=[], metavar="NAME=SECONDS")
    ap.add_argument("--map", action="store_true")
    args = ap.parse_args()
    if args.map:
        frame = pd.DataFrame([_map(args.workers if args.workers > 1 else 2)])
        show("prism_slack's map by continuation in chart angles", frame, {})
        write_csv(frame, "spatial_map")
        return
    budgets = dict(BUDGETS)
    for item in args.budget:
        name, _, seconds = item.partition("=")
        if name not in budgets:
            raise SystemExit(f"--budget: unknown example {name!r}")
        budgets[name] = float(seconds)
    if args.dask:
        from distributed import LocalCluster

        with LocalCluster(n_workers=args.dask, threads_per_worker=1, processes=True,
                          dashboard_address=":0") as cluster:  # fmt: skip
            rows = [_solve(n, budgets[n], args.dask, cluster.scheduler_address)
                    for n in args.only]  # fmt: skip
    else:
        rows = [_solve(n, budgets[n], args.workers) for n in args.only]
    frame = pd.DataFrame(rows)
    show("the real route on products of spheres: first solve within a budget", frame,
         {"first_solve_s": ".1f", "search_s": ".1f", "boxes_per_s": ".0f",
          "undecided_share": ".3g"})  # fmt: skip
    tag = f"_dask{args.dask}" if args.dask else (f"_w{args.workers}" if args.workers > 1 else "")
    write_csv(frame, "spatial_route" + tag)


if __name__ == "__main__":
    main()
