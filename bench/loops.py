"""Closed loops (four-bars) on the real route against the complex route, in one run.

For each file: the first solve in a fresh cache (a process of its own: the derivation, the
search and the rows, as a user's first `solve` pays them), then a later solve (same process,
the derivation cached, no result cache), on the real route (the default) and, with
`--complex`, on the complex route (its first solve tracks every path of its generic sets).
Rows, kinds and the status side by side; the largest pose difference between the routes. Then
the command line end to end (process start included): the first solve in a fresh cache and
the median of three later ones.

Benchmarks, not tests: nothing is asserted; figures are printed and written to
bench/results/loops.csv.
Usage: .venv/bin/python bench/loops.py [--complex] [FILE ...]
"""

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
from benchlib import show, write_csv

ROOT = Path(__file__).resolve().parents[1]
FILES = ("tests/fixtures/fourbar_springs.toml", "examples/fourbar.toml")
ONE = """
import json, sys, time
import cotm_bertini as cb
fw = cb.Framework.from_toml(sys.argv[1])
out = {}
for when in ("first", "later"):
    t = time.perf_counter()
    res = cb.solve(fw, route=sys.argv[2], cache=False)
    out[when] = time.perf_counter() - t
cols = ["crank.angle_deg", "coupler.angle_deg", "rocker.angle_deg"]
ph = res.physical.sort_values(cols[0])
out.update(status=res.status, rows=len(ph), kinds=" ".join(ph["kind"]),
           poses=ph[cols].to_numpy(float).tolist(), boxes=res.counts.get("boxes"))
print(json.dumps(out))
"""


def measure(path: str, route: str) -> dict:
    """First and later solve of `path` on `route`, in a fresh process with a fresh cache."""
    with tempfile.TemporaryDirectory(prefix="bench-loops-") as cache:
        env = {**os.environ, "COTM_CACHE": cache}
        proc = subprocess.run([sys.executable, "-c", ONE, str(ROOT / path), route], env=env,
                              capture_output=True, text=True, check=True)  # fmt: skip
    return json.loads(proc.stdout.strip().splitlines()[-1])


def command_line(path: str, repeats: int = 3) -> dict:
    """`cotm-bertini solve --framework FILE --no-cache --no-plots` end to end (process start
    included), as a user runs it: the first in a fresh cache, then the median of `repeats`."""
    exe = str(Path(sys.executable).with_name("cotm-bertini"))
    with tempfile.TemporaryDirectory(prefix="bench-loops-") as cache:
        env = {**os.environ, "COTM_CACHE": cache}
        args = [exe, "solve", "--framework", str(ROOT / path), "--no-cache", "--no-plots",
                "--quiet", "--out", str(Path(cache) / "runs")]  # fmt: skip
        walls = []
        for _ in range(1 + repeats):
            start = time.perf_counter()
            subprocess.run(args, env=env, capture_output=True, check=True)
            walls.append(time.perf_counter() - start)
    later = sorted(walls[1:])[len(walls[1:]) // 2]
    return {"file": Path(path).name, "first_s": walls[0], "later_s": later,
            "first/later": walls[0] / later}  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="*", default=list(FILES))
    ap.add_argument("--complex", action="store_true", help="the complex route too (minutes)")
    args = ap.parse_args()
    rows = []
    for path in args.files:
        got = {r: measure(path, r) for r in (("real", "complex") if args.complex else ("real",))}
        for route, m in got.items():
            gap = None
            if route == "complex" and m["rows"] == got["real"]["rows"]:
                diff = [
                    abs((a - b + 180) % 360 - 180)
                    for p, q in zip(m["poses"], got["real"]["poses"], strict=True)
                    for a, b in zip(p, q, strict=True)
                ]
                gap = max(diff, default=0.0)  # fmt: skip
            rows.append({"file": Path(path).name, "route": route, "first_s": m["first"],
                         "later_s": m["later"], "first/later": m["first"] / m["later"],
                         "boxes": m["boxes"], "status": m["status"], "rows": m["rows"],
                         "kinds": m["kinds"], "max_angle_gap_deg": gap})  # fmt: skip
    frame = pd.DataFrame(rows)
    show("closed loops: first and later solve, real and complex routes", frame, {})
    write_csv(frame, "loops")
    cli = pd.DataFrame([command_line(path) for path in args.files])
    show("the command line, end to end (real route)", cli, {})
    write_csv(cli, "loops_cli")
    print(json.dumps({"files": args.files, "complex": args.complex}))


if __name__ == "__main__":
    main()
