"""Monodromy (issue 28) against the ab-initio generic solve, per system: the paper's cases 1-3
and the examples' first taut sets. For each: the current route (Bertini's total-degree or
multihomogeneous start, one ZeroDimSolver call, use_cache=False): its paths, wall and CPU
seconds, the generic count N; the monodromy route (backends/monodromy.py): the augmented
count N'', edges, paths tracked, wall and CPU seconds, trace test residual, whether complete
and whether its set equals the current route's (to 1e-8).

Usage: python bench/monodromy.py [--systems case1 case2 case3 zeeman double_pendulum]
[--seed 1]; add prism, cotm or fourbar for the larger examples (minutes each). CPU seconds
count every thread of the process (Bertini's ZeroDimSolver is multi-threaded, our paths run
on one): on a shared machine they are the fairer figure.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
from benchlib import BENCH, example_system, same_points, show, write_csv

ROOT = BENCH.parent
CASES = {"case1": (True, True), "case2": (False, True), "case3": (False, False)}
DEFAULT = ["case1", "case2", "case3", "zeeman", "double_pendulum"]


def _system(name: str):
    """(parametric system, start centre, variable groups or None) of a case or an example."""
    from cotm_bertini.backends.homotopy import START_CENTRE

    if name in CASES:
        from cotm_bertini.model.compiled import parametric_system

        return parametric_system(CASES[name]), START_CENTRE, None
    return example_system(name)


def _row(name: str, seed: int) -> dict:
    from cotm_bertini.backends.homotopy import generic_set
    from cotm_bertini.backends.monodromy import monodromy_generic

    ps, centre, groups = _system(name)
    t0 = time.perf_counter()
    gs = generic_set(ps, seed, use_cache=False, centre=centre, groups=groups)
    ab_initio = time.perf_counter() - t0
    m = monodromy_generic(ps, seed, centre)
    return {
        "system": name, "unknowns": len(ps.variables),
        "start": "multihomogeneous" if groups else "total degree",
        "ab_paths": gs.paths, "ab_s": ab_initio, "ab_cpu_s": gs.route.get("cpu_seconds"),
        "N": len(gs.points), "N_aug": m.augmented, "edges": m.edges,
        "mono_paths": m.paths, "mono_s": m.seconds, "mono_cpu_s": m.cpu_seconds,
        "trace_residual": m.trace_residual, "complete": m.complete,
        "failed_paths": m.failed_paths, "same_set": same_points(m.points, gs.points),
        "cpu_ratio": m.cpu_seconds / max(gs.route.get("cpu_seconds", np.nan), 1e-9),
        "load_avg_1min": os.getloadavg()[0],
    }  # fmt: skip


def main() -> None:
    """Print and write bench/results/monodromy.csv."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--systems", nargs="*", default=DEFAULT)
    ap.add_argument("--seed", type=int, default=1)
    opts = ap.parse_args()
    rows = []
    for name in opts.systems:
        rows.append(_row(name, opts.seed))
        print(rows[-1], file=sys.stderr, flush=True)
    frame = pd.DataFrame(rows)
    show(
        f"monodromy vs ab initio: generic set, seed {opts.seed}, {os.cpu_count()} cores",
        frame,
        {"trace_residual": ".1e", "ab_s": ".1f", "mono_s": ".1f", "cpu_ratio": ".2f"},
    )
    write_csv(frame, "monodromy")


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    main()
