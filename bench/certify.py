"""Certification cost (issues 11, 17): the proof of each case against its own solve, and per
random geometry; the proof's parts (rows, equilibria, completeness) and, with --torus, the
earlier two-dimensional branch and bound for comparison; with --frameworks, the examples'
certificates (issue 19) and the 4-link chain's (tests/fixtures/chain4.toml, issue 46) against
their solves (the real route's search wherever it covers the framework, the `route` column).
Prints; asserts nothing.

Each solve is the homotopy engine's, generic set warm, no cache (what `certify case3` runs the
first time); each proof is cold (the parallel curve's cover is not reused between them).
Usage: .venv/bin/python bench/certify.py [--random 20] [--torus]
       .venv/bin/python bench/certify.py --frameworks [--only NAME ...] [--repeat 3]
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


def one(params, label: str, torus: bool) -> dict:
    """Solve (homotopy engine, no cache) and certify one parameter set, both timed."""
    from cotm_bertini.analysis.certify.mechanism import certify_table
    from cotm_bertini.analysis.certify.search import _cover
    from cotm_bertini.point import solve_point

    solve_point(params)  # warm: generic set and generated code loaded
    start = time.perf_counter()
    solved = solve_point(params)
    solve_s = time.perf_counter() - start
    _cover.cache_clear()
    cert = certify_table(params, solved.columns)
    row = {
        "geometry": label,
        "solve_s": solve_s,
        "certify_s": cert.seconds,
        "ratio": cert.seconds / solve_s,
        "rows_s": cert.timings["rows"],
        "complete_s": cert.timings["completeness"],
        "status": cert.status,
        "equilibria": cert.proved_equilibria,
        "rows_certified": int(cert.certified.sum()),
        "rows": len(cert.certified),
        "boxes": cert.boxes,
        "excluded": cert.excluded_boxes,
        "spring_bound_m": cert.shortest_spring,
    }
    if torus:
        old = certify_table(params, solved.columns, method="torus")
        row.update(torus_complete_s=old.timings["completeness"], torus_boxes=old.boxes,
                   torus_status=old.status)  # fmt: skip
    return row


FRAMEWORKS = {"zeeman": {"x": 0.1, "y": -0.25}, "zeeman_cables": {"x": 1.45, "y": 0.2},
              "double_pendulum": {}, "cotm": {}, "xmodule": {}, "chain3": {}, "chain4": {},
              "fourbar": {}}  # fmt: skip
ROOT = Path(__file__).resolve().parent.parent
# The examples, and the 4-link chain of issue 46 (a 4-torus: the certificate's hardest case).
FILES = {name: ROOT / "examples" / f"{name}.toml" for name in FRAMEWORKS} | {
    "chain4": ROOT / "tests" / "fixtures" / "chain4.toml"}  # fmt: skip


def one_framework(name: str, repeat: int = 1) -> dict:
    """Solve (generic sets warm, no cache) and certify one example framework, both timed: the
    fastest of `repeat` runs of each, taken in turn (the 2 cores are shared: the least loaded
    run is the nearest to each one's own cost)."""
    import cotm_bertini as cb
    from cotm_bertini.analysis.certify.framework import certify_framework_table
    from cotm_bertini.point import solve_framework_point
    from cotm_bertini.routes import choose
    from cotm_bertini.settings import Settings

    fw = cb.Framework.from_toml(FILES[name]).replace(**FRAMEWORKS[name])
    solve_framework_point(fw)  # warm: generic sets and generated code loaded
    solves, certs = [], []
    for _ in range(repeat):
        start = time.perf_counter()
        solved = solve_framework_point(fw)
        solves.append(time.perf_counter() - start)
        certs.append(certify_framework_table(fw, solved.columns))
    cert = min(certs, key=lambda c: c.seconds)
    return {
        "framework": name, "route": choose(fw, Settings()).route, "solve_s": min(solves),
        "certify_s": cert.seconds, "ratio": cert.seconds / min(solves),
        "rows_s": cert.timings["rows"], "complete_s": cert.timings["completeness"],
        "status": cert.status, "equilibria": cert.proved_equilibria,
        "rows_certified": int(cert.certified.sum()), "rows": len(cert.certified),
        "boxes": cert.boxes, "excluded": cert.excluded_boxes,
    }  # fmt: skip


def frameworks(names: list[str], repeat: int) -> None:
    """The examples' certificates against their solves."""
    table = pd.DataFrame([one_framework(n, repeat) for n in names or FRAMEWORKS])
    formats = {k: ".3f" for k in ("solve_s", "certify_s", "rows_s", "complete_s")}
    show("Frameworks: certification against the solve (seconds, 2 cores)", table,
         {**formats, "ratio": ".2f"})  # fmt: skip
    write_csv(table, "certify_frameworks")


def main() -> None:
    from test_stress import random_params

    from cotm_bertini.params import Params

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--random", type=int, default=20, help="random geometries to certify")
    ap.add_argument("--torus", action="store_true", help="also time the 2-D branch and bound")
    ap.add_argument("--frameworks", action="store_true", help="only the example frameworks")
    ap.add_argument("--only", nargs="*", default=[], choices=list(FRAMEWORKS),
                    help="with --frameworks: these frameworks only")  # fmt: skip
    ap.add_argument("--repeat", type=int, default=1,
                    help="with --frameworks: the fastest of this many runs of each")  # fmt: skip
    args = ap.parse_args()
    if args.frameworks:
        frameworks(args.only, args.repeat)
        return
    rows = [one(Params.case(case), case, args.torus) for case in ("case1", "case2", "case3")]
    rows += [one(random_params(s), f"random {s}", args.torus) for s in range(1, args.random + 1)]
    table = pd.DataFrame(rows)
    formats = {k: ".3f" for k in ("solve_s", "certify_s", "rows_s", "complete_s",
                                  "torus_complete_s")}  # fmt: skip
    formats.update(ratio=".2f", spring_bound_m=".3g")
    show("Certification against the solve (seconds, 2 cores)", table, formats)
    rand = table[table["geometry"].str.startswith("random")]
    if len(rand):
        print(
            f"random geometries: {int((rand['status'] == 'proved').sum())} of {len(rand)} proved; "
            f"certify mean {rand['certify_s'].mean():.2f} s, max {rand['certify_s'].max():.2f} s"
            f"; ratio to the solve: median {np.median(rand['ratio']):.2f}, max "
            f"{rand['ratio'].max():.2f}"
        )
    write_csv(table, "certify")


if __name__ == "__main__":
    main()
