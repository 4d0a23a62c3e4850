"""The generic solution sets a solve starts from, by route, cached, with their evidence.

Two routes find the generic set of a seed (the finite nonsingular solutions at the seed's
random complex start parameters, homotopy.generic_start):

- "monodromy" (backends/monodromy.py): loops of Bertini's parameter homotopy,
  complete when the trace test passes; its cost follows the number of solutions.
- "total-degree": Bertini's own total-degree or multihomogeneous start system
  (homotopy.generic_set), whose cost follows the Bezout bound; its completeness evidence is
  a second set from an independent start (seed + SECOND_START) with the same count.

`Settings.generic` chooses: "monodromy", "total-degree", or "both" (the monodromy set, checked
against the total-degree set of the same seed); unset, DEFAULT_ROUTE, monodromy (one set and
its proof instead of two sets, and a cost that follows the solutions: docs/benchmarks.md), or
total-degree with a Dask scheduler (which splits that route's paths over its workers).
Both routes' sets are cached apart (the key names the route), so each is solved once.
"""

from __future__ import annotations

import json
from dataclasses import replace

from ..fs import atomic_write_text
from ..model.polynomial import ParametricSystem
from ..progress import say
from ..settings import Settings
from .homotopy import (
    SECOND_START,
    START_CENTRE,
    GenericSet,
    cached_generic,
    generic_key,
    generic_path,
    generic_set,
    solver_errors,
)
from .monodromy import ROUTE, monodromy_generic

_LOADED: dict[tuple[int, int], GenericSet] = {}  # (id(ps), seed): monodromy sets this process


def monodromy_set(
    ps: ParametricSystem,
    seed: int = 1,
    centre: dict[str, float] | None = None,
    use_cache: bool = True,
) -> GenericSet:
    """The generic set of `ps` for `seed` by monodromy: from memory, the cache, or found (its
    working state checkpointed next to the cache entry, so an interrupted search resumes). An
    incomplete set (the trace test failed) comes back with route["complete"] False, and whoever
    uses it reports it (status incomplete) or falls back (evidence_sets); it is cached as such,
    so that a sweep's points and workers do not run the failing search again."""
    if use_cache and (id(ps), seed) in _LOADED:
        return replace(_LOADED[id(ps), seed], source="memory")
    centre = START_CENTRE if centre is None else centre
    key = generic_key(ps, seed, centre, route=ROUTE)
    path = generic_path(key)
    cached = cached_generic(path) if use_cache else None
    if cached is not None:
        _LOADED[id(ps), seed] = cached
        return cached
    checkpoint = path.with_name(f"monodromy-{key}.partial.json") if use_cache else None
    with solver_errors(f"the monodromy generic set (seed {seed}, {len(ps.variables)} unknowns)"):
        found = monodromy_generic(ps, seed, centre, checkpoint=checkpoint)
    gs = found.generic_set(key, incomplete_ok=True)
    if not found.complete:
        say(f"cotm-bertini: warning: the monodromy generic set (seed {seed}) is incomplete: "
            f"{found.reason}")  # fmt: skip
    if use_cache:
        atomic_write_text(path, json.dumps(gs.to_json()))
        _LOADED[id(ps), seed] = gs
        if checkpoint is not None:
            checkpoint.unlink(missing_ok=True)  # finished, complete or not: nothing to resume
    return gs


DEFAULT_ROUTE = "monodromy"


def route_of(settings: Settings) -> str:
    """The route of `settings`: its `generic`, else DEFAULT_ROUTE (total-degree with a Dask
    scheduler, which splits that route's paths; monodromy runs in one process)."""
    if settings.generic is not None:
        return settings.generic
    return "total-degree" if settings.scheduler else DEFAULT_ROUTE


def generic_for(
    ps: ParametricSystem,
    seed: int,
    settings: Settings,
    centre: dict[str, float] | None = None,
    groups: list[list[str]] | None = None,
) -> GenericSet:
    """`seed`'s generic set of `ps` by the route of `settings` ("both": the monodromy one)."""
    if route_of(settings) == "total-degree":
        return generic_set(ps, seed, centre=centre, groups=groups, scheduler=settings.scheduler)
    return monodromy_set(ps, seed, centre)


def evidence_sets(
    ps: ParametricSystem,
    settings: Settings,
    centre: dict[str, float] | None = None,
    groups: list[list[str]] | None = None,
) -> tuple[GenericSet, ...]:
    """The generic sets a solve starts from and checks its completeness with, the first the
    one it tracks: monodromy, its own (the trace test is its evidence); total-degree, two from
    independent starts (the same count is the evidence); both, the monodromy set and the
    total-degree set of the same seed (the same count, two routes)."""
    route, seed = route_of(settings), settings.seed
    first = generic_for(ps, seed, settings, centre, groups)
    if route == "monodromy" and failed(first) and settings.generic is None:
        return _fallback(ps, settings, centre, groups, first)
    if route == "monodromy":
        return (first,)
    other = seed + SECOND_START if route == "total-degree" else seed
    second = generic_set(ps, other, centre=centre, groups=groups, scheduler=settings.scheduler)
    return first, second


def failed(gs: GenericSet) -> bool:
    """Whether a generic set is one whose route says it is incomplete (a failed trace test)."""
    return gs.route.get("complete") is False


def _fallback(ps, settings: Settings, centre, groups, failed_set: GenericSet) -> tuple:
    """The default route after a failed trace test: the total-degree route's two sets (their
    counts the evidence), the first recording why the monodromy set was not used. An explicit
    generic='monodromy' does not fall back: its incomplete set is reported as such."""
    reason = failed_set.route.get("reason", "no reason recorded")
    if failed_set.source == "solved":  # once, not at every point of a sweep (run.json says it)
        say(f"cotm-bertini: the monodromy generic set (seed {settings.seed}) failed its trace "
            "test; the default route falls back to the total-degree route (two seeds)")  # fmt: skip
    sets = [generic_set(ps, s, centre=centre, groups=groups)
            for s in (settings.seed, settings.seed + SECOND_START)]  # fmt: skip
    note = {"after_monodromy": f"the monodromy set was incomplete ({reason})"}
    return (replace(sets[0], route={**sets[0].route, **note}), sets[1])


def disagreements(sets) -> list[str]:
    """Why these generic sets do not agree (their counts differ), if they do not."""
    counts = [len(g.points) for g in sets]
    if len(set(counts)) <= 1:
        return []
    return [f"two generic sets disagree ({' vs '.join(map(str, counts))} roots): "
            "equilibria may be missing"]  # fmt: skip


def incomplete_sets(sets) -> list[str]:
    """Why each of these generic sets is incomplete (a route record whose `complete` is
    False): the warnings of the solve that used them."""
    return [
        f"the generic set of seed {g.seed} ({g.route.get('route', 'total-degree')}) is "
        f"incomplete: {g.route.get('reason', 'no reason recorded')}; equilibria may be missing"
        for g in sets
        if g.route.get("complete") is False
    ]
