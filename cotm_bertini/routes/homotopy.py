"""The homotopy route: Bertini 2 in-process, a parameter homotopy from a cached generic set, of
the paper's system (`paper_homotopy`) or of each taut set of a framework (`solve_complex`)."""

from __future__ import annotations

from ..backends.crossings import in_solve
from ..model.framework.taut_sets import split_taut_sets
from ..params import Params
from ..settings import Settings, Tolerances
from .result import STATUS_INCOMPLETE, STATUS_OK, PointSolution, Timings


def paper_homotopy(params: Params, settings: Settings, ps, t: Timings, warm) -> tuple:
    """The paper's system by the parameter homotopy from its generic set (`warm`: a
    neighbouring point's, to continue from): its endpoints and what produced them."""
    from ..backends.target import solve_target

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


def solve_taut_set(fw, taut, unit, target, centre, settings, tolerances, t: Timings, warm):
    """One taut set: ((its rows, its system, their solutions) or None, what was done, the
    homotopy input text). `warm`: (the starts of a neighbouring point by system key, where this
    point's starts go)."""
    from ..analysis.framework_checks import continuum_check
    from ..analysis.framework_classify import framework_rows
    from ..backends.target import solve_parameters
    from ..model.framework.compiled import check_terms, framework_system, variable_groups

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


def bertini_version() -> str:
    """The bertini module's version."""
    from ..versions import bertini2_version

    return bertini2_version()


def solve_complex(fw, settings: Settings, tolerances: Tolerances, t: Timings, warm=None):
    """Every equilibrium of a framework: each taut set of its cables solved by the parameter
    homotopy, classified, checked for completeness, in one table. `warm` (the `warm` of a
    neighbouring point's solution: a start per taut set) lets a sweep continue each taut set
    from that point by Newton (backends.target.solve_parameters)."""
    from ..analysis.framework_checks import completeness, framework_counts, order_rows
    from ..analysis.framework_continua import absorb, continuum_record, find_continua
    from ..model.framework.units import normalized_slots, units

    unit = units(fw)
    target, centre = normalized_slots(fw), normalized_slots(fw.at_defaults())
    parts, report, texts, starts = [], {}, [], {}
    sets, pruned = split_taut_sets(fw)
    for taut, why in pruned.items():  # not solved: no consistent equilibrium
        report[" ".join(taut) or "none"] = {"excluded": True, "pruned": "bound smoothing",
                                           "note": why.note()}  # fmt: skip
    for taut in sets:
        part, info, text = solve_taut_set(
            fw, taut, unit, target, centre, settings, tolerances, t, (warm or {}, starts)
        )
        report[" ".join(taut) or "none"] = info
        if part is not None:
            parts.append(part)
            texts.append(text)
    with t.stage("classify"):
        # Rows on a curve of equilibria are that curve's points, counted apart.
        continua = find_continua(fw, parts, unit, tolerances)
        absorb(parts, continua)
        table = order_rows(fw, [p[0] for p in parts])
        checks = completeness(fw, table, report, continua)
    counts = framework_counts(table, report, continua)
    status = STATUS_INCOMPLETE if checks["warnings"] else STATUS_OK
    engine = {"flavour": "homotopy", "path": "bertini module (in-process)",
              "version": bertini_version()}  # fmt: skip
    shape = {"taut_sets": list(report), "units": {"length": unit[0], "stiffness": unit[1]}}
    return PointSolution(
        fw, settings, table, None, counts, checks["morse"], status, tuple(checks["warnings"]),
        engine, shape, {"taut_sets": report}, "\n".join(texts), t.stages, starts,
        tuple(continuum_record(c, n) for n, c in enumerate(continua, start=1)),
    )  # fmt: skip
