"""Benchmark: the paper's sweep (L01 0..12 m, 241 points) against fresh bertini2 solves.

Prints wall time per sweep point (parameter homotopy, local processes) and the time of a fresh
total-degree `bertini2` solve per point, measured in the same run on a sample of points, and the
ratio. Usage: .venv/bin/python bench/sweep.py [--points 241] [--workers N] [--fresh 5]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from cotm_bertini.params import TABLE1, make_params
from cotm_bertini.pipeline import solve_in
from cotm_bertini.settings import Settings
from cotm_bertini.sweep import SweepSpec, default_workers, prepare, run_points, warm_generic_sets


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--points", type=int, default=241)
    ap.add_argument("--workers", type=int, default=default_workers())
    ap.add_argument("--fresh", type=int, default=5, help="fresh bertini2 solves to time")
    args = ap.parse_args()

    spec = SweepSpec(dict(TABLE1), "L01", 0.0, 12.0, args.points)
    with tempfile.TemporaryDirectory(prefix="bench-sweep-") as tmp:
        t0 = time.perf_counter()
        warm_generic_sets(spec)  # cached on disk after the first run
        t_generic = time.perf_counter() - t0
        folder = prepare(spec, Path(tmp))
        stats = run_points(spec, folder, workers=args.workers)
    per_point = stats["seconds"] / stats["solved"]

    fresh = []
    for v in np.linspace(0.5, 12.0, args.fresh):
        params = make_params(None, {**TABLE1, "L01": float(v)})
        with tempfile.TemporaryDirectory(prefix="bench-fresh-") as tmp:
            t = time.perf_counter()
            solve_in(Path(tmp) / "run", params, Settings(seed=1, engine="cli"))
            fresh.append(time.perf_counter() - t)
    fresh_mean = float(np.mean(fresh))

    print(f"paper sweep: {stats['solved']} points, {args.workers} workers")
    print(f"  generic solution set (once, then cached): {t_generic:.2f} s")
    print(f"  sweep wall time:                {stats['seconds']:8.2f} s   (target < 60 s)")
    print(f"  per point (wall / points):      {per_point * 1e3:8.1f} ms")
    print(f"  lost paths:                     {stats['lost_paths']:8d}")
    print(
        f"  fresh bertini2 solve per point: {fresh_mean * 1e3:8.1f} ms "
        f"(mean of {len(fresh)}, full pipeline, 2 threads)"
    )
    print(f"  ratio fresh / sweep point:      {fresh_mean / per_point:8.1f} x  (target >= 10 x)")


if __name__ == "__main__":
    main()
