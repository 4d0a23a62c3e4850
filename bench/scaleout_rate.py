"""Scale-out rate (issue 29, item 4): paths a second per core of the split generic solve (the
route `--scheduler` takes: our own multihomogeneous linear-product start, chunks tracked by
homotopy.track_chunk on Dask workers) on a large framework's taut set, measured on its first
paths on a LocalCluster of 1 and then 2 worker processes, and what a cluster of N machines
would give for the whole first solve (every taut set, two seeds). Sets this large cannot be
solved here: the rate is measured on a sample and the projection is arithmetic on it, said as
such. Benchmarks: nothing asserted.

Usage: python bench/scaleout_rate.py [--example prism4] [--paths 96] [--workers 1 2]
[--cores 8 --machines 10 100]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import pandas as pd
from benchlib import BENCH, show, write_csv

ROOT = BENCH.parent


def _smallest_set(name: str):
    """(framework, smallest taut set's system at seed 1's generic start, groups, all sets'
    path counts)."""
    import cotm_bertini as cb
    from cotm_bertini.backends.homotopy import generic_start
    from cotm_bertini.backends.path_progress import path_count
    from cotm_bertini.model.framework.compiled import framework_system, variable_groups
    from cotm_bertini.model.framework.taut_sets import taut_sets
    from cotm_bertini.model.framework.units import normalized_slots

    fw = cb.Framework.from_toml(ROOT / "examples" / f"{name}.toml")
    slots = normalized_slots(fw.at_defaults())
    systems = [framework_system(fw, t) for t in taut_sets(fw)]
    systems = [fs for fs in systems if not fs.free]
    counts = [path_count(fs.ps, variable_groups(fs)) for fs in systems]
    fs = systems[counts.index(min(counts))]
    start = generic_start(fs.ps, 1, {n: slots[n] for n in fs.ps.parameters})
    return fs, fs.ps.instantiate([start[n] for n in fs.ps.parameters]), counts


def _run(system, groups, paths: int, workers: int) -> dict:
    """The first `paths` paths of the split solve, in 4 chunks a worker, on a LocalCluster."""
    import numpy as np
    from distributed import LocalCluster

    from cotm_bertini.backends.dask_jobs import run_jobs
    from cotm_bertini.backends.homotopy import own_start, track_chunk

    lp, texts = own_start(system, groups, 1)
    sample = next(lp.chunks(paths))[:, lp.declared]  # made lazily, chunk by chunk
    jobs = [{"texts": texts, "points": c} for c in np.array_split(sample, 4 * workers)]
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster:  # fmt: skip
        t0 = time.perf_counter()
        done = [r for _, r in run_jobs(track_chunk, jobs, cluster.scheduler_address)]
        wall = time.perf_counter() - t0
    cpu = sum(r["cpu_seconds"] for r in done)
    return {"workers": workers, "paths": len(sample), "wall_s": wall, "cpu_s": cpu,
            "paths_per_s": len(sample) / wall, "paths_per_cpu_s": len(sample) / cpu,
            "retracked_adaptive": sum(r["retracked_adaptive"] for r in done),
            "finite": sum(sum(r["finite"]) for r in done),
            "load_avg_1min": os.getloadavg()[0]}  # fmt: skip


def main() -> None:
    """Print and write bench/results/scaleout_rate-<example>.csv, then the projection."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--example", default="prism4")
    ap.add_argument("--paths", type=int, default=96)
    ap.add_argument("--workers", nargs="*", type=int, default=[1, 2])
    ap.add_argument("--cores", type=int, default=8, help="cores a machine of the cluster")
    ap.add_argument("--machines", nargs="*", type=int, default=[10, 100])
    opts = ap.parse_args()
    fs, system, counts = _smallest_set(opts.example)
    from cotm_bertini.model.framework.compiled import variable_groups

    groups = variable_groups(fs)
    rows = [_run(system, groups, opts.paths, n) for n in opts.workers]
    frame = pd.DataFrame(rows)
    what = f"taut set {' '.join(fs.taut) or 'none'}"
    size = f"{len(system.variables)} unknowns, {min(counts):,} paths"
    print(f"\n{opts.example}: {what} ({size}), first {opts.paths} paths, {os.cpu_count()} cores")
    show("scale-out rate", frame, {"wall_s": ".1f", "cpu_s": ".1f", "paths_per_s": ".2f",
                                   "paths_per_cpu_s": ".2f"})  # fmt: skip
    write_csv(frame, f"scaleout_rate-{opts.example}")
    per_core = rows[-1]["paths"] / rows[-1]["cpu_s"]
    total = 2 * sum(counts)  # every taut set, two seeds (the total-degree route's evidence)
    print(f"\nprojection at {per_core:.2f} paths a CPU second (the last row): {total:,} paths")
    for m in opts.machines:
        hours = total / (per_core * m * opts.cores) / 3600
        years = hours / 24 / 365
        print(f"  {m} machines x {opts.cores} cores: {hours:,.0f} h ({years:,.1f} years)")


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    main()
