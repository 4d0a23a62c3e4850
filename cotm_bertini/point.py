"""One parameter set solved end to end: the single path behind solve, sweeps and event refinement.

The route is chosen (routes.choose) and run (routes/real.py, routes/homotopy.py,
routes/command.py); the endpoints are classified, counted and checked for completeness here, the
same for every route.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from .analysis.classify import classify_columns
from .analysis.morse import morse_check
from .backends.endpoints import Endpoints
from .errors import ParameterError
from .model.compiled import parametric_system
from .params import Params
from .routes import choose
from .routes.choice import check_route
from .routes.result import (
    STATUS_CONTRADICTION,
    STATUS_INCOMPLETE,
    STATUS_OK,
    PointSolution,
    Timings,
)
from .settings import Settings, Tolerances


def path_counts(
    endpoints: Endpoints, table: dict, paths_tracked: int | None, lost: int | None,
    crossings: int = 0,
) -> dict:  # fmt: skip
    """Path and solution counts, each meaning one thing (docs/columns.md, "counts"): closed-form
    endpoints apart from tracked ones; real = physical + negative_d + zero_length_real, and
    distinct_solutions = real + complex, complex counting zero_length_complex among its rows."""
    tracked_ends = endpoints.tracked
    other = None if paths_tracked is None else paths_tracked - tracked_ends
    real = np.asarray(table["is_real"], dtype=bool)
    zero = np.asarray(table["reason"] == "zero_length_spring", dtype=bool)
    return {
        "paths_tracked": paths_tracked,
        "finite_endpoints": tracked_ends,
        "closed_form_endpoints": len(endpoints) - tracked_ends,
        "infinite_or_failed_paths": other,
        "lost_paths": lost,
        "crossings_unresolved": crossings,
        "distinct_solutions": len(table["solution_id"]),
        "real": int(real.sum()),
        "complex": int((~real).sum()),
        "physical": int(table["physical"].sum()),
        "stable": int(table["stable"].sum()),
        "negative_d": int((table["reason"] == "negative_d").sum()),
        "zero_length_real": int((zero & real).sum()),
        "zero_length_complex": int((zero & ~real).sum()),
        "singular": int(table["singular"].sum()),
    }


def _checks(morse: dict, counts: dict, generic: list[str], proved: bool = False) -> tuple:
    """The status and the warnings of a solve: complete, or why equilibria may be missing
    (`generic`: why its generic set is incomplete, if it is), or a contradiction (`proved`: a
    real search proved the rows complete, and the Morse count says otherwise)."""
    warnings = list(generic)
    proved = proved and not morse["degenerate"]  # a row without an index: no judgement
    if not morse["ok"]:
        total = morse["euler_characteristic"]
        parts = [f"#min - #saddle + #max (+ zero-length maxima) = {total} != 0 on the torus"] * (
            total != 0
        )
        parts += [f"{morse['degenerate']} degenerate"] * bool(morse["degenerate"])
        parts += ["no minimum, though V has one on the compact torus"] * (not morse["min"])
        warnings.append(
            f"contradiction: the real search proved the rows complete, yet {'; '.join(parts)}: "
            "a bug (please report it with run.json)" if proved
            else "; ".join(parts) + ": equilibria may be missing"
        )  # fmt: skip
    if counts.get("lost_paths"):
        warnings.append(f"{counts['lost_paths']} paths lost: solutions may be missing")
    if counts.get("crossings_unresolved"):
        warnings.append(
            f"{counts['crossings_unresolved']} paths crossed another path and the solver could "
            "not part them: the affected solutions may be wrong"
        )
    if any(w.startswith("contradiction:") for w in warnings):
        return STATUS_CONTRADICTION, tuple(dict.fromkeys(warnings))
    return (STATUS_INCOMPLETE if warnings else STATUS_OK), tuple(warnings)


def solve_point(
    params: Params,
    settings: Settings = Settings(),
    tolerances: Tolerances = Tolerances(),
    folder: Path | None = None,
    title: str = "",
    warm=None,
) -> PointSolution:
    """Every finite solution of `params`, classified, with the counts and the Morse check.

    The `cli` engine runs Bertini in `folder` (which must be empty; a temporary one when None)
    and leaves its files there; the homotopy engine writes nothing. `warm` (the `warm` of a
    neighbouring point's solution) lets the homotopy engine continue from that point. With
    `settings.route == "real"` no Bertini runs: the real route's search finds and proves the
    real equilibria (routes.real.paper_real), classified in the same columns.
    """
    check_route(params, settings)
    t = Timings()
    with t.stage("derive"):
        ps = parametric_system(params.zfl)
        system = ps.instantiate([getattr(params, n) for n in ps.parameters])
    route = choose(params, settings).route
    if route == "real":
        from .routes.real import paper_real

        solved = paper_real(params, settings, tolerances, t)
    elif route == "homotopy":
        from .routes.homotopy import paper_homotopy

        solved = paper_homotopy(params, settings, ps, t, warm)
    else:
        from .routes.command import paper_command

        if folder is None:
            with tempfile.TemporaryDirectory(prefix="cotm-") as tmp:
                solved = paper_command(params, settings, system, Path(tmp) / "run", title, t)
        else:
            solved = paper_command(params, settings, system, Path(folder), title, t)
    endpoints, tracked, lost, engine, details, text, warm_next = solved
    with t.stage("classify"):
        table = classify_columns(params, endpoints, tolerances)
        morse = morse_check(params, table)
    counts = path_counts(endpoints, table, tracked, lost, details.get("crossings_unresolved", 0))
    if "real_search" in details:  # no path: the endpoints are the search's critical points
        counts.update(finite_endpoints=0, infinite_or_failed_paths=0,
                      boxes=details["real_search"]["boxes"])  # fmt: skip
    proved = "real_search" in details and not details["real_search"]["warnings"]
    status, warnings = _checks(
        morse, counts, details.get("homotopy", {}).get("generic_warnings", [])
        + details.get("framework_warnings", []), proved,
    )  # fmt: skip
    shape = {
        "variables": list(system.variables),
        "functions": list(system.names),
        "degrees": list(system.degrees),
        "total_degree": system.total_degree,
    }
    return PointSolution(
        params, settings, table, endpoints, counts, morse, status, warnings, engine, shape,
        details, text, t.stages, warm_next,
    )  # fmt: skip


def solve_framework_point(
    fw, settings: Settings = Settings(), tolerances: Tolerances = Tolerances(), warm=None
) -> PointSolution:
    """Every equilibrium of a framework (cb.Framework), by the route routes.choose gives it:
    the real route's search (routes.real), or each taut set by the homotopy (routes.homotopy;
    `warm`, the `warm` of a neighbouring point's solution, continues each from that point)."""
    t = _framework_checks(fw, settings)
    if choose(fw, settings).real:
        from .routes.real import solve_real

        return solve_real(fw, settings, tolerances, t)
    from .routes.homotopy import solve_complex

    return solve_complex(fw, settings, tolerances, t, warm)


def _framework_checks(fw, settings: Settings) -> Timings:
    """Refuse what no route of a framework solves (ParameterError); the timings begun."""
    from .model.framework.compiled import framework_system
    from .model.framework.structure import check_mobility

    if settings.engine != "homotopy":
        raise ParameterError(
            f"engine = {settings.engine!r}: a framework is solved by the in-process homotopy "
            "engine (engine='homotopy')"
        )
    check_route(fw, settings)
    t = Timings()
    with t.stage("derive"):
        # Free even with every cable taut: a continuum of equilibria, refused as bad input.
        check_mobility(fw, framework_system(fw, tuple(c.name for c in fw.cables)))
    return t


def solve_framework_points(
    fws: list, settings: Settings = Settings(), tolerances: Tolerances = Tolerances()
) -> list[PointSolution]:
    """solve_framework_point at each of several values of one framework (a sweep's points).
    On the real route their searches run together, in the same batches of boxes
    (boxsearch.families.search_frameworks): each point keeps its own search, box for box
    the one it would have alone; every point is checked before any is searched."""
    from .boxsearch.families import search_frameworks
    from .routes.real import real_landscape, solve_real

    if not fws or not choose(fws[0], settings).real:
        return [solve_framework_point(fw, settings, tolerances) for fw in fws]
    timings = [_framework_checks(fw, settings) for fw in fws]
    ready = [real_landscape(fw, t, settings.only) for fw, t in zip(fws, timings, strict=True)]
    found = search_frameworks(fws, settings.timeout, [land for land, _, _ in ready])
    out = []
    for fw, t, r, f in zip(fws, timings, ready, found, strict=True):
        t.stages["solve"] = f.seconds  # this point's share of the batches' time
        out.append(solve_real(fw, settings, tolerances, t, r, f))
    return out
