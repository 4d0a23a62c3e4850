"""What solving a framework will cost, said before it costs it (`cost`, `params --framework`,
the first line of a solve).

A framework is solved taut set by taut set; each taut set that does not move freely needs a
generic solution set, by the route backends.generic.route_choice gives it (each set's line says
which and why: total degree for a set of few paths, else monodromy; `generic` overrides it).
By monodromy its paths follow
the number of solutions, which no count knows before the solve: the statement gives the Bezout
number as what the total-degree route would track, and no time estimate (the progress lines
measure the rate as the paths finish). By the total-degree route it needs two (seeds s and
s + SECOND_START, the second a cross-check of the first), each an ab-initio solve of as many
paths as the multihomogeneous Bezout number of its variable groups. A generic set already in
the cache costs nothing. The time a path takes is measured on the first paths of the largest
taut set's generic solve itself (its first chunks of paths, until SAMPLE_SECONDS have passed):
an estimate, and said to be one (paths differ in cost; on the examples the whole solve took
0.5 to 2 times the rate of its first paths).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from ..settings import Settings

SAMPLE_SECONDS = 4.0  # the first paths of the solve itself, tracked this long, give the rate
SAMPLE_CHUNK = 8  # paths a Bertini call of the sample (the clock is read between calls)
SAMPLE_FROM = 30.0  # a solve samples the rate when its first guess is beyond this (seconds)
# A set of more paths is not sampled, the largest set below this is (a 4 s sample of it would
# be a few paths of tens of thousands; Bertini's own start, used before, also laid out every
# start point first: prism_slack's smallest set spent 56 s there, measured).
SAMPLE_MAX_PATHS = 5_000
HOUR = 3600.0  # an estimate beyond this is said plainly, with what to do about it
REAL_SAMPLE_SECONDS = 2.0  # params: the real route's search, run this long, gives its pace


@dataclass(frozen=True)
class SetCost:
    """One taut set: its unknowns, its path count and which generic sets are cached already."""

    taut: tuple[str, ...]
    unknowns: int
    groups: int
    paths: int  # per generic set: the multihomogeneous Bezout number of its variable groups
    free: bool  # moves freely with the other cables slack: not solved (a continuum check)
    cached: tuple[int, ...]  # seeds whose generic set is in the cache already
    route: str = "total-degree"  # of its generic sets (backends.generic.route_choice)
    why: str = ""  # why that route
    seeds: tuple[int, ...] = ()  # the seeds of its generic sets (two by total degree)

    @property
    def label(self) -> str:
        """The taut set as solve records name it."""
        return " ".join(self.taut) or "none"


@dataclass(frozen=True)
class Cost:
    """The work of a framework's first solve: taut sets, paths, seeds and an estimate."""

    name: str
    sets: tuple[SetCost, ...]
    seeds: tuple[int, ...]
    seconds_per_path: float  # wall seconds a path of the solve (see `rate_source`)
    rate_source: str
    measured: bool  # the rate was measured on sample paths (not a first guess)
    derive_seconds: float  # spent deriving equations to count the paths (cached from now on)
    route: str = "total-degree"  # of the generic sets (backends.generic.route_of); "both":
    # `sets` count the total-degree set of the seed, the monodromy one is not counted
    pruned: int = 0  # taut sets no pose can hold (model.framework.taut_sets): not in `sets`
    search: dict | None = None  # the real route's sample search (_search_sample), if run
    why: str = ""  # why the route was chosen (routes.choose)

    @property
    def paths(self) -> int:
        """Paths of every generic set the solve needs, cached or not (a monodromy set counted
        as the total-degree route's paths of one seed: its own are not known before)."""
        return sum(s.paths * len(s.seeds) for s in self.sets if not s.free)

    @property
    def paths_to_solve(self) -> int:
        """Paths of the generic sets not in the cache: the work still to do."""
        return sum(
            s.paths * sum(seed not in s.cached for seed in s.seeds) for s in self.sets if not s.free
        )

    @property
    def by_monodromy(self) -> list[SetCost]:
        """The taut sets whose generic set is still to be found by monodromy."""
        return [
            s for s in self.sets
            if not s.free and s.route == "monodromy" and len(s.cached) < len(s.seeds)
        ]  # fmt: skip

    @property
    def estimate(self) -> float:
        """Seconds the generic sets still to solve take at the rate (an estimate; NaN when a
        set is to be found by monodromy, whose path count is not known before the solve)."""
        if self.by_monodromy:
            return float("nan")
        return self.paths_to_solve * self.seconds_per_path

    @property
    def over_an_hour(self) -> bool:
        """Whether the estimate is beyond an hour."""
        return self.estimate > HOUR

    def headline(self) -> str:
        """One line: the total work and its estimate (the first line of a solve)."""
        if self.route == "real":
            from ..routes import PROVES

            return (
                f"{self.name}: the real route ({PROVES['real']}; chosen: {self.why}; no "
                "generic set to solve; --route complex solves every complex root of every taut "
                "set instead)" + _paced(self.search)
            )
        solved = [s for s in self.sets if not s.free]
        tracked = [s for s in solved if s.route != "monodromy"]  # paths counted beforehand
        free = len(self.sets) - len(solved)
        text = self._taut_sets() + (f" ({free} moving freely, not solved)" if free else "")
        if tracked or not solved:
            seeds = max(len(s.seeds) for s in tracked) if tracked else len(self.seeds)
            text += (f", {_per_set(tracked)} paths per generic set x {seeds} seeds = "
                     f"{sum(s.paths * len(s.seeds) for s in tracked)} paths")  # fmt: skip
        if not self.paths_to_solve:
            return f"{text}; every generic set is in the cache already"
        mono = self.by_monodromy
        if mono:
            return self._monodromy(text, mono, bool(tracked))
        from ..progress import duration

        also = "; and a monodromy set of the same seed to check it" * (self.route == "both")
        return (
            f"{text}; {self.paths_to_solve} still to solve, an estimated "
            f"{duration(self.estimate)} at {self.seconds_per_path:.2g} s a path "
            f"({self.rate_source}){also}"
        )

    def _monodromy(self, text: str, mono: list[SetCost], tracked: bool) -> str:
        """The headline with generic sets `mono` to find by monodromy (after `text`, which
        counts the `tracked` sets' paths): no time (and why), and what the total-degree
        fallback would take at a rate measured now, when one was."""
        from ..progress import duration

        sets = f"{len(mono)} generic set{'s' * (len(mono) != 1)}"
        text += (
            f"{' and ' if tracked else ', '}{sets} to find by monodromy; no time estimate: a "
            "monodromy search tracks paths until its trace test passes, and how many it needs "
            "follows the number of solutions, which nothing counts before the solve (the "
            "progress lines measure the rate as it runs)"
        )
        if not self.measured:
            return f"{text}; the total-degree route would track {_per_set(mono)} paths per set"
        fallback = 2 * sum(s.paths for s in mono)
        return (
            f"{text}; should a trace test fail, the total-degree fallback tracks {fallback} "
            f"paths (two seeds), an estimated {duration(fallback * self.seconds_per_path)} at "
            f"{self.seconds_per_path:.2g} s a path ({self.rate_source})"
        )

    def _taut_sets(self) -> str:
        """The name and the taut sets counted (and those pruned, if any)."""
        n = len(self.sets)
        pruned = f" ({self.pruned} more pruned: no pose holds them)" if self.pruned else ""
        return f"{self.name}: {n} taut set{'s' * (n != 1)}{pruned}"

    def advice(self) -> str:
        """What to do about an estimate beyond an hour (empty otherwise)."""
        if not self.over_an_hour:
            return ""
        from ..progress import duration

        return (
            f"this solve is estimated to take {duration(self.estimate)}, beyond an hour. To "
            "make it cheaper: give fewer springs and cables a free length (each one adds "
            "two unknowns and multiplies the paths; each cable that can go slack adds taut "
            "sets), or split the paths over a Dask cluster (--scheduler tcp://host:8786, "
            "docs/frameworks.md). Once solved, the generic sets are cached and later solves "
            "of this file take seconds."
        )

    def lines(self) -> list[str]:
        """The statement `params --framework` prints: per taut set, then the total."""
        if self.route == "real":
            return [f"# {self.headline()}"]
        out = [f"# work of a first solve of {self.name} (seed {self.seeds[0]}):"]
        for s in self.sets:
            if s.free:
                out.append(f"#   taut set {s.label}: moves freely, not solved (no paths)")
                continue
            cached = ", ".join(str(k) for k in s.cached)
            out.append(
                f"#   taut set {s.label}: {s.unknowns} unknowns in {s.groups} groups, "
                f"{s.paths} paths per generic set"
                + (f" (seeds {cached} cached)" if cached else "")
                + f"; by {s.route} ({s.why})"
            )
        out.append(f"# {self.headline()}")
        if self.measured:
            out.append("#   (measured on this machine now: an estimate, paths differ in cost)")
        if self.advice():
            out.append(f"# {self.advice()}")
        return out


