"""Rigid bodies turning in space (SO(3) on the real route) against the complex route, in one run.

For each file: the first solve in a fresh cache (a process of its own: the derivation, the
search and the rows, as a user's first `solve` pays them), then a later solve (same process,
the derivation cached, no result cache), on the real route (the default) and, with
`--complex`, on the complex route (its first solve tracks every path of its generic set: about
16 minutes for examples/ball_joint.toml). Rows, kinds, boxes and the status side by side; the
largest quaternion difference between the routes (q and -q one rotation). With `--chain S`,
the two-body chain (ball joint, then ball joint: six chart coordinates) with a timeout of S
seconds: what the search decided, and the rows it found.

Benchmarks, not tests: nothing is asserted; figures are printed and written to
bench/results/rotations.csv.
Usage: .venv/bin/python bench/rotations.py [--complex] [--chain SECONDS] [FILE ...]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
from benchlib import show, write_csv

ROOT = Path(__file__).resolve().parents[1]
FILES = ("examples/ball_joint.toml",)
CHAIN = "tests/fixtures/ball_ball_chain.toml"
ONE = """
import json, sys, time
import cotm_bertini as cb
fw = cb.Framework.from_toml(sys.argv[1])
timeout = float(sys.argv[3]) or None
out = {}
for when in ("first", "later")[: 1 if timeout else 2]:
    t = time.perf_counter()
    res = cb.solve(fw, route=sys.argv[2], cache=False, timeout=timeout)
    out[when] = time.perf_counter() - t
qs = [c for c in res.physical.columns if c[-3:-1] == ".q"]
ph = res.physical.sort_values("energy")
out.update(status=res.status, rows=len(ph), kinds=" ".join(ph["kind"]),
           quaternions=ph[qs].to_numpy(float).tolist(), boxes=res.counts.get("boxes"),
           warnings=res.warnings)
print(json.dumps(out))
"""


def measure(path: str, route: str, timeout: float = 0.0) -> dict:
    """First and later solve of `path` on `route`, in a fresh process with a fresh cache (the
    first alone, with a timeout, where `timeout` is given)."""
    with tempfile.TemporaryDirectory(prefix="bench-rotations-") as cache:
        env = {**os.environ, "COTM_CACHE": cache}
        proc = subprocess.run([sys.executable, "-c", ONE, str(ROOT / path), route, str(timeout)],
                              env=env, capture_output=True, text=True, check=True)  # fmt: skip
    return json.loads(proc.stdout.strip().splitlines()[-1])


def gap(a: list, b: list) -> float | None:
    """The largest difference between two routes' rows' quaternions, each body's sign free."""
    if len(a) != len(b):
        return None
    a, b = np.asarray(a).reshape(len(a), -1, 4), np.asarray(b).reshape(len(b), -1, 4)
    return float(np.minimum(np.abs(a - b), np.abs(a + b)).max(initial=0.0))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="*", default=list(FILES))
    ap.add_argument("--complex", action="store_true", help="the complex route too (minutes)")
    ap.add_argument("--chain", type=float, default=0.0, help="the two-body chain, this timeout")
    args = ap.parse_args()
    rows = []
    for path in args.files:
        got = {r: measure(path, r) for r in (("real", "complex") if args.complex else ("real",))}
        for route, m in got.items():
            rows.append({"file": Path(path).name, "route": route, "first_s": m["first"],
                         "later_s": m["later"], "boxes": m["boxes"], "status": m["status"],
                         "rows": m["rows"], "kinds": m["kinds"],
                         "max_quaternion_gap": gap(m["quaternions"], got["real"]["quaternions"])
                         if route != "real" else None})  # fmt: skip
    if args.chain:
        m = measure(CHAIN, "real", args.chain)
        rows.append({"file": Path(CHAIN).name, "route": f"real, timeout {args.chain:g} s",
                     "first_s": m["first"], "later_s": None, "boxes": m["boxes"],
                     "status": m["status"], "rows": m["rows"], "kinds": m["kinds"],
                     "max_quaternion_gap": None})  # fmt: skip
        print("\n".join(m["warnings"]))
    frame = pd.DataFrame(rows)
    show("bodies in space: first and later solve, real and complex routes", frame, {})
    write_csv(frame, "rotations")
    print(json.dumps({"files": args.files, "complex": args.complex, "chain": args.chain}))


if __name__ == "__main__":
    main()
