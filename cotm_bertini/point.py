"""One parameter set solved end to end: the single path behind solve, sweeps and event refinement.

equations (cached numeric form) -> engine (in-process parameter homotopy, or a Bertini binary in a
run folder) -> endpoint table -> classified solutions, with path accounting and the Morse check.
"""

from __future__ import annotations

import dataclasses
import tempfile
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import cached_property, partial
from pathlib import Path

import numpy as np

from .analysis.classify import classify_columns
from .analysis.morse import morse_check
from .backends.crossings import in_solve
from .backends.endpoints import Endpoints
from .boxsearch.boxes import MIN_WIDTH
from .errors import ParameterError
from .model.compiled import parametric_system
from .model.framework.structure import layout as model_layout
from .params import Params
from .settings import Settings, Tolerances

STATUS_OK = "ok"
STATUS_INCOMPLETE = "incomplete"
STATUS_CONTRADICTION = "contradiction"  # a proof that contradicts an independent check: a bug


@dataclass
class Timings:
    """Wall-clock seconds per stage."""

    stages: dict[str, float] = field(default_factory=dict)

    @contextmanager
    def stage(self, name: str):
        start = time.perf_counter()
        try:
            yield
        finally:
            self.stages[name] = self.stages.get(name, 0.0) + time.perf_counter() - start


