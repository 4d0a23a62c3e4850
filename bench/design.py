"""Design maps (issue 10): the fold curves of the paper plane, the time per fold point, the
design map's grid of direct solves, and the energy barriers of cases 1-3.

Benchmarks, not tests: nothing is asserted; the target (fold curves of the paper plane in under
60 s on 2 cores) is printed beside the measurement.
Usage: .venv/bin/python bench/design.py [--points N]
"""

from __future__ import annotations

import argparse
import time

import cotm_bertini as cb


def main() -> None:
    from cotm_bertini.analysis.certify_curve import certify_samples
    from cotm_bertini.analysis.fold_curves import _grid, parallel_samples

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=41, help="grid points a side of the map")
    args = ap.parse_args()
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


if __name__ == "__main__":
    main()
