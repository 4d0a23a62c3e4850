"""Taut sets that no pose can hold, decided without solving them (issue 29, item 1).

A taut set asks every cable in it to be at least its free length and every other cable at
most its own. Together with what the pins, bodies, bars and ground fix, that bounds the
distance between every two points of the framework from below and above. Triangle inequality
bound smoothing (as in distance geometry: Crippen and Havel) tightens the bounds, each new one
implied by two others:

    up(i, j) <= up(i, k) + up(k, j)        lo(i, j) >= lo(i, k) - up(k, j)

Every bound so derived holds in every pose that satisfies the inputs, in any dimension. So a
pair whose lower bound exceeds its upper one proves that no pose satisfies them all: the set
has no consistent equilibrium, and solving it could only add rows that are not physical. The
proof is named in run.json (the pair, the two bounds, and the chain of elements behind each).

Inputs, each exact (up to the floats of the file): points joined by a pin coincide; two points
of one body, or of the ground, are at their fixed distance; a bar's ends at its length; the
reach bounds of model/framework/reach.py (over the pinned tree) for every pair they cover;
springs add nothing (two-sided). A cable that could never be taut or slack is already decided
by reach.cable_states, before any set is formed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import combinations

from .reach import length_bounds
from .spec import Framework

SLACK_TOL = 1e-9  # relative: a lower bound must beat the upper one by this to prove anything


@dataclass(frozen=True)
class Pruned:
    """Why no pose holds a taut set: the pair whose bounds cross, and why each holds."""

    a: str
    b: str
    lower: float
    upper: float
    lower_chain: tuple[str, ...]
    upper_chain: tuple[str, ...]

    def note(self) -> str:
        """One line for run.json."""
        return (
            f"no pose holds it (bound smoothing): |{self.a} - {self.b}| >= {self.lower:.6g} "
            f"by {' + '.join(self.lower_chain)}, <= {self.upper:.6g} by "
            f"{' + '.join(self.upper_chain)}"
        )


def points(fw: Framework) -> list[str]:
    """Every named point: the ground's, each body's, the nodes."""
    out = [f"ground.{n}" for n, _ in fw.ground]
    for body, pts in fw.bodies:
        out += [f"{body}.{n}" for n, _ in pts]
    return out + list(fw.nodes)


def _fixed(fw: Framework) -> dict[tuple[str, str], tuple[float, str]]:
    """Distances every pose keeps: (pair) -> (distance, why)."""
    vals, out = fw.values, {}
    frames = [("ground", list(fw.ground))] + [(b, list(p)) for b, p in fw.bodies]
    for owner_name, pts in frames:
        coords = {f"{owner_name}.{n}": [e.evaluate(vals) for e in c] for n, c in pts}
        for p, q in combinations(coords, 2):
            out[p, q] = (math.dist(coords[p], coords[q]), f"{owner_name} rigid")
    for p, q in fw.pins:
        out[p, q] = (0.0, f"pin {p}={q}")
    for bar in fw.bars:
        out[bar.a, bar.b] = (bar.length.evaluate(vals), f"bar {bar.name}")
    return out


def prune(fw: Framework, taut: tuple[str, ...]) -> Pruned | None:
    """Why no pose holds taut set `taut` (its cables at least their free lengths, the others
    at most theirs), or None when bound smoothing finds no contradiction (which proves
    nothing: the set is then solved)."""
    names = points(fw)
    index = {p: k for k, p in enumerate(names)}
    n = len(names)
    lo = [[0.0] * n for _ in range(n)]
    up = [[0.0 if i == j else math.inf for j in range(n)] for i in range(n)]
    why_lo = [[()] * n for _ in range(n)]
    why_up = [[()] * n for _ in range(n)]

    def bound(p: str, q: str, low: float, high: float, why: str) -> None:
        i, j = index[p], index[q]
        for a, b in ((i, j), (j, i)):
            if low > lo[a][b]:
                lo[a][b], why_lo[a][b] = low, (why,)
            if high < up[a][b]:
                up[a][b], why_up[a][b] = high, (why,)

    for (p, q), (d, why) in _fixed(fw).items():
        bound(p, q, d, d, why)
    for p, q in combinations(names, 2):
        low, high = length_bounds(fw, p, q)
        bound(p, q, low, high, "the pinned tree's reach")
    slots = fw.slots()
    for c in fw.cables:
        L0 = slots[f"L0_{c.name}"]
        if c.name in taut:
            bound(c.a, c.b, L0, math.inf, f"cable {c.name} taut")
        else:
            bound(c.a, c.b, 0.0, L0, f"cable {c.name} slack")
    _smooth(lo, up, why_lo, why_up)
    return _crossing(names, lo, up, why_lo, why_up)


def _smooth(lo: list, up: list, why_lo: list, why_up: list) -> None:
    """Triangle bound smoothing in place, repeated until nothing tightens: through every third
    point k, up(i, j) <= up(i, k) + up(k, j) and lo(i, j) >= lo(i, k) - up(k, j) (each pair
    kept symmetric, so both orders of i, j give the two lower-bound rules)."""
    n = len(lo)

    def tighten(i: int, j: int, k: int) -> bool:
        changed = False
        through = up[i][k] + up[k][j]
        if through < up[i][j] * (1 - SLACK_TOL) - SLACK_TOL:
            up[i][j] = up[j][i] = through
            why_up[i][j] = why_up[j][i] = why_up[i][k] + why_up[k][j]
            changed = True
        low = lo[i][k] - up[k][j]
        if low > lo[i][j] * (1 + SLACK_TOL) + SLACK_TOL:
            lo[i][j] = lo[j][i] = low
            why_lo[i][j] = why_lo[j][i] = why_lo[i][k] + tuple(f"-({w})" for w in why_up[k][j])
            changed = True
        return changed

    for _ in range(n + 1):
        changed = False
        for k in range(n):
            for i in range(n):
                for j in range(n):
                    if i != j and k not in (i, j):
                        changed = tighten(i, j, k) or changed
        if not changed:
            return


def _crossing(names, lo, up, why_lo, why_up) -> Pruned | None:
    """The pair whose bounds cross by the most (relative), if any."""
    best, found = 0.0, None
    for i, j in combinations(range(len(names)), 2):
        gap = lo[i][j] - up[i][j]
        scale = max(1.0, abs(up[i][j]) if math.isfinite(up[i][j]) else 1.0)
        if gap > SLACK_TOL * scale and gap / scale > best:
            best = gap / scale
            found = Pruned(names[i], names[j], lo[i][j], up[i][j], why_lo[i][j], why_up[i][j])
    return found
