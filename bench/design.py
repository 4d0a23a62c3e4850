"""Design maps (issue 10): the fold curves of the paper plane, the time per fold point, the
design map's grid of direct solves, and the energy barriers of cases 1-3.

Benchmarks, not tests: nothing is asserted; the target (fold curves of the paper plane in under
60 s on 2 cores) is printed beside the measurement.
Usage: .venv/bin/python bench/design.py [--points N]
"""

from __future__ import annotations

import argparse
import contextlib
import os
import tempfile
import time
from pathlib import Path

import cotm_bertini as cb


def main() -> None:
    from cotm_bertini.analysis.certify.curve import certify_samples
    from cotm_bertini.catastrophe.paper_folds import _grid, parallel_samples

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=41, help="grid points a side of the map")
    ap.add_argument("--zeeman-points", type=int, default=101, help="Zeeman map grid a side")
    ap.add_argument("--zeeman-only", action="store_true", help="only the Zeeman map")
    ap.add_argument("--folds-only", action="store_true", help="only the frameworks' fold curves")
    ap.add_argument(
        "--with-cotm",
        action="store_true",
        help="cotm.toml's fold curves too (seeds by sweeps along the lines: about a minute a run)",
    )
    args = ap.parse_args()
    if args.folds_only:
        framework_folds(args.with_cotm)
        return
    if args.zeeman_only:
        framework_map(args.zeeman_points)
        return
    p = cb.Params.case("case3")
    t0 = time.perf_counter()
    folds = cb.fold_curves(p)
    seconds = time.perf_counter() - t0
    phys = folds[folds.physical & folds.L01.between(0, 14) & folds.L02.between(0, 14)]
    print("== fold curves of the paper geometry (target: under 60 s) ==")
    print(f"  {seconds:.2f} s for {len(folds)} fold points ({len(phys)} physical in (0, 14]^2),")
    pieces = folds.curve_id[folds.curve_id >= 0].nunique()
    cusps = int((folds.kind == "cusp").sum())
    print(f"  {1e6 * seconds / len(folds):.0f} us a fold point, {pieces} pieces, {cusps} cusps")
    t0 = time.perf_counter()
    samples = parallel_samples(p)
    sampled = time.perf_counter() - t0
    record, _ = certify_samples(p, samples, _grid(1500))
    print("== the map's certificate: the parallel curve's samples proved to miss no part of it ==")
    print(f"  {record['status']}: {record['leaves']} leaves, {record['edge_crossings']} edge "
          f"crossings, {record['samples_added']} samples added; {record['seconds']:.2f} s "
          f"(the samples themselves: {sampled:.2f} s)")  # fmt: skip
    t0 = time.perf_counter()
    m = cb.design_map(p, (0.0, 14.0), (0.0, 14.0), args.points, workers=2)
    seconds = time.perf_counter() - t0
    print(f"== design map, {args.points} x {args.points} direct solves, 2 workers ==")
    print(f"  {seconds:.1f} s in all (folds {m.record['timings']['folds']:.1f} s, "
          f"regions {m.record['timings']['regions']:.1f} s)")  # fmt: skip
    print("== energy barriers ==")
    for case in ("case1", "case2", "case3"):
        res = cb.solve(cb.Params.case(case))
        found = cb.barriers(res)
        print(f"  {case}: {len(found.table)} saddles, {len(found.pairs)} pairs, "
              f"{found.seconds:.2f} s")  # fmt: skip
    framework_map(args.zeeman_points)
    framework_folds(args.with_cotm)


def _fold_run(fw, x: str, xr: tuple, y: str, yr: tuple) -> tuple[float, float, dict]:
    """(wall seconds, of which the witness sets' solve or load, the record) of one fold map."""
    from cotm_bertini.catastrophe.framework_folds import framework_fold_curves

    t0 = time.perf_counter()
    _, rec = framework_fold_curves(fw, x, xr, y, yr, workers=2)
    witness = sum(
        r.get("generic_seconds", 0.0) for ts in rec["taut_sets"].values() for r in ts.values()
    )
    return time.perf_counter() - t0, witness, rec


