"""Bertini's unresolved path crossings: read from its per-path flags, never its raw console line.

When two paths of one solve meet at the endgame boundary and Bertini's own re-tracks do not part
them, it flags the affected paths (`crossing_unresolved` in their metadata; their success codes
may still read Success) and its C++ code prints "warning: N path crossing(s) ... the affected
solutions may be wrong" on file descriptor 2, unprefixed, which no Python redirection catches.
Here a flagged path reads as the code CROSSING (homotopy._code), so every route treats it as a
failed path (tracked again in adaptive precision, else counted lost: the status says it), and
`quiet()` keeps that raw line off the console while a solve runs; the package says it in its
own words instead. The bertini2 command's output is read with `count_in`.
"""

from __future__ import annotations

import os
import re
import sys
import tempfile
import threading
from collections.abc import Iterator
from contextlib import contextmanager

CROSSING = "CrossingUnresolved"  # the code a flagged path reads as (not Bertini's)
# Bertini's line (zero_dim_solve.hpp; the same in the module and the bertini2 command).
MESSAGE = re.compile(
    rb"warning: (\d+) path crossing\(s\) detected at the endgame boundary remained unresolved"
    rb"[^\n]*\n?"
)
_START = b"warning: "
POLL = 0.05  # seconds between two looks at the captured output while a solve runs


def flagged(m) -> bool:
    """Whether Bertini flagged this path's crossing as unresolved (its endpoint may be wrong)."""
    return bool(getattr(m, "crossing_unresolved", False))


def count_in(text: str) -> int:
    """Unresolved crossings Bertini reported in `text` (a run's stderr), summed over its lines."""
    return sum(int(m.group(1)) for m in MESSAGE.finditer(text.encode()))


def in_solve(info: dict) -> int:
    """Paths of one solve whose crossing Bertini left unresolved (crossings.py): of the
    tracking to the target, and of the generic sets it started from."""
    sets = info.get("generic_route", {}).get("generic_sets", [])
    return int(info.get("crossings_unresolved", 0)) + sum(
        int(g.get("crossings_unresolved", 0)) for g in sets
    )


def solve(solver) -> None:
    """`solver.solve()` without Bertini's own progress bar and raw crossing line (`quiet`)."""
    with quiet():
        solver.solve(show_progress=False)


class _Filter:
    """Bytes written to stderr, passed on as they come except Bertini's crossing lines: a line
    is held back only while it may still become one (it starts with "warning: ")."""

    def __init__(self, out: int):
        self.out, self.held, self.line_start, self.dropped = out, b"", True, 0

    def feed(self, data: bytes) -> None:
        """Pass on `data` (or hold the start of a possible crossing line)."""
        buf, self.held = self.held + data, b""
        while buf:
            cut = buf.find(b"\n") + 1
            piece, buf = (buf[:cut], buf[cut:]) if cut else (buf, b"")
            maybe = self.line_start and (
                piece.startswith(_START) or _START.startswith(piece.rstrip(b"\n"))
            )
            if maybe and not cut:
                self.held = piece  # wait for the rest of the line
                return
            if maybe and MESSAGE.fullmatch(piece):
                self.dropped += 1
            else:
                os.write(self.out, piece)
            self.line_start = bool(cut)

    def flush(self) -> None:
        """Pass on whatever is still held (an unfinished line)."""
        if self.held:
            os.write(self.out, self.held)
            self.held = b""


_LOCK = threading.RLock()  # guards _STATE, between solves' threads and the pump's thread
_DEPTH = [0]
_STATE: dict = {}  # while capturing: saved (the real stderr), pump, read (bytes passed on)
_SINK: dict = {}  # one file and one pump thread a process, made at the first capture


@contextmanager
def quiet() -> Iterator[None]:
    """Inside, file descriptor 2 goes to a file a thread passes on to the real stderr as it
    grows, without Bertini's crossing lines (nested and threaded uses share one capture)."""
    with _LOCK:
        _DEPTH[0] += 1
        if _DEPTH[0] == 1:
            _start()
    try:
        yield
    finally:
        with _LOCK:
            _DEPTH[0] -= 1
            if _DEPTH[0] == 0:
                _stop()


def _start() -> None:
    try:
        sys.stderr.flush()
    except (AttributeError, ValueError):
        pass
    try:
        saved = os.dup(2)  # each time: a test harness may have moved stderr in between
    except OSError:  # no stderr at all: nothing to keep clean
        return
    if _SINK.get("pid") != os.getpid():  # (a forked worker has its parent's: not its own)
        _SINK.update(file=tempfile.TemporaryFile(), pid=os.getpid())
        threading.Thread(target=_pass_on, daemon=True).start()
    fd = _SINK["file"].fileno()
    os.lseek(fd, 0, os.SEEK_SET)
    os.ftruncate(fd, 0)
    os.dup2(fd, 2)
    _STATE.update(saved=saved, pump=_Filter(saved), read=0)


def _pass_on() -> None:
    """The pump: what reached the file, passed on every POLL seconds while a capture runs."""
    while True:
        threading.Event().wait(POLL)
        with _LOCK:
            if _STATE:
                _drain()


def _drain() -> None:
    fd = _SINK["file"].fileno()
    while data := os.pread(fd, 1 << 16, _STATE["read"]):
        _STATE["read"] += len(data)
        _STATE["pump"].feed(data)


def _stop() -> None:
    if not _STATE:
        return
    try:
        sys.stderr.flush()
    except (AttributeError, ValueError):
        pass
    os.dup2(_STATE["saved"], 2)  # nothing more goes to the file
    _drain()
    _STATE["pump"].flush()
    os.close(_STATE["saved"])
    _STATE.clear()


def _after_fork() -> None:
    """A forked child starts with no capture: its stderr the real one, a lock of its own (the
    parent's pump may have held it at the fork)."""
    global _LOCK
    if _STATE:
        os.dup2(_STATE["saved"], 2)
        os.close(_STATE["saved"])
    _LOCK = threading.RLock()
    _DEPTH[0] = 0
    _STATE.clear()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_after_fork)
