"""Where picklable jobs run: in this process, on local worker processes, or on a Dask cluster
(backends.dask_jobs). Sweeps send runs of grid points this way (continuation.runner), fold
curves their lines (catastrophe.framework_folds), the real route its shares of boxes
(boxsearch.box_shares).
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Callable, Iterable, Iterator

from ..errors import ParameterError

Run = Callable[[Callable, list], list]  # run(function, tasks) -> the results, in order
Jobs = Iterable | Callable[[int], Iterable]  # the jobs, or a function of the worker count


def check_workers(workers: object) -> None:
    """Refuse a worker count that is not an integer >= 1, naming the argument `workers`."""
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ParameterError(f"workers = {workers!r}: must be an integer >= 1")


def default_workers() -> int:
    """One worker per core."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return max(1, os.cpu_count() or 1)


def start_method() -> str:
    """How worker processes start: `fork` while this process has not loaded the bertini module
    and runs no other thread (the workers then begin with numpy, this package and the generic
    sets already loaded), else `spawn` (the bertini module is not fork-safe with its threads)."""
    import threading

    if sys.platform == "linux" and "bertini" not in sys.modules and threading.active_count() == 1:
        return "fork"
    return "spawn"


@contextlib.contextmanager
def worker_pool(workers: int) -> Iterator[Run]:
    """A `Run` in this process (workers = 1) or in `workers` processes, started at the first
    run as the sweeps' are (start_method: by then this process may have loaded the bertini
    module, and must not fork); the tasks and the function must pickle."""
    check_workers(workers)
    if workers == 1:
        yield lambda fn, tasks: [fn(t) for t in tasks]
        return
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    pools: list[ProcessPoolExecutor] = []

    def run(fn: Callable, tasks: list) -> list:
        if not pools:
            ctx = mp.get_context(start_method())
            pools.append(ProcessPoolExecutor(max_workers=workers, mp_context=ctx))
        return list(pools[0].map(fn, tasks))

    try:
        yield run
    finally:
        for pool in pools:
            pool.shutdown()


def as_done(
    fn: Callable, jobs: Jobs, workers: int = 1, scheduler: str | None = None
) -> Iterator[tuple[int, object]]:
    """(index, fn(job)) for every job as each finishes: on the Dask cluster at `scheduler`, on
    `workers` local processes, or one after another in this process (one worker). The local
    processes start and take their jobs before this returns (a progress bar's thread started
    afterwards does not make them spawn rather than fork); the function and jobs must pickle."""
    if scheduler is not None:
        from .dask_jobs import run_jobs

        return run_jobs(fn, jobs, scheduler)
    check_workers(workers)
    jobs = list(jobs(workers) if callable(jobs) else jobs)
    if workers == 1:
        return ((k, fn(job)) for k, job in enumerate(jobs))
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    pool = ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context(start_method()))
    futures = {pool.submit(fn, job): k for k, job in enumerate(jobs)}
    return _finished(pool, futures)


def _finished(pool, futures: dict) -> Iterator[tuple[int, object]]:
    """The futures' (index, result) as each finishes; the pool shut down at the end, or early
    (its queued jobs cancelled) when the caller stops or a job fails."""
    from concurrent.futures import as_completed

    try:
        for fut in as_completed(futures):
            yield futures[fut], fut.result()
    finally:
        pool.shutdown(cancel_futures=True)
