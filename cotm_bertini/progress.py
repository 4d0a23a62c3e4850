"""How far long work has got, written once for every stage (generic solves, derivations, fold
curves, sweeps, certificates): a stage name, done/total, the rate measured so far and the time
left at that rate.

On a terminal (stderr a tty) a tqdm bar; otherwise a plain line on stderr at most every
LINE_SECONDS (COTM_PROGRESS_SECONDS) and one at the end. A stage shorter than its `delay` shows
nothing. Everything here is silenced by `silenced()` (the CLI's --quiet on sweep and map) or by
COTM_PROGRESS=0, which worker processes inherit; a caller that asked for a report explicitly
(`sweep(progress=True)`) passes force=True.
"""

from __future__ import annotations

import os
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

ENV = "COTM_PROGRESS"  # "0": no progress report at all
ENV_SECONDS = "COTM_PROGRESS_SECONDS"  # seconds between two lines when stderr is no terminal
ENV_DELAY = "COTM_PROGRESS_DELAY"  # seconds a stage nobody announced runs before it is shown
LINE_SECONDS = 5.0
DELAY = 5.0
ONE_OFF = 3.0  # the first units' pace this many times the later ones': not the pace to come
ONE_OFF_MOST = 10  # units left beyond which one unit done gives no time left
WINDOW = 10.0  # seconds at least: a fraction's time left is at the rate of its last window
OFF = ("0", "no", "off", "false")


def enabled() -> bool:
    """Whether progress is reported (COTM_PROGRESS is not 0)."""
    return os.environ.get(ENV, "1").strip().lower() not in OFF


def _seconds(name: str, default: float) -> float:
    try:
        return max(0.0, float(os.environ.get(name, default)))
    except ValueError:
        return default


def line_seconds() -> float:
    """Seconds between two progress lines off a terminal (COTM_PROGRESS_SECONDS, default 5)."""
    return _seconds(ENV_SECONDS, LINE_SECONDS)


def default_delay() -> float:
    """Seconds a stage runs before it is shown (COTM_PROGRESS_DELAY, default 5): short work
    stays silent."""
    return _seconds(ENV_DELAY, DELAY)


@contextmanager
def silenced(quiet: bool = True) -> Iterator[None]:
    """No progress report inside (when `quiet`), in this process and the workers it starts."""
    if not quiet:
        yield
        return
    before = os.environ.get(ENV)
    os.environ[ENV] = "0"
    try:
        yield
    finally:
        if before is None:
            os.environ.pop(ENV, None)
        else:
            os.environ[ENV] = before


def say(text: str, force: bool = False) -> None:
    """One line on stderr (above any bar on a terminal), unless progress is silenced."""
    if not (force or enabled()):
        return
    if sys.stderr.isatty():
        from tqdm import tqdm

        tqdm.write(text, file=sys.stderr)
    else:
        print(text, file=sys.stderr, flush=True)


def duration(seconds: float) -> str:
    """A time for people: 0.4 s, 45 s, 4 min 10 s, 3.2 h, 4.5 days, 1,400 years (under a
    millisecond: 0 s)."""
    if seconds < 1e-3:
        return "0 s"
    if seconds < 10:
        return f"{seconds:.2g} s"
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 90 * 60:
        minutes, rest = divmod(round(seconds), 60)
        return f"{minutes} min {rest} s" if minutes < 10 else f"{seconds / 60:.0f} min"
    if seconds < 48 * 3600:
        return f"{seconds / 3600:.1f} h"
    days = seconds / 86400
    if days < 365:
        return f"{days:.1f} days" if days < 10 else f"{days:.0f} days"
    years = days / 365.25
    return f"{years:.1f} years" if years < 10 else f"{years:,.0f} years"


def _one(unit: str) -> str:
    """'paths' -> 'path', 'taut sets' -> 'taut set'."""
    return unit[:-1] if unit.endswith("s") else unit


