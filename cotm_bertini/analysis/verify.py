"""Cross-check one parameter set by independent routes and say which agree with Bertini."""

from __future__ import annotations

import time
from dataclasses import dataclass

import pandas as pd

from ..model.compiled import polynomial_system
from ..params import Params
from .classify import classify
from .critical_points import compare_physical, critical_points
from .morse import morse_check
from .resultant import case1_resultant, case2_resultant
from .resultant import compare as compare_sets

AGREE_DEG = 1e-6  # routes agree when every solution matches within this (degrees)


@dataclass(frozen=True)
class RouteResult:
    """What one route found and how it compares with the Bertini solutions."""

    route: str
    found: str
    agrees: bool | None  # None: the route does not apply or could not run
    max_disagreement_deg: float
    seconds: float
    note: str = ""


def _energy(params: Params, solutions: pd.DataFrame) -> RouteResult:
    t = time.perf_counter()
    cp = critical_points(params)
    c = compare_physical(cp, solutions)
    ok = c["only_energy_route"] == 0 and c["only_polynomial_route"] == 0
    ok = ok and c["worst_deg"] <= AGREE_DEG
    kinds = cp["kind"].value_counts().to_dict()
    return RouteResult(
        "energy Newton on the torus",
        f"{len(cp)} critical points {kinds}",
        ok,
        c["worst_deg"],
        time.perf_counter() - t,
        f"only energy route: {c['only_energy_route']}, only Bertini: {c['only_polynomial_route']}",
    )


def _resultant(params: Params, solutions: pd.DataFrame) -> RouteResult:
    if params.zfl == (True, True):
        res = case1_resultant(params)
    elif params.zfl == (False, True):
        res = case2_resultant(params)
    else:
        return RouteResult(
            "Sylvester resultant",
            "-",
            None,
            float("nan"),
            0.0,
            "only for L02 = 0 (cases 1 and 2), as in the paper",
        )
    c = compare_sets(res.roots, solutions, tol=1e-3)
    ok = c.only_resultant == 0 and c.only_solutions == 0 and c.max_angle_deg <= AGREE_DEG
    factors = ", ".join(f"{f.degree}x{f.multiplicity} {f.label}" for f in res.factors)
    return RouteResult(
        "Sylvester resultant",
        f"degree {res.degree}: {factors}",
        ok,
        c.max_angle_deg,
        res.seconds,
        f"{c.matched} matched, {c.at_infinity} at gamma = 180 deg (x = oo)",
    )


def _phc(params: Params, solutions: pd.DataFrame, seed: int) -> RouteResult:
    from ..backends.phc import PhcError, phc_available, solve_phc

    if not phc_available():
        return RouteResult(
            "PHCpack phc -b",
            "-",
            None,
            float("nan"),
            0.0,
            "phc not installed: apt-get install phcpack (make verify does)",
        )
    system = polynomial_system(params)
    try:
        run = solve_phc(system, seed=seed)
    except PhcError as exc:
        return RouteResult("PHCpack phc -b", "failed", False, float("nan"), 0.0, str(exc))
    table = classify(params, run.endpoints)
    c = compare_sets(table, solutions, tol=1e-3)
    ok = (
        c.only_resultant == 0
        and c.only_solutions == 0
        and len(table) == len(solutions)
        and c.max_angle_deg <= AGREE_DEG
    )
    return RouteResult(
        "PHCpack phc -b",
        f"{len(table)} distinct finite ({int(table['is_real'].sum())} real) from "
        f"{run.root_count} paths",
        ok,
        c.max_angle_deg,
        run.seconds,
    )


def verify(params: Params, solutions: pd.DataFrame, seed: int = 1) -> list[RouteResult]:
    """Run every independent route on `params` and compare each with Bertini's `solutions`."""
    morse = morse_check(params, solutions)
    routes = [
        RouteResult(
            "Morse count on the torus",
            f"{morse['min']} min - {morse['saddle']} saddle + {morse['max']} max "
            f"+ {morse['zero_length_maxima']} zero-length = "
            f"{morse['euler_characteristic']}",
            morse["ok"],
            float("nan"),
            0.0,
        ),
        _energy(params, solutions),
        _resultant(params, solutions),
        _phc(params, solutions, seed),
    ]
    return routes
