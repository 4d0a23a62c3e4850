"""What solving a framework will cost, said before it costs it (`cost`, `params --framework`,
the first line of a solve).

A framework is solved taut set by taut set; each taut set that does not move freely needs a
generic solution set. By monodromy (`generic='monodromy'`, backends/generic.py) its paths follow
the number of solutions, which no count knows before the solve: the statement gives the Bezout
number as what the total-degree route would track, and no time estimate (the progress lines
measure the rate as the paths finish). By the total-degree route it needs two (seeds s and
s + SECOND_START, the second a cross-check of the first), each an ab-initio solve of as many
paths as the multihomogeneous Bezout number of its variable groups. A generic set already in
the cache costs nothing. The time a path takes is measured on the first paths of the largest
taut set's generic solve itself (the same ZeroDimSolver call, stopped after SAMPLE_SECONDS):
an estimate, and said to be one (paths differ in cost; on the examples the whole solve took
0.5 to 2 times the rate of its first paths).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from ..settings import Settings

SAMPLE_SECONDS = 4.0  # the first paths of the solve itself, tracked this long, give the rate
SAMPLE_FROM = 30.0  # a solve samples the rate when its first guess is beyond this (seconds)
# Bertini lays out every start point before its first path, about 1.1 ms a point (prism_slack's
# smallest taut set: 46,656 paths, 56 s and no path finished in a 4 s sample; measured): a
# set of more paths is not sampled, the largest set below this is.
SAMPLE_MAX_PATHS = 5_000
HOUR = 3600.0  # an estimate beyond this is said plainly, with what to do about it


@dataclass(frozen=True)
class SetCost:
    """One taut set: its unknowns, its path count and which generic sets are cached already."""

    taut: tuple[str, ...]
    unknowns: int
    groups: int
    paths: int  # per generic set: the multihomogeneous Bezout number of its variable groups
    free: bool  # moves freely with the other cables slack: not solved (a continuum check)
    cached: tuple[int, ...]  # seeds whose generic set is in the cache already

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
    pruned: int = 0  # taut sets no pose can hold (point.pruned_taut_sets): not in `sets`

    @property
    def paths(self) -> int:
        """Paths of every generic set the solve needs, cached or not."""
        return sum(s.paths * len(self.seeds) for s in self.sets if not s.free)

    @property
    def paths_to_solve(self) -> int:
        """Paths of the generic sets not in the cache: the work still to do."""
        return sum(
            s.paths * sum(seed not in s.cached for seed in self.seeds)
            for s in self.sets
            if not s.free
        )

    @property
    def estimate(self) -> float:
        """Seconds the generic sets still to solve take at the rate (an estimate; NaN by
        monodromy, whose path count is not known before the solve)."""
        if self.route == "monodromy" and self.paths_to_solve:
            return float("nan")
        return self.paths_to_solve * self.seconds_per_path

    @property
    def over_an_hour(self) -> bool:
        """Whether the estimate is beyond an hour."""
        return self.estimate > HOUR

    def headline(self) -> str:
        """One line: the total work and its estimate (the first line of a solve)."""
        if self.route == "real":
            return (
                f"{self.name}: the real route (a branch and bound over its body angles, real "
                "equilibria only, proved complete; no generic set to solve: seconds, not paths; "
                "--route complex solves every complex root of every taut set instead)"
            )
        solved = [s for s in self.sets if not s.free]
        counts = sorted({s.paths for s in solved})
        per = "+".join(str(s.paths) for s in solved) if len(solved) <= 4 else (
            f"{counts[0]} to {counts[-1]}")  # fmt: skip
        per = per or "0"
        free = len(self.sets) - len(solved)
        text = (
            f"{self._taut_sets()}"
            + (f" ({free} moving freely, not solved)" if free else "")
            + f", {per} paths per generic set x {len(self.seeds)} seeds = {self.paths} paths"
        )
        if not self.paths_to_solve:
            return f"{text}; every generic set is in the cache already"
        if self.route == "monodromy":
            return self._monodromy(solved, per)
        from ..progress import duration

        also = "; and a monodromy set of the same seed to check it" * (self.route == "both")
        return (
            f"{text}; {self.paths_to_solve} still to solve, an estimated "
            f"{duration(self.estimate)} at {self.seconds_per_path:.2g} s a path "
            f"({self.rate_source}){also}"
        )

    def _monodromy(self, solved: list[SetCost], per: str) -> str:
        """The headline by monodromy: no time (and why), and what the total-degree fallback
        would take at a rate measured now, when one was."""
        from ..progress import duration

        todo = sum(len(self.seeds) - len(s.cached) for s in solved)
        text = (
            f"{self._taut_sets()}, {todo} generic set{'s' * (todo != 1)} to find by monodromy; "
            "no time estimate: a monodromy search tracks paths until its trace test passes, "
            "and how many it needs follows the number of solutions, which nothing counts "
            "before the solve (the progress lines measure the rate as it runs)"
        )
        fallback = 2 * sum(s.paths for s in solved if len(s.cached) < len(self.seeds))
        if not self.measured:
            return f"{text}; the total-degree route would track {per} paths per set"
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
                f"{s.paths} paths per generic set" + (f" (seeds {cached} cached)" if cached else "")
            )
        out.append(f"# {self.headline()}")
        if self.measured:
            out.append("#   (measured on this machine now: an estimate, paths differ in cost)")
        if self.advice():
            out.append(f"# {self.advice()}")
        return out


def sample_rate(ps, groups, seed: int, centre: dict) -> tuple[float, int]:
    """(wall seconds a path, paths finished): the generic solve of `ps` for `seed` itself (the
    same ZeroDimSolver call, on every core) run for SAMPLE_SECONDS, its paths counted as they
    finish; with none finished, the seconds spent (a lower bound)."""
    from bertini import nag_algorithm as na

    from ..backends.crossings import solve as quiet_solve
    from ..backends.homotopy import GENERIC_MAX_STEPS, _bertini, generic_start, solver_errors
    from ..backends.path_progress import watched
    from ..backends.render import render_system
    from ..progress import Progress

    start = generic_start(ps, seed, centre)
    system = ps.instantiate([start[n] for n in ps.parameters])
    report = Progress("sample", None, "paths", force=True, delay=1e9)  # counts, never shown
    t0 = time.perf_counter()
    with solver_errors(f"a sample of the generic solve (seed {seed})"):
        bertini = _bertini()
        bertini.random.set_random_seed(seed)
        solver = na.ZeroDimSolver(bertini.parse.system(render_system(system, groups)))
        solver.set(max_num_steps=GENERIC_MAX_STEPS, max_solve_wall_clock_duration=SAMPLE_SECONDS)
        with watched(solver, report):
            quiet_solve(solver)
    done = int(report.done)
    return (time.perf_counter() - t0) / max(done, 1), done


def cost(fw, settings: Settings | None = None, *, sample: bool | None = True) -> Cost:
    """The work of solving `fw` (a cb.Framework) with `settings` (its seed): every
    taut set's unknowns and paths, the generic sets already cached, and an estimate of the rest
    from a rate measured on sample paths (module docstring). Derives the equations of every
    taut set (kept in the cache for the solve). `sample`: False, a first guess only (from an
    earlier solve in this process, or a fixed prior); None, sample only when the first guess
    is beyond SAMPLE_FROM seconds."""
    from ..backends.generic import route_of
    from ..backends.homotopy import SECOND_START
    from ..backends.path_progress import first_guess, remember
    from ..point import framework_route

    settings = settings or Settings()
    if framework_route(fw, settings) == "real":
        return Cost(fw.name, (), (settings.seed,), 0.0, "no generic set", False, 0.0, "real")
    route = route_of(settings)
    # "both": the total-degree set of the seed itself is the one counted (and a monodromy set).
    one = route in ("monodromy", "both")
    seeds = (settings.seed,) if one else (settings.seed, settings.seed + SECOND_START)
    t0 = time.perf_counter()
    sets, systems, pruned = _sets(fw, seeds, route)
    derive_seconds = time.perf_counter() - t0
    todo = [k for k, s in enumerate(sets) if not s.free and len(s.cached) < len(seeds)]
    big = max(todo, key=lambda k: sets[k].paths) if todo else None
    rate, source = first_guess(*systems[big][:2]) if big is not None else (0.0, "nothing to do")
    source, measured = f"a first guess: {source}", False
    pending = sum(sets[k].paths * (len(seeds) - len(sets[k].cached)) for k in todo)
    wanted = sample or (sample is None and pending * rate > SAMPLE_FROM)
    small = [k for k in todo if sets[k].paths <= SAMPLE_MAX_PATHS]
    probe = max(small, key=lambda k: sets[k].paths) if small else None
    # By monodromy only when asked (`params`): the rate then times the total-degree fallback.
    wanted = wanted and (route != "monodromy" or sample is True)
    if big is not None and wanted and probe is None:
        source += (f" (not sampled: every taut set has more than {SAMPLE_MAX_PATHS:,} paths, "
                   "and Bertini lays out every start point before its first path)")  # fmt: skip
    elif big is not None and wanted:
        ps, groups, centre = systems[probe]
        rate, n = sample_rate(ps, groups, seeds[0], centre)
        source = (
            f"measured on the first {n} paths of taut set {sets[probe].label}"
            if n
            else f"no path of taut set {sets[probe].label} finished in {SAMPLE_SECONDS:g} s"
        )
        remember(ps, groups, rate, source)
        measured = True
    return Cost(fw.name, tuple(sets), seeds, rate, source, measured, derive_seconds, route, pruned)


def _sets(fw, seeds: tuple[int, ...], route: str) -> tuple[list[SetCost], list[tuple], int]:
    """Each taut set's SetCost and (system, groups, centre) of its generic solves, derived in
    order with "taut set k/n" in the derivation's progress lines; and how many were pruned."""
    from ..backends.homotopy import generic_path
    from ..backends.path_progress import path_count
    from ..model.framework.compiled import framework_system, variable_groups
    from ..model.framework.units import normalized_slots
    from ..point import split_taut_sets

    slots = normalized_slots(fw.at_defaults())  # the generic sets' centre, as a solve has it
    tauts, pruned = split_taut_sets(fw)
    sets, systems = [], []
    for k, taut in enumerate(tauts):
        fs = framework_system(fw, taut, label=f"taut set {k + 1}/{len(tauts)}")
        groups = variable_groups(fs)
        centre = {n: slots[n] for n in fs.ps.parameters}
        cached = tuple(
            seed for seed in seeds
            if generic_path(_key(fs.ps, seed, centre, groups, route)).is_file()
        )  # fmt: skip
        free = bool(fs.free)
        paths = 0 if free else path_count(fs.ps, groups)
        sets.append(SetCost(taut, len(fs.ps.variables), len(groups), paths, free, cached))
        systems.append((fs.ps, groups, centre))
    return sets, systems, len(pruned)


def _key(ps, seed: int, centre: dict, groups, route: str) -> str:
    """The cache key of a generic set by this route (the monodromy one ignores groups)."""
    from ..backends.homotopy import generic_key
    from ..backends.monodromy import ROUTE

    if route == "monodromy":
        return generic_key(ps, seed, centre, route=ROUTE)
    return generic_key(ps, seed, centre, groups)


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
