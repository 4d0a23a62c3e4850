"""Completeness of a framework solve: generic counts, lost paths, continua, the Morse count."""

from __future__ import annotations

import numpy as np

from ..backends.crossings import in_solve
from ..boxsearch.free_nodes import free_nodes_only
from ..boxsearch.loops import single_loop
from ..model.framework.compiled import FrameworkSystem, framework_system, slot_vector
from ..model.framework.spec import Framework
from ..model.framework.structure import layout
from ..model.framework.units import normalized_slots, units
from ..settings import Settings
from .framework_classify import column_names, positions

_GROUP_KEYS = ("physical", "is_real")
SWITCH_POSE_TOL = 1e-3  # two rows of one equilibrium at a switch: poses this close (length unit)


def order_rows(fw: Framework, parts: list[dict]) -> dict[str, np.ndarray]:
    """The rows of every taut set in one table (an equilibrium at a cable's switch found by two
    taut sets: one physical row, _merge_switch_pairs): physical, then real, then complex;
    within a group by energy, then by the pose columns; ids 1, 2, ... in that order."""
    names = column_names(fw)
    if not parts:
        return {n: np.zeros(0) for n in names}
    cols = {n: np.concatenate([p[n] for p in parts]) for n in names if n != "solution_id"}
    _merge_switch_pairs(fw, cols)
    group = np.where(cols["physical"], 0, np.where(cols["is_real"], 1, 2))
    pose = [np.round(cols[n], 9) for n in reversed(names[1:4]) if n in cols]
    order = np.lexsort((*pose, np.round(cols["energy"], 9), group))
    out = {"solution_id": np.arange(1, len(order) + 1)}
    out.update({n: cols[n][order] for n in names if n != "solution_id"})
    return out


def _merge_switch_pairs(fw: Framework, cols: dict) -> None:
    """An equilibrium with a cable within the borderline tolerance of its free length is found
    by both taut sets, with the cable taut and slack, both rows `degenerate` at nearly one pose
    (a count of two for one equilibrium). Of such a pair the row whose cable state holds (taut
    and not shorter than L0, or slack and not longer) stays physical, the taut one if both do;
    the other is kept as not physical, reason `switch_duplicate:<cable>` (in place)."""
    near = np.flatnonzero(cols["physical"] & (cols["kind"] == "degenerate"))
    if len(near) < 2:
        return
    unit = units(fw)[0]
    xyz = [n for n in cols if n.endswith((".x", ".y", ".z"))]
    pose = np.stack([cols[n][near] for n in xyz], axis=1) / unit
    sets = [set(cols["taut_set"][i].split()) for i in near]
    L0 = fw.slots()
    for a in range(len(near)):
        for b in range(a + 1, len(near)):
            (i, j), diff = near[[a, b]], sets[a] ^ sets[b]
            if len(diff) != 1 or np.abs(pose[a] - pose[b]).max() > SWITCH_POSE_TOL:
                continue
            (cable,) = diff
            if not (cols["physical"][i] and cols["physical"][j]):
                continue  # one of them already stands for a pair
            taut, slack = (i, j) if cable in sets[a] else (j, i)
            stretch = cols[f"{cable}.length"][[taut, slack]] - L0[f"L0_{cable}"]
            gone = taut if stretch[0] < 0 <= -stretch[1] else slack
            cols["physical"][gone] = cols["stable"][gone] = False
            cols["kind"][gone] = ""
            cols["reason"][gone] = f"switch_duplicate:{cable}"


