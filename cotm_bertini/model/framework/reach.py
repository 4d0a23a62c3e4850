"""Bounds on the distance between two points over every pose: which cables are always taut.

Pins place bodies in a tree rooted at the ground. Walking from a point to the ground through
that tree, its position is a ground point plus one rigid vector per body on the way, each turned
by its body's rotation. The vector between two points is then a constant plus such vectors (a
body on both walks contributes the difference of its two vectors), whose lengths are fixed and
whose rotations are independent on an open chain: its length lies in [lo, hi] below, and
loops (pins that close them, bars) only remove poses, so the bounds stay valid.
"""

from __future__ import annotations

import math

from .spec import Framework, owner
from .structure import layout


def _walk(fw: Framework, point: str, placed: dict, vals: dict) -> tuple | None:
    """(ground coordinates, [(body, local vector)]) from the ground to `point`; None when the
    point's position is not tied to the ground by pins (a free node or body)."""
    steps = []
    while True:
        ent = owner(point)
        if ent == "ground":
            coords = dict(fw.ground)[point.split(".", 1)[1]]
            return [e.evaluate(vals) for e in coords], steps[::-1]
        if ent not in placed:
            return None
        entry, source = placed[ent]
        if ent in fw.nodes:
            point = source
            continue
        local = fw.body_points(ent)
        here = [e.evaluate(vals) for e in local[point.split(".", 1)[1]]]
        start = [e.evaluate(vals) for e in local[entry.split(".", 1)[1]]]
        steps.append((ent, [h - s for h, s in zip(here, start, strict=True)]))
        point = source


def length_bounds(fw: Framework, a: str, b: str) -> tuple[float, float]:
    """[lo, hi] containing |a - b| in every pose (0, inf when the pins do not tie them down)."""
    placed = {e: (pt, src) for e, pt, src in layout(fw).placed_by}
    vals = fw.values
    wa, wb = _walk(fw, a, placed, vals), _walk(fw, b, placed, vals)
    if wa is None or wb is None:
        return 0.0, math.inf
    const = [x - y for x, y in zip(wa[0], wb[0], strict=True)]
    vectors: dict[str, list[float]] = {}
    for sign, steps in ((1.0, wa[1]), (-1.0, wb[1])):
        for body, vec in steps:
            old = vectors.get(body, [0.0] * fw.dim)
            vectors[body] = [o + sign * v for o, v in zip(old, vec, strict=True)]
    radii = [math.hypot(*v) for v in vectors.values()]
    c = math.hypot(*const)
    total = sum(radii)
    lo = max([0.0, c - total] + [r - (total - r) - c for r in radii])
    return lo, c + total


def cable_states(fw: Framework) -> dict[str, str]:
    """Each cable: 'taut' (longer than L0 in every pose), 'slack' (never longer), or 'either'."""
    slots = fw.slots()
    out = {}
    for cable in fw.cables:
        lo, hi = length_bounds(fw, cable.a, cable.b)
        L0 = slots[f"L0_{cable.name}"]
        # A cable of zero free length pulls whenever its ends are apart: always taut (at d = 0
        # both models give no force).
        taut = lo > L0 or L0 == 0
        out[cable.name] = "taut" if taut else ("slack" if hi < L0 else "either")
    return out


def sphere_chain(fw: Framework) -> tuple[tuple[tuple[str, str, str], ...], str]:
    """((node, the point its bar hangs from, the bar), ...) in hanging order, when every free
    node of a spatial framework hangs by one bar from a ground point or from a node hung
    before it (each on a sphere about that point: a product of spheres), else ((), why not)."""
    lay = layout(fw)
    if fw.dim != 3 or fw.bodies or fw.pins:
        return (), "a spatial framework with bodies or pins (spheres of nodes on bars only)"
    if not lay.free_nodes:
        return (), "no free node"
    hung: dict[str, tuple[str, str]] = {}
    changed = True
    while changed:
        changed = False
        for bar in fw.bars:
            for top, node in ((bar.a, bar.b), (bar.b, bar.a)):
                held = owner(top) == "ground" or top in hung
                if held and node in lay.free_nodes and node not in hung:
                    hung[node], changed = (top, bar.name), True
    if len(hung) < len(lay.free_nodes):
        loose = [n for n in lay.free_nodes if n not in hung]
        return (), f"node {loose[0]} hangs by no bar from the ground (not a product of spheres)"
    if len(fw.bars) > len(hung):
        return (), "a bar closes a loop (not a product of spheres)"
    return tuple((n, top, bar) for n, (top, bar) in hung.items()), ""
