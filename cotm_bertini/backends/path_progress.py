"""How long a generic solve takes: first guesses before it starts, progress measured as its
paths finish.

A first guess of the seconds a path comes from the best thing known in this process: the rate
of an earlier solve of the same system (the second generic set of a framework's taut set
follows its first), a rate measured on sample paths (api.costs, before a framework solve), or
PRIOR_SECONDS_PER_PATH. Once the solve runs, each chunk of its paths reports as it comes back
(homotopy._own_solve), so the rate and the time left shown are measured on this solve's paths.
"""

from __future__ import annotations

import json

from ..progress import Progress

# The one fixed prior left: case 3's 192 paths in ~12 s. Frameworks' paths cost up to ten times
# more (the prism with a free-length diagonal: 0.59 s a path), hence the measured rates below.
PRIOR_SECONDS_PER_PATH = 0.06
PRIOR_SOURCE = "a fixed prior"  # the source of a first guess when nothing was measured
_RATES: dict[tuple, tuple[float, str]] = {}  # (system, groups) -> (seconds a path, source)


def _key(ps, groups) -> tuple:
    # ParametricSystem objects live as long as the process (homotopy._LOADED keys them so too).
    return id(ps), json.dumps(groups)


def remember(ps, groups, seconds_per_path: float, source: str) -> None:
    """Keep a measured rate of `ps`'s generic solve (with `groups`) for later first guesses."""
    if seconds_per_path > 0:
        _RATES[_key(ps, groups)] = (float(seconds_per_path), source)


def first_guess(ps, groups) -> tuple[float, str]:
    """(seconds a path, where that figure comes from) before a generic solve of `ps` starts."""
    return _RATES.get(_key(ps, groups), (PRIOR_SECONDS_PER_PATH, PRIOR_SOURCE))


def path_count(ps, groups) -> int:
    """The paths of `ps`'s generic solve: the multihomogeneous Bezout number for `groups`
    (Bertini's own start and ours have exactly that many), else the total degree."""
    from .start_system import bezout_number, group_degrees

    # The degree structure at generic parameter values (a coefficient vanishing only there).
    system = ps.instantiate([1.0 + 0.1j * k for k in range(len(ps.parameters))])
    if not groups:
        return system.total_degree
    return bezout_number(group_degrees(system, groups), [len(g) for g in groups])


def expected(ps, groups) -> tuple[int, float, str]:
    """(paths, first guess of the seconds a path, where the guess comes from) of a generic
    solve of `ps` with `groups`, before it starts."""
    rate, source = first_guess(ps, groups)
    return path_count(ps, groups), rate, source


def generic_report(seed: int, paths: int, announced: bool) -> Progress:
    """The progress of one generic solve: shown at once when it was announced, else only if it
    runs past progress.default_delay()."""
    return Progress(f"generic set (seed {seed})", paths, "paths",
                    delay=0.0 if announced else None)  # fmt: skip