@dataclass(frozen=True)
class PointSolution:
    """The classified solutions of one parameter set and everything that produced them."""

    params: Params
    settings: Settings
    columns: dict[str, np.ndarray]  # the solutions.csv columns, as numpy arrays
    endpoints: Endpoints
    counts: dict
    morse: dict
    status: str  # "ok"; "incomplete" when a completeness check failed; "contradiction"
    warnings: tuple[str, ...]
    engine: dict  # flavour, path, version
    system: dict  # variables, functions, degrees, total degree
    details: dict  # engine specifics: homotopy report and generic set, or the cli attempts
    input_text: str
    timings: dict
    warm: object = None  # homotopy engine: this point as a start for a neighbouring one
    continua: tuple = ()  # a framework's continua of equilibria: continuum_record dicts

    @cached_property
    def table(self):
        """The solutions as a pandas DataFrame (built on first use: pandas loads only then)."""
        import pandas as pd

        return pd.DataFrame(self.columns)


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
    real equilibria (`_paper_real`), classified in the same columns.
    """
    check_route(params, settings)
    t = Timings()
    with t.stage("derive"):
        ps = parametric_system(params.zfl)
        system = ps.instantiate([getattr(params, n) for n in ps.parameters])
    if settings.route == "real":
        solved = _paper_real(params, settings, tolerances, t)
    elif settings.engine == "homotopy":
        solved = _homotopy(params, settings, ps, t, warm)
    elif folder is None:
        with tempfile.TemporaryDirectory(prefix="cotm-") as tmp:
            solved = _cli(params, settings, system, Path(tmp) / "run", title, t)
    else:
        solved = _cli(params, settings, system, Path(folder), title, t)
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


def _homotopy(params: Params, settings: Settings, ps, t: Timings, warm) -> tuple:
    from .backends.target import solve_target

    with t.stage("solve"):
        hs = solve_target(ps, params, settings, warm)
    engine = {
        "flavour": "homotopy",
        "path": "bertini module (in-process)",
        "version": hs.generic.bertini_version,
    }
    details = {"homotopy": hs.info, "generic_set": hs.generic.summary(),
               "crossings_unresolved": in_solve(hs.info)}  # fmt: skip
    info = hs.info
    return hs.endpoints, info["tracked"], info["lost"], engine, details, hs.input_text, hs.warm


def _paper_real(params: Params, settings: Settings, tolerances: Tolerances, t: Timings):
    """The paper's mechanism by the real route: its framework (model.framework.paper) searched
    as any torus framework is (`_solve_real`), each equilibrium then handed on as an endpoint of
    the paper's own system (c, s and the spring lengths d), so that it is refined, classified
    and Morse-checked as Bertini's endpoints are. The framework's own warnings (undecided
    boxes, its Morse count from the search's cone points) are kept beside the paper's checks."""
    from .model.framework.paper import ANGLE_COLUMNS, paper_framework
    from .model.kinematics import spring_vectors

    sol = _solve_real(paper_framework(params), settings, tolerances, t)
    g1, g2 = (np.radians(np.asarray(sol.columns[c], dtype=float)) for c in ANGLE_COLUMNS)
    c1, s1, c2, s2 = np.cos(g1), np.sin(g1), np.cos(g2), np.sin(g2)
    vec = spring_vectors(params, c1, s1, c2, s2)
    value = {"c1": c1, "s1": s1, "c2": c2, "s2": s2,
             "d1": np.hypot(*vec["spring1"]), "d2": np.hypot(*vec["spring2"])}  # fmt: skip
    # The compiled system's variables (variables_for's), read without importing sympy.
    variables = parametric_system(params.zfl).variables
    n = len(g1)
    records = [{"coords": [value[v][k] for v in variables], "path_number": k} for k in range(n)]
    endpoints = Endpoints.from_records(variables, records)
    details = {"route": "real", "real_search": sol.details["real_search"],
               "framework_warnings": list(sol.warnings)}  # fmt: skip
    if sol.continua:
        details["continua"] = list(sol.continua)
    return endpoints, 0, 0, sol.engine, details, "", None


def _cli(params: Params, settings: Settings, system, folder: Path, title: str, t: Timings):
    from .backends.bertini_cli import solve_cli

    with t.stage("solve"):
        cs = solve_cli(system, settings, folder, params.as_dict(), title)
    t.stages.update(cs.timings)
    run = cs.run
    engine = {"flavour": run.engine.flavour, "path": run.engine.path, "version": run.version}
    details = {
        "output_layout": cs.output.layout,
        "bertini_seconds": cs.run.seconds,
        "bertini1_failed_paths_file": cs.output.failed_paths,
        "crossings_unresolved": cs.run.crossings_unresolved,
    }
    if cs.attempts:
        details["attempts"] = cs.attempts
    out = cs.output
    # Bertini 1 lists failed paths; those truncated on their way to infinity are not lost.
    lost = None if out.failed_paths is None else out.failed_paths - (out.truncated_infinite or 0)
    return cs.endpoints, cs.paths_tracked, lost, engine, details, cs.input_text, None


def solve_framework_point(
    fw, settings: Settings = Settings(), tolerances: Tolerances = Tolerances(), warm=None
) -> PointSolution:
    """Every equilibrium of a framework (cb.Framework): each taut set of its cables solved by
    the parameter homotopy, classified, checked for completeness, in one table. `warm` (the
    `warm` of a neighbouring point's solution: a start per taut set) lets a sweep continue each
    taut set from that point by Newton (backends.target.solve_parameters)."""
    from .analysis.framework_checks import completeness, framework_counts, order_rows
    from .analysis.framework_continua import absorb, continuum_record, find_continua
    from .model.framework.units import normalized_slots, units

    t = _framework_checks(fw, settings)
    if framework_route(fw, settings) == "real":
        return _solve_real(fw, settings, tolerances, t)
    unit = units(fw)
    target, centre = normalized_slots(fw), normalized_slots(fw.at_defaults())
    parts, report, texts, starts = [], {}, [], {}
    sets, pruned = split_taut_sets(fw)
    for taut, why in pruned.items():  # not solved: no consistent equilibrium
        report[" ".join(taut) or "none"] = {"excluded": True, "pruned": "bound smoothing",
                                           "note": why.note()}  # fmt: skip
    for taut in sets:
        part, info, text = _solve_taut_set(
            fw, taut, unit, target, centre, settings, tolerances, t, (warm or {}, starts)
        )
        report[" ".join(taut) or "none"] = info
        if part is not None:
            parts.append(part)
            texts.append(text)
    with t.stage("classify"):
        # Rows on a curve of equilibria are that curve's points, counted apart (issue 39).
        continua = find_continua(fw, parts, unit, tolerances)
        absorb(parts, continua)
        table = order_rows(fw, [p[0] for p in parts])
        checks = completeness(fw, table, report, continua)
    counts = framework_counts(table, report, continua)
    status = STATUS_INCOMPLETE if checks["warnings"] else STATUS_OK
    engine = {"flavour": "homotopy", "path": "bertini module (in-process)",
              "version": _bertini_version()}  # fmt: skip
    shape = {"taut_sets": list(report), "units": {"length": unit[0], "stiffness": unit[1]}}
    return PointSolution(
        fw, settings, table, None, counts, checks["morse"], status, tuple(checks["warnings"]),
        engine, shape, {"taut_sets": report}, "\n".join(texts), t.stages, starts,
        tuple(continuum_record(c, n) for n, c in enumerate(continua, start=1)),
    )  # fmt: skip


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
    (boxsearch.real_route.search_frameworks): each point keeps its own search, box for box
    the one it would have alone; every point is checked before any is searched."""
    from .boxsearch.real_route import search_frameworks

    if not fws or framework_route(fws[0], settings) != "real":
        return [solve_framework_point(fw, settings, tolerances) for fw in fws]
    timings = [_framework_checks(fw, settings) for fw in fws]
    ready = [_real_landscape(fw, t, settings.only) for fw, t in zip(fws, timings, strict=True)]
    found = search_frameworks(fws, settings.timeout, [land for land, _, _ in ready])
    out = []
    for fw, t, r, f in zip(fws, timings, ready, found, strict=True):
        t.stages["solve"] = f.seconds  # this point's share of the batches' time
        out.append(_solve_real(fw, settings, tolerances, t, r, f))
    return out


def check_route(model, settings: Settings, what: str = "solve") -> None:
    """Refuse a route the model cannot take, a setting it would not honour, or local workers
    where nothing would use them, before any work or folder (ParameterError). `what`: "solve",
    or one of PAPER_BERTINI_ONLY (a sweep or map solves each point in one process and splits
    its points over its own workers)."""
    workers = settings.workers not in (None, 1)
    if what != "solve" and settings.workers is not None:
        raise ParameterError(
            f"workers = {settings.workers!r} in the settings: a sweep or map solves each point "
            "in one process and splits its points over its own workers (workers=, --workers)"
        )
    if settings.only != "all" and (
        isinstance(model, Params) or framework_route(model, settings) != "real"
    ):
        name = "the paper's mechanism" if isinstance(model, Params) else model.name
        raise ParameterError(
            f"only = {settings.only!r}: a search of the real route's alone; {name} is solved "
            "on the complex route, every critical point (its stable rows: result.stable)"
        )
    if not isinstance(model, Params):
        if settings.only != "all" and model.dim == 2 and model_layout(model).closing_pins:
            raise ParameterError(
                f"only = {settings.only!r}: not yet for a closed loop ({model.name}): its "
                "search is for every critical point on the loop (the stable rows: "
                "result.stable)"
            )
        if framework_route(model, settings) == "complex" and workers:
            raise ParameterError(
                f"workers = {settings.workers!r}: local workers share the real route's boxes; "
                f"the complex route of {model.name} is not split over them (a scheduler splits "
                "its generic sets' paths)"
            )
        return
    if workers:
        raise ParameterError(
            f"workers = {settings.workers!r}: the paper's mechanism is solved in one process "
            "(threads= sets Bertini's threads)"
        )
    if settings.route == "real":
        if what in PAPER_BERTINI_ONLY:
            raise ParameterError(
                f"route = 'real': {what} of the paper's mechanism is by Bertini only "
                f"({PAPER_BERTINI_ONLY[what]}); solve one point with route='real', or use "
                "examples/cotm.toml, the same mechanism as a framework"
            )
        for name in PAPER_REAL_REFUSED:
            if getattr(settings, name) != getattr(Settings(engine="homotopy"), name):
                raise ParameterError(
                    f"{name} = {getattr(settings, name)!r} with route = 'real': the real route "
                    "runs no Bertini (a branch and bound over the angles, in this process)"
                )


# What the paper's mechanism does on Bertini's complex roots only, and why.
PAPER_BERTINI_ONLY = {
    "sweep": "its continuation and events follow complex roots: a real sweep loses its folds",
    "map": "its fold curves and regions follow complex roots",
    "verify": "it compares every complex root with the resultant's and PHCpack's",
}


# Settings that only reach Bertini: the real route cannot honour them (`timeout` it does; it
# runs in one thread, so `threads` is kept as a bound, as a sweep's workers set it).
PAPER_REAL_REFUSED = (
    "engine", "mptype", "precision", "final_tol", "tracktol_before_eg", "tracktol_during_eg",
    "security_level", "condnum_threshold", "max_norm", "bertini", "extra_config",
    "variable_groups", "scheduler",
)  # fmt: skip


def framework_route(fw, settings: Settings) -> str:
    """'real' or 'complex': the route asked for, or by default the real one wherever it covers
    the configuration space (a refusal names why it cannot where 'real' was asked for)."""
    from .boxsearch.real_route import covers

    why = covers(fw)
    if settings.route == "real" and why:
        raise ParameterError(f"route = 'real': not yet for {fw.name}: {why}; use route='complex'")
    if settings.route is not None:
        return settings.route
    return "complex" if why or settings.generic else "real"


SEEDS_AT_BUDGET = 512  # Newton starts in the boxes a search stopped by its budget left
DESCENTS = 64  # local descents from random poses when a search is stopped by its budget


def _real_landscape(fw, t: Timings, only: str = "all") -> tuple:
    """(the real route's landscape of `fw` searching for `only`, its taut sets, those pruned),
    every taut set's equations derived and checked."""
    from .boxsearch.real_route import landscape
    from .model.framework.compiled import check_terms
    from .model.framework.units import normalized_slots

    sets, pruned = split_taut_sets(fw)
    with t.stage("derive"):
        land = landscape(fw, only)
        target = normalized_slots(fw)
        for taut, fs in land.hessian_sets:  # derived (or loaded) here, not in the search's clock
            if taut in sets:
                check_terms(fw, fs, target)  # a degenerate equation: refused, not searched
    return land, sets, pruned


def _solve_real(
    fw, settings: Settings, tolerances: Tolerances, t: Timings, ready=None, found=None
) -> PointSolution:
    """Every real equilibrium of a framework on a circle, torus or product of spheres, by the
    branch and bound of boxsearch.boxes over its configuration space, classified as the complex
    route's endpoints are; the search's proof (or what it left undecided) is the completeness
    check. Boxes left undecided are searched for continua of equilibria, traced and counted
    apart as on the complex route; regions where a node floats are reported apart. `ready` and
    `found`: the landscape (_real_landscape) and its search, where already made."""
    from .analysis.framework_checks import completeness, framework_counts, order_rows
    from .analysis.framework_continua import absorb, continuum_record, find_continua
    from .boxsearch.box_shares import deepened, split_search
    from .boxsearch.boxes import SHORT
    from .boxsearch.real_route import landscape
    from .model.framework.units import units

    unit = units(fw)
    land, sets, pruned = ready or _real_landscape(fw, t, settings.only)
    with t.stage("solve"):
        if found is None:  # shared over local processes or a Dask cluster where asked
            found = split_search(partial(landscape, only=settings.only), fw, SHORT, MIN_WIDTH,
                                 workers=settings.workers, scheduler=settings.scheduler,
                                 max_seconds=settings.timeout,
                                 label=f"real search of {fw.name}")  # fmt: skip
        found = deepened(land, found, SHORT, MIN_WIDTH, f"real search of {fw.name}")
        seeds, descents, regions = _unproved(land, found, unit, settings.seed)
        stability = None
        if settings.only == "stable":
            found, seeds, stability = _minima_only(land, found, seeds, descents, settings.seed)
        groups = land.endpoints(np.vstack([found.roots, seeds]))
    report: dict = {" ".join(taut) or "none": {"excluded": True, "pruned": "bound smoothing",
                    "note": why.note()} for taut, why in pruned.items()}  # fmt: skip
    with t.stage("classify"):
        parts = _real_parts(fw, sets, groups, report, unit, tolerances)
        continua = find_continua(fw, parts, unit, tolerances) if len(seeds) else []
        absorb(parts, continua)
        table = order_rows(fw, [p[0] for p in parts])
        cones = cone_records(land, found, unit)
        checks = completeness(fw, table, report, continua, near_cones=found.set_aside_boxes,
                              cones=cones, morse=stability is None)  # fmt: skip
    morse_bott = all(c.index is not None for c in continua)
    search_info = real_search_info(found, unit[0], along_continua(land, found, continua),
                                   morse_bott, regions)  # fmt: skip
    search_info["found_by_newton"] = len(seeds)
    search_info["cone_points"] = cones
    if descents["starts"]:
        search_info["descents"] = {k: v for k, v in descents.items() if k != "points"}
    failure = checks["morse"].get("failure")
    if stability is not None:
        search_info["only"] = stability
        search_info["warnings"] += stability.pop("warnings")
        failure = stability.pop("failure")
    status, warnings = _real_status(found, search_info, checks, failure)
    counts = {**framework_counts(table, report, continua), "boxes": found.boxes}
    engine = {"flavour": "real", "path": "branch and bound (boxsearch.boxes)", "version": ""}
    shape = {"taut_sets": list(report), "units": {"length": unit[0], "stiffness": unit[1]}}
    return PointSolution(
        fw, settings, table, None, counts, checks["morse"],
        status, warnings, engine, shape, {"taut_sets": report, "real_search": search_info}, "",
        t.stages, None,
        tuple(continuum_record(c, n) for n, c in enumerate(continua, start=1)),
    )  # fmt: skip


def _real_status(found, search_info: dict, checks: dict, failure: str | None) -> tuple:
    """(status, warnings) of a real search: ok, incomplete where it or the checks left
    something, contradiction where the search proved its rows complete yet a check that shares
    none of its code (`failure`: the Morse count's, or the descents' of a search for minima)
    says they are not."""
    warnings = tuple(search_info["warnings"] + checks["warnings"])
    if failure and not any(w.startswith(failure) for w in warnings):
        warnings = (*warnings, f"{failure}: equilibria may be missing")
    status = STATUS_INCOMPLETE if warnings else STATUS_OK
    if failure and search_info["free_regions"] and failure == checks["morse"].get("failure"):
        # A region of equilibria has no term in the Morse sum: the count says nothing here.
        checks["morse"].update(
            applicable=False, ok=None, reason="a region of equilibria (a node free to float)"
        )
        warnings = tuple(w for w in warnings if not w.startswith(failure))
        status, failure = (STATUS_INCOMPLETE if warnings else STATUS_OK), None
    if failure and not search_info["warnings"] and not checks["morse"].get("degenerate"):
        # The search proved its rows are every critical point; the Morse count, which shares
        # none of its code, says they are not: one of the two is wrong, and no later check
        # can tell which. That is a bug to report, never a set that "may" be incomplete.
        # (A row too near degenerate to have an index, at a cable switch say, leaves the
        # count unable to judge: that stays incomplete.)
        status = STATUS_CONTRADICTION
        warnings = (f"contradiction: the real search proved its {len(found.roots)} critical "
                    f"points are all there are, yet {failure}: a bug (please report it with "
                    "run.json)",
                    *(w for w in warnings if not w.startswith(failure)))  # fmt: skip
    return status, warnings


def _minima_only(land, found, seeds: np.ndarray, descents: dict, seed: int | None) -> tuple:
    """(found, seeds, what was proved) of a search for the stable equilibria alone: its roots
    proved minima or not (boxsearch.minima; those proved not to be dropped, the undecided kept
    with a warning), the seeds Newton found (not proved) kept where their Hessian is positive
    definite."""
    from .boxsearch.minima import proved_minima
    from .boxsearch.real_route import descent_minima

    verdict = proved_minima(land, found.roots)
    keep = verdict >= 0
    found = dataclasses.replace(found, roots=found.roots[keep],
                                root_boxes=found.root_boxes[keep])  # fmt: skip
    if len(seeds):
        seeds = seeds[np.linalg.eigvalsh(land.derivatives(seeds)[1])[:, 0] > 0]
    # The check that shares no code with the search (the Morse count has no use here): local
    # descents from random poses; a minimum they reach that the search did not find joins the
    # rows, and where the search was proved complete that is a contradiction.
    reached = (
        descents["points"]
        if descents["starts"]
        else land.fresh(  # (a budget's: made)
            descent_minima(land, DESCENTS, 0 if seed is None else seed), np.zeros((0, land.n))
        )
    )
    missed = land.fresh(reached, np.vstack([found.roots, seeds]))
    seeds = np.vstack([seeds, missed])
    unsure = int((verdict == 0).sum())
    said = [f"{unsure} critical points found where only minima were looked for are neither "
            "proved minima nor proved not to be (degenerate, or too badly conditioned): kept, "
            "with the kind their Hessian gives"] * bool(unsure)  # fmt: skip
    failure = (
        (
            f"{len(missed)} of the {len(reached)} minima that local descents from "
            f"{DESCENTS} random poses reach are not among the search's"
        )
        if len(missed)
        else None
    )
    return found, seeds, {"what": "stable", "proved_minima": int((verdict == 1).sum()),
                          "undecided": unsure, "dropped": int((verdict == -1).sum()),
                          "descents": {"starts": DESCENTS, "minima": len(reached),
                                       "not_found_by_the_search": len(missed)},
                          "warnings": said, "failure": failure}  # fmt: skip


def _unproved(land, found, unit: tuple[float, float], seed: int | None) -> tuple:
    """(seeds, descents, regions): the critical points the search could not prove, in boxes
    left undecided (a continuum passes there) or set aside next to a cone point, found by
    Newton (not proved unique; a search stopped by its budget leaves much undecided: more
    seeds, more rows found) and by descents; the free regions, whose points are not rows."""
    from .boxsearch.real_route import critical_seeds

    most = SEEDS_AT_BUDGET if found.budget_hit else 32
    seeds = land.fresh(np.vstack([critical_seeds(land, found.undecided, most),
                                  critical_seeds(land, found.set_aside_boxes)]),
                       found.roots)  # fmt: skip
    descents = _descents(land, found, seeds, seed)
    seeds = np.vstack([seeds, land.fresh(descents["points"], np.vstack([found.roots, seeds]))])
    regions = free_regions(land, found, unit)
    return seeds[~in_regions(land, seeds, regions, unit)], descents, regions


def _descents(land, found, seeds, seed: int | None) -> dict:
    """Evidence for a search stopped by its budget (none otherwise): local descents from
    DESCENTS random poses, the minima they reach, and how many of those the search or Newton
    had already found (the others join the rows)."""
    from .boxsearch.real_route import descent_minima

    if not found.budget_hit:
        return {"starts": 0, "points": np.zeros((0, land.n))}
    minima = land.fresh(descent_minima(land, DESCENTS, 0 if seed is None else seed),
                        np.zeros((0, land.n)))  # fmt: skip
    new = land.fresh(minima, np.vstack([found.roots, seeds]))
    return {
        "starts": DESCENTS,
        "minima": len(minima),
        "minima_not_found_before": len(new),
        "points": minima,
    }


def _real_parts(fw, sets: list, groups: dict, report: dict, unit, tolerances) -> list:
    """Each taut set's rows from the real route's endpoints, (columns, system, solutions), with
    its line of run.json's taut sets."""
    from .analysis.framework_classify import framework_rows
    from .model.framework.compiled import framework_system

    parts = []
    for taut in sets + [g for g in groups if g not in sets]:
        eps = groups.get(taut)
        report[" ".join(taut) or "none"] = {"route": "real", "roots": len(eps or ())}
        if eps is not None:
            fs = framework_system(fw, taut)
            cols, x = framework_rows(fw, fs, eps, unit, tolerances)
            parts.append((cols, fs, x))
    return parts


def real_table(fw, groups: dict, tolerances: Tolerances) -> dict:
    """The rows (analysis.framework_checks.order_rows) of the real route's endpoints `groups`
    ({taut set: Endpoints}, a landscape's `endpoints`), classified as a solve's are."""
    from .analysis.framework_checks import order_rows
    from .model.framework.units import units

    parts = _real_parts(fw, [], groups, {}, units(fw), tolerances)
    return order_rows(fw, [p[0] for p in parts])


def along_continua(land, found, continua: list) -> int:
    """How many of the search's undecided boxes lie along a traced continuum: within the
    largest step between its traced points (in the body angles) of one of them. (Chart
    angles of spheres are not body angles: none is counted there.)"""
    if not continua or not len(found.undecided) or not land.bodies:
        return 0
    n = land.n
    mid = 0.5 * (found.undecided[:, :n] + found.undecided[:, n:])
    near = np.zeros(len(mid), dtype=bool)
    for c in continua:
        pts = np.radians(np.stack([c.columns[f"{b}.angle_deg"] for b in land.bodies], axis=1))
        gap = lambda a, b: np.abs((a - b + np.pi) % (2 * np.pi) - np.pi).max(axis=-1)  # noqa: E731
        step = gap(pts[1:], pts[:-1]).max() if len(pts) > 1 else 0.0
        near |= gap(mid[:, None, :], pts[None]).min(axis=1) <= step + 2 * MIN_WIDTH
    return int(near.sum())


def real_search_info(found, length_unit: float, along: int = 0, morse_bott: bool = False,
                     free: list | None = None) -> dict:  # fmt: skip
    """The real search's record for run.json: what was decided, set aside and left, and the
    warnings a search that is not a proof gives (`along`: undecided boxes that lie along a
    continuum of equilibria, which no box test can decide; `morse_bott`: every continuum has a
    nondegenerate Hessian across it; `free`: free_regions' regions of equilibria)."""
    warnings = []
    if len(found.undecided) > along:
        warnings.append(
            f"the real search left {len(found.undecided) - along} boxes undecided "
            f"({found.undecided_share:.3g} of the configuration space"
            f"{'; ' + found.budget_hit if found.budget_hit else ''}): equilibria may be missing "
            "there"
        )
    notes = []
    if along:
        # Along a curve of critical points whose Hessian across it is nondegenerate (checked
        # at every traced point: the continuum's Morse index) the Morse-Bott lemma leaves no
        # other critical point near it; where that index is unknown the boxes stay a warning.
        (notes if morse_bott else warnings).append(
            f"{along} boxes of the real search (no wider than {MIN_WIDTH:g} rad) lie along "
            "the continua of equilibria and stay undecided (V is constant along a continuum)"
            + ("; no other equilibrium lies there by the Morse-Bott lemma (each continuum's "
               "Hessian across it nondegenerate at its traced points)" if morse_bott else
               ": no other equilibrium is proved absent within them")
        )  # fmt: skip
    if found.newton_failed:
        warnings.append(f"{found.newton_failed} proved critical points not reached by Newton")
    free = free or []
    for r in free:
        if not r["witnessed"]:
            warnings.append(f"region {r['region']}: no pose of it was seen with every cable of "
                            f"{', '.join(r['free_nodes'])} slack (it may be empty)")  # fmt: skip
    if found.edge:
        warnings.append(f"{found.edge} boxes at the edges of regions of equilibria left "
                        "undecided (a cable there may be taut or slack)")  # fmt: skip
    return {
        "boxes": found.boxes,
        "seconds": round(found.seconds, 4),
        "cpu_seconds": round(found.cpu_seconds, 4),
        "shares": found.shares,
        "roots": len(found.roots),
        "set_aside": found.set_aside,
        "set_aside_longest_spring": found.set_aside_bound * length_unit,
        "shortest_spring": (
            None if not np.isfinite(found.shortest_length) else found.shortest_length * length_unit
        ),  # fmt: skip
        "undecided": len(found.undecided),
        "undecided_along_continua": along,
        "undecided_share": found.undecided_share,
        "undecided_boxes_deg": np.degrees(found.undecided[:20]).round(6).tolist(),
        "free_regions": free,
        "undecided_at_free_edges": found.edge,
        "warnings": warnings,
        "notes": notes,
    }


def cone_records(land, found, unit: tuple[float, float]) -> list[dict]:
    """The search's proved cone points (poses where a spring has zero length and V a critical
    point in Clarke's sense: boxsearch.cones), each with its spring, the body angles (deg), the
    other elements' pull there against the spring's k L0 (file units), and its index and kind
    (V falls across the cone set: a maximum in the plane of the spring's ends)."""
    n = land.n
    bodies = getattr(land, "bodies", None)
    out = []
    for row in found.cones:
        x = land.links[land.free_springs[int(row[n])]]
        angles = np.degrees(np.mod(row[:n], 2 * np.pi))
        index = int(row[n + 2])
        out.append({"spring": x.name, "pull": float(row[n + 1]) * unit[0] * unit[1],
                    "push": float(x.k * x.L0) * unit[0] * unit[1], "index": index,
                    "kind": "max" if index == n else "saddle",
                    "angles_deg": dict(zip(bodies, angles.round(10).tolist(), strict=True))
                    if bodies else angles.round(10).tolist()})  # fmt: skip
    return out


def free_regions(land, found, unit: tuple[float, float]) -> list[dict]:
    """The search's free pieces grouped into regions of equilibria: the same nodes free and
    the others at the same pose (to 1e-8); each with its free and held nodes, the held ones'
    coordinates (file units), V there (file units), its pieces, and whether a sampled pose of
    a piece has every cable of the free nodes slack (a pose of the region seen: `witnessed`)."""
    out: list[dict] = []
    if not len(found.free_boxes):
        return out
    X = land.positions(found.free_points)
    free_length = {x.name: x.L0 for x in land.links}
    floating = land.floating()
    for k, (mask, x) in enumerate(zip(found.free_masks, X, strict=True)):
        free = [i for i in range(len(land.nodes)) if mask[2 * i]]
        # V over the region: its free nodes' cables slack (the piece's middle may not be).
        cut = tuple(c for i in free for c in floating.get(i, []))
        v = land.energy(found.free_points[k : k + 1], cut)[0] * unit[1] * unit[0] ** 2
        held = [i for i in range(len(land.nodes)) if not mask[2 * i]]
        pose = np.concatenate([x[3 * i : 3 * i + 3] for i in held]) if held else np.zeros(0)
        slack = _witness(land, found, k, cut, free_length)
        same = next((r for r in out if r["free_nodes"] == [land.nodes[i] for i in free]
                     and np.abs(r["_pose"] - pose).max(initial=0) < 1e-8), None)  # fmt: skip
        if same is None:
            out.append({"region": len(out) + 1, "free_nodes": [land.nodes[i] for i in free],
                        "held_nodes": [land.nodes[i] for i in held],
                        "held_pose": (pose * unit[0]).round(12).tolist(), "energy": float(v),
                        "pieces": 1, "witnessed": slack, "_pose": pose})  # fmt: skip
        else:
            same["pieces"] += 1
            same["witnessed"] |= slack
    return [{k: v for k, v in r.items() if k != "_pose"} for r in out]


def _witness(land, found, k: int, cables: tuple[str, ...], L0: dict, tries: int = 64) -> bool:
    """Whether some pose of free piece k (its point, or its free angles drawn over the box, the
    others at its point) has every cable of `cables` slack: a pose of the region seen."""
    n = land.n
    box, x, mask = found.free_boxes[k], found.free_points[k], found.free_masks[k]
    u = np.random.default_rng(k).random((tries, n))
    pts = np.vstack([x, np.where(mask, box[:n] + u * (box[n:] - box[:n]), x)])
    lengths = land.cable_lengths(pts)
    return bool(np.all([lengths[c] < L0[c] for c in cables], axis=0).any())


def in_regions(land, points: np.ndarray, regions: list[dict], unit) -> np.ndarray:
    """Which points (Newton's, from undecided boxes) lie in a reported region of equilibria:
    its free nodes' cables all slack there and the other nodes at its pose (to 1e-7): rows of
    it, not equilibria apart."""
    out = np.zeros(len(points), dtype=bool)
    if not regions or not len(points):
        return out
    X, lengths = land.positions(points), land.cable_lengths(points)
    L0, floating = {x.name: x.L0 for x in land.links}, land.floating()
    for r in regions:
        free = [land.nodes.index(v) for v in r["free_nodes"]]
        held = [land.nodes.index(v) for v in r["held_nodes"]]
        slack = np.ones(len(points), dtype=bool)
        for i in free:
            for c in floating.get(i, []):
                slack &= lengths[c] < L0[c]
        pose = X[:, [3 * i + c for i in held for c in range(3)]]
        near = np.abs(pose - np.asarray(r["held_pose"]) / unit[0]).max(axis=1, initial=0) < 1e-7
        out |= slack & near
    return out


def taut_sets(fw) -> list[tuple[str, ...]]:
    """The subsets of the cables that can be taut together (all taut first), each its own
    polynomial system: a cable longer than its free length in every pose is in all of them, one
    never longer in none (model.framework.reach bounds the lengths over every pose), and a set
    no pose can hold is left out (pruned_taut_sets says which and why)."""
    return split_taut_sets(fw)[0]


def pruned_taut_sets(fw) -> dict:
    """The taut sets no pose can hold (model.framework.prune: bound smoothing), each with its
    proof (a prune.Pruned)."""
    return split_taut_sets(fw)[1]


def split_taut_sets(fw) -> tuple[list[tuple[str, ...]], dict]:
    """(taut_sets, pruned_taut_sets) from one pass of the pruning."""
    from .model.framework.prune import prune

    found = {t: prune(fw, t) for t in _cable_subsets(fw)}
    return [t for t, p in found.items() if p is None], {
        t: p for t, p in found.items() if p is not None
    }


def _cable_subsets(fw) -> list[tuple[str, ...]]:
    """Every subset of the cables reach.cable_states leaves open, with the always-taut ones."""
    from itertools import combinations

    from .model.framework.reach import cable_states

    states = cable_states(fw)
    always = tuple(n for n, s in states.items() if s == "taut")
    either = [n for n, s in states.items() if s == "either"]
    subsets = [c for r in range(len(either), -1, -1) for c in combinations(either, r)]
    order = [c.name for c in fw.cables]
    return [tuple(sorted(always + c, key=order.index)) for c in subsets]


def _solve_taut_set(fw, taut, unit, target, centre, settings, tolerances, t: Timings, warm):
    """One taut set: ((its rows, its system, their solutions) or None, what was done, the
    homotopy input text). `warm`: (the starts of a neighbouring point by system key, where this
    point's starts go)."""
    from .analysis.framework_checks import continuum_check
    from .analysis.framework_classify import framework_rows
    from .backends.target import solve_parameters
    from .model.framework.compiled import check_terms, framework_system, variable_groups

    with t.stage("derive"):
        fs = framework_system(fw, taut)
    if fs.free:
        # With these cables slack something moves freely: equilibria there form a continuum,
        # which matters only where every cable of the set can be slack at once.
        return None, continuum_check(fw, fs, unit), ""
    check_terms(fw, fs, target)  # a degenerate equation: refused, not solved
    with t.stage("solve"):
        hs = solve_parameters(
            fs.ps, target, centre, settings, variable_groups(fs), warm[0].get(fs.key)
        )
    if hs.warm is not None:
        warm[1][fs.key] = hs.warm
    with t.stage("classify"):
        cols, x = framework_rows(fw, fs, hs.endpoints, unit, tolerances)
    info = {**hs.info, "variables": list(fs.ps.variables), "functions": len(fs.ps.names)}
    return (cols, fs, x), info, hs.input_text


def _bertini_version() -> str:
    from .versions import bertini2_version

    return bertini2_version()
