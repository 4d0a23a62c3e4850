"""Bertini 2 in-process: generic solution sets, parameter homotopies from them, ab initio solves.

A total-degree solve (ab initio) at random complex parameters p0 gives the generic solution set.
Any real target p1 is then reached by tracking those solutions while every parameter moves on
the straight line from p0 (t = 1) to p1 (t = 0): since p0 is random complex, the line misses the
parameter values where paths meet (the "gamma trick"). This is the Paramotopy / HomotopyContinuation
approach; the `bertini2` command cannot do it, the `bertini` module can.

The singular roots of the generic set are the d = 0 artefacts (a spring with L0 > 0 at zero
length, see the reference notes): they are not tracked but computed at the target in closed form.
"""

from __future__ import annotations

import hashlib
import json
import time
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..errors import SolverError
from ..fs import atomic_write_text, cache_root
from ..model.artefacts import zero_length_points
from ..model.polynomial import ParametricSystem
from ..params import Params
from ..progress import duration, say
from ..settings import Settings
from ..versions import bertini2_version
from . import crossings
from .crossings import CROSSING
from .crossings import solve as quiet_solve
from .endpoints import Endpoints
from .path_progress import PRIOR_SOURCE, expected, generic_report, remember
from .render import render_parameter_homotopy, render_system
from .start_system import (
    gamma_homotopy_text,
    linear_product_start,
)

_SUCCESS = "Success"
DOUBLE_FINAL_TOLERANCE = 1e-8
DOUBLE_MAX_STEPS = 2000
GENERIC_MAX_STEPS = 20000  # steps a path of a framework's generic solve may take
SECOND_START = 7919  # seed offset of the independent second generic set
# The paths of a generic solve left with crossings Bertini did not resolve are tracked again
# with these (its defaults: 1e-5, 1e-5, 1e-6), 100 times tighter, as its own warning advises.
CROSSING_TOLERANCES = {
    "tracking_tolerance": 1e-7,
    "newton_before_endgame": 1e-7,
    "newton_during_endgame": 1e-8,
}
ENDGAME_T = (
    0.1  # Bertini's endgame boundary: on a patch, a path at infinity before this is retracked
)
PATCH_SEED = 2028  # Bertini's random patch of every projective homotopy (the same on every run)
# A generic solve in this process goes in about LOCAL_CHUNKS Bertini calls of at least
# LOCAL_CHUNK paths, the progress lines between them (the X-module's 128-path set: 4.9 CPU s
# in chunks of 8, 4.6 s in chunks of 64, measured).
LOCAL_CHUNKS, LOCAL_CHUNK = 32, 8
ANNOUNCE_SECONDS = 2.0  # a generic solve expected to take longer is announced on stderr
CHUNKS_PER_WORKER = 4  # a split generic solve sends this many chunks of paths per Dask worker
BERTINI_MAX_NORM = 1e5  # Bertini's default security max norm (a larger norm counts as infinite)
INFINITE_CODES = ("GoingToInfinity", "SecurityMaxNormReached")
NEVER_TRACKED = ("NeverStarted", "SingularStartPoint")  # lost, whatever the point's norm
# Every generic set cached before the route was recorded was solved by Bertini's own start.
EARLIER_ROUTE = {"method": "bertini start system (ZeroDimSolver), one call"}


@contextmanager
def solver_errors(what: str) -> Iterator[None]:
    """Bertini's own exceptions (parse errors, a rank-deficient system, ...) as one-line
    SolverErrors that name what was being solved: never a traceback for the user."""
    try:
        yield
    except SolverError:
        raise
    except RuntimeError as exc:
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise SolverError(f"{what}: Bertini stopped: {reason}") from exc


def _bertini():
    import bertini

    bertini.recording(False)  # never recall or store runs on disk behind our back
    return bertini


def _code(m) -> str:
    """A path's outcome: the endgame's success code, or the pre-endgame one when the endgame
    never started (a path that went to infinity before it reads NeverStarted there: lost);
    CROSSING for a path whose crossing of another Bertini left unresolved (crossings.py)."""
    if crossings.flagged(m):
        return CROSSING
    code = str(m.endgame_success_code).rsplit(".", 1)[-1]
    if code == "NeverStarted":
        before = str(m.pre_endgame_success_code).rsplit(".", 1)[-1]
        return code if before == _SUCCESS else before
    return code


def _points(pts) -> np.ndarray:
    return np.array([[complex(z) for z in p] for p in pts], dtype=complex)


