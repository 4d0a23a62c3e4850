"""The structure-keeping step's size (issue 29): monodromy on the constant-term family
F(x) + e (the slope M x of backends/monodromy.py's family set to zero, so every non-constant
term of F is kept) until stagnation, against the general family F + c M x + e that the
package certifies with the trace test. The constant-term family's trace test is not valid (its
slices are not general: on Zeeman and the double pendulum the complete fibre fails it), so its
counts here are found, not proved: they size the next step, they are not a route.
Benchmarks: nothing asserted.

Usage: python bench/constant_family.py [--systems prism double_pendulum
prism_slack:diag_a,diag_b,diag_c] [--stall 5]  (an example's first taut set, or name:taut,set)
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import pandas as pd
from benchlib import BENCH, example_system, show, write_csv


def _system(spec: str):
    """(parametric system, start centre) of "name" (its first taut set with isolated
    equilibria) or "name:cable,cable"."""
    import cotm_bertini as cb

    name, _, taut = spec.partition(":")
    fw = cb.Framework.from_toml(BENCH.parent / "examples" / f"{name}.toml")
    cables = {c.name for c in fw.cables}
    unknown = sorted(set(taut.split(",")) - cables) if taut else []
    if unknown:
        raise SystemExit(f"constant_family.py: {name} has no cable {unknown[0]!r}")
    ps, centre, _ = example_system(name, tuple(taut.split(",")) if taut else None)
    return ps, centre


def _constant_family(run):
    """Run `run()` with the augmented family's slope M drawn as zeros (F(x) + e)."""
    from cotm_bertini.backends import monodromy as mo

    real = mo._gaussian

    def zero_slope(rng, shape):
        z = real(rng, shape)  # the same random stream: x0 and the pencil as in the real run
        return z * 0 if isinstance(shape, tuple) and len(shape) == 3 else z

    mo._gaussian = zero_slope
    try:
        return run()
    finally:
        mo._gaussian = real


def main() -> None:
    """Print and write bench/results/constant_family.csv."""
    from cotm_bertini.backends.monodromy import monodromy_generic

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--systems", nargs="*", default=["prism", "double_pendulum"])
    ap.add_argument("--stall", type=int, default=5)
    opts = ap.parse_args()
    rows = []
    for spec in opts.systems:
        ps, centre = _system(spec)
        t0 = time.perf_counter()
        m = _constant_family(
            lambda ps=ps, centre=centre: monodromy_generic(ps, 1, centre, max_stall=opts.stall)
        )
        rows.append({"system": spec, "unknowns": len(ps.variables), "fibre_found": m.augmented,
                     "N": len(m.points), "edges": m.edges, "paths": m.paths,
                     "seconds": time.perf_counter() - t0, "cpu_s": m.cpu_seconds,
                     "trace_passed": m.complete, "load_avg_1min": os.getloadavg()[0]})  # fmt: skip
        print(rows[-1], file=sys.stderr, flush=True)
    frame = pd.DataFrame(rows)
    show("constant-term family: fibre found by monodromy until stagnation", frame,
         {"seconds": ".1f", "cpu_s": ".1f"})  # fmt: skip
    write_csv(frame, "constant_family")


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    main()
