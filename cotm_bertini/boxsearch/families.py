"""Frameworks of one structure searched together: a sweep's or a map's points in the same
batches of boxes (TorusFamily, search_frameworks), each point's search the one it would have
alone; and the last frameworks' real equilibria kept (real_equilibria)."""

from __future__ import annotations

import copy

import numpy as np

from ..backends.endpoints import Endpoints
from ..model.framework.spec import Framework
from ..model.intervals import Interval
from .boxes import MIN_WIDTH, SHORT, BoxSearch, cover, domain, search, search_each
from .links import Link
from .real_route import TorusFramework, landscape

# A family's boxes no member can have a critical point in are excluded together (its hull,
# boxes.cover) down to this width, its halves' to half of it, ... down to FAMILY_LEAF members
# (a 32-point family of chain4: 0.63 s a point, against 1.07 s with no cover; finer covers or
# smaller leaves cost more than they save).
COVER_WIDTH = 0.1

FAMILY_LEAF = 16

TOGETHER = 32  # frameworks searched in one family (more gain little: 0.010 against 0.011 s)


class TorusFamily:
    """Frameworks of one structure (TorusFramework.structure: the same systems, units and
    links; other parameter values) as one landscape over boxes that each belong to a member
    (boxsearch.boxes.search_each): each box's slots, spring stiffnesses and free lengths are
    its member's, a number where all members share it (so that the arithmetic is the member's
    own search's), else an array over the boxes."""

    def __init__(self, lands: list[TorusFramework]):
        self.base, self.members, self.n = lands[0], len(lands), lands[0].n
        if any(land.structure() != self.base.structure() for land in lands):
            raise ValueError("a TorusFamily's frameworks must share one structure")
        self.P = [_shared([land.P[j] for land in lands]) for j in range(len(self.base.P))]
        self.links = [
            (_shared([land.links[i].k for land in lands]),
             _shared([land.links[i].L0 for land in lands]))
            for i in range(len(self.base.links))
        ]  # fmt: skip

    def hull(self) -> TorusFramework:
        """One landscape whose numbers are intervals holding every member's (the slots and
        the links' k and L0): its enclosures hold each member's, so a box it excludes holds
        no critical point of any member (boxsearch.boxes.cover)."""
        view = copy.copy(self.base)
        view.P = [_interval(v) for v in self.P]
        view.links = tuple(
            Link(x.name, _interval(k), None if L0 is None else _interval(L0), x.cable)
            for x, (k, L0) in zip(self.base.links, self.links, strict=True)
        )
        return view

    def rows(self, member: np.ndarray) -> TorusFramework:
        """The landscape over a batch whose box i belongs to member[i]."""
        view = copy.copy(self.base)
        view.P = [v if np.ndim(v) == 0 else v[member] for v in self.P]
        view.links = tuple(
            Link(x.name, k if np.ndim(k) == 0 else k[member],
                 L0 if L0 is None or np.ndim(L0) == 0 else L0[member], x.cable)
            for x, (k, L0) in zip(self.base.links, self.links, strict=True)
        )  # fmt: skip
        view.member, view.family = member, self
        return view


def _interval(v):
    """A number shared by the members as it is; the members' values as their hull."""
    return v if np.ndim(v) == 0 else Interval(np.min(v), np.max(v))


def _shared(values: list):
    """The members' values of one number: that number where they all agree, else an array."""
    if all(v == values[0] for v in values):
        return values[0]
    return np.array(values, dtype=float)


def search_frameworks(
    fws: list[Framework],
    max_seconds: float | None = None,
    lands: list[TorusFramework] | None = None,
) -> list[BoxSearch]:
    """The search (defaults of boxsearch.boxes) of each framework, those of one structure
    together in batches (TorusFamily, search_each): each the same as its own search."""
    lands = lands or [landscape(fw) for fw in fws]
    groups: dict[tuple, list[int]] = {}
    out: list = [None] * len(lands)
    for k, land in enumerate(lands):
        # charts of spheres, and free nodes (each its own bounding cube): a search each
        if not isinstance(land, TorusFramework) or land.nodes:
            out[k] = search(land, SHORT, MIN_WIDTH, max_seconds=max_seconds,
                            label=f"real search of {fws[k].name}")  # fmt: skip
            continue
        groups.setdefault(land.structure(), []).append(k)
    # TOGETHER at most in a family: each step holds up to TOGETHER x BATCH boxes
    chunks = [ks[i : i + TOGETHER] for ks in groups.values() for i in range(0, len(ks), TOGETHER)]
    for members in chunks:
        _search_family(fws, lands, members, max_seconds, out, domain(lands[members[0]], 8))
    return out


def _search_family(fws, lands, members: list[int], max_seconds, out: list, first,
                   stop: float = COVER_WIDTH, shared: dict | None = None) -> None:  # fmt: skip
    """search_each of the frameworks `members` (their records into `out`), after what none of
    them can have a critical point in is excluded once for all (their hull's enclosures:
    boxes.cover, to `stop` rad); halves of a larger family are covered again from what is
    left (their hulls are tighter), down to FAMILY_LEAF members. `shared`: each member's share
    of the boxes covered so far."""
    family, shared = TorusFamily([lands[k] for k in members]), dict(shared or {})
    if len(members) > 1:
        first, looked = cover(family.hull(), first, stop)
        for k in members:
            shared[k] = shared.get(k, 0.0) + looked / len(members)
    if len(members) > FAMILY_LEAF:
        half = (len(members) + 1) // 2
        for part in (members[:half], members[half:]):
            _search_family(fws, lands, part, max_seconds, out, first, stop / 2, shared)
        return
    label = f"real search of {fws[members[0]].name}, {len(members)} points"
    found = search_each(family, SHORT, MIN_WIDTH, max_seconds=max_seconds, label=label,
                        boxes=first if len(members) > 1 else None)  # fmt: skip
    for k, f in zip(members, found, strict=True):
        if shared.get(k):
            f.notes.append(f"{shared[k]:,.0f} boxes (a share of those searched for its "
                           "neighbours and it together first)")  # fmt: skip
        out[k] = f


KEEP = 128  # real_equilibria keeps the last this many frameworks' equilibria

_KEPT: dict[Framework, tuple] = {}


def real_equilibria(fw: Framework) -> tuple[dict[tuple[str, ...], Endpoints], BoxSearch]:
    """Every real critical point of V (the search's default settings), as endpoints by taut set
    (keys sorted, as FrameworkSystem.taut), with the search's record; kept for the last
    frameworks asked for, since fold seeds of every curve system share their crossings."""
    return real_equilibria_of([fw])[0]


def real_equilibria_of(fws: list[Framework]) -> list[tuple]:
    """real_equilibria of each framework; those not kept are searched together
    (search_frameworks: each its own search, in shared batches of boxes)."""
    todo = [fw for fw in dict.fromkeys(fws) if fw not in _KEPT]
    made = {}
    if todo:
        lands = [landscape(fw) for fw in todo]
        for fw, land, found in zip(todo, lands, search_frameworks(todo, lands=lands),
                                   strict=True):  # fmt: skip
            groups = land.endpoints(found.roots).items()
            made[fw] = {tuple(sorted(k)): v for k, v in groups}, found
    out = [made[fw] if fw in made else _KEPT[fw] for fw in fws]
    _KEPT.update(made)
    for fw in list(_KEPT)[: max(0, len(_KEPT) - KEEP)]:
        del _KEPT[fw]
    return out