def framework_counts(table: dict, report: dict, continua: list = ()) -> dict:
    """Paths tracked, endpoints and solution counts over every taut set (continua apart)."""
    solved = [r for r in report.values() if "tracked" in r]
    return {
        "paths_tracked": sum(r["tracked"] for r in solved),
        "finite_endpoints": sum(r["finite"] for r in solved),
        "closed_form_endpoints": 0,
        "infinite_or_failed_paths": sum(r["tracked"] - r["finite"] for r in solved),
        "lost_paths": sum(r["lost"] for r in solved),
        "crossings_unresolved": sum(in_solve(r) for r in solved),
        "generic_paths": sum(r["generic_paths"] for r in solved),
        "distinct_solutions": len(table["solution_id"]),
        "real": int(np.sum(table["is_real"])),
        "physical": int(np.sum(table["physical"])),
        "stable": int(np.sum(table["stable"])),
        "singular": int(np.sum(table["singular"])),
        # On the real route every kept taut set is covered by the one search.
        "taut_sets_solved": len(solved) + sum(r.get("route") == "real" for r in report.values()),
        "taut_sets_continuum": sum(
            "tracked" not in r and "pruned" not in r and "route" not in r for r in report.values()
        ),
        "taut_sets_pruned": sum("pruned" in r for r in report.values()),
        "continua": len(continua),
    }


def completeness(
    fw: Framework,
    table: dict,
    report: dict,
    continua: list = (),
    near_cones=None,
    cones=None,
    morse: bool = True,
) -> dict:
    """Why no equilibrium is missing, or warnings saying why one may be: {"morse", "warnings"}
    (`continua`: analysis.framework_continua's, each a term of the Morse sum; `cones`: the
    real search's proved cone points, each a term; `morse` False: the rows are the minima
    alone, and the Morse sum does not apply)."""
    warnings = []
    for label, info in report.items():
        if info.get("route") == "real":  # the search's own record says what it left
            continue
        if "tracked" not in info:
            if not info["excluded"]:
                warnings.append(f"taut set {label}: {info['note']}")
            continue
        counts = info["generic_counts"]
        if len(set(counts)) > 1:
            warnings.append(
                f"taut set {label}: two independent generic solves disagree "
                f"({counts[0]} vs {counts[1]} roots)"
            )
        warnings += [f"taut set {label}: {w}" for w in info.get("generic_warnings", [])]
        if info["lost"]:
            warnings.append(f"taut set {label}: {info['lost']} paths lost")
        if info.get("crossings_unresolved"):  # (a generic set's: in its generic_warnings)
            warnings.append(
                f"taut set {label}: {info['crossings_unresolved']} of them crossed another "
                "path and the solver could not part them: the affected solutions may be wrong"
            )
        if info["generic_singular"]:
            warnings.append(
                f"taut set {label}: {info['generic_singular']} singular endpoints at generic "
                "parameters (a positive-dimensional solution set, not enumerated)"
            )
    if not morse:
        reason = "only the stable equilibria were searched for (no saddle or maximum)"
        return {"morse": {"applicable": False, "ok": None, "reason": reason},
                "warnings": warnings}  # fmt: skip
    morse = morse_count(fw, table, continua, near_cones, cones)
    if morse.get("continuum_unknown"):
        warnings.append(f"{morse['reason']}: the Morse check is not applicable, so equilibria "
                        "may be missing")  # fmt: skip
    if morse["applicable"] and not morse["ok"]:
        total, chi, space = morse["euler_characteristic"], morse["expected"], morse["manifold"]
        parts = [f"Morse count {total} != {chi}, the Euler characteristic of {space}"] * (
            total != chi
        )
        parts += [f"{morse['degenerate']} degenerate"] * bool(morse["degenerate"])
        none = not (morse["min"] or morse["continua_minima"])
        parts += [f"no minimum, though V has one on the compact {space}"] * none
        warnings.append("; ".join(parts) + ": equilibria may be missing")
        morse["failure"] = "; ".join(parts)
    return {"morse": morse, "warnings": warnings}