def _per_set(sets: list[SetCost]) -> str:
    """The path counts a set of these taut sets, "a+b+c" (or "a to b" for many)."""
    counts = sorted({s.paths for s in sets})
    if not counts:
        return "0"
    if len(sets) <= 4:
        return "+".join(str(s.paths) for s in sets)
    return f"{counts[0]} to {counts[-1]}"


def sample_rate(ps, groups, seed: int, centre: dict) -> tuple[float, int]:
    """(wall seconds a path, paths finished): the generic solve of `ps` for `seed` itself (its
    start and homotopy, homotopy.track_chunk on every core) on its first chunks of SAMPLE_CHUNK
    paths until SAMPLE_SECONDS have passed."""
    from ..backends.homotopy import generic_start, own_start, solver_errors, track_chunk

    start = generic_start(ps, seed, centre)
    system = ps.instantiate([start[n] for n in ps.parameters])
    t0, done = time.perf_counter(), 0
    with solver_errors(f"a sample of the generic solve (seed {seed})"):
        lp, texts = own_start(system, groups, seed)
        for chunk in lp.chunks(SAMPLE_CHUNK):
            track_chunk({"texts": texts, "points": chunk[:, lp.declared], "threads": None})
            done += len(chunk)
            if time.perf_counter() - t0 > SAMPLE_SECONDS:
                break
    return (time.perf_counter() - t0) / max(done, 1), done


