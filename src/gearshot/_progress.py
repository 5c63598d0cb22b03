"""Progress of long work, on a terminal and off it.

On a terminal: a rich progress bar. Off a terminal (output redirected to a file, a pipe,
a batch system's log): plain lines on standard error, such as::

    simulating blocks: 3/24 (12 %), elapsed 1m02s, ETA 7m14s

one when the work starts, then one at least every ``interval`` seconds (10 by default)
even while no step ends (a clock thread writes it), and one when it ends -- a log shows
that the work is alive and when it will end. The ETA is given only once it means
something: after :data:`ETA_MIN_STEPS` steps done here and :data:`ETA_MIN_SECONDS`.

:func:`set_quiet` (the command line's ``--quiet``) turns all of it off.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
from collections.abc import Iterator
from typing import TextIO

__all__ = ["progress", "track", "PlainProgress", "format_duration", "set_quiet",
           "ETA_MIN_STEPS", "ETA_MIN_SECONDS"]

#: An ETA is printed only after this many steps done in this run ...
ETA_MIN_STEPS = 2
#: ... and this many seconds (one quick first step says little about the rest).
ETA_MIN_SECONDS = 10.0

_QUIET = {"on": False}


def set_quiet(quiet: bool) -> None:
    """No progress bars or lines at all (``gearshot --quiet``) when ``quiet`` is True."""
    _QUIET["on"] = bool(quiet)


def format_duration(seconds: float) -> str:
    """``75`` -> ``'1m15s'``; ``3725`` -> ``'1h02m'``; ``9`` -> ``'9s'``."""
    s = int(round(max(seconds, 0.0)))
    if s < 60:
        return f"{s}s"
    if s < 3600:
        return f"{s // 60}m{s % 60:02d}s"
    return f"{s // 3600}h{(s % 3600) // 60:02d}m"


class PlainProgress:
    """Plain progress lines with percent and ETA (for output that is not a terminal).

    Parameters
    ----------
    description : str
        What is being done (``"simulating blocks"``).
    total : int
        Number of steps.
    completed : int
        Steps already done (resumed work); the ETA counts only the steps done now.
    stream : file, optional
        Default: ``sys.stderr``.
    interval : float
        Longest time between lines, s (the first and last lines are always written).
    clock : callable, optional
        Returns seconds (default :func:`time.monotonic`); tests pass their own. With the
        default clock a daemon thread writes a line whenever ``interval`` passes without
        one (call :meth:`close` at the end; :func:`progress` does); with another clock,
        :meth:`tick` does that job.
    """

    def __init__(self, description: str, total: int, *, completed: int = 0,
                 stream: TextIO | None = None, interval: float = 10.0, clock=None):
        self.description, self.total = description, int(total)
        self.done = self.start_done = int(completed)
        self.stream = stream if stream is not None else sys.stderr
        self.interval = float(interval)
        self.clock = clock or time.monotonic
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self.t0 = self.clock()
        self.last = -float("inf")
        self._line(force=True)
        self._thread: threading.Thread | None = None
        if clock is None and self.done < self.total:
            self._thread = threading.Thread(target=self._beat, name="gearshot-progress",
                                            daemon=True)
            self._thread.start()

    def _beat(self) -> None:
        while not self._stop.wait(min(1.0, self.interval / 4)):
            self.tick()

    def eta(self, elapsed: float) -> str:
        """The line's last part: ``done``, ``ETA 7m14s`` or ``ETA not yet known`` (before
        :data:`ETA_MIN_STEPS` steps and :data:`ETA_MIN_SECONDS` s of this run)."""
        new = self.done - self.start_done
        if self.done >= self.total:
            return "done"
        if new >= ETA_MIN_STEPS and elapsed >= ETA_MIN_SECONDS:
            return f"ETA {format_duration(elapsed / new * (self.total - self.done))}"
        return "ETA not yet known"

    def _line(self, *, force: bool = False) -> None:
        with self._lock:
            now = self.clock()
            if not force and now - self.last < self.interval:
                return
            self.last = now
            elapsed = now - self.t0
            pct = 100.0 * self.done / self.total if self.total else 100.0
            print(f"{self.description}: {self.done}/{self.total} ({pct:.0f} %), elapsed "
                  f"{format_duration(elapsed)}, {self.eta(elapsed)}", file=self.stream,
                  flush=True)

    def tick(self) -> None:
        """Write a line if ``interval`` has passed since the last one (work still alive)."""
        self._line()

    def advance(self, n: int = 1) -> None:
        """Count ``n`` more steps done; write a line if ``interval`` has passed."""
        with self._lock:
            self.done += int(n)
        self._line(force=self.done >= self.total)

    def close(self) -> None:
        """Stop the clock thread (no line is written after this)."""
        self._stop.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join()


class _RichProgress:
    def __init__(self, bar, task):
        self.bar, self.task = bar, task

    def advance(self, n: int = 1) -> None:
        self.bar.advance(self.task, n)


@contextlib.contextmanager
def progress(description: str, total: int, *, completed: int = 0, enabled: bool = True,
             stream: TextIO | None = None, interval: float = 10.0) -> Iterator:
    """A progress reporter with ``advance(n=1)``: a rich bar on a terminal, plain lines
    (:class:`PlainProgress`) otherwise, nothing when ``enabled`` is False."""
    out = stream if stream is not None else sys.stderr
    if not enabled or _QUIET["on"]:
        yield _Silent()
        return
    if getattr(out, "isatty", lambda: False)():
        from rich.console import Console
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )

        columns = (TextColumn(description), BarColumn(), MofNCompleteColumn(),
                   TimeElapsedColumn(), TimeRemainingColumn())
        with Progress(*columns, console=Console(file=out)) as bar:
            yield _RichProgress(bar, bar.add_task(description, total=total,
                                                  completed=completed))
        return
    plain = PlainProgress(description, total, completed=completed, stream=out,
                          interval=interval)
    try:
        yield plain
    finally:
        plain.close()


def track(items, description: str, *, enabled: bool = True):
    """Iterate over ``items`` (a sequence) with :func:`progress`."""
    with progress(description, len(items), enabled=enabled) as bar:
        for item in items:
            yield item
            bar.advance()


class _Silent:
    def advance(self, n: int = 1) -> None:
        """Nothing."""
