"""The generic solution sets a solve starts from, by route, cached, with their evidence.

Two routes find the generic set of a seed (the finite nonsingular solutions at the seed's
random complex start parameters, homotopy.generic_start):

- "monodromy" (backends/monodromy.py): loops of Bertini's parameter homotopy,
  complete when the trace test passes; its cost follows the number of solutions.
- "total-degree": Bertini's own total-degree or multihomogeneous start system
  (homotopy.generic_set), whose cost follows the Bezout bound; its completeness evidence is
  a second set from an independent start (seed + SECOND_START) with the same count.

`Settings.generic` chooses: "monodromy", "total-degree", or "both" (the monodromy set, checked
against the total-degree set of the same seed). Unset (`route_choice`): total-degree with a
Dask scheduler (which splits that route's paths over its workers); for a framework's taut set
(its variable groups known), total-degree when its two seeds track at most TOTAL_DEGREE_PATHS
paths, else monodromy; for a system without groups (the paper's mechanism), DEFAULT_ROUTE,
monodromy. Both routes' sets are cached apart (the key names the route), so each is solved once.
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
# The total-degree route solves a taut set by default when its two seeds track at most this
# many paths (2 x its multihomogeneous Bezout number). Below it the route tracks fewer paths
# than monodromy is expected to: monodromy tracked 5-11 paths per root of its augmented
# fibre N'', and N'' was 0.44-1.6 times the Bezout number on the 9 systems measured
# (docs/benchmarks.md: at least 2.2 Bezout numbers against the route's 2), and on a projective
# patch a path costs 0.015-0.04 CPU s (the X-module's taut sets, measured), so 5,000 paths are
# 1-3 CPU minutes. Above it the count of roots may be far below the Bezout number (chain3: a
# set of 1,504 roots and 86,528 Bezout paths), where monodromy's cost follows the roots.
TOTAL_DEGREE_PATHS = 5_000
_PATHS: dict[tuple, int] = {}  # (id(ps), groups): the Bezout number, counted once a process


def route_choice(settings: Settings, paths: int | None = None) -> tuple[str, str]:
    """(route, why) of a generic set: `settings.generic` if given; total-degree with a Dask
    scheduler (monodromy runs in one process); for a set of `paths` start paths a seed (a
    framework's taut set), total-degree when 2 x paths <= TOTAL_DEGREE_PATHS, else monodromy;
    without a count (the paper's mechanism), DEFAULT_ROUTE."""
    if settings.generic is not None:
        return settings.generic, f"generic = {settings.generic!r} asked for"
    if settings.scheduler:
        return "total-degree", "a Dask scheduler splits the total-degree route's paths"
    if paths is None:
        return DEFAULT_ROUTE, "the default for a system without variable groups"
    if 2 * paths <= TOTAL_DEGREE_PATHS:
        return "total-degree", (
            f"2 seeds x {paths:,} paths <= {TOTAL_DEGREE_PATHS:,}: fewer than monodromy is "
            "expected to track"
        )
    return "monodromy", (
        f"2 seeds x {paths:,} paths > {TOTAL_DEGREE_PATHS:,}: monodromy's paths follow the "
        "roots, which may be far fewer"
    )


def route_of(settings: Settings, ps: ParametricSystem | None = None, groups=None) -> str:
    """The route of a generic set of `ps` (with its variable `groups`, a framework's taut set;
    without them: the paper's mechanism) under `settings` (route_choice)."""
    return route_choice(settings, None if ps is None or groups is None else paths_of(ps, groups))[0]


def paths_of(ps: ParametricSystem, groups) -> int:
    """The paths a seed of `ps`'s total-degree route tracks (path_progress.path_count), kept."""
    from .path_progress import path_count

    key = (id(ps), tuple(map(tuple, groups or ())))
    if key not in _PATHS:
        _PATHS[key] = path_count(ps, groups)
    return _PATHS[key]


def generic_for(
    ps: ParametricSystem,
    seed: int,
    settings: Settings,
    centre: dict[str, float] | None = None,
    groups: list[list[str]] | None = None,
) -> GenericSet:
    """`seed`'s generic set of `ps` by the route of `settings` ("both": the monodromy one)."""
    if route_of(settings, ps, groups) == "total-degree":
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
    route, seed = route_of(settings, ps, groups), settings.seed
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