def framework_folds(with_cotm: bool = False) -> None:
    """Fold curves by the Bertini route (catastrophe/framework_folds.py): Zeeman over the
    issue's window, and with `with_cotm` cotm.toml over (0, 14]^2 against the closed-form
    route's time on the built-in model (target: at most 10 times it), each run twice (the
    witness sets solved, or loaded from the cache, then in memory)."""
    from cotm_bertini.catastrophe.paper_folds import fold_curves_proved

    runs = [("zeeman", "x", (-0.6, 0.8), "y", (-0.8, 0.2))]
    if with_cotm:
        runs.append(("cotm", "L01", (1e-9, 14.0), "L02", (1e-9, 14.0)))
    for name, x, xr, y, yr in runs:
        fw = cb.Framework.from_toml(f"examples/{name}.toml")
        first, witness, rec = _fold_run(fw, x, xr, y, yr)
        again, _, _ = _fold_run(fw, x, xr, y, yr)
        print(f"== fold curves of {name}.toml by Bertini, {x} x {y}, 2 workers ==")
        print(f"  first run {first:.1f} s (witness sets {witness:.1f} s), again {again:.1f} s; "
              f"{rec['counts']} on {rec['curves_found']} curves")  # fmt: skip
        if name == "cotm":
            t0 = time.perf_counter()
            fold_curves_proved(cb.Params.case("case3"))
            closed = time.perf_counter() - t0
            print(
                f"  closed form (fold_curves_proved, Table 1) {closed:.2f} s: ratio "
                f"{again / closed:.1f} cached, {first / closed:.1f} first (target <= 10)"
            )


@contextlib.contextmanager
def _solves_uncached():
    """A fresh cache holding the user cache's derivations and generic (witness) sets only, so
    the grid's solves and sweeps are computed, not loaded."""
    from cotm_bertini.fs import cache_root

    user, old = cache_root(), os.environ.get("COTM_CACHE")
    with tempfile.TemporaryDirectory(prefix="cotm-bench-map-") as tmp:
        for entry in user.iterdir():
            if entry.name not in ("solves", "sweeps"):
                (Path(tmp) / entry.name).symlink_to(entry)
        os.environ["COTM_CACHE"] = tmp
        try:
            yield
        finally:
            if old is None:
                os.environ.pop("COTM_CACHE")
            else:
                os.environ["COTM_CACHE"] = old


def framework_map(points: int = 101) -> None:
    """Zeeman's machine over the issue's window (target: the 101 x 101 map in 60 s or less):
    wall time of the fold curves and of the regions (the 2-D sweep, 2 workers), and the CPU
    time spent in this process and its workers (the wall time depends on the machine's load)."""
    import resource

    def cpu() -> float:
        return sum(
            r.ru_utime + r.ru_stime
            for r in (
                resource.getrusage(w) for w in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)
            )
        )

    fw = cb.Framework.from_toml("examples/zeeman.toml")
    window = ("x", (-0.6, 0.8), "y", (-0.8, 0.2))
    cb.design_map(fw, *window, points=3, workers=2)  # the witness sets, solved once and cached
    with _solves_uncached():
        c0, t0 = cpu(), time.perf_counter()
        m = cb.design_map(fw, *window, points=points, workers=2)
        seconds, cpu_seconds = time.perf_counter() - t0, cpu() - c0
    rec, t = m.record, m.record["timings"]
    print(
        f"== Zeeman map, {points} x {points}, 2 workers, witness sets cached, every grid point "
        "solved (target: 60 s or less) =="
    )
    print(f"  {seconds:.1f} s in all: folds {t['folds']:.1f} s, regions {t['regions']:.1f} s "
          f"({1e3 * t['regions'] / points**2:.1f} ms a grid point), check {t['check']:.2f} s; "
          f"CPU {cpu_seconds:.1f} s")  # fmt: skip
    print(f"  {rec['fold_points']} fold points on {rec['fold_curves']} curves, {rec['cusps']} "
          f"cusps; {rec['count_changes']} stable-count changes, {rec['unexplained_changes']} "
          f"unexplained; sweep {rec['sweep_status']}")  # fmt: skip


if __name__ == "__main__":
    main()
