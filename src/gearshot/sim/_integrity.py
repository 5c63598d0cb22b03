"""What keeps a database store honest: one writer at a time, and a manifest that cannot lie.

* :func:`store_lock` -- an exclusive lock on the store (``filelock``: an OS lock on
  ``.gearshot.lock``, released by the kernel when its holder dies, so a crashed build never
  leaves a stale lock) plus a note of who holds it (``.gearshot.writer.json``). A second
  build with *other* arguments is refused at once, naming the process that holds the store;
  one with the *same* arguments waits (Ctrl-C stops the wait) and then finds the work done.
* :func:`manifest_digest` -- SHA-256 of the manifest's canonical JSON; the builder hashes
  the manifest it was given (never the file it finds) into every block it writes.
* :func:`block_draws` -- a block's fault sizes and signal seeds, a pure function of the
  manifest and the block's position; :func:`block_content_problem` checks a loaded block's
  coordinates (speed, load, grade, sizes, seeds, lengths) against them, so a manifest edited
  to other speeds, loads, grades, seed or ``n_points`` cannot pass off other data.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import socket
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from .._atomic import write_json_atomic
from .._errors import GearshotError

__all__ = ["store_lock", "manifest_digest", "manifest_diff", "block_draws",
           "block_content_problem", "LOCK_NAME", "WRITER_NAME"]

LOCK_NAME = ".gearshot.lock"
WRITER_NAME = ".gearshot.writer.json"
_INFO_WAIT = 5.0      # s: how long a newcomer waits for the holder's note to appear


def manifest_digest(manifest: dict) -> str:
    """SHA-256 (hex) of ``manifest`` as canonical JSON (sorted keys, no spaces)."""
    text = json.dumps(manifest, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


def manifest_diff(a: dict, b: dict) -> str:
    """``"seed (0 vs 5), speeds ([15.0] vs [16.0])"``: the keys where two manifests differ."""
    keys = sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k))
    return ", ".join(f"{k} ({a.get(k)!r} vs {b.get(k)!r})" for k in keys)


def _read_writer(path: Path) -> dict | None:
    try:
        info = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return info if isinstance(info, dict) else None


@contextlib.contextmanager
def store_lock(store: Path, manifest: dict, *, progress: bool = True) -> Iterator[None]:
    """Hold the store's writer lock for the body; refuse or wait for another writer.

    Raises
    ------
    GearshotError
        Another live process is building the store with other arguments (the message names
        its process id, host and the arguments that differ).
    """
    from filelock import FileLock, Timeout

    digest = manifest_digest(manifest)
    lock = FileLock(str(store / LOCK_NAME))
    note = store / WRITER_NAME
    try:
        lock.acquire(timeout=0)
    except Timeout:
        other = None
        deadline = time.monotonic() + _INFO_WAIT
        while other is None and time.monotonic() < deadline:
            other = _read_writer(note)
            if other is None:
                time.sleep(0.1)
        if other is not None and other.get("manifest_sha256") != digest:
            recorded = other.get("manifest")
            theirs: dict = recorded if isinstance(recorded, dict) else {}
            raise GearshotError(
                f"store {str(store)!r} is being built right now by process "
                f"{other.get('pid')} on {other.get('host')!r} with other arguments "
                f"(differs in {manifest_diff(theirs, manifest)}); wait for it to finish and "
                f"use another store (--store / store=)") from None
        if progress:
            who = f"process {other.get('pid')}" if other else "another process"
            print(f"store {str(store)!r} is being built by {who} with the same arguments; "
                  f"waiting for it (Ctrl-C stops)", file=sys.stderr)
        while True:      # short timeouts: Ctrl-C is honoured between them
            try:
                lock.acquire(timeout=1.0)
                break
            except Timeout:
                continue
    try:
        write_json_atomic({"pid": os.getpid(), "host": socket.gethostname(),
                           "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
                           "manifest_sha256": digest, "manifest": manifest}, note,
                          sort_keys=False)
        yield
    finally:
        with contextlib.suppress(OSError):
            note.unlink()
        lock.release()


def block_draws(seed: int, i: int, j: int, k: int, code: int, n_healthy: int,
                n_faulty: int) -> tuple[np.ndarray, np.ndarray]:
    """Fault sizes and signal seeds of block ``(i, j, k)`` of fault type number ``code``.

    The block's stream is ``SeedSequence(seed, spawn_key=(i, j, k))`` (``(i, j, k, code)``
    for a fault type other than the FTFF): ``n_healthy`` zeros then ``n_faulty`` sizes
    ``U(0, 1)``, then one int64 seed per signal.
    """
    key = (i, j, k) if code == 0 else (i, j, k, code)
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=key))
    sizes = np.concatenate([np.zeros(n_healthy), rng.uniform(0.0, 1.0, n_faulty)])
    seeds = rng.integers(0, 2 ** 63 - 1, n_healthy + n_faulty, dtype=np.int64)
    return sizes, seeds


def block_content_problem(ds, man: dict, i: int, j: int, k: int, fault_type: str,
                          code: int) -> str | None:
    """What in a loaded block contradicts the manifest at its position (``None``: nothing).

    Compares the block's own coordinates -- speed, load, grade, the fault sizes and signal
    seeds drawn from the manifest's seed, the number and length of its SAs, the healthy
    twins of a paired build -- with what the manifest prescribes for block ``(i, j, k)``.
    """
    n_h, n_f = int(man.get("n_healthy", -1)), int(man.get("n_faulty", -1))
    checks = [
        ("speed", float(ds["speed"]) if "speed" in ds.coords else None,
         float(man["speeds"][i])),
        ("load", float(ds["load"]) if "load" in ds.coords else None, float(man["loads"][j])),
    ]
    for name, got, want in checks:
        if got is None or not np.isclose(got, want, rtol=1e-12, atol=0):
            return f"it holds {name}={got!r} but the manifest says {want!r} for it"
    if "sa" not in ds or ds["sa"].ndim != 2:
        return "its SA array is missing"
    n, n_points = ds["sa"].shape
    if n != n_h + n_f:
        return (f"it holds {n} signals but the manifest says n_healthy + n_faulty = "
                f"{n_h} + {n_f}")
    if n_points != man.get("n_points"):
        return (f"its SAs have {n_points} points but the manifest says "
                f"n_points={man.get('n_points')}")
    grades = np.asarray(ds["grade"].values) if "grade" in ds.coords else None
    if grades is None or not np.all(grades == int(man["grades"][k])):
        return f"its grade coordinate is not {int(man['grades'][k])} throughout"
    if ds.attrs.get("fault_type", fault_type) != fault_type:
        return f"it holds {ds.attrs.get('fault_type')!r} signals, not {fault_type!r}"
    if ("sa_twin" in ds) != bool(man.get("paired")):
        return "its healthy twins (sa_twin) do not match the manifest's 'paired'"
    sizes, seeds = block_draws(int(man["seed"]), i, j, k, code, n_h, n_f)
    if "seed" not in ds.coords or not np.array_equal(np.asarray(ds["seed"].values), seeds):
        return (f"its signal seeds are not those of seed={man['seed']} at this block "
                f"(built by another build)")
    if "fault_size" not in ds.coords or not np.array_equal(
            np.asarray(ds["fault_size"].values), sizes):
        return "its fault sizes are not those the manifest's seed draws"
    return None
