"""Nodes held by springs and cables alone (no bar, no body): their space is R^2 or R^3 each, and
the real route searches a box of it that provably holds every equilibrium.

The bound. Put the origin c at the mean of the ground points the nodes are linked to, and let
node i be the one farthest from it, at r = |x_i - c|, u = (x_i - c) / r. A link from it to a
ground point a (|a - c| <= rho) pulls it along -u by at least k (r - rho - L0) once
r > rho + L0 (its length d >= r - rho, (d - L0) / d grows with d, and (x_i - a) . u >= r - rho;
a cable the same or 0); a spring to another node j, no farther from c, pushes it out by at most
k L0 ((x_i - x_j) . u >= 0, and a compressed spring's push is k (L0 - d) (x_i - x_j) . u / d
<= k L0); a cable to it pulls it in or not at all; a load pushes it out by at most |F_i|. So
where

    r > (|F_i| + sum_ground k (rho + L0) + sum_springs to nodes k L0) / sum_ground k

the farthest node's force has a component along -u: no equilibrium. Every node then lies in the
ball of the largest such radius over the nodes, and each needs one link to the ground at least.
"""

from __future__ import annotations

import numpy as np

from ..model.framework.spec import Framework, owner
from ..model.framework.structure import layout

MARGIN = 1.01  # the bound widened by 1% (and by 1e-9): rounding never decides an edge


def free_nodes_only(fw: Framework) -> str:
    """'' where `fw`'s moving parts are nodes held by springs and cables alone, each linked to
    the ground at least once, else why not."""
    lay = layout(fw)
    if not lay.free_nodes:
        return "no free node"
    if lay.rotations or lay.translations or fw.bars:
        return "free nodes with bodies or bars (not yet on the real route)"
    grounded = {p for x in fw.links for p, q in ((x.a, x.b), (x.b, x.a))
                if owner(q) == "ground" and owner(p) != "ground"}  # fmt: skip
    loose = [v for v in lay.free_nodes if v not in grounded]
    if loose:
        return f"node {loose[0]} has no spring or cable to the ground (no bound on where it is)"
    for v in lay.free_nodes:
        mine = [x for x in fw.links if v in (x.a, x.b)]
        loaded = any(ld.point == v for ld in fw.loads)
        # Without a load, a node on cables alone floats over a region where all are slack,
        # and one on a single spring over a circle or sphere: boxes to the smallest width.
        if not loaded and (len(mine) < 2 or all(x.kind == "cable" for x in mine)):
            return (f"node {v} has no load and {len(mine)} link(s), "
                    f"{'all cables' if all(x.kind == 'cable' for x in mine) else 'one spring'}: "
                    "it may float over a region of equilibria")  # fmt: skip
    return ""


def reach(fw: Framework, slots: dict) -> tuple[np.ndarray, float]:
    """(c, R): every equilibrium has each node within R of c (normalised units, `slots` the
    framework's normalised slots; module docstring)."""
    dim = fw.dim
    axes = "xyz"[:dim]

    def ground(p: str) -> np.ndarray:
        g = p.split(".", 1)[1]
        return np.array([slots[f"g_{g}_{a}"] for a in axes])

    links = [x for x in fw.links if x.kind != "bar"]
    anchors = [ground(p) for x in links for p in (x.a, x.b) if owner(p) == "ground"]
    c = np.mean(anchors, axis=0)
    radius = 0.0
    for v in layout(fw).free_nodes:
        pull, out = 0.0, 0.0
        for x in links:
            if v not in (x.a, x.b):
                continue
            other = x.b if x.a == v else x.a
            k, L0 = slots[f"k_{x.name}"], slots[f"L0_{x.name}"]
            if owner(other) == "ground":
                pull += k
                out += k * (float(np.linalg.norm(ground(other) - c)) + L0)
            elif x.kind == "spring":
                out += k * L0
        force = np.zeros(dim)
        for ld in fw.loads:
            if ld.point == v:
                force += [slots[f"f_{ld.name}_{a}"] for a in axes]
        radius = max(radius, (float(np.linalg.norm(force)) + out) / pull)
    return c, MARGIN * radius + 1e-9
