"""The branch and bound of boxsearch.boxes split over processes: local ones (`workers`) or a
Dask cluster's (`scheduler`). Boxes are independent (a box's fate is its own), so the start
boxes, after a few breadth-first steps where they are too few to balance, are dealt round-robin
into shares (neighbouring boxes to different shares: each gets a similar mix of easy and hard
ones), each searched by a worker that rebuilds the landscape from a picklable source
(`factory(source)`: any BoxLandscape, the torus of a planar framework or the charts of a spatial
one), and the records are merged into one (boxes.merged).
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import multiprocessing
import threading
import time
from collections.abc import Callable

import numpy as np

from ..backends.pools import as_done, default_workers, start_method
from ..errors import SolverError
from ..model.intervals import Interval
from ..progress import Progress, silenced
from .boxes import BATCH, BoxLandscape, BoxSearch, domain, merged, search, spread

# A worker done early takes another share, and the progress moves a share at a time; but each
# share walks its boxes down in as many batch steps as the whole search (about 1 ms of numpy's
# overhead each): more than one share a worker only where the start boxes fill BATCH-box steps.
SHARES_A_WORKER = 4
# ... but a search over 4 or more dimensions takes minutes, and its hard boxes cluster (round
# critical points): one share a worker left a worker idle for most of prism4's search.
SHARES_A_WORKER_LARGE = 16
LARGE = 4  # dimensions from which a search counts as large
BOXES_A_SHARE = 16  # breadth-first steps until there are this many boxes a share to deal
SPREAD_STEPS = 8  # ... at most (a 1-D domain of 8 boxes: 16 a share after a few steps)
# workers=None: the search runs in this process for this long first (most frameworks are
# proved in well under a second, where starting processes would cost more than they save),
# then the boxes it has not decided go to one process a core.
PROBE_SECONDS = 2.0


def split_search(
    factory: Callable[[object], BoxLandscape],
    source: object,
    short: float,
    min_width: float,
    *,
    workers: int | None = 1,
    scheduler: str | None = None,
    start: int = 8,
    max_boxes: int | None = None,
    max_seconds: float | None = None,
    label: str = "real search",
) -> BoxSearch:
    """boxes.search over the landscape `factory(source)`, its boxes shared among `workers`
    local processes or the workers of the Dask cluster at `scheduler` (a single worker: the
    plain search in this process; None: in this process for PROBE_SECONDS, then what is left
    over one process a core); the budgets hold for the whole search. `factory` and `source`
    must pickle (a module's function and a frozen spec)."""
    land = factory(source)
    if scheduler is None and workers == 1:
        return search(land, short, min_width, start, max_boxes, max_seconds, label)
    t0 = time.perf_counter()
    first = domain(land, start)
    volume = float(np.prod(first[1] - first[0], axis=1).sum())
    deadline = None if max_seconds is None else time.time() + max_seconds
    heads = []
    if workers is None and scheduler is not None:
        workers = 1  # the cluster's workers take the shares
    elif workers is None:
        # a worker of a pool already (a sweep's point, an event's solve): this process only
        workers = 1 if multiprocessing.parent_process() is not None else default_workers()
        probe = PROBE_SECONDS if max_seconds is None else min(PROBE_SECONDS, max_seconds)
        if workers == 1:
            return search(land, short, min_width, start, max_boxes, max_seconds, label)
        found = search(land, short, min_width, start, max_boxes, probe, label, boxes=first)
        if not found.budget_hit or probe == max_seconds or (max_boxes and found.boxes >= max_boxes):
            return found  # proved, or stopped by the caller's own budget
        first = (found.undecided[:, : land.n], found.undecided[:, land.n :])
        heads.append(dataclasses.replace(found, undecided=found.undecided[:0], budget_hit="",
                                         shares=0))  # fmt: skip
        max_boxes = None if max_boxes is None else max_boxes - found.boxes
    _warm(land, first)
    dealt: dict = {}  # what the breadth-first steps decided here, and the shares dealt

    def jobs(count: int) -> list[tuple]:
        per = min(SHARES_A_WORKER, max(1, len(first[0]) // BATCH))
        shares = max(1, count) * (SHARES_A_WORKER_LARGE if land.n >= LARGE else per)
        (lo, hi), done = spread(land, first, short, min_width, shares * BOXES_A_SHARE,
                                SPREAD_STEPS)  # fmt: skip
        dealt["head"] = dataclasses.replace(done, shares=0, volume=volume)
        dealt["left"] = float(np.prod(hi - lo, axis=1).sum()) / volume  # of the whole domain
        dealt["shares"] = min(shares, len(lo))
        most = None if max_boxes is None else max(1, math.ceil(max_boxes / shares))
        step = dealt["shares"]
        dealt["volumes"] = [float(np.prod(hi[k::step] - lo[k::step], axis=1).sum())
                            for k in range(step)]  # fmt: skip
        return [(factory, source, lo[k::step], hi[k::step], short, min_width, most, deadline,
                 shared, k) for k in range(step)]  # fmt: skip

    with _shares_said(scheduler) as shared:
        finished = as_done(_search_share, jobs, workers, scheduler)  # local processes start now
        parts: dict[int, BoxSearch] = {}
        with Progress(label, 1.0, "of the poses decided", heartbeat=True) as report:
            with _polled(report, dealt, parts, shared, volume):
                for k, part in finished:
                    parts[k] = part
                    boxes = dealt["head"].boxes + sum(p.boxes for p in parts.values())
                    report.set(
                        _decided(dealt, parts, _said(shared), volume),
                        note=f"{boxes:,} boxes, {len(parts)}/{dealt['shares']} shares",
                    )
    found = heads + [dealt["head"]] + [parts[k] for k in sorted(parts)]
    _check_cover(label, dealt, parts, volume)
    return merged(found, volume, time.perf_counter() - t0)


SHARE_SAID = 1.0  # seconds: a worker says its share's progress at most this often


@contextlib.contextmanager
def _shares_said(scheduler: str | None):
    """Where local workers say how much of their shares they have decided (a manager's dict,
    share -> fraction), so that the progress moves before a share comes back; None on a
    cluster (its shares are said as they come back)."""
    if scheduler is not None:
        yield None
        return
    # started as the pool's workers are (pools.start_method: no fork once the bertini module
    # runs threads in this process)
    manager = multiprocessing.get_context(start_method()).Manager()
    try:
        yield manager.dict()
    finally:
        manager.shutdown()


@contextlib.contextmanager
def _polled(report: Progress, dealt: dict, parts: dict, shared, volume: float):
    """The progress set every SHARE_SAID seconds from the workers' fractions of the shares not
    yet back, in a thread, while the shares run."""
    if shared is None:
        yield
        return
    stop = threading.Event()

    def poll() -> None:
        while not stop.wait(SHARE_SAID):
            report.set(_decided(dealt, parts, _said(shared), volume))

    thread = threading.Thread(target=poll, daemon=True)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join()


def _said(shared) -> dict:
    """What the workers have said of their shares (share -> fraction decided), or nothing."""
    if shared is None:
        return {}
    try:
        return dict(shared)
    except (OSError, EOFError):  # the manager gone: the shares are over
        return {}


def _decided(dealt: dict, parts: dict, said: dict, volume: float) -> float:
    """The share of the domain decided: the breadth-first steps', the shares back (less what a
    budget left undecided in them), and the fractions the workers have said of the others."""
    running = sum(f * dealt["volumes"][k] for k, f in said.items() if k not in parts)
    back = sum(p.volume * (1.0 - p.undecided_share) for p in parts.values())
    return 1.0 - dealt["left"] + (back + running) / volume


def _check_cover(label: str, dealt: dict, parts: dict, volume: float) -> None:
    """The steps here and the shares back cover the whole domain (every job comes back or
    raises: a gap is a bug, never a smaller proof passed off as the whole)."""
    covered = 1.0 - dealt["left"] + sum(p.volume for p in parts.values()) / volume
    lost = sorted(set(range(dealt["shares"])) - set(parts))
    if lost or abs(covered - 1.0) > 1e-9:
        raise SolverError(
            f"{label}: the shares searched cover {covered:.9g} of the domain, not all of it "
            f"(shares {lost} of {dealt['shares']} never came back)"
        )


def _warm(land: BoxLandscape, first: tuple[np.ndarray, np.ndarray], most: int = 64) -> None:
    """Every function of the landscape run once on a few boxes spread over the domain (cables
    taut, slack and either: every taut set's Hessian), so that their generated code is
    compiled before local workers fork from this process (each would compile it again)."""
    pick = slice(None, None, max(1, len(first[0]) // most))
    box = Interval(first[0][pick], first[1][pick])
    _, _, states = land.enclose(box)
    land.hessian(box, states)
    land.derivatives(box.mid)


def _search_share(job: tuple) -> BoxSearch:
    """One share of boxes searched in a worker: the landscape rebuilt from its source (once a
    process where the factory keeps it), its CPU time counted with the search's."""
    factory, source, lo, hi, short, min_width, most, deadline, shared, k = job
    c0 = time.process_time()
    last = [0.0]

    def say(fraction: float) -> None:
        if shared is not None and time.time() - last[0] >= SHARE_SAID:
            last[0] = time.time()
            shared[k] = fraction

    with silenced():  # the parent reports the merged progress
        land = factory(source)
        left = None if deadline is None else max(deadline - time.time(), 1e-9)
        found = search(land, short, min_width, max_boxes=most, max_seconds=left, boxes=(lo, hi),
                       step=say)  # fmt: skip
    return dataclasses.replace(found, cpu_seconds=time.process_time() - c0)


# A finished search's undecided boxes, where few, searched again with sides this much finer:
# next to a badly conditioned critical point (the pair about to meet at a fold, or the ghost
# left where it has just vanished, grad V nearly 0) the enclosures decide only below the usual
# smallest width. Along a continuum nothing decides at any width: the budget bounds that cost.
DEEPER = 100
DEEPEN_MOST = 2000  # undecided boxes at most, to search again
DEEPEN_BOXES = 50  # ... with this many boxes for each


def deepened(land: BoxLandscape, found: BoxSearch, short: float, min_width: float,
             label: str = "real search") -> BoxSearch:  # fmt: skip
    """`found` with its undecided boxes (if it stopped at the smallest width on at most
    DEEPEN_MOST of them) searched again down to min_width / DEEPER, the records merged."""
    left = found.undecided
    if found.budget_hit or not 0 < len(left) <= DEEPEN_MOST:
        return found
    n = left.shape[1] // 2
    again = search(land, short, min_width / DEEPER, max_boxes=DEEPEN_BOXES * len(left),
                   label=f"{label}, {len(left)} undecided boxes again",
                   boxes=(left[:, :n], left[:, n:]))  # fmt: skip
    if again.budget_hit:  # a continuum, say: nothing gained, the first record stands
        return found
    head = dataclasses.replace(found, undecided=left[:0], edge=0)
    return merged([head, again], found.volume, found.seconds + again.seconds)
