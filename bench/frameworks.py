"""Frameworks (issue 18): each example's first solve (generic sets from scratch, in a fresh
cache) and a later one, paths, and the paper's mechanism from cotm.toml against the built-in
model, and the barriers of each solve (cb.barriers, issue 19). Usage: python
bench/frameworks.py [--skip NAME ...] [--generic ROUTE] (the prism takes minutes); ROUTE:
monodromy, total-degree or both (default: the package's default route), the same for every
solve of the run; the ratio first / later solve is the issue 28 target (<= 5)."""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd
from benchlib import BENCH, cli_seconds, show, write_csv

ROOT = BENCH.parent
CLI = str(Path(sys.executable).with_name("cotm-bertini"))
EXAMPLES = {
    "zeeman": ["--set", "x=0.1", "--set", "y=-0.25"],
    "zeeman_cables": ["--set", "x=1.45", "--set", "y=0.2"],
    "cotm": [],
    "double_pendulum": [],
    "fourbar": [],
    "prism": [],
}


def _row(name: str, env: dict, route: str | None) -> dict:
    import cotm_bertini as cb

    args = ["solve", "--framework", str(ROOT / "examples" / f"{name}.toml"), *EXAMPLES[name]]
    args += ["--generic", route] if route else []
    first = cli_seconds(args, env)
    later = min(cli_seconds(args, env) for _ in range(3))
    os.environ["COTM_CACHE"] = env["COTM_CACHE"]
    fw = cb.Framework.from_toml(ROOT / "examples" / f"{name}.toml")
    sets = dict(a.split("=") for a in EXAMPLES[name][1::2])
    res = cb.solve(fw.replace(**{k: float(v) for k, v in sets.items()}),
                   settings=cb.Settings(generic=route))  # fmt: skip
    c = res.counts
    t0 = time.perf_counter()
    found = cb.barriers(res)  # every index-1 saddle's two descents (issue 19)
    barriers_s = time.perf_counter() - t0
    return {"example": name, "route": route or "default", "first_solve_s": first,
            "later_solve_s": later, "first_over_later": first / later,
            "generic_paths": c["generic_paths"], "paths_tracked": c["paths_tracked"],
            "physical": c["physical"], "stable": c["stable"], "status": res.status,
            "morse": res.morse.get("manifold", "n/a"), "barriers_s": barriers_s,
            "saddles": len(found.table), "pairs_joined": len(found.pairs),
            "barrier_warnings": len(found.warnings)}  # fmt: skip


def main() -> None:
    """Print and write bench/results/frameworks.csv."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--skip", nargs="*", default=[])
    ap.add_argument("--generic", choices=("monodromy", "total-degree", "both"))
    opts = ap.parse_args()
    env = {**os.environ, "COTM_CACHE": tempfile.mkdtemp(prefix="cotm-bench-fw-")}
    rows = []
    for name in EXAMPLES:
        if name not in opts.skip:
            rows.append(_row(name, env, opts.generic))
            print(rows[-1], file=sys.stderr, flush=True)
    builtin = min(cli_seconds(["solve", "case3"], env) for _ in range(3))
    frame = pd.DataFrame(rows)
    show("frameworks: CLI solve, end to end (s); cb.barriers of the solve (s)", frame,
         {"first_solve_s": ".1f", "first_over_later": ".1f", "barriers_s": ".2f"})  # fmt: skip
    print(f"\nbuilt-in `solve case3` (same run, cached generic set): {builtin:.2f} s; "
          f"cotm.toml later solve / built-in: "
          f"{frame.set_index('example').loc['cotm', 'later_solve_s'] / builtin:.1f}x"
          if "cotm" in frame["example"].values else "")  # fmt: skip
    write_csv(frame, "frameworks")


if __name__ == "__main__":
    main()