def configuration_space(fw: Framework) -> tuple[list[str], str]:
    """The factors of the configuration space when it is a closed manifold the Morse count
    applies to (S1 per planar body and SO3 per spatial body of a pinned open chain, a sphere per
    node hung from a placed point by one bar, "loop" for a four-bar's circles, R2 or R3 per node
    held by springs and cables alone), else ([], why not)."""
    lay = layout(fw)
    if not free_nodes_only(fw):
        # Nodes held by springs and cables alone: the product of balls boxsearch.free_nodes
        # bounds them in, where the gradient points out at the boundary (chi 1).
        return ["R2" if fw.dim == 2 else "R3" for _ in lay.free_nodes], ""
    if lay.closing_pins and not lay.translations and not single_loop(fw):
        # One loop of one degree of freedom: where no pose is singular its poses are one or
        # two circles (a four-bar's assembly branches), Euler characteristic 0 either way.
        return ["loop"], ""
    if lay.translations or lay.closing_pins:
        return [], "a body is not pinned to the ground or a pin closes a loop"
    factors = ["S1" if fw.dim == 2 else "SO3" for _ in lay.rotations]
    # Free nodes hang by bars, one each, from a placed point or from a node hung before them
    # (a two-stage tower): a sphere (circle) each about a point that moves with the ones above.
    free, hung, left = set(lay.free_nodes), set(), list(fw.bars)
    while left:
        bar = next((b for b in left for top, node in ((b.a, b.b), (b.b, b.a))
                    if node in free - hung and (top not in free or top in hung)), None)  # fmt: skip
        if bar is None:
            return [], f"bar {left[0].name} closes a loop"
        hung |= {p for p in (bar.a, bar.b) if p in free}
        left.remove(bar)
    if hung != free:
        return [], "a node is not hung from a placed point by exactly one bar"
    factors += ["S1" if fw.dim == 2 else "S2" for _ in hung]
    return factors, ""


def _collapsible(fw: Framework) -> list[str]:
    """Springs with a free length whose ends may meet (V has a cone point there)."""
    from ..model.framework.reach import length_bounds

    slots = fw.slots()
    return [x.name for x in fw.springs
            if slots[f"L0_{x.name}"] > 0 and length_bounds(fw, x.a, x.b)[0] <= 0]  # fmt: skip


def morse_count(fw: Framework, table: dict, continua: list = (), near_cones=None,
                cones: list | None = None) -> dict:  # fmt: skip
    """sum (-1)^index over the physical equilibria (plus the cone points', plus each
    continuum's term: docs/frameworks.md) must equal the Euler characteristic of the
    configuration space: 0 for a torus, 2^n for n spheres S2. `cones`: the real search's cone
    points (each with its index), where it proved them all; else, on a two-body torus, the
    zero-length maxima solved here (cone_points)."""
    factors, why = configuration_space(fw)
    if not factors:
        return {"applicable": False, "ok": None, "reason": why or "nothing moves"}
    terms = [c.morse() for c in continua]
    for n, (term, why) in enumerate(terms, start=1):
        if term is None:
            why = f"continuum {n} ({why}) has no known term in the Morse sum"
            return {"applicable": False, "ok": None, "continuum_unknown": True, "reason": why}
    torus2 = factors == ["S1", "S1"] and fw.dim == 2
    collapsible = _collapsible(fw)
    aside = near_cones is not None and len(near_cones) > 0
    if collapsible and (cones is None or aside) and not torus2:
        return {"applicable": False, "ok": None, "reason": f"spring {collapsible[0]} may reach "
                "zero length (a cone point of V the count cannot place)"}  # fmt: skip
    chi = int(np.prod([{"S1": 0, "SO3": 0, "S2": 2, "loop": 0, "R2": 1, "R3": 1}[f]
                       for f in factors]))  # fmt: skip
    phys = np.asarray(table["physical"], dtype=bool)
    kinds = np.asarray(table["kind"], dtype=object)[phys]
    index = np.asarray(table["index"], dtype=int)[phys]
    counts = {k: int((kinds == k).sum()) for k in ("min", "saddle", "max", "degenerate")}
    if cones is not None and not aside:
        cone_terms = [(-1) ** int(c["index"]) for c in cones]
        maxima = sum(int(c["index"]) == len(factors) for c in cones)
    else:
        found = cone_points(fw, near_cones) if torus2 else []
        maxima = sum(c["is_max"] for c in found)
        cone_terms = [(-1) ** len(factors)] * maxima
    total = int(sum((-1) ** int(i) for i, k in zip(index, kinds, strict=True) if k != "degenerate"))
    total += sum(cone_terms) + sum(t for t, _ in terms)
    # V is continuous on the compact configuration space: its global minimum is an equilibrium
    # (a cone point is a maximum), so a table without a minimum (isolated or a continuum of
    # minima) misses equilibria, whatever the alternating sum says (an empty table sums to 0).
    minima = sum(c.index == 0 for c in continua)
    ok = total == chi and counts["degenerate"] == 0 and counts["min"] + minima > 0
    return {"applicable": True, "manifold": " x ".join(factors), "expected": chi, **counts,
            "zero_length_maxima": maxima, "cone_points": len(cone_terms),
            "continua": len(continua), "continua_minima": minima,
            "continua_term": sum(t for t, _ in terms), "euler_characteristic": total,
            "ok": ok}  # fmt: skip


