"""The real route (issue 40): each torus example's first solve (a fresh cache: equations derived,
then the branch and bound) against a later one (derivations cached), end to end on the command
line, each the best of three; the search's boxes and CPU time a box; and the paper's cases 1-3
(cb.Params) by Bertini and by the real route, with the real route's proof against the
parallel-curve certificate. Usage: python bench/real_route.py [--skip NAME ...] [--map]
[--workers] (--map adds the X-module's 41 x 41 map over L0c and fy, workers=2; --workers
measures chain3's and the X-module's search in one process and over two instead)."""

from __future__ import annotations

import argparse
import os
import tempfile
import time

import numpy as np
import pandas as pd
from benchlib import BENCH, cli_seconds, show, write_csv

ROOT = BENCH.parent
EXAMPLES = {
    "xmodule": [],
    "chain3": [],
    "zeeman": ["--set", "x=0.1", "--set", "y=-0.25"],
    "zeeman_cables": ["--set", "x=1.45", "--set", "y=0.2"],
    "double_pendulum": [],
    "cotm": [],
}


def _search_cpu(fw) -> tuple[int, float, int]:
    """(boxes, CPU seconds of the search alone, roots), derivations warm."""
    from cotm_bertini.boxsearch.boxes import MIN_WIDTH, SHORT, search
    from cotm_bertini.boxsearch.real_route import TorusFramework

    land = TorusFramework(fw)
    _ = land.hessian_sets
    search(land, SHORT, MIN_WIDTH)  # warm numpy's caches
    c0 = time.process_time()
    found = search(land, SHORT, MIN_WIDTH)
    return found.boxes, time.process_time() - c0, len(found.roots)


def _row(name: str) -> dict:
    import cotm_bertini as cb

    args = ["solve", "--framework", str(ROOT / "examples" / f"{name}.toml"), *EXAMPLES[name]]
    # Best of three each, as the later solve always was: a first solve in a fresh cache every
    # time (one sample of 0.2 s on a shared machine is mostly noise).
    firsts = []
    for _ in range(3):
        env = {**os.environ, "COTM_CACHE": tempfile.mkdtemp(prefix="cotm-bench-real-")}
        firsts.append(cli_seconds(args, env))
    first = min(firsts)
    later = min(cli_seconds(args, env) for _ in range(3))
    os.environ["COTM_CACHE"] = env["COTM_CACHE"]
    fw = cb.Framework.from_toml(ROOT / "examples" / f"{name}.toml")
    sets = dict(a.split("=") for a in EXAMPLES[name][1::2])
    fw = fw.replace(**{k: float(v) for k, v in sets.items()})
    res = cb.solve(fw, route="real", cache=False)
    boxes, cpu, _ = _search_cpu(fw)
    return {"example": name, "first_solve_s": first, "later_solve_s": later,
            "first_over_later": first / later, "slowest_first_s": max(firsts), "boxes": boxes,
            "search_cpu_s": cpu,
            "us_per_box": 1e6 * cpu / boxes, "physical": res.counts["physical"],
            "stable": res.counts["stable"], "status": res.status}  # fmt: skip


def _best(run, repeat: int = 3):
    """(the result of `run`, its shortest wall-clock seconds over `repeat` calls)."""
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = run()
        best = min(best, time.perf_counter() - t0)
    return out, best


def _paper(case: str) -> dict:
    """The paper's case by Bertini (generic set warm) and by the real route (derivations warm),
    each end to end in cb.solve; the real route's proof (its search) against the paper's
    parallel-curve certificate and the two-dimensional ball branch and bound of the same torus;
    and each route's first solve on the command line with a fresh cache."""
    import cotm_bertini as cb
    from cotm_bertini.analysis.certify.mechanism import certify_table

    p = cb.Params.case(case)
    bert, t_bert = _best(lambda: cb.solve(p, cache=False))
    real, t_real = _best(lambda: cb.solve(p, route="real", cache=False))
    a = bert.physical[["gamma1_deg", "gamma2_deg"]].to_numpy(float)
    b = real.physical[["gamma1_deg", "gamma2_deg"]].to_numpy(float)
    gap = float(np.abs((a - b + 180) % 360 - 180).max()) if a.shape == b.shape else float("nan")
    search = real.record["details"]["real_search"]
    rows = bert.table.reset_index(drop=True)  # by position, as cb.certify passes them
    curve, t_curve = _best(lambda: certify_table(p, rows))
    torus, _ = _best(lambda: certify_table(p, rows, method="torus"), 1)
    env = {**os.environ, "COTM_CACHE": tempfile.mkdtemp(prefix="cotm-bench-paper-")}
    first_real = cli_seconds(["solve", case, "--route", "real"], env)
    first_bert = cli_seconds(["solve", case], env)
    return {"case": case, "physical": f"{len(a)} / {len(b)}", "max_gap_deg": gap,
            "bertini_s": t_bert, "real_s": t_real, "real_boxes": search["boxes"],
            "real_search_s": search["seconds"], "curve_cert_s": t_curve,
            "curve_complete_s": curve.timings["completeness"], "curve_boxes": curve.boxes,
            "torus_cert_complete_s": torus.timings["completeness"], "torus_boxes": torus.boxes,
            "first_real_cli_s": first_real, "first_bertini_cli_s": first_bert}  # fmt: skip


