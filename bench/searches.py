"""The real route's search on every shipped framework it covers and the collapsing chains: boxes,
seconds, roots, cone points and boxes per equilibrium, one process each (`search`, no shares),
derivations warm. With --dump FILE the roots go to a JSON file; with --against FILE (a dump made
by another version of the package: `PYTHONPATH=<its checkout> python bench/searches.py --dump`)
each example's roots are matched to those (angles to 1e-8 rad, mod 2 pi) and both versions'
boxes printed side by side. With --stable each example is searched twice in the same run, for
every critical point and for the minima alone (`only="stable"`), and the minima compared.
Usage: python bench/searches.py [--only NAME ...] [--budget S] [--dump FILE] [--against FILE]
[--stable]."""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import pandas as pd
from benchlib import BENCH, show, write_csv

ROOT = BENCH.parent
FILES = {
    "xmodule": "examples/xmodule.toml",
    "chain3": "examples/chain3.toml",
    "zeeman": "examples/zeeman.toml",
    "zeeman_cables": "examples/zeeman_cables.toml",
    "double_pendulum": "examples/double_pendulum.toml",
    "cotm": "examples/cotm.toml",
    "chain4": "tests/fixtures/chain4.toml",
    "chain3_collapse": "tests/fixtures/chain3_collapse.toml",
    "chain4_collapse": "tests/fixtures/chain4_collapse.toml",
    "prism": "examples/prism.toml",
    "prism_slack": "examples/prism_slack.toml",
    "prism_saddle": "tests/fixtures/prism_saddle.toml",
    "prism4": "examples/prism4.toml",
    "tower": "examples/tower.toml",
}
SETS = {"zeeman": {"x": 0.1, "y": -0.25}, "zeeman_cables": {"x": 1.45, "y": 0.2}}


def run(name: str, budget: float, only: str = "all") -> tuple[dict, np.ndarray]:
    """One example's search (for `only`: "all" critical points, or the "stable" ones): its row
    of the table, and its roots."""
    import cotm_bertini as cb
    from cotm_bertini.boxsearch.boxes import MIN_WIDTH, SHORT, search
    from cotm_bertini.boxsearch.real_route import new_landscape

    fw = cb.Framework.from_toml(ROOT / FILES[name])
    if name in SETS:
        fw = fw.replace(**SETS[name])
    land = new_landscape(fw)
    land.only = only
    search(land, SHORT, MIN_WIDTH, max_boxes=2000)  # derive and compile the code first
    t0 = time.perf_counter()
    found = search(land, SHORT, MIN_WIDTH, max_seconds=budget)
    seconds = time.perf_counter() - t0
    cones = len(getattr(found, "cones", ()))
    points = len(found.roots) + cones
    return {
        "example": name, "angles": land.n, "seconds": seconds, "boxes": found.boxes,
        "roots": len(found.roots), "cone_points": cones, "set_aside": found.set_aside,
        "undecided_share": found.undecided_share, "boxes_per_point": found.boxes / max(points, 1),
        "proved": not found.budget_hit and not len(found.undecided),
    }, found.roots  # fmt: skip


def minima(name: str, roots: np.ndarray) -> np.ndarray:
    """The roots where the Hessian (double precision) is positive definite."""
    import cotm_bertini as cb
    from cotm_bertini.boxsearch.real_route import new_landscape

    fw = cb.Framework.from_toml(ROOT / FILES[name])
    if not len(roots):
        return roots
    H = new_landscape(fw.replace(**SETS.get(name, {}))).derivatives(roots)[1]
    return roots[np.linalg.eigvalsh(H)[:, 0] > 0]


def stable_row(name: str, budget: float) -> dict:
    """Both searches of one example, same run: boxes, seconds, minima, and whether the minima
    agree (the stable search's roots may hold a few saddles the Hessian test could not drop:
    the solve proves each root and drops those)."""
    full, roots = run(name, budget)
    only, kept = run(name, budget, "stable")
    a, b = minima(name, roots), minima(name, kept)
    return {"example": name, "angles": full["angles"], "boxes_all": full["boxes"],
            "seconds_all": full["seconds"], "boxes_stable": only["boxes"],
            "seconds_stable": only["seconds"], "minima": len(a), "roots_stable": len(kept),
            "same_minima": same_roots(a, b) if full["proved"] and only["proved"] else None,
            "box_ratio": only["boxes"] / max(full["boxes"], 1)}  # fmt: skip


def same_roots(a: np.ndarray, b: np.ndarray, apart: float = 1e-8) -> bool:
    """Whether two root sets are equal (each root of one within `apart` rad of one of the
    other, angles mod 2 pi)."""
    if len(a) != len(b):
        return False
    if not len(a):
        return True
    gap = np.abs((a[:, None, :] - b[None, :, :] + np.pi) % (2 * np.pi) - np.pi).max(axis=2)
    return bool((gap.min(axis=1) < apart).all() and (gap.min(axis=0) < apart).all())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="*", choices=sorted(FILES), default=None)
    ap.add_argument("--budget", type=float, default=120.0, help="seconds, each example")
    ap.add_argument("--dump", type=Path, help="write the roots here (JSON)")
    ap.add_argument("--against", type=Path, help="a dump of another version to compare with")
    ap.add_argument("--stable", action="store_true", help="every critical point, then minima")
    args = ap.parse_args()
    if args.stable:
        frame = pd.DataFrame([stable_row(n, args.budget) for n in args.only or FILES])
        show("all critical points against the minima alone, one process", frame,
             {"seconds_all": ".2f", "seconds_stable": ".2f", "box_ratio": ".3f"})  # fmt: skip
        write_csv(frame, "searches_stable")
        return
    other = json.loads(args.against.read_text()) if args.against else {}
    rows, dump = [], {}
    for name in args.only or FILES:
        row, roots = run(name, args.budget)
        dump[name] = {"roots": roots.tolist(), "boxes": row["boxes"], "proved": row["proved"]}
        if name in other:
            row["other_boxes"] = other[name]["boxes"]
            both = row["proved"] and other[name]["proved"]
            row["same_roots"] = same_roots(roots, np.array(other[name]["roots"])) if both else None
        rows.append(row)
        print(row, flush=True)
    if args.dump:
        args.dump.write_text(json.dumps(dump))
    frame = pd.DataFrame(rows)
    show("the real route's search, one process", frame, {"seconds": ".2f"})
    write_csv(frame, "searches")


if __name__ == "__main__":
    main()
