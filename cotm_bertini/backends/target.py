"""One target solved by the homotopy engine: from a neighbour if one is given, else from the
generic set (with its fallbacks), plus the closed-form d = 0 roots."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..model.polynomial import ParametricSystem
from ..params import Params
from ..settings import Settings
from .endpoints import Endpoints
from .generic import disagreements, evidence_sets, generic_for, incomplete_sets, route_of
from .homotopy import (
    SECOND_START,
    GenericSet,
    ab_initio,
    route_record,
    track,
    zero_length_roots,
)
from .neighbour import WarmStart, continue_from, newton_continue


@dataclass(frozen=True)
class HomotopySolve:
    """Every finite endpoint at a target and how the homotopy got there."""

    endpoints: Endpoints  # tracked endpoints, then the closed-form d = 0 roots
    info: dict
    generic: GenericSet
    input_text: str
    warm: WarmStart | None = None  # this target as a start for a neighbouring one


def solve_target(
    ps: ParametricSystem,
    params: Params,
    settings: Settings = Settings(),
    warm: WarmStart | None = None,
) -> HomotopySolve:
    """Every finite endpoint at `params` (tracked ones plus the closed-form d = 0 artefacts).

    With `warm` (a neighbouring real point of the same structure, solved completely), its
    solutions are continued to `params` (see `continue_from`); if that fails a check, the point
    is solved from the generic set as without it. From the generic set: a lost path, or fewer
    finite endpoints than the generic count, sends the point to a second, independent generic
    set (a new random start, like Paramotopy's new gamma); if that does not settle it, the target
    is solved ab initio. `info["method"]` says which route, `info["lost"]` how many paths were
    lost.

    The target is solved in units of L3 and max(k1, k2) (equilibria do not change when every
    length, or every stiffness, is scaled), so the paths see numbers of order one whatever the
    user's units; the spring lengths are scaled back.
    """
    deadline = None if settings.timeout is None else time.perf_counter() + settings.timeout
    # "both": the total-degree set of the same seed too, its count the cross-check; the
    # default route: the total-degree sets when the monodromy one failed its trace test.
    if route_of(settings) == "total-degree":
        sets = (generic_for(ps, settings.seed, settings),)
    else:
        sets = evidence_sets(ps, settings)
    gs = sets[0]
    unit = params.normalized()
    result, note = None, ""
    if warm is not None:
        result, note = newton_continue(ps, gs, warm, params)
        if result is None:
            result, note = continue_from(ps, gs, warm, params, settings, deadline)
    if result is None:
        result = from_generic(ps, gs, unit, settings, deadline)
        if note:
            result[1]["method"] += f" ({note})"
    endpoints, info, text = result
    complete = info["lost"] == 0 and info["finite"] == len(gs.points)
    warm_next = None
    if complete:  # from a neighbour, the solutions come in its order: a secant start next
        continued = warm is not None and info["method"].startswith(("Newton", "continued"))
        if continued:
            warm_next = warm.next_to(params, endpoints.points, gs.key)
        else:
            warm_next = WarmStart(params, endpoints.points, gs.key)
    is_d = np.array([v.startswith("d") for v in ps.variables])
    scaled = np.where(is_d, endpoints.points * params.L3, endpoints.points)
    endpoints = endpoints.with_points(scaled)
    info.update(
        units={"length": params.L3, "stiffness": max(params.k1, params.k2)},
        generic_key=gs.key,
        generic_paths=gs.paths,
        generic_finite=gs.finite_endpoints,
        generic_route=route_record(list(sets), settings.scheduler),
        generic_warnings=incomplete_sets(sets) + disagreements(sets),
    )
    closed = zero_length_roots(params, ps.variables)
    return HomotopySolve(endpoints.concat(closed), info, gs, text, warm_next)


def from_generic(
    ps,
    gs: GenericSet,
    unit,
    settings: Settings,
    deadline,
    centre: dict | None = None,
    groups: list[list[str]] | None = None,
) -> tuple:
    """Track the generic set to the (normalised) target, with the fallbacks of solve_target:
    (endpoints, info, homotopy input text). `unit`: a Params or a mapping of parameter values;
    `centre`: the generic sets' start centre (default: the paper's)."""
    endpoints, rep = track(ps, gs, unit, settings, deadline)
    method = "parameter homotopy" + (" + adaptive retrack" if rep.retracked_adaptive else "")
    if rep.lost or rep.finite < len(gs.points):
        gs2 = generic_for(ps, settings.seed + SECOND_START, settings, centre, groups)
        endpoints2, rep2 = track(ps, gs2, unit, settings, deadline)
        if rep2.lost == 0 and not rep.lost and rep2.finite == rep.finite:
            method += "; finite count confirmed from a second start"
        elif rep2.lost == 0 and rep2.finite >= rep.finite and len(gs2.points) >= len(gs.points):
            # (a second set with fewer roots, an incomplete one, proves nothing)
            endpoints, rep = endpoints2, rep2
            method = "parameter homotopy from a second start (the first lost paths)"
        else:
            endpoints, rep = ab_initio(ps, unit, settings)
            method = "ab initio (both parameter homotopies lost paths)"
    return endpoints, {**rep.as_dict(), "method": method}, rep.input_text


def solve_parameters(
    ps: ParametricSystem,
    target: dict[str, float],
    centre: dict[str, float],
    settings: Settings = Settings(),
    groups: list[list[str]] | None = None,
    warm: WarmStart | None = None,
) -> HomotopySolve:
    """Every finite endpoint of `ps` at `target` (normalised parameter values), from the generic
    set around `centre`, with the fallbacks of solve_target; a second, independent generic set
    is solved too when the route asks for one (backends.generic.evidence_sets), the counts
    recorded (`info["generic_counts"]`): the trace test of the monodromy set, or two sets that
    agree, are the completeness evidence of a framework solve.
    `groups`: variable groups of a multihomogeneous start for the ab-initio solves. `warm`: a
    neighbouring point's complete set (a sweep): Newton from it first, accepted only when it
    proves the set complete (`newton_continue`), else the generic set as without it."""
    deadline = None if settings.timeout is None else time.perf_counter() + settings.timeout
    centre = {n: centre[n] for n in ps.parameters}
    sets = evidence_sets(ps, settings, centre, groups)
    gs = sets[0]
    result, note = (None, "") if warm is None else newton_continue(ps, gs, warm, target)
    if result is not None:
        endpoints, info, text = result
    elif ps.parameters:
        endpoints, info, text = from_generic(ps, gs, target, settings, deadline, centre, groups)
        if note:
            info["method"] += f" ({note})"
    else:  # nothing to move: the generic set is the answer
        records = [{"path_number": k, "coords": p} for k, p in enumerate(gs.points)]
        endpoints = Endpoints.from_records(ps.variables, records)
        info = {
            "tracked": gs.paths,
            "finite": len(records),
            "infinite": gs.paths - gs.finite_endpoints,
            "retracked_adaptive": 0,
            "lost": 0,
            "method": "ab initio (the system has no parameters)",
            "seconds": gs.seconds,
            "notes": "",
        }
        text = ""
    info.update(
        generic_key=gs.key,
        generic_paths=gs.paths,
        generic_finite=gs.finite_endpoints,
        generic_singular=gs.singular_endpoints,
        generic_counts=[len(g.points) for g in sets],
        generic_route=route_record(list(sets), settings.scheduler),
        generic_warnings=incomplete_sets(sets),
    )
    return HomotopySolve(endpoints, info, gs, text, _next_start(gs, warm, target, endpoints, info))


def _next_start(gs: GenericSet, warm, target, endpoints: Endpoints, info: dict):
    """This target as a start for the next point of a sweep, when its set is complete (in the
    warm start's order when continued from it: a secant start next)."""
    if info["lost"] or info["finite"] != len(gs.points) or len(endpoints) != len(gs.points):
        return None
    if warm is not None and info["method"].startswith("Newton"):
        return warm.next_to(dict(target), endpoints.points, gs.key)
    return WarmStart(dict(target), endpoints.points, gs.key)
