"""PolySystem evaluation by route: values and Jacobian at many points, per call and per row.

The monomial route (`PolySystem._table`: every monomial the values and the partial derivatives
hold, evaluated once, then one sum per output) against the sparse route (`_Terms`: prefix and
suffix products of each term's factors), on the paper's case-3 system and the frameworks'
(every cable taut), at 70 points (a paper point's Newton step: its ~70 solutions) and 700.
The route a system takes by default is marked; the two must agree (max difference printed).

Usage: .venv/bin/python bench/evaluate.py
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pandas as pd
from benchlib import show, write_csv

from cotm_bertini.model import polynomial
from cotm_bertini.model.compiled import polynomial_system
from cotm_bertini.model.framework.compiled import framework_system
from cotm_bertini.model.framework.spec import Framework
from cotm_bertini.params import Params

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
FRAMEWORKS = ("zeeman", "prism", "prism_slack")
REPEATS = 30


def systems() -> dict[str, polynomial.PolySystem]:
    """The systems timed, by name, instantiated at their own parameter values."""
    out = {"paper case 3": polynomial_system(Params.case("case3").normalized())}
    for name in FRAMEWORKS:
        fw = Framework.from_toml(EXAMPLES / f"{name}.toml")
        ps = framework_system(fw, tuple(c.name for c in fw.cables)).ps
        rng = np.random.default_rng(1)
        out[name] = ps.instantiate(rng.uniform(0.5, 1.5, len(ps.parameters)))
    return out


def timed(system: polynomial.PolySystem, x: np.ndarray) -> tuple[float, tuple]:
    """Median seconds of one value_and_jacobian call at the rows of x, and its result."""
    result = system.value_and_jacobian(x)
    times = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        system.value_and_jacobian(x)
        times.append(time.perf_counter() - start)
    return float(np.median(times)), result


def fresh(system: polynomial.PolySystem) -> polynomial.PolySystem:
    """The same system without its cached evaluation tables."""
    return polynomial.PolySystem(system.variables, system.names, system.exponents,
                                 system.coefficients)  # fmt: skip


def main() -> None:
    rows = []
    rng = np.random.default_rng(0)
    for name, system in systems().items():
        m = len(system.variables)
        default = "monomials" if fresh(system)._table is not None else "sparse"
        for n in (70, 700):
            x = rng.normal(size=(n, m)) + 1j * rng.normal(size=(n, m))
            limit = polynomial.TABLE_LIMIT
            try:
                polynomial.TABLE_LIMIT = 0
                sparse, (f0, j0) = timed(fresh(system), x)
                polynomial.TABLE_LIMIT = 1 << 30
                table, (f1, j1) = timed(fresh(system), x)
            finally:
                polynomial.TABLE_LIMIT = limit
            scale = max(np.abs(f0).max(), np.abs(j0).max())
            diff = max(np.abs(f1 - f0).max(), np.abs(j1 - j0).max()) / scale
            rows.append({
                "system": f"{name} ({m} vars, {sum(map(len, system.exponents))} terms)",
                "points": n, "sparse ms": sparse * 1e3, "monomials ms": table * 1e3,
                "ratio": sparse / table, "default": default, "rel. difference": diff,
            })  # fmt: skip
    frame = pd.DataFrame(rows)
    show(f"value_and_jacobian by route (median of {REPEATS} calls)", frame,
         {"ratio": ".1f", "rel. difference": ".1e"})  # fmt: skip
    write_csv(frame, "evaluate")


if __name__ == "__main__":
    main()