@dataclass(frozen=True)
class GenericSet:
    """The solutions of the system at generic complex parameters: the start of every homotopy."""

    key: str
    seed: int
    start: dict[str, complex]
    points: np.ndarray  # nonsingular finite solutions, tracked to every target
    paths: int
    finite_endpoints: int
    singular_endpoints: int
    seconds: float
    bertini_version: str
    route: dict = field(default_factory=lambda: dict(EARLIER_ROUTE))  # how it was solved
    source: str = "solved"  # for this request: "solved" now, or read from "cache" or "memory"

    def to_json(self) -> dict:
        """JSON-able form (complex numbers as [re, im])."""
        return {
            "key": self.key,
            "seed": self.seed,
            "start": {k: [v.real, v.imag] for k, v in self.start.items()},
            "points": [[[z.real, z.imag] for z in p] for p in self.points],
            "paths": self.paths,
            "finite_endpoints": self.finite_endpoints,
            "singular_endpoints": self.singular_endpoints,
            "seconds": self.seconds,
            "bertini_version": self.bertini_version,
            "route": self.route,
        }

    @classmethod
    def from_json(cls, d: dict) -> GenericSet:
        """Inverse of to_json."""
        pts = np.array([[complex(*z) for z in p] for p in d["points"]], dtype=complex)
        return cls(
            d["key"],
            d["seed"],
            {k: complex(*v) for k, v in d["start"].items()},
            pts,
            d["paths"],
            d["finite_endpoints"],
            d["singular_endpoints"],
            d["seconds"],
            d["bertini_version"],
            d.get("route", EARLIER_ROUTE),
        )

    def summary(self) -> dict:
        """What run.json records of the generic set."""
        return {
            "key": self.key,
            "seed": self.seed,
            "paths": self.paths,
            "finite_endpoints": self.finite_endpoints,
            "singular_endpoints": self.singular_endpoints,
            "tracked_points": len(self.points),
            "solve_seconds": self.seconds,
            "start_parameters": {k: [v.real, v.imag] for k, v in self.start.items()},
            "route": self.route,
            "source": self.source,
        }


# The generic start: the paper's case 3 in normalised units, plus a random complex perturbation
# of this size in every parameter. Random complex, so the straight line to any real target misses
# the parameters where paths meet (with probability one); centred on the real parameters users
# ask about, so the paths are short: 2.5 times fewer steps than a start centred at 0 (measured on
# case 3 and random geometries; bench/homotopy_start.py).
START_CENTRE = {
    "L3": 1.0, "k1": 1.0, "k2": 1.0, "p2x": 0.3541666666666667, "p3x": -0.28605555555555556,
    "p3y": 0.5478777777777778, "p6x": 0.4722222222222222, "p5x": -0.03322222222222222,
    "p5y": -0.3874666666666667, "L01": 1.2777777777777777, "L02": 1.2777777777777777,
}  # fmt: skip
START_SPREAD = 0.5