def cone_points(fw: Framework, near: np.ndarray | None = None) -> list[dict]:
    """Real poses of a two-body planar torus where a spring with L0 > 0 has zero length; each is
    a local maximum of V (a cone) when the other elements' pull there is weaker than k L0.
    Solved by Bertini, or, given `near` (angle boxes (A, 4) as lo1, lo2, hi1, hi2 in radians that
    hold every such pose: the real search's boxes set aside), by Newton from their middles."""
    fs = framework_system(fw, tuple(c.name for c in fw.cables))
    if not fs.cones:
        return []
    from ..backends.homotopy import ab_initio

    slots_n = normalized_slots(fw)
    found = []
    for name, ps in fs.cones.items():
        if near is None:
            points = ab_initio(ps, {n: slots_n[n] for n in ps.parameters}, Settings())[0].points
        else:
            points = _cones_near(fw, ps, slots_n, near)
        for pose in points:
            if np.abs(pose.imag).max() > 1e-8:
                continue
            pull, push = _cone_pull(fw, fs, name, pose.real, slots_n)
            found.append({"spring": name, "pose": pose.real.tolist(), "pull": pull,
                          "push": push, "is_max": pull < push})  # fmt: skip
    return found


def _cones_near(fw: Framework, ps, slots_n: dict, near: np.ndarray) -> np.ndarray:
    """The zero-length poses of one spring (system `ps`) that Newton reaches from the middles of
    the boxes `near` (lo1, lo2, hi1, hi2 rad), each once."""
    from ..boxsearch.seeds import coarse_pick
    from ..model.framework.structure import layout
    from .refine import newton_refine

    bodies = layout(fw).rotations
    n = len(bodies)
    near = coarse_pick(near, 64) if len(near) else near  # one a cell: each cone point's cluster
    mid = 0.5 * (near[:, :n] + near[:, n:]) if len(near) else np.zeros((0, n))
    x0 = np.zeros((len(mid), len(ps.variables)), dtype=complex)
    for k, v in enumerate(ps.variables):
        head, _, body = v.partition("_")
        x0[:, k] = (np.cos if head == "c" else np.sin)(mid[:, bodies.index(body)])
    system = ps.instantiate([slots_n[n] for n in ps.parameters])
    x, res = newton_refine(system, x0, 12)
    found: list[np.ndarray] = []
    for pose in x[res < 1e-10]:
        if all(np.abs(pose - f).max() > 1e-8 for f in found):
            found.append(pose)
    return np.array(found).reshape(-1, len(ps.variables))


