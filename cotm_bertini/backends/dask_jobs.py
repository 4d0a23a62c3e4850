"""Run picklable jobs on a Dask cluster: the one place that talks to a Dask scheduler.

Sweeps send runs of grid points this way (continuation.runner), a large solve its chunks of
paths (backends.homotopy). A scheduler that does not answer is bad input: one line naming it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator

from ..errors import CotmError, ParameterError, SolverError

CONNECT_SECONDS = 10.0  # how long to wait for a scheduler to answer before giving up


def connect(scheduler: str):
    """A distributed.Client on `scheduler`; ParameterError if nothing answers there."""
    if not isinstance(scheduler, str) or not scheduler:
        raise ParameterError(f"scheduler = {scheduler!r}: expected an address, tcp://host:8786")
    import dask
    from dask.utils import parse_timedelta
    from distributed import Client

    # Dask's own connect timeout (30 s by default; DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT),
    # at most CONNECT_SECONDS: a mistyped address should not hang a command for long.
    wait = parse_timedelta(dask.config.get("distributed.comm.timeouts.connect"), default="s")
    try:
        return Client(scheduler, timeout=min(CONNECT_SECONDS, wait))
    except (OSError, TimeoutError, ValueError, TypeError) as exc:
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ParameterError(
            f"scheduler = {scheduler!r}: no Dask scheduler answers there ({reason})"
        ) from None


def check_scheduler(scheduler: str) -> int:
    """The number of workers of the scheduler at `scheduler` (ParameterError if unreachable)."""
    with connect(scheduler) as client:
        return len(client.scheduler_info()["workers"])


def run_jobs(
    fn: Callable, jobs: Iterable | Callable[[int], Iterable], scheduler: str
) -> Iterator[tuple[int, object]]:
    """(index, fn(job)) for every job, run on the Dask cluster at `scheduler`, as each finishes.
    `jobs` may be a function of the cluster's worker count (to cut work into enough pieces)."""
    from distributed import as_completed

    with connect(scheduler) as client:
        if callable(jobs):
            jobs = jobs(max(1, len(client.scheduler_info()["workers"])))
        futures = client.map(fn, list(jobs), pure=False)
        where = {f.key: k for k, f in enumerate(futures)}
        for fut in as_completed(futures):
            try:
                result = fut.result()
            except CotmError:
                raise
            except Exception as exc:  # a task's error, or a worker lost: the solve failed
                raise SolverError(
                    f"a task on the Dask cluster at {scheduler} failed: {type(exc).__name__}: "
                    f"{str(exc).splitlines()[0] if str(exc) else ''}"
                ) from exc
            yield where[fut.key], result