def cost(fw, settings: Settings | None = None, *, sample: bool | None = True) -> Cost:
    """The work of solving `fw` (a cb.Framework) with `settings` (its seed): every
    taut set's unknowns and paths, the generic sets already cached, and an estimate of the rest
    from a rate measured on sample paths (module docstring). Derives the equations of every
    taut set (kept in the cache for the solve). `sample`: False, a first guess only (from an
    earlier solve in this process, or a fixed prior); None, sample only when the first guess
    is beyond SAMPLE_FROM seconds."""
    from ..backends.path_progress import first_guess, remember
    from ..routes import choose

    settings = settings or Settings()
    choice = choose(fw, settings)
    if choice.real:
        probe = _search_sample(fw) if sample is True else None
        return Cost(fw.name, (), (settings.seed,), 0.0, "no generic set", False, 0.0, "real",
                    search=probe, why=choice.why)  # fmt: skip
    t0 = time.perf_counter()
    sets, systems, pruned = _sets(fw, settings)
    derive_seconds = time.perf_counter() - t0
    # Sets whose paths are counted beforehand (total degree, "both"'s set of the seed) and
    # still to solve: the rate is theirs; a monodromy set's paths are not known before. A set
    # by monodromy by default counts only when asked (`params`): the rate then times the
    # total-degree fallback a failed trace test takes (an explicit 'monodromy' has none).
    fallback = sample is True and settings.generic is None
    todo = [
        k for k, s in enumerate(sets)
        if not s.free and (s.route != "monodromy" or fallback) and len(s.cached) < len(s.seeds)
    ]  # fmt: skip
    big = max(todo, key=lambda k: sets[k].paths) if todo else None
    rate, source = first_guess(*systems[big][:2]) if big is not None else (0.0, "nothing to do")
    source, measured = f"a first guess: {source}", False
    pending = sum(sets[k].paths * (len(sets[k].seeds) - len(sets[k].cached)) for k in todo)
    wanted = sample or (sample is None and pending * rate > SAMPLE_FROM)
    small = [k for k in todo if sets[k].paths <= SAMPLE_MAX_PATHS]
    probe = max(small, key=lambda k: sets[k].paths) if small else None
    if big is not None and wanted and probe is None:
        source += (f" (not sampled: every taut set has more than {SAMPLE_MAX_PATHS:,} "
                   "paths)")  # fmt: skip
    elif big is not None and wanted:
        ps, groups, centre = systems[probe]
        rate, n = sample_rate(ps, groups, settings.seed, centre)
        source = (
            f"measured on the first {n} paths of taut set {sets[probe].label}"
            if n
            else f"no path of taut set {sets[probe].label} finished in {SAMPLE_SECONDS:g} s"
        )
        remember(ps, groups, rate, source)
        measured = True
    routes = {s.route for s in sets if not s.free} or {"total-degree"}
    route = routes.pop() if len(routes) == 1 else "mixed"
    seeds = max((s.seeds for s in sets), key=len, default=(settings.seed,))
    return Cost(fw.name, tuple(sets), seeds, rate, source, measured, derive_seconds, route, pruned,
                why=choice.why)  # fmt: skip