def _cone_pull(fw, fs: FrameworkSystem, name: str, pose, slots_n) -> tuple[float, float]:
    """|J^-T g| (g: every other element's energy gradient) and k L0 of the collapsed spring."""
    X = np.zeros((1, len(fs.ps.variables)))
    X[0, : len(pose)] = pose
    P = np.array(list(slots_n.values()))[None, :]
    vals = [float(np.asarray(v).reshape(-1)[0]) for v in fs.numeric.first_order(X, P)]
    m, dim = fs.local_size, fw.dim
    grad, jac = np.array(vals[-m:]), None
    for k, link in enumerate(fs.active):
        block = vals[k * (dim + dim * m) : (k + 1) * (dim + dim * m)]
        r, J = np.array(block[:dim]), np.array(block[dim:]).reshape(dim, m)
        if link == name:
            jac = J
            continue
        length = float(np.linalg.norm(r))
        L0 = slots_n[f"L0_{link}"]
        stretch = length - L0
        if any(c.name == link for c in fw.cables):
            stretch = max(stretch, 0.0)
        if length > 0:
            grad = grad + slots_n[f"k_{link}"] * stretch / length * (J.T @ r)
    push = slots_n[f"k_{name}"] * slots_n[f"L0_{name}"]
    return float(np.linalg.norm(np.linalg.solve(jac.T, grad))), float(push)


def continuum_check(fw: Framework, fs: FrameworkSystem, unit: tuple[float, float]) -> dict:
    """Whether a taut set whose equations leave a direction free can hold at all: it needs every
    other cable slack at once. On a circle or torus this is decided on a grid with a Lipschitz
    margin (a proof that no pose has them all slack); elsewhere it is not decided."""
    slack = [c for c in fw.cables if c.name not in fs.taut]
    lay = layout(fw)
    if not slack:
        return {"excluded": False, "note": f"nothing resists {fs.free[0]}: a continuum"}
    if fw.dim != 2 or not lay.is_torus:
        return {"excluded": False, "note": f"with {', '.join(c.name for c in slack)} slack, "
                f"nothing resists {fs.free[0]}: a possible continuum, not enumerated"}  # fmt: skip
    n = len(lay.rotations)
    steps = {1: 7200, 2: 720}.get(n, 60)
    h = 2 * np.pi / steps
    axes = np.meshgrid(*([np.arange(steps) * h] * n), indexing="ij")
    X = np.zeros((axes[0].size, len(fs.ps.variables)))
    for k, theta in enumerate(axes):
        X[:, 2 * k], X[:, 2 * k + 1] = np.cos(theta.ravel()), np.sin(theta.ravel())
    slots = fw.slots()
    where = positions(fs, X, slot_vector(normalized_slots(fw)), 2, unit[0])
    where = {p: v.real for p, v in where.items()}
    excess = np.max([np.linalg.norm(where[c.a] - where[c.b], axis=1) - slots[f"L0_{c.name}"]
                     for c in slack], axis=0)  # fmt: skip
    margin = n * _radius_sum(fw) * h
    excluded = bool((excess > margin).all())
    what = ", ".join(c.name for c in slack)
    note = (f"no pose has {what} all slack (grid of {steps}^{n} poses, Lipschitz margin "
            f"{margin:.3g}: proved)" if excluded else
            f"{what} can all be slack: nothing then resists {fs.free[0]}, a continuum of "
            "equilibria may exist (not enumerated)")  # fmt: skip
    return {"excluded": excluded, "note": note, "min_excess": float(excess.min())}


def _radius_sum(fw: Framework) -> float:
    """Sum over bodies of the largest distance between two of its points (a lever-arm bound)."""
    vals, total = fw.values, 0.0
    for _, pts in fw.bodies:
        xy = np.array([[e.evaluate(vals) for e in c] for _, c in pts])
        total += float(np.max(np.linalg.norm(xy[:, None] - xy[None], axis=2)))
    return total
