"""Certification cost (issue 11): the proof of each case against its solve, and per random
geometry. Prints; asserts nothing.

Usage: .venv/bin/python bench/certify.py [--random 20]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
from benchlib import show, write_csv

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests" / "stress"))


def one(params, label: str) -> dict:
    """Solve (homotopy engine, no cache) and certify one parameter set, both timed."""
    from cotm_bertini.analysis.certify import certify_table
    from cotm_bertini.point import solve_point

    solve_point(params)  # warm: generic set and generated code loaded
    start = time.perf_counter()
    solved = solve_point(params)
    solve_s = time.perf_counter() - start
    cert = certify_table(params, solved.columns)
    return {
        "geometry": label,
        "solve_s": solve_s,
        "certify_s": cert.seconds,
        "ratio": cert.seconds / solve_s,
        "status": cert.status,
        "equilibria": cert.proved_equilibria,
        "rows_certified": int(cert.certified.sum()),
        "rows": len(cert.certified),
        "boxes": cert.boxes,
        "excluded": cert.excluded_boxes,
        "spring_bound_m": cert.shortest_spring,
    }


def main() -> None:
    from test_stress import random_params

    from cotm_bertini.params import Params

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--random", type=int, default=20, help="random geometries to certify")
    args = ap.parse_args()
    rows = [one(Params.case(case), case) for case in ("case1", "case2", "case3")]
    rows += [one(random_params(seed), f"random {seed}") for seed in range(1, args.random + 1)]
    table = pd.DataFrame(rows)
    formats = {"solve_s": ".3f", "certify_s": ".3f", "ratio": ".1f", "spring_bound_m": ".3g"}
    show("Certification against the solve (seconds, 2 cores)", table, formats)
    rand = table[table["geometry"].str.startswith("random")]
    if len(rand):
        print(
            f"random geometries: {int((rand['status'] == 'proved').sum())} of {len(rand)} proved; "
            f"certify mean {rand['certify_s'].mean():.2f} s, max {rand['certify_s'].max():.2f} s"
            f"; median ratio to the solve {np.median(rand['ratio']):.1f}"
        )
    write_csv(table, "certify")


if __name__ == "__main__":
    main()