def _xmodule_map() -> dict:
    import cotm_bertini as cb

    fw = cb.Framework.from_toml(ROOT / "examples" / "xmodule.toml")
    t0 = time.perf_counter()
    m = cb.design_map(fw, "L0c", (1.0, 1.6), "fy", (-0.2, 0.0), points=41, workers=2)
    spent = m.record["timings"]
    return {"map_41x41_s": time.perf_counter() - t0, "fold_curves_s": spent["folds"],
            "grid_s": spent["regions"], "status": m.status}  # fmt: skip


def _shared(name: str, workers: int, repeat: int = 3) -> dict:
    """The search of `name` shared over `workers` local processes (boxsearch.box_shares), warm
    (derivations cached, the landscape built): best wall of `repeat`, with that run's CPU in
    every process; and the CLI solve end to end with --workers (best of `repeat`)."""
    import cotm_bertini as cb
    from cotm_bertini.boxsearch.box_shares import split_search
    from cotm_bertini.boxsearch.boxes import MIN_WIDTH, SHORT
    from cotm_bertini.boxsearch.real_route import landscape

    fw = cb.Framework.from_toml(ROOT / "examples" / f"{name}.toml")
    landscape(fw).hessian_sets  # noqa: B018 (derived here, not in the search's clock)
    runs = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        found = split_search(landscape, fw, SHORT, MIN_WIDTH, workers=workers)
        runs.append((time.perf_counter() - t0, found))
    wall, found = min(runs, key=lambda r: r[0])
    largest = _largest_share_cpu(landscape(fw), found.shares) if workers > 1 else found.cpu_seconds
    args = ["solve", "--framework", str(ROOT / "examples" / f"{name}.toml"), "--workers",
            str(workers)]  # fmt: skip
    solve = min(cli_seconds(args, dict(os.environ)) for _ in range(repeat))
    return {"example": name, "workers": workers, "shares": found.shares, "boxes": found.boxes,
            "roots": len(found.roots), "search_wall_s": wall, "search_cpu_s": found.cpu_seconds,
            "boxes_per_s_wall": found.boxes / wall,
            "boxes_per_cpu_s": found.boxes / found.cpu_seconds, "largest_share_cpu_s": largest,
            "cli_solve_s": solve,
            "load_avg_1min": os.getloadavg()[0]}  # fmt: skip


def _largest_share_cpu(land, shares: int) -> float:
    """The CPU of the largest of `shares` round-robin shares of the start boxes, each searched
    here alone (best of 3): the wall time the shared search would take on free cores."""
    from cotm_bertini.boxsearch.boxes import MIN_WIDTH, SHORT, domain, search

    lo, hi = domain(land, 8)
    best = []
    for k in range(shares):
        runs = []
        for _ in range(3):
            c0 = time.process_time()
            search(land, SHORT, MIN_WIDTH, boxes=(lo[k::shares], hi[k::shares]))
            runs.append(time.process_time() - c0)
        best.append(min(runs))
    return max(best)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--skip", nargs="*", default=[])
    ap.add_argument("--map", action="store_true")
    ap.add_argument("--workers", action="store_true", help="chain3 and the X-module: 1 and 2")
    args = ap.parse_args()
    if args.workers:
        frame = pd.DataFrame([_shared(n, w) for n in ("chain3", "xmodule") for w in (1, 2)])
        show("real route: the search in one process and shared over two", frame,
             {"search_wall_s": ".3f", "search_cpu_s": ".3f", "boxes_per_s_wall": ",.0f",
              "boxes_per_cpu_s": ",.0f", "largest_share_cpu_s": ".3f", "cli_solve_s": ".2f",
              "load_avg_1min": ".1f"})  # fmt: skip
        write_csv(frame, "real_route_workers")
        return
    rows = [_row(n) for n in EXAMPLES if n not in args.skip]
    frame = pd.DataFrame(rows)
    show("real route: first solve against a later one, the search's boxes", frame,
         {"first_solve_s": ".2f", "later_solve_s": ".2f", "first_over_later": ".2f",
          "slowest_first_s": ".2f",
          "search_cpu_s": ".3f", "us_per_box": ".1f"})  # fmt: skip
    if len(frame):  # every example skipped: an earlier run's table is kept
        write_csv(frame, "real_route")
    paper = pd.DataFrame([_paper(case) for case in ("case1", "case2", "case3")])
    show(
        "the paper's cases: Bertini against the real route, and their proofs",
        paper,
        {c: ".3f" for c in paper.columns if c.endswith("_s")} | {"max_gap_deg": ".1e"},
    )
    write_csv(paper, "real_route_paper")
    if args.map:
        show("the X-module's 41 x 41 map", pd.DataFrame([_xmodule_map()]))


if __name__ == "__main__":
    main()
