"""The real route: a framework's real equilibria by the branch and bound of boxsearch over its
configuration space, classified as the homotopy's endpoints are, the search's proof (or what it
left undecided) the completeness check; and the paper's mechanism through its framework."""

from __future__ import annotations

import dataclasses
from functools import partial

import numpy as np

from ..backends.endpoints import Endpoints
from ..boxsearch.boxes import MIN_WIDTH
from ..model.compiled import parametric_system
from ..model.framework.taut_sets import split_taut_sets
from ..params import Params
from ..settings import Settings, Tolerances
from .result import STATUS_CONTRADICTION, STATUS_INCOMPLETE, STATUS_OK, PointSolution, Timings

SEEDS_AT_BUDGET = 512  # Newton starts in the boxes a search stopped by its budget left

DESCENTS = 64  # local descents from random poses when a search is stopped by its budget


def real_landscape(fw, t: Timings, only: str = "all") -> tuple:
    """(the real route's landscape of `fw` searching for `only`, its taut sets, those pruned),
    every taut set's equations derived and checked."""
    from ..boxsearch.real_route import landscape
    from ..model.framework.compiled import check_terms
    from ..model.framework.units import normalized_slots

    sets, pruned = split_taut_sets(fw)
    with t.stage("derive"):
        land = landscape(fw, only)
        target = normalized_slots(fw)
        for taut, fs in land.hessian_sets:  # derived (or loaded) here, not in the search's clock
            if taut in sets:
                check_terms(fw, fs, target)  # a degenerate equation: refused, not searched
    return land, sets, pruned


def solve_real(
    fw, settings: Settings, tolerances: Tolerances, t: Timings, ready=None, found=None
) -> PointSolution:
    """Every real equilibrium of a framework on a circle, torus or product of spheres, by the
    branch and bound of boxsearch.boxes over its configuration space, classified as the complex
    route's endpoints are; the search's proof (or what it left undecided) is the completeness
    check. Boxes left undecided are searched for continua of equilibria, traced and counted
    apart as on the complex route; regions where a node floats are reported apart. `ready` and
    `found`: the landscape (real_landscape) and its search, where already made."""
    from ..analysis.framework_checks import completeness, framework_counts, order_rows
    from ..analysis.framework_continua import absorb, continuum_record, find_continua
    from ..boxsearch.box_shares import deepened, split_search
    from ..boxsearch.boxes import SHORT
    from ..boxsearch.real_route import landscape
    from ..model.framework.units import units

    unit = units(fw)
    land, sets, pruned = ready or real_landscape(fw, t, settings.only)
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
    from ..boxsearch.minima import proved_minima
    from ..boxsearch.seeds import descent_minima

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
    from ..boxsearch.seeds import critical_seeds

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
    from ..boxsearch.seeds import descent_minima

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
    from ..analysis.framework_classify import framework_rows
    from ..model.framework.compiled import framework_system

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
    from ..analysis.framework_checks import order_rows
    from ..model.framework.units import units

    parts = _real_parts(fw, [], groups, {}, units(fw), tolerances)
    return order_rows(fw, [p[0] for p in parts])


def along_continua(land, found, continua: list) -> int:
    """How many of the search's undecided boxes lie along a traced continuum: within the
    largest step between its traced points (in the body angles) of one of them. (Chart
    coordinates of spheres and rotations are not body angles: none is counted there.)"""
    if not continua or not len(found.undecided) or not land.bodies or land.spatial:
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


def paper_real(params: Params, settings: Settings, tolerances: Tolerances, t: Timings):
    """The paper's mechanism by the real route: its framework (model.framework.paper) searched
    as any torus framework is (`solve_real`), each equilibrium then handed on as an endpoint of
    the paper's own system (c, s and the spring lengths d), so that it is refined, classified
    and Morse-checked as Bertini's endpoints are. The framework's own warnings (undecided
    boxes, its Morse count from the search's cone points) are kept beside the paper's checks."""
    from ..model.framework.paper import ANGLE_COLUMNS, paper_framework
    from ..model.kinematics import spring_vectors

    sol = solve_real(paper_framework(params), settings, tolerances, t)
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
