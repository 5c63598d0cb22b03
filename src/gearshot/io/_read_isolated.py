"""Reading a file in a child process, so that a budget holds whatever the library does.

A reader stuck in a thread can be abandoned only when it lets go of Python's global
interpreter lock; libhdf5 (through h5py) holds it for the whole of one library call, so a
call that loops on a damaged file froze the process past any thread timeout. Here the
reader runs in a forked child process: the caller waits in short, interruptible steps and
kills the child when the budget is spent.

A fork copies the caller as it is, without importing or running anything again (spawned
or fork-server children re-import the caller's main script, which a script without an
``if __name__ == "__main__"`` guard cannot bear); it is used only while the caller runs a
single Python thread, so that no lock held by another thread is copied into the child.
Otherwise, and where a process may not start children, the read stays in a thread.
"""

from __future__ import annotations

import multiprocessing
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar, cast

from .._errors import GearshotError

__all__ = ["read_isolated", "can_isolate"]

_T = TypeVar("_T")


def can_isolate() -> bool:
    """True when this process may fork a reader: one Python thread, not a daemonic
    multiprocessing worker, and a platform with ``fork``."""
    return (threading.active_count() == 1
            and not multiprocessing.current_process().daemon
            and "fork" in multiprocessing.get_all_start_methods())


def _child(reader: Callable[[Path], Any], path: Path, conn: Any) -> None:
    try:
        result: tuple[str, Any] = ("ok", reader(path))
    except BaseException as exc:  # handed to the caller
        result = ("exc", exc)
    try:
        conn.send(result)
    except Exception as exc:  # an exception that does not pickle: its text
        conn.send(("exc", RuntimeError(f"{type(result[1]).__name__}: {result[1]}"
                                       if result[0] == "exc" else str(exc))))
    finally:
        conn.close()


def read_isolated(reader: Callable[[Path], _T], path: Path, budget: float) -> _T:
    """``reader(path)`` in a child process, given up after ``budget`` seconds.

    Raises
    ------
    GearshotError
        The budget is spent (the child is killed), or the child died without an answer.
    Exception
        Whatever ``reader`` raised in the child.
    """
    ctx = multiprocessing.get_context("fork")
    receive, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(reader, path, send),
                       name=f"gearshot-read-{path.name}")
    proc.start()
    send.close()
    try:
        deadline = time.monotonic() + budget
        while True:
            if receive.poll(0.1):
                try:
                    status, payload = receive.recv()
                except EOFError:   # the child died before it answered
                    proc.join(1.0)
                    raise GearshotError(f"reading {str(path)!r} stopped the reading process "
                                        f"(exit code {proc.exitcode}): a damaged file") from None
                break
            if not proc.is_alive() and not receive.poll(0):
                raise GearshotError(f"reading {str(path)!r} stopped the reading process "
                                    f"(exit code {proc.exitcode}): a damaged file")
            if time.monotonic() >= deadline:
                raise GearshotError(f"reading {str(path)!r} did not finish within "
                                    f"{budget:.0f} s: a damaged file (or a stalled disk)")
    finally:
        if proc.is_alive():
            proc.kill()
        proc.join()
        receive.close()
    if status == "exc":
        raise payload
    return cast(_T, payload)