class Progress:
    """One stage's progress: `update` as units finish (from any thread), `close` at the end (or
    use it as a context manager). `total` None: a count with no end known; a float total: a
    fraction done (shown in percent). `delay`: seconds before anything is shown (default:
    default_delay(); 0 for a stage already announced); `heartbeat`: a line every few seconds
    even while no unit finishes; `force`: shown even when silenced (asked for explicitly)."""

    def __init__(
        self,
        stage: str,
        total: float | None,
        unit: str = "paths",
        *,
        delay: float | None = None,
        initial: int = 0,
        force: bool = False,
        heartbeat: bool = False,
    ):
        self.stage, self.total, self.unit = stage, total, unit
        self.delay = default_delay() if delay is None else delay
        self.done = self.initial = initial
        self.note = ""
        self.start = self._last = time.perf_counter()
        self._history = [(self.start, float(initial))]  # (time, done): a fraction's window
        self._first: tuple[float, float] | None = None  # (time, done) at the first completion
        self.active = force or enabled()
        self._shown = self._ended = False
        self._lock = threading.Lock()
        self._bar = None
        if self.active and sys.stderr.isatty():
            from tqdm import tqdm

            # No total: the count (if any) and the time so far; a fraction: in percent.
            shape = None
            if total is None:
                shape = "{desc}: {n_fmt} " + unit + " [{elapsed}{postfix}]" if unit else (
                    "{desc} [{elapsed}{postfix}]")  # fmt: skip
            elif isinstance(total, float):
                shape = "{desc}: {percentage:3.0f}%|{bar}| [{elapsed}<{remaining}{postfix}]"
            self._bar = tqdm(
                total=total, initial=initial, unit=unit, desc=f"{stage} {unit}".strip(),
                delay=self.delay, file=sys.stderr, leave=True, dynamic_ncols=True,
                bar_format=shape,
            )  # fmt: skip
        self._stop, self._thread = threading.Event(), None
        if self.active and heartbeat:
            # A stage whose units are long (a sympy derivation, one slow path) still says, every
            # few seconds, how long it has run: from a thread, as the work holds this one.
            self._thread = threading.Thread(target=self._beat, daemon=True)
            self._thread.start()

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    @property
    def elapsed(self) -> float:
        """Seconds since the stage began."""
        return time.perf_counter() - self.start

    @property
    def rate(self) -> float | None:
        """Seconds a unit, measured on the units done so far (None before the first); the
        units after the first completion alone where the first ones took more than ONE_OFF
        times as long each (they carried one-off costs: a worker pool starting, a generic set
        solved; a 101 x 101 map's first point took 25 s, said "2.9 days left", and the map
        74 s)."""
        done = self.done - self.initial
        if done <= 0:
            return None
        if self._first is not None and self.done > self._first[1]:
            t1, d1 = self._first
            later = (time.perf_counter() - t1) / (self.done - d1)
            if (t1 - self.start) / (d1 - self.initial) > ONE_OFF * later:
                return later
        return self.elapsed / done

    @property
    def left(self) -> float | None:
        """Seconds left at the measured rate (None when no rate or no total is known). For a
        fraction (a search's share of volume decided, whose pace falls as it goes) the rate is
        that of the last window (a third of the time so far, WINDOW seconds at least): None
        before a window has passed or when the window decided nothing."""
        if self.total is None:
            return None
        if isinstance(self.total, float):
            return self._window_left()
        if self.done - self.initial <= 1 and self.total - self.done > ONE_OFF_MOST:
            return None  # one unit of many: it may have carried one-off costs (`rate`)
        rate = self.rate
        return None if rate is None else max(0.0, rate * (self.total - self.done))

    def _window_left(self) -> float | None:
        now = time.perf_counter()
        span = max(WINDOW, (now - self.start) / 3)
        if now - self.start < span:
            return None
        t0, d0 = next((t, d) for t, d in reversed(self._history) if now - t >= span)
        if self.done <= d0:
            return None
        return max(0.0, (now - t0) / (self.done - d0) * (self.total - self.done))

    @property
    def falling(self) -> bool:
        """Whether a fraction's pace over its last window is under half that of the window
        before (a search's last boxes are its hardest): then the time left at the last pace
        is a floor, and the line says so."""
        now = time.perf_counter()
        span = max(WINDOW, (now - self.start) / 3)
        if not isinstance(self.total, float) or now - self.start < 2 * span:
            return False
        t1, d1 = next((t, d) for t, d in reversed(self._history) if now - t >= span)
        t0, d0 = next((t, d) for t, d in reversed(self._history) if now - t >= 2 * span)
        return (self.done - d1) / max(now - t1, 1e-9) < 0.5 * (d1 - d0) / max(t1 - t0, 1e-9)

    def update(self, n: float = 1, note: str | None = None) -> None:
        """`n` more units done; `note`: what to show after the count (e.g. paths lost)."""
        with self._lock:
            self.done += n
            now = time.perf_counter()
            if self._first is None and self.done > self.initial:
                self._first = (now, self.done)
            if now - self._history[-1][0] >= 0.5:
                self._history.append((now, self.done))
            if note is not None:
                self.note = note
            if self._bar is not None:
                self._bar.update(n)
                if note:
                    self._bar.set_postfix_str(note, refresh=False)
                return
            if not self.active or self._ended:
                return
            now = time.perf_counter()
            if self.total is not None and self.done >= self.total:
                if self._shown or now - self.start >= self.delay:
                    self._print(final=True)
                self._ended = True
            elif now - self.start >= self.delay and now - self._last >= line_seconds():
                self._print(final=False)

    def set(self, done: float, note: str | None = None) -> None:
        """The count is now `done` (a fraction decided, say)."""
        self.update(done - self.done, note)

    def _beat(self) -> None:
        while not self._stop.wait(max(0.2, min(1.0, line_seconds()))):
            with self._lock:
                now = time.perf_counter()
                if self._ended or now - self.start < self.delay:
                    continue
                if self._bar is not None:
                    self._bar.refresh()
                elif now - self._last >= line_seconds():
                    self._print(final=False)

    def close(self) -> None:
        """End the stage: the bar closed, or a last line if lines were shown and the count did
        not reach its total (the line says how far it got)."""
        self._stop.set()
        if self._thread is not None:  # gone before a worker pool decides how to start
            self._thread.join()
        with self._lock:
            if self._bar is not None:
                self._bar.close()
                self._bar = None
            elif self.active and self._shown and not self._ended:
                self._print(final=True)
            self._ended = True

    def line(self, final: bool = False) -> str:
        """The plain line: stage, count, note; before the end the rate and the time left."""
        if self.total is None:
            count = f"{self.done:g} {self.unit}" if self.done else ""
        elif isinstance(self.total, float):
            count = f"{100 * self.done / self.total:.0f}% {self.unit}"
        else:
            count = f"{self.done:g}/{self.total:g} {self.unit}"
        if final and not count:
            return f"{self.stage}: done in {duration(self.elapsed)}"
        text = f"{self.stage}: {count}" if count else self.stage
        text += f", {self.note}" if self.note else ""
        if final:
            return text
        parts = []
        if self.rate is not None and not isinstance(self.total, float):
            parts.append(f"{duration(self.rate)} a {_one(self.unit)}")
        parts.append(f"{duration(self.elapsed)} so far")
        left = self.left
        if left is not None and self.falling:
            parts.append(f"at least about {duration(left)} left (the pace is falling)")
        elif left is not None:
            parts.append(f"about {duration(left)} left")
        elif self.total is not None:
            parts.append("time left not known yet")
        return f"{text}; {', '.join(parts)}"

    def _print(self, final: bool) -> None:
        print(self.line(final), file=sys.stderr, flush=True)
        self._shown, self._last = True, time.perf_counter()