def generic_key(
    ps: ParametricSystem,
    seed: int,
    centre: dict[str, float] | None = None,
    groups: list[list[str]] | None = None,
    route: str | None = None,
) -> str:
    """Content hash of what a generic set depends on: equations, seed, start, engine version,
    and the route when it is not the total-degree one (whose keys predate routes)."""
    start = {"centre": START_CENTRE if centre is None else centre, "spread": START_SPREAD}
    if groups is not None:
        start["groups"] = groups
    what = {"system": ps.to_json(), "seed": seed, "bertini2": bertini2_version(), "start": start}
    if route is not None:
        what["route"] = route
    blob = json.dumps(what, sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


def generic_path(key: str) -> Path:
    """Where the generic set of this key is cached."""
    return cache_root() / f"generic-{key}.json"


_LOADED: dict[tuple[int, int], GenericSet] = {}


def generic_set(
    ps: ParametricSystem,
    seed: int = 1,
    use_cache: bool = True,
    centre: dict[str, float] | None = None,
    groups: list[list[str]] | None = None,
    scheduler: str | None = None,
) -> GenericSet:
    """The generic solution set of `ps` for `seed`, from memory, the disk cache, or solved.

    Its start parameters are `centre` (default: the paper's case 3, normalised) plus a random
    complex perturbation of size START_SPREAD in every parameter. With variable `groups` the
    ab-initio solve starts from a multihomogeneous start system (fewer paths). With a Dask
    `scheduler` (an address) a solve is split: our own start system's paths in chunks on its
    workers (`_own_solve`); the set is the same, and so is its key and cache entry."""
    if use_cache and (id(ps), seed) in _LOADED:  # ps objects live as long as the process
        return replace(_LOADED[id(ps), seed], source="memory")
    centre = START_CENTRE if centre is None else centre
    gs = _load_or_solve(ps, seed, use_cache, centre, groups, scheduler)
    if use_cache:
        _LOADED[id(ps), seed] = gs
    return gs


def cached_generic(path: Path) -> GenericSet | None:
    """The generic set cached at `path` (source "cache"), or None: none there, or a damaged
    entry (removed: it is recomputed, not trusted)."""
    if not path.is_file():
        return None
    try:
        return replace(GenericSet.from_json(json.loads(path.read_text())), source="cache")
    except (ValueError, KeyError):
        path.unlink(missing_ok=True)
        return None


def _load_or_solve(
    ps: ParametricSystem, seed: int, use_cache: bool, centre: dict, groups, scheduler=None
) -> GenericSet:
    key = generic_key(ps, seed, centre, groups)
    path = generic_path(key)
    cached = cached_generic(path) if use_cache else None
    if cached is not None:
        return cached
    _announce(ps, seed, path if use_cache else None, groups, scheduler)
    what = f"the generic solution set (seed {seed}, {len(ps.variables)} unknowns)"
    with solver_errors(what):
        gs = _solve_generic(ps, seed, key, centre, groups, scheduler)
    if use_cache:
        atomic_write_text(path, json.dumps(gs.to_json()))
    return gs


def _announce(
    ps: ParametricSystem, seed: int, stored: Path | None, groups=None, scheduler=None
) -> None:
    """One line on stderr before a generic solve long enough to be noticed: what, and a first
    guess of how long (the progress lines that follow measure the rate on its paths)."""
    paths, rate, source = expected(ps, groups)
    seconds = paths * rate
    if seconds < ANNOUNCE_SECONDS:
        return
    where = f"once: kept in {stored} for every later solve" if stored else "not cached"
    how = f", split over the Dask workers at {scheduler}" if scheduler else ""
    if source == PRIOR_SOURCE and groups:
        # A framework's system with nothing measured on it yet: the prior (the paper's paths)
        # is no estimate (a fallback set of 352 paths took ten times its 21 s): the first
        # progress line, a few seconds in, gives the time left at its own paths' rate.
        say(
            f"cotm-bertini: solving the generic solution set of these equations for seed "
            f"{seed} ({paths} paths{how}; {where}); no path of this system has been timed yet, "
            "so the time is not estimated here: the progress lines give it, measured on "
            "its first paths"
        )
        return
    roughly = f"{seconds:.0f} s" if seconds < 90 else duration(seconds)
    say(
        f"cotm-bertini: solving the generic solution set of these equations for seed {seed} "
        f"({paths} paths, roughly {roughly}{how}; {where}); that is a first guess at "
        f"{rate:.2g} s a path ({source}): the rate is measured as the paths finish"
    )


def generic_start(ps: ParametricSystem, seed: int, centre: dict) -> dict[str, complex]:
    """The start parameters of `seed`'s generic set: `centre` plus a random complex
    perturbation of size START_SPREAD in every parameter."""
    rng = np.random.default_rng(seed)
    return {
        name: centre[name] + START_SPREAD * complex(*rng.normal(size=2)) / np.sqrt(2)
        for name in ps.parameters
    }


def _solve_generic(
    ps: ParametricSystem, seed: int, key: str, centre: dict, groups=None, scheduler=None
) -> GenericSet:
    start = generic_start(ps, seed, centre)
    system = ps.instantiate([start[n] for n in ps.parameters])
    paths, rate, _ = expected(ps, groups)
    t0 = time.perf_counter()
    with generic_report(seed, paths, paths * rate >= ANNOUNCE_SECONDS) as report:
        ends, route = _own_solve(system, seed, groups, scheduler, report)
    seconds = time.perf_counter() - t0
    codes, finite_flags, singular, pts = ends
    # The next solve of this system (the second seed) starts from this measured rate.
    remember(ps, groups, seconds / max(len(codes), 1), f"measured on seed {seed}'s paths")
    finite = [i for i, c in enumerate(codes) if finite_flags[i] and c == _SUCCESS]
    regular = [i for i in finite if not singular[i]]
    return GenericSet(
        key,
        seed,
        start,
        pts[regular] if regular else np.zeros((0, len(ps.variables)), dtype=complex),
        len(codes),
        len(finite),
        len(finite) - len(regular),
        seconds,
        bertini2_version(),
        route,
    )


def own_start(system, groups, seed: int) -> tuple:
    """(start, (homotopy text, target text)): `seed`'s random linear-product start system of
    `system` for `groups` (None: total degree) and the gamma-trick homotopy to `system`, both
    texts declaring the start's variable groups (points in `start.declared` order)."""
    lp = linear_product_start(system, groups, seed)
    gamma = np.exp(2j * np.pi * np.random.default_rng((seed, 1)).random())
    names = [[system.variables[k] for k in g] for g in lp.groups]
    return lp, (gamma_homotopy_text(system, lp, gamma), render_system(system, names))


def _own_solve(system, seed: int, groups, scheduler=None, report=None) -> tuple[tuple, dict]:
    """Every path of our own linear-product start system (backends.start_system) on a
    multiprojective patch, in chunks (`track_chunk`): in this process, or on the Dask workers at
    `scheduler`: (codes, finite, singular, points), the route record. `report` (a
    progress.Progress) advances as each chunk comes back."""
    from .dask_jobs import run_jobs

    lp, texts = own_start(system, groups, seed)
    total, starts, workers = lp.count(), [], []

    def job(points: np.ndarray, **more) -> dict:
        return {"texts": texts, "points": points[:, lp.declared], **more}

    def jobs(n: int) -> list[dict]:
        workers.append(n)
        starts.extend(lp.chunks(max(1, -(-total // (CHUNKS_PER_WORKER * n)))))
        return [job(c) for c in starts]

    def run(batch) -> Iterator[tuple[int, dict]]:
        if scheduler is not None:
            return run_jobs(track_chunk, batch, scheduler)
        return ((k, track_chunk({**j, "threads": None})) for k, j in enumerate(batch))

    batch = jobs
    if scheduler is None:  # chunks for the progress lines; Bertini's threads share each one
        workers.append(1)
        starts.extend(lp.chunks(max(LOCAL_CHUNK, -(-total // LOCAL_CHUNKS))))
        batch = [job(c) for c in starts]
    done = {}
    for k, chunk in run(batch):
        done[k] = chunk
        if report is not None:
            report.update(len(chunk["codes"]))
    chunks = [done[k] for k in range(len(done))]
    ends = [[x for c in chunks for x in c[f]] for f in ("codes", "finite", "singular")]
    back = np.argsort(lp.declared)  # Bertini's coordinates are group by group
    pts = np.vstack([c["points"] for c in chunks])[:, back]

    def again(idx: list[int], **more) -> float:
        """The paths `idx` tracked again in adaptive precision (with `more`), their ends
        replaced: the CPU seconds it took."""
        out = next(iter(run([job(np.vstack(starts)[idx], mptype="adaptive", **more)])))[1]
        for k, i in enumerate(idx):
            for f, col in zip(("codes", "finite", "singular"), ends, strict=True):
                col[i] = out[f][k]
            pts[i] = out["points"][k][back]
        return out["cpu_seconds"]

    twins = _twins(*ends, pts)  # one path jumped onto another's root in double precision
    again_cpu = again(twins) if twins else 0.0
    crossing_cpu, crossings_record = _part_crossings(seed, ends[0], again)
    for i in _twins(*ends, pts):  # still together: a multiple root, as ZeroDimSolver says
        ends[2][i] = True
    where = f"on {scheduler}" if scheduler else "in this process"
    route = {
        "method": f"own {'multihomogeneous' if groups else 'total-degree'} linear-product "
        f"start on a projective patch, double then adaptive precision, {len(chunks)} chunks "
        f"{where}",
        "scheduler": scheduler,
        "workers": workers[0],
        "chunks": len(chunks),
        "paths_per_chunk": [len(c["codes"]) for c in chunks],
        "chunk_seconds": [round(c["seconds"], 3) for c in chunks],
        "cpu_seconds": round(sum(c["cpu_seconds"] for c in chunks) + again_cpu + crossing_cpu, 3),
        "retracked_adaptive": sum(c["retracked_adaptive"] for c in chunks)
        + len(twins)
        + crossings_record.get("crossings_first_solve", 0),
        "failed_paths": _failed(ends[0]),
        **crossings_record,
    }
    return (*ends, pts), route


def _part_crossings(seed: int, codes: list[str], again) -> tuple[float, dict]:
    """(CPU seconds, record): nothing when no path of the generic solve is still flagged as
    crossing another (CROSSING, after its retrack in adaptive precision); else those paths
    tracked again (`again`, which replaces their ends in `codes`) at CROSSING_TOLERANCES,
    said, and recorded (a set whose crossings remain is incomplete: its route says why)."""
    crossed = [i for i, c in enumerate(codes) if c == CROSSING]
    if not crossed:
        return 0.0, {}
    # Bertini's own re-tracks (each at half the tolerance) did not part two paths.
    say(
        f"cotm-bertini: warning: {len(crossed)} paths of the generic solve (seed {seed}) "
        "crossed another path and Bertini could not part them (the affected solutions may be "
        f"wrong); tracking them again from their starts at tracking tolerances "
        f"{CROSSING_TOLERANCES}"
    )
    cpu = again(crossed, tolerances=CROSSING_TOLERANCES)
    left = sum(codes[i] == CROSSING for i in crossed)
    record = {"crossings_first_solve": len(crossed), "crossings_unresolved": left,
              "crossings_solved_again_at": CROSSING_TOLERANCES}  # fmt: skip
    if left:
        why = (f"{left} paths crossed another path, unresolved even at tracking tolerances "
               f"{CROSSING_TOLERANCES}: the affected solutions may be wrong")  # fmt: skip
        say(f"cotm-bertini: warning: the generic set (seed {seed}) is incomplete: {why}")
        record.update(complete=False, reason=why)
    else:
        say(f"cotm-bertini: the generic solve (seed {seed}) again: no crossing left")
    return cpu, record


def _failed(codes: list[str]) -> int:
    """Paths that ended neither at a finite point nor on the way to infinity (lost)."""
    return sum(c != _SUCCESS and c not in INFINITE_CODES for c in codes)


def _twins(codes: list, finite: list, singular: list, pts: np.ndarray) -> list[int]:
    """The nonsingular finite endpoints that coincide with another one (relative 1e-7)."""
    idx = [i for i, c in enumerate(codes) if c == _SUCCESS and finite[i] and not singular[i]]
    return [idx[k] for k in sorted(coincident_rows(pts[idx]))]


def coincident_rows(pts: np.ndarray, tol: float = 1e-7) -> set[int]:
    """Rows of `pts` within `tol` (relative to 1 + the larger norm) of another row."""
    out: set[int] = set()
    if len(pts) < 2:
        return out
    scale = 1.0 + np.abs(pts).max(axis=1)
    for a in range(len(pts)):
        d = np.abs(pts[a + 1 :] - pts[a]).max(axis=1) / np.maximum(scale[a + 1 :], scale[a])
        near = np.nonzero(d < tol)[0]
        if len(near):
            out.update([a, *(a + 1 + near).tolist()])
    return out


def _end_points(pts, n: int) -> np.ndarray:
    """Endpoints as an (m, n) array; a path to infinity may report other coordinates: NaN."""
    out = np.full((len(pts), n), np.nan, dtype=complex)
    for k, p in enumerate(pts):
        if len(p) == n:
            out[k] = [complex(z) for z in p]
    return out


def track_chunk(job: dict) -> dict:
    """One chunk of a generic solve (a Dask task: plain data in, plain data out): the
    gamma-trick homotopy `job["texts"]` tracked from `job["points"]` on a projective patch by
    double_then_adaptive (`job["mptype"] = "adaptive"`: all in AMP); `job["threads"]`:
    Bertini's threads (None: its default, every core; 1 on a cluster, whose workers are the
    parallelism); `job["tolerances"]`: tracking tolerances other than Bertini's defaults."""
    t0 = time.perf_counter()  # one task at a time a worker process
    points = np.asarray(job["points"], dtype=complex)
    options = {
        "projective": True,
        "max_norm": BERTINI_MAX_NORM,
        "num_threads": job.get("threads", 1),
        **job.get("tolerances", {}),  # CROSSING_TOLERANCES for paths left crossing
    }
    if job.get("mptype") == "adaptive":
        cpu = time.process_time()
        out = tracked_paths(job["texts"], points, "adaptive", options)
        out.update(retracked_adaptive=0, cpu_seconds=time.process_time() - cpu)
    else:
        out = double_then_adaptive(job["texts"], points, options)
    return {**out, "seconds": time.perf_counter() - t0}


def double_then_adaptive(
    texts: tuple[str, str], points: np.ndarray, options: dict, singular_ok: bool = False
) -> dict:
    """The homotopy texts[0] (target texts[1]) from `points` in double precision, then in
    adaptive precision every path that did not end at a finite point, that met another or
    (unless `singular_ok`: a caller to whom a singular endpoint is no root it keeps, whose
    retrack costs ~0.15 s for the same point) that ended singular. On a projective patch
    (`options["projective"]`) a path that reached infinity inside the endgame (t < ENDGAME_T)
    is not tracked again: a root escaping as t -> 0 grows like t^-a, past the max norm only
    near t = 0, while a path past it earlier may be a finite root's (in affine coordinates
    such a path fails in double precision instead, and its adaptive retrack costs 0.3-1 s:
    the X-module's total-degree paths, monodromy's final homotopy). Every other failed path is
    tracked again (without that the double pendulum's monodromy lost 550 of 1,700 paths), a
    path Bertini flagged as crossing another (CROSSING, whatever its success code) among them."""
    cpu = time.process_time()
    out = tracked_paths(texts, points, "double", options)
    fields = [out[f] for f in ("codes", "finite", "singular")]
    patch = bool(options.get("projective"))
    times = zip(out["codes"], out["times"], strict=True)
    away = [patch and c in INFINITE_CODES and t < ENDGAME_T for c, t in times]
    redo = {
        k
        for k, (c, f, sing) in enumerate(zip(*fields, strict=True))
        if (c != _SUCCESS or not f or (sing and not singular_ok)) and not away[k]
    }
    redo = sorted(redo | set(_twins(*fields, out["points"])))
    if redo:
        again = tracked_paths(texts, points[redo], "adaptive", options)
        for f in ("codes", "finite", "singular"):
            for k, i in enumerate(redo):
                out[f][i] = again[f][k]
        out["points"][redo] = again["points"]
    return {**out, "retracked_adaptive": len(redo), "cpu_seconds": time.process_time() - cpu}


def tracked_paths(texts: tuple[str, str], points: np.ndarray, mptype: str, options: dict) -> dict:
    """One HomotopySolver call (one thread unless `options["num_threads"]` says otherwise,
    None: Bertini's default) with the step caps of track, each path's outcome the code it
    stopped with (_code) and the t it stopped at; `options["projective"]`: on a patch
    (parsed_system); "predictor" by name; the rest Bertini's settings."""
    _bertini()  # recording off, before the import
    from bertini import nag_algorithm as na
    from bertini import tracking

    options = {"num_threads": 1, **options}
    if options["num_threads"] is None:
        del options["num_threads"]
    if "predictor" in options:  # by name here: the enum needs the module
        options["predictor"] = getattr(tracking.Predictor, options["predictor"])
    hom = parsed_system(texts[0], options.pop("projective", False))
    solver = na.HomotopySolver(hom, list(points), parsed_system(texts[1]), mptype=mptype)
    if mptype == "double":
        solver.set(final_tolerance=DOUBLE_FINAL_TOLERANCE, max_num_steps=DOUBLE_MAX_STEPS)
    else:
        solver.set(max_num_steps=GENERIC_MAX_STEPS)
    solver.set(**options)
    quiet_solve(solver)  # our progress lines; no raw crossing line
    meta = solver.solution_metadata()
    return {
        "codes": [_code(m) for m in meta],
        "finite": [bool(m.is_finite) for m in meta],
        "singular": [is_singular(m) for m in meta],
        "times": [abs(complex(m.final_time_used)) for m in meta],
        "points": _end_points(solver.all_solutions(), points.shape[1]),
    }


@lru_cache(maxsize=16)
def parsed_system(text: str, projective: bool = False):
    """Bertini's parse of a system text, kept: a monodromy edge is tracked again and again, and
    a parse of case 3's homotopy costs 3 ms (11 % of a run, measured); a solver does not change
    the system it tracks (same endpoints from a kept parse and a fresh one, checked).

    `projective`: homogenized (one homogenizing variable per variable group: multiprojective)
    on a patch drawn from a fixed seed (Bertini's own homogenization; its solver dehomogenizes
    the endpoints), for homotopies whose paths mostly go to infinity: in affine coordinates
    double precision fails on them near t = 0 (296 of the prism's 343 paths of monodromy's
    final homotopy) and each costs a 0.27 s adaptive retrack (83 s of a 122 s run); on a patch
    they end at infinity in double precision (that final homotopy 3.2 s, the same 22 roots)."""
    bertini = _bertini()
    system = bertini.parse.system(text)
    if not projective:
        return system
    from bertini import system as bsys

    bertini.random.set_random_seed(PATCH_SEED)  # the same patch on every run
    system = bsys.clone(system)
    system.homogenize()
    system.auto_patch()
    return system


def route_record(sets: list[GenericSet], scheduler: str | None) -> dict:
    """How a solve's generic sets were obtained (solved now by which route, or loaded), and
    whether a given Dask scheduler was used: only a set solved now needs it."""
    out: dict = {"generic_sets": [{"seed": g.seed, "source": g.source, **g.route} for g in sets]}
    if scheduler is not None:
        used = any(g.source == "solved" for g in sets)
        out["scheduler"] = scheduler
        out["scheduler_used"] = used
        if not used:
            out["note"] = "scheduler not needed: every generic set was already solved"
    return out


def is_singular(m) -> bool:
    """Bertini's singular flag: multiplicity > 1 or a condition number over its threshold."""
    return bool(m.is_singular or m.multiplicity > 1)


@dataclass
class TrackReport:
    """What tracking to one target did."""

    tracked: int = 0
    finite: int = 0
    infinite: int = 0
    retracked_adaptive: int = 0
    lost: int = 0
    crossings_unresolved: int = 0  # of the lost: paths Bertini flagged (crossings.py)
    method: str = "parameter homotopy"
    seconds: float = 0.0
    notes: list[str] = field(default_factory=list)
    input_text: str = ""  # the homotopy as rendered (written to the run folder as `input`)

    def as_dict(self) -> dict:
        """For run.json and sweep rows."""
        out = {**self.__dict__, "notes": "; ".join(self.notes)}
        del out["input_text"]
        return out


def _configure(
    solver, settings: Settings, mptype: str, deadline: float | None, size: float = 1.0
) -> None:
    """Every tracking setting the caller passed (Bertini's defaults for the rest). `size`: the
    largest parameter value's magnitude: Bertini's max norm grows with it, since the solutions
    grow with the parameters (Zeeman's wheel pulled from 1e5 units away has a band 1e5 long, at
    infinity for the default max norm, and a run with no solution at all)."""
    options: dict[str, object] = {}
    if size > 1.0:
        options["max_norm"] = BERTINI_MAX_NORM * size
    if settings.threads is not None:
        options["num_threads"] = settings.threads
    if mptype == "double":
        # The endgame cannot reach Bertini's default 1e-11 in double precision on a few paths
        # and fails them; 1e-8 is enough, as classification Newton-refines every endpoint.
        options["final_tolerance"] = DOUBLE_FINAL_TOLERANCE
        # In double precision a path whose step was cut can crawl for 1e5 steps (tens of
        # seconds); a normal path takes under a hundred. Give up early: AMP redoes it in ms.
        options["max_num_steps"] = DOUBLE_MAX_STEPS
    chosen = {
        "final_tolerance": settings.final_tol,
        "newton_before_endgame": settings.tracktol_before_eg,
        "newton_during_endgame": settings.tracktol_during_eg,
        "level": settings.security_level,
        "max_norm": settings.max_norm,
        "condition_number_threshold": settings.condnum_threshold,
    }
    options.update({k: v for k, v in chosen.items() if v is not None})
    if deadline is not None:
        remaining = deadline - time.perf_counter()
        if remaining <= 0:
            raise SolverError(f"the in-process solve timed out after {settings.timeout:g} s")
        options["max_solve_wall_clock_duration"] = remaining
    solver.set(**options)


def _track(
    texts: tuple[str, str],
    gs: GenericSet,
    idx: list[int],
    mptype: str,
    settings: Settings,
    deadline: float | None,
    size: float = 1.0,
):
    bertini = _bertini()
    from bertini import nag_algorithm as na

    with solver_errors(f"the parameter homotopy from the generic set ({len(idx)} paths)"):
        hom, tgt = (bertini.parse.system(text) for text in texts)
        solver = na.HomotopySolver(hom, [gs.points[i] for i in idx], tgt, mptype=mptype)
        _configure(solver, settings, mptype, deadline, size)
        quiet_solve(solver)
    if deadline is not None and time.perf_counter() > deadline:
        raise SolverError(f"the in-process solve timed out after {settings.timeout:g} s")
    return solver.solution_metadata(), solver.all_solutions()


def parameter_values(ps: ParametricSystem, params: Params | Mapping[str, float]) -> dict:
    """The values of `ps`'s parameters: from a mapping (a framework's slots) or a Params."""
    if isinstance(params, Mapping):
        return {n: params[n] for n in ps.parameters}
    return {n: getattr(params, n) for n in ps.parameters}


def track(
    ps: ParametricSystem,
    gs: GenericSet,
    params: Params | Mapping[str, float],
    settings: Settings = Settings(),
    deadline: float | None = None,
    retrack_diverged: bool = True,
) -> tuple[Endpoints, TrackReport]:
    """Finite endpoints at `params`, tracked from the generic set.

    Paths are tracked in double precision; with mptype 2 any path that does not end in success
    is tracked again with adaptive precision (mptype 0 keeps double precision only); a path that
    still fails is counted as lost (the caller re-solves). `retrack_diverged=False`: a path that
    fails in double precision beyond Bertini's finite threshold (1e5) is counted at infinity
    without the adaptive retrack (for a caller that wants only points of order one: the retrack
    of such a path costs about 0.2 s and ends at infinity).
    """
    t0 = time.perf_counter()
    target = parameter_values(ps, params)
    texts = (
        render_parameter_homotopy(ps, gs.start, target),
        render_system(ps.instantiate([target[n] for n in ps.parameters])),
    )
    n = len(gs.points)
    rep = TrackReport(tracked=n, input_text=texts[0])
    size = max([1.0, *(abs(v) for v in target.values())])
    meta, pts = _track(texts, gs, list(range(n)), "double", settings, deadline, size)
    results = {i: (meta[i], pts[i]) for i in range(n)}
    redo = [i for i in range(n) if _code(meta[i]) != _SUCCESS or not meta[i].is_finite]
    crossed = sum(_code(m) == CROSSING for m in meta)
    if crossed:
        rep.notes.append(f"{crossed} paths crossed another in double precision (Bertini's flag)")
    if _crossing(results, [i for i in range(n) if i not in redo]):
        redo = list(range(n))
        rep.notes.append("path crossing in double precision: all paths re-tracked")
    elif not retrack_diverged:
        kept = [i for i in redo if meta[i].is_finite or _code(meta[i]) in NEVER_TRACKED]
        if len(kept) < len(redo):
            rep.notes.append(f"{len(redo) - len(kept)} paths diverged in double precision")
        redo = kept
    if redo and settings.mptype == 2:
        rep.retracked_adaptive = len(redo)
        meta2, pts2 = _track(texts, gs, redo, "adaptive", settings, deadline, size)
        for k, i in enumerate(redo):
            results[i] = (meta2[k], pts2[k])
    rows = []
    for i in range(n):
        m, p = results[i]
        code = _code(m)
        if code == _SUCCESS and m.is_finite:
            rows.append(endpoint_record(i, m, p))
        elif code in INFINITE_CODES or (code not in NEVER_TRACKED and not m.is_finite):
            rep.infinite += 1
        else:
            rep.lost += 1
            rep.crossings_unresolved += code == CROSSING
            rep.notes.append(f"path {i}: {code}")
    rep.finite = len(rows)
    rep.seconds = time.perf_counter() - t0
    return Endpoints.from_records(ps.variables, rows), rep


def endpoint_record(index: int, m, point) -> dict:
    """One endpoint's metadata (the Endpoints fields) and coordinates."""
    d = m.to_dict()
    return {
        "path_number": index,
        "condition_number": float(d["condition_number"]),
        "function_residual": float(d["function_residual"]),
        "newton_residual": float(d["newton_residual"]),
        "final_t": complex(d["final_time_used"]).real,
        "max_precision": float(d["max_precision_used"]),
        "accuracy_estimate": float(d["accuracy_estimate_user_coords"]),
        "cycle_number": int(d["cycle_num"]),
        "bertini_multiplicity": int(d["multiplicity"]),
        "coords": [complex(z) for z in point],
    }


def _crossing(results: dict, idx: list[int], tol: float = 1e-7) -> bool:
    """Two paths ending at the same nonsingular point: one of them jumped."""
    pts = np.array(
        [[complex(z) for z in results[i][1]] for i in idx if not is_singular(results[i][0])],
        dtype=complex,
    )
    return bool(coincident_rows(pts, tol))


def zero_length_roots(params: Params, variables: tuple[str, ...]) -> Endpoints:
    """The d = 0 artefacts at `params` in closed form, as endpoints (two paths end at each)."""
    points = zero_length_points(params, variables)
    records = [
        {
            "path_number": -1,
            "condition_number": np.inf,
            "function_residual": 0.0,
            "newton_residual": 0.0,
            "final_t": 0.0,
            "accuracy_estimate": 0.0,
            "cycle_number": 1,
            "bertini_multiplicity": 2,
            "closed_form": True,
            "coords": point,
        }
        for point in points
    ]
    return Endpoints.from_records(variables, records)


def ab_initio(
    ps: ParametricSystem, params: Params | Mapping[str, float], settings: Settings = Settings()
) -> tuple[Endpoints, TrackReport]:
    """Total-degree solve at the target itself (in-process): the last resort.

    Returns the nonsingular finite endpoints (the closed form reports the d = 0 artefacts) and
    its report: paths tracked (the total degree), finite, at infinity, lost (neither)."""
    bertini = _bertini()
    from bertini import nag_algorithm as na

    t0 = time.perf_counter()
    bertini.random.set_random_seed(settings.seed)
    values = parameter_values(ps, params)
    system = ps.instantiate([values[n] for n in ps.parameters])
    with solver_errors(f"the total-degree solve at the target ({system.total_degree} paths)"):
        solver = na.ZeroDimSolver(bertini.parse.system(render_system(system)))
        _configure(solver, settings, "adaptive", None, max([1.0, *map(abs, values.values())]))
        quiet_solve(solver)
        ends = list(zip(solver.solution_metadata(), solver.all_solutions(), strict=True))
    rows, rep = [], TrackReport(tracked=len(ends), method="ab initio")
    for i, (m, p) in enumerate(ends):
        code = _code(m)
        if m.is_finite and code == _SUCCESS:
            if not is_singular(m):
                rows.append(endpoint_record(i, m, p))
        elif code not in INFINITE_CODES and (m.is_finite or code in NEVER_TRACKED):
            rep.lost += 1
            rep.crossings_unresolved += code == CROSSING
            rep.notes.append(f"path {i}: {code}")
        else:
            rep.infinite += 1
    rep.finite, rep.seconds = len(rows), time.perf_counter() - t0
    return Endpoints.from_records(ps.variables, rows), rep
