"""The real route (issue 40): each torus example's first solve (a fresh cache: equations derived
with sympy, then the branch and bound) against a later one (derivations cached), end to end on
the command line; the search's boxes and CPU time a box; and the paper's case 3 from cotm.toml
against the built-in model's Bertini solve. Usage: python bench/real_route.py [--skip NAME ...]
[--map] (--map adds the X-module's 41 x 41 map over L0c and fy, workers=2)."""

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
    from cotm_bertini.backends.boxes import MIN_WIDTH, SHORT, search
    from cotm_bertini.backends.real_route import TorusFramework

    land = TorusFramework(fw)
    _ = land.hessian_sets
    search(land, SHORT, MIN_WIDTH)  # warm numpy's caches
    c0 = time.process_time()
    found = search(land, SHORT, MIN_WIDTH)
    return found.boxes, time.process_time() - c0, len(found.roots)


def _row(name: str) -> dict:
    import cotm_bertini as cb

    env = {**os.environ, "COTM_CACHE": tempfile.mkdtemp(prefix="cotm-bench-real-")}
    args = ["solve", "--framework", str(ROOT / "examples" / f"{name}.toml"), *EXAMPLES[name]]
    first = cli_seconds(args, env)
    later = min(cli_seconds(args, env) for _ in range(3))
    os.environ["COTM_CACHE"] = env["COTM_CACHE"]
    fw = cb.Framework.from_toml(ROOT / "examples" / f"{name}.toml")
    sets = dict(a.split("=") for a in EXAMPLES[name][1::2])
    fw = fw.replace(**{k: float(v) for k, v in sets.items()})
    res = cb.solve(fw, route="real", cache=False)
    boxes, cpu, _ = _search_cpu(fw)
    return {"example": name, "first_solve_s": first, "later_solve_s": later,
            "first_over_later": first / later, "boxes": boxes, "search_cpu_s": cpu,
            "us_per_box": 1e6 * cpu / boxes, "physical": res.counts["physical"],
            "stable": res.counts["stable"], "status": res.status}  # fmt: skip


def _paper_case3() -> dict:
    """cotm.toml by the real route against the built-in model (Bertini), same run."""
    import cotm_bertini as cb

    p = cb.Params.case("case3")
    t0 = time.perf_counter()
    paper = cb.solve(p, cache=False)
    t_paper = time.perf_counter() - t0
    fw = cb.Framework.from_toml(ROOT / "examples" / "cotm.toml")
    t0 = time.perf_counter()
    real = cb.solve(fw, route="real", cache=False)
    t_real = time.perf_counter() - t0
    a = np.sort(paper.physical[["gamma1_deg", "gamma2_deg"]].to_numpy(float), axis=0)
    b = np.sort(real.physical[["rod.angle_deg", "top.angle_deg"]].to_numpy(float), axis=0)
    gap = float(np.abs(a - b).max()) if a.shape == b.shape else float("nan")
    return {"paper_case3_bertini_s": t_paper, "cotm_toml_real_s": t_real,
            "physical": f"{len(a)} / {len(b)}", "max_angle_gap_deg": gap}  # fmt: skip


def _xmodule_map() -> dict:
    import cotm_bertini as cb

    fw = cb.Framework.from_toml(ROOT / "examples" / "xmodule.toml")
    t0 = time.perf_counter()
    m = cb.design_map(fw, "L0c", (1.0, 1.6), "fy", (-0.2, 0.0), points=41, workers=2)
    spent = m.record["timings"]
    return {"map_41x41_s": time.perf_counter() - t0, "fold_curves_s": spent["folds"],
            "grid_s": spent["regions"], "status": m.status}  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--skip", nargs="*", default=[])
    ap.add_argument("--map", action="store_true")
    args = ap.parse_args()
    rows = [_row(n) for n in EXAMPLES if n not in args.skip]
    frame = pd.DataFrame(rows)
    show("real route: first solve against a later one, the search's boxes", frame,
         {"first_solve_s": ".2f", "later_solve_s": ".2f", "first_over_later": ".2f",
          "search_cpu_s": ".3f", "us_per_box": ".1f"})  # fmt: skip
    write_csv(frame, "real_route")
    show(
        "the paper's case 3: built-in model (Bertini) and cotm.toml (real route)",
        pd.DataFrame([_paper_case3()]),
    )
    if args.map:
        show("the X-module's 41 x 41 map", pd.DataFrame([_xmodule_map()]))


if __name__ == "__main__":
    main()