def _sets(fw, settings: Settings) -> tuple[list[SetCost], list[tuple], int]:
    """Each taut set's SetCost (its route by backends.generic.route_choice, on its path count)
    and (system, groups, centre) of its generic solves, derived in order with "taut set k/n" in
    the derivation's progress lines; and how many were pruned."""
    from ..backends.generic import route_choice
    from ..backends.homotopy import SECOND_START, generic_key, generic_path
    from ..backends.monodromy import ROUTE
    from ..backends.path_progress import path_count
    from ..model.framework.compiled import framework_system, variable_groups
    from ..model.framework.taut_sets import split_taut_sets
    from ..model.framework.units import normalized_slots

    slots = normalized_slots(fw.at_defaults())  # the generic sets' centre, as a solve has it
    tauts, pruned = split_taut_sets(fw)
    sets, systems = [], []
    for k, taut in enumerate(tauts):
        fs = framework_system(fw, taut, label=f"taut set {k + 1}/{len(tauts)}")
        groups = variable_groups(fs)
        centre = {n: slots[n] for n in fs.ps.parameters}
        free = bool(fs.free)
        paths = 0 if free else path_count(fs.ps, groups)
        route, why = route_choice(settings, paths)
        # "both": the total-degree set of the seed itself is the one counted (and a monodromy
        # set); by monodromy one set (its trace test the evidence); by total degree two.
        one = route in ("monodromy", "both")
        seeds = (settings.seed,) if one else (settings.seed, settings.seed + SECOND_START)
        key = {"route": ROUTE} if route == "monodromy" else {"groups": groups}
        keys = {seed: generic_key(fs.ps, seed, centre, **key) for seed in seeds}
        cached = tuple(seed for seed in seeds if generic_path(keys[seed]).is_file())
        sets.append(
            SetCost(taut, len(fs.ps.variables), len(groups), paths, free, cached, route, why, seeds)
        )
        systems.append((fs.ps, groups, centre))
    return sets, systems, len(pruned)


def _search_sample(fw) -> dict:
    """The real route's search of `fw` on one process for at most REAL_SAMPLE_SECONDS: its
    seconds, boxes, the share of the poses it decided, and whether it finished."""
    from ..boxsearch.boxes import MIN_WIDTH, SHORT, search
    from ..boxsearch.real_route import landscape

    found = search(landscape(fw), SHORT, MIN_WIDTH, max_seconds=REAL_SAMPLE_SECONDS,
                   label=f"sample search of {fw.name}")  # fmt: skip
    return {"seconds": found.seconds, "boxes": found.boxes, "done": not found.budget_hit,
            "decided": 1.0 - found.undecided_share}  # fmt: skip


def _paced(probe: dict | None) -> str:
    """What the sample search says of the whole search's time (nothing where not run)."""
    from ..progress import duration

    if probe is None:
        return ""
    if probe["done"]:
        return (f"; a whole search took {duration(probe['seconds'])} on one process "
                f"({probe['boxes']:,} boxes)")  # fmt: skip
    said = (f"; a {duration(probe['seconds'])} sample search decided {probe['decided']:.2%} of "
            f"the poses ({probe['boxes']:,} boxes)")  # fmt: skip
    if probe["decided"] <= 0:
        return said + ": the whole search is far beyond the sample"
    return said + (f": at least about {duration(probe['seconds'] / probe['decided'])} on one "
                   "process, likely more (the first boxes decide the most)")  # fmt: skip


def announce(fw, settings: Settings) -> Cost | None:
    """Before a framework solve with generic sets to solve (longer than a moment): one line of
    its total work and estimate, and plain advice when that is beyond an hour."""
    from ..backends.homotopy import ANNOUNCE_SECONDS
    from ..progress import enabled, say

    if not enabled() or settings.engine != "homotopy":  # another engine is refused at once
        return None
    c = cost(fw, settings, sample=None)
    if c.route == "real" or c.estimate < ANNOUNCE_SECONDS:
        return c
    say(f"cotm-bertini: {c.headline()}")
    if c.over_an_hour:
        say(f"cotm-bertini: {c.advice()}")
    return c
