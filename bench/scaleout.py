"""Scale-out (issue 18): one framework's first generic solve (seed 1, its first taut set) by
Bertini's own start system in one call, and split in chunks over a Dask LocalCluster of 1 and
2 worker processes (our own linear-product start system); wall and CPU times (the CPU time does
not depend much on how loaded the machine is), paths per second, counts, and whether the sets
agree. Usage: python bench/scaleout.py [--example prism] [--workers 1 2] (the prism takes
minutes; the load average is printed: on a shared machine wall times are inflated).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd
from benchlib import BENCH, example_system, same_points, show, write_csv

ROOT = BENCH.parent


def _row(route: str, gs, wall: float, reference) -> dict:
    return {"route": route, "seconds": wall, "paths": gs.paths,
            "paths_per_s": gs.paths / wall, "finite": gs.finite_endpoints,
            "nonsingular": len(gs.points), "singular": gs.singular_endpoints,
            "cpu_s": gs.route.get("cpu_seconds", float("nan")),
            "chunks": gs.route.get("chunks", 1),
            "retracked_adaptive": gs.route.get("retracked_adaptive", "-"),
            "same_set_as_bertini": "-" if reference is None else same_points(gs.points, reference),
            "load_avg_1min": os.getloadavg()[0]}  # fmt: skip


def main() -> None:
    """Print and write bench/results/scaleout.csv."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--example", default="prism")
    ap.add_argument("--workers", nargs="*", type=int, default=[1, 2])
    opts = ap.parse_args()
    os.environ["COTM_CACHE"] = tempfile.mkdtemp(prefix="cotm-bench-scaleout-")
    from distributed import LocalCluster

    from cotm_bertini.backends.homotopy import generic_set

    ps, centre, groups = example_system(opts.example)
    kw = {"use_cache": False, "centre": centre, "groups": groups}
    t0 = time.perf_counter()
    ref = generic_set(ps, 1, **kw)
    rows = [_row("bertini start, one call (all cores)", ref, time.perf_counter() - t0, None)]
    for n in opts.workers:
        with LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                          dashboard_address=":0") as cluster:  # fmt: skip
            t0 = time.perf_counter()
            gs = generic_set(ps, 1, scheduler=cluster.scheduler_address, **kw)
            wall = time.perf_counter() - t0
        rows.append(_row(f"own start, split on {n} worker(s)", gs, wall, ref.points))
        print(f"{n} worker(s): chunk seconds {gs.route['chunk_seconds']}", file=sys.stderr)
    frame = pd.DataFrame(rows)
    print(f"\n{opts.example}: first generic set (seed 1, first taut set), {os.cpu_count()} cores")
    show(
        "scale-out: generic solve", frame, {"seconds": ".1f", "paths_per_s": ".2f", "cpu_s": ".1f"}
    )
    write_csv(frame, f"scaleout-{opts.example}")


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    main()
