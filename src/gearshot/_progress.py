"""Progress of long work, on a terminal and off it.

On a terminal: a rich progress bar. Off a terminal (output redirected to a file, a pipe,
a batch system's log): plain lines on standard error, such as::

    simulating blocks: 3/24 (12 %), elapsed 1m02s, ETA 7m14s

one when the work starts, then at most one every ``interval`` seconds (10 by default),
and one when it ends -- a log shows that the work is alive and when it will end.
"""

from __future__ import annotations

import contextlib
import sys
import time
from collections.abc import Iterator
from typing import TextIO

__all__ = ["progress", "track", "PlainProgress", "format_duration"]


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
        Seconds between lines (the first and last lines are always written).
    clock : callable, optional
        Returns seconds (default :func:`time.monotonic`); tests pass their own.
    """

    def __init__(self, description: str, total: int, *, completed: int = 0,
                 stream: TextIO | None = None, interval: float = 10.0, clock=None):
        self.description, self.total = description, int(total)
        self.done = self.start_done = int(completed)
        self.stream = stream if stream is not None else sys.stderr
        self.interval = float(interval)
        self.clock = clock or time.monotonic
        self.t0 = self.clock()
        self.last = -float("inf")
        self._line(force=True)

    def _line(self, *, force: bool = False) -> None:
        now = self.clock()
        if not force and now - self.last < self.interval:
            return
        self.last = now
        elapsed = now - self.t0
        pct = 100.0 * self.done / self.total if self.total else 100.0
        new = self.done - self.start_done
        if self.done >= self.total:
            eta = "done"
        elif new > 0:
            eta = f"ETA {format_duration(elapsed / new * (self.total - self.done))}"
        else:
            eta = "ETA unknown"
        print(f"{self.description}: {self.done}/{self.total} ({pct:.0f} %), elapsed "
              f"{format_duration(elapsed)}, {eta}", file=self.stream, flush=True)

    def advance(self, n: int = 1) -> None:
        """Count ``n`` more steps done; write a line if ``interval`` has passed."""
        self.done += int(n)
        self._line(force=self.done >= self.total)


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
    if not enabled:
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
    yield PlainProgress(description, total, completed=completed, stream=out,
                        interval=interval)


def track(items, description: str, *, enabled: bool = True):
    """Iterate over ``items`` (a sequence) with :func:`progress`."""
    with progress(description, len(items), enabled=enabled) as bar:
        for item in items:
            yield item
            bar.advance()


class _Silent:
    def advance(self, n: int = 1) -> None:
        """Nothing."""
