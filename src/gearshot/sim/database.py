"""Simulated SA databases on disk (xarray / Zarr), resumable and Dask-parallel: the build.

Layout of a store (a folder)::

    store/
      manifest.json                 build parameters (written first, atomically)
      blocks/s{i}_l{j}_g{k}.zarr    one (speed, load, grade) block, an xarray Dataset
      blocks/s{i}_l{j}_g{k}_{type}.zarr   ... of a fault type other than "ftff"

A block is written to a temporary folder beside its final name and renamed when complete
(:func:`gearshot._atomic.atomic_dir`), so a block is either absent or whole; an interrupted
build resumes by skipping the blocks present. Each block carries a checksum list: the size
and CRC-32 of every other file in it and the build's manifest (the attribute
``gearshot_block`` of the block's root ``zarr.json``). Every read checks a block
against it (a missing or overwritten chunk is named, never read as NaN), and a build
rebuilds exactly the blocks found damaged, reusing the rest; a lost ``manifest.json`` is
restored from the blocks' copies. Each block's random stream derives from
``SeedSequence(seed, spawn_key=(i, j, k))`` (``(i, j, k, code)`` for a fault type other
than the FTFF, ``code`` the type's fixed code in :mod:`gearshot.fault_registry`) and each
signal's from the block's, so contents do not depend on order or interruption. A build of
FTFFs only keeps the layout and manifest of stores built before fault types existed.

The pieces: this module builds (:func:`build_database`, one block per task, in-process
(:mod:`._block_threads`: one block per core side by side) or on a Dask client);
:mod:`._db_manifest` writes, checks and restores the manifest; :mod:`._db_checksums`
writes and checks each block's record; :mod:`._db_load` loads a condition
(:func:`load_database`); :mod:`._integrity` holds the store's lock and the blocks' draws;
:mod:`._block_read` reads a block once, checked.
"""

from __future__ import annotations

import os
import shutil
import sys
import time
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from .._atomic import atomic_dir, check_writable, remove_tree
from .._cluster import IN_PROCESS_BLOCKS, dask_client
from .._errors import GearshotError
from .._paths import data_home
from .._validation import check_finite, check_int, check_load, check_speed, describe
from ..fault_registry import check_fault_type, fault_type_record
from ._block_read import resume_problem
from ._block_threads import block_threads, run_blocks
from ._db_checksums import ownership_problem, write_checksums
from ._db_load import load_database
from ._db_manifest import PAIR_ATTRS, block_name, make_manifest, pair_attrs, prepare_store
from ._integrity import block_draws, store_lock
from .dynamics import simulate_sa, simulate_sa_paired
from .geometry import GearPair

__all__ = ["build_database", "load_database", "default_database_path", "pair_attrs",
           "PAIR_ATTRS"]

_MAX_POINTS = 1 << 20          # SA length bound (a block row is 8 MiB at this length)
_MAX_SIGNALS = 1_000_000       # signals per block


def default_database_path(name: str = "sim-db") -> Path:
    """Default store location: ``gearshot.data_home() / "databases" / name``."""
    return data_home() / "databases" / name


def build_database(store, pair: GearPair | None = None, *, speeds, loads, grades,
                   n_healthy: int = 100, n_faulty: int = 700, seed: int = 0,
                   n_points: int = 2048, client=None, progress: bool = True,
                   fault_types=("ftff",), paired: bool = True) -> Path:
    """Simulate SAs for every (speed, load, grade) and store them as Zarr.

    Parameters
    ----------
    store : str or Path
        Folder of the database (created). A store holding a different build is refused.
    pair : GearPair, optional
        Default ``GearPair.paper()``.
    speeds : sequence of float
        Input shaft speeds, rev/s.
    loads : sequence of float
        Output load torques, N m.
    grades : sequence of int
        DIN grades (1 ... 12).
    n_healthy, n_faulty : int
        Signals per block: healthy, then faulty with y ~ U(0, 1).
    seed : int
        Root seed.
    n_points : int
        SA length.
    client : dask.distributed.Client, False or None
        Run blocks on this client (its workers write the blocks themselves, so the store
        must be on a file system they share). ``None``: a LocalCluster (one
        single-threaded worker process per core) for builds of more than 16 blocks,
        in-process otherwise; ``False``: always in-process. In-process, several blocks
        run side by side on one thread per core (:mod:`._block_threads`), a single block
        on numba threads over its batches.
    progress : bool
        Show a rich progress bar.
    fault_types : sequence of str
        Fault types (:data:`~gearshot.sim.FAULT_TYPES`): one block of ``n_healthy`` +
        ``n_faulty`` signals per type and (speed, load, grade); sizes mean the type's
        size (:mod:`gearshot.sim.fault_types`). Default the FTFF only.
    paired : bool, default True
        Also store, as ``sa_twin``, each signal's *healthy twin*: the SA of the same gear
        pair (same seed, hence the same profile errors) without the fault (a healthy
        signal is its own twin). The ``sa`` of a paired store equal those of the unpaired
        store of the same arguments; the twins cost one more simulation per faulty
        signal. The estimator's default ``simulated_reference="auto"`` subtracts them and
        its default ``calibration="joint"`` calibrates fault gain and width on them
        (issue #19). ``False`` builds the old unpaired layout (stores built that way
        still load; finish them with ``paired=False``).

    Returns
    -------
    Path
        The store.
    """
    pair, manifest = _check_build(pair, speeds, loads, grades, n_healthy, n_faulty, seed,
                                  n_points, fault_types, paired)
    store = Path(store).expanduser()
    check_writable(store, "store", folder=True)
    try:
        store.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise GearshotError(f"store {str(store)!r} cannot be created "
                            f"({exc.strerror or exc})") from None
    with store_lock(store, manifest, progress=progress):
        try:
            _remove_temporaries(store)          # of killed runs
            prepare_store(store, manifest, progress)
            _build_locked(store, pair, manifest, client, progress)
        finally:   # temporaries of this run (a failed or killed worker): we hold the lock
            _remove_temporaries(store)
    return store


def _check_build(pair, speeds, loads, grades, n_healthy, n_faulty, seed, n_points,
                 fault_types, paired) -> tuple[GearPair, dict]:
    """The pair and the manifest of a build, every argument checked (nothing written)."""
    pair = GearPair.paper() if pair is None else pair
    if not isinstance(pair, GearPair):
        raise GearshotError(f"pair must be a GearPair; got {describe(pair)}")
    speeds = _check_values(speeds, "speeds", lo=0)
    loads = _check_values(loads, "loads", lo=0)
    for v in speeds:
        check_speed(float(v), "speeds")
    for v in loads:
        check_load(float(v), "loads")
    grades = _check_values(grades, "grades", integer=True, hi=12)
    n_healthy = check_int(n_healthy, "n_healthy", minimum=0)
    n_faulty = check_int(n_faulty, "n_faulty", minimum=0)
    if n_healthy + n_faulty == 0:
        raise GearshotError("n_healthy + n_faulty must be > 0; got 0")
    seed = check_int(seed, "seed", minimum=0)
    n_points = check_int(n_points, "n_points", minimum=16, maximum=_MAX_POINTS)
    if n_healthy + n_faulty > _MAX_SIGNALS:
        raise GearshotError(f"n_healthy + n_faulty must be <= {_MAX_SIGNALS} per block; got "
                            f"{n_healthy + n_faulty}")
    fault_types = _check_fault_types(fault_types)
    if not isinstance(paired, (bool, np.bool_)):
        raise GearshotError(f"paired must be True or False; got {describe(paired)}")
    return pair, make_manifest(pair, speeds, loads, grades, n_healthy, n_faulty, seed,
                               n_points, fault_types, bool(paired))


def _check_values(values, name, *, integer=False, lo=None, hi=None):
    try:
        arr = np.atleast_1d(np.asarray(values, dtype=float))
    except (TypeError, ValueError):
        raise GearshotError(f"{name} must be numbers; got {describe(values)}") from None
    if arr.ndim != 1 or arr.size == 0:
        raise GearshotError(f"{name} must be a non-empty 1-D sequence; got {describe(values)}")
    check_finite(arr, name)
    if lo is not None and np.any(arr <= lo):
        bad = arr[arr <= lo][0]
        raise GearshotError(f"{name} must be > {lo}; got {bad!r}")
    if integer:
        if np.any(arr != np.round(arr)):
            raise GearshotError(f"{name} must be integers; got {describe(values)}")
        if hi is not None and np.any((arr < 1) | (arr > hi)):
            bad = arr[(arr < 1) | (arr > hi)][0]
            raise GearshotError(f"{name} must lie in 1 ... {hi}; got {int(bad)!r}")
        return arr.astype(int)
    if len(np.unique(arr)) != arr.size:
        raise GearshotError(f"{name} must not repeat values; got {describe(values)}")
    return arr



def _check_fault_types(fault_types):
    if isinstance(fault_types, str):
        fault_types = [fault_types]
    try:
        types = list(fault_types)
    except TypeError:
        raise GearshotError(f"fault_types must be a sequence of names; got "
                            f"{describe(fault_types)}") from None
    if not types:
        raise GearshotError("fault_types must not be empty")
    for t in types:
        check_fault_type(t)
    if len(set(types)) != len(types):
        raise GearshotError(f"fault_types must not repeat names; got {types!r}")
    return types



class _Task(NamedTuple):
    """One block: its position (i, j, k), condition, grade and fault type."""

    i: int
    j: int
    k: int
    speed: float
    load: float
    grade: int
    fault_type: str


def _build_locked(store: Path, pair: GearPair, manifest: dict, client, progress) -> None:
    """Build the blocks missing or damaged (the store's lock held)."""
    tasks = [_Task(i, j, k, s, ld, int(g), ft)
             for i, s in enumerate(manifest["speeds"]) for j, ld in enumerate(manifest["loads"])
             for k, g in enumerate(manifest["grades"])
             for ft in manifest.get("fault_types", ["ftff"])]
    todo = _blocks_to_build(store, manifest, tasks, progress)
    # no client given and many blocks: a LocalCluster of one worker per core, closed after
    with dask_client(None, os.cpu_count() or 1,
                     needed=client is None and len(todo) > IN_PROCESS_BLOCKS) as own:
        _run_tasks(store, pair, todo, len(tasks), manifest, client or own, progress)


def _blocks_to_build(store: Path, manifest: dict, tasks: list[_Task],
                     progress) -> list[_Task]:
    """The tasks whose block is absent, damaged or of another build (removed)."""
    todo = []
    damaged = []
    for t in tasks:
        path = store / "blocks" / block_name(t.i, t.j, t.k, t.fault_type)
        if path.exists():
            problem = resume_problem(path) or ownership_problem(path, manifest, t.i, t.j, t.k,
                                                                t.fault_type)
            if problem is None:
                continue
            damaged.append(f"{path.name} ({problem})")
            remove_tree(path)
        todo.append(t)
    if damaged and progress:
        print(f"rebuilding {len(damaged)} damaged block(s) of {str(store)!r}: "
              + "; ".join(damaged), file=sys.stderr)
    return todo


def _remove_temporaries(store: Path) -> None:
    """Remove hidden temporary folders/files (``.*.tmp``) of blocks and the manifest."""
    for folder in (store, store / "blocks"):
        if folder.is_dir():
            for leftover in folder.glob(".*.tmp*"):
                if leftover.is_dir():
                    shutil.rmtree(leftover, ignore_errors=True)
                else:
                    leftover.unlink(missing_ok=True)


def _run_tasks(store: Path, pair: GearPair, todo: list[_Task], n_total: int, manifest: dict,
               client, progress) -> None:
    from .._progress import progress as progress_of

    args = (manifest["n_healthy"], manifest["n_faulty"], manifest["seed"],
            manifest["n_points"])
    paired = bool(manifest.get("paired"))
    with progress_of("simulating blocks", n_total, completed=n_total - len(todo),
                     enabled=progress) as bar:
        calls = [(str(store), pair, *t[:6], *args, True, t.fault_type, paired, manifest)
                 for t in todo]
        if client is None:     # one block per core side by side (numba: one thread each),
            n_threads = block_threads(len(todo))     # or numba threads over the batch
            if n_threads > 1:
                run_blocks(_build_block, calls, n_threads, bar.advance)
                return
            for c in calls:
                _build_block(*c[:12], False, *c[13:])
                bar.advance()
            return
        futures = [client.submit(_build_block, *c, pure=False) for c in calls]
        _collect(client, futures, store, bar)


def _collect(client, futures, store, bar) -> None:
    """Wait for the blocks built on ``client``; on a failure (a full disk, ...) drop the
    queued blocks and give the running ones a minute to finish or to remove their
    temporary folders, then raise it."""
    from dask.distributed import as_completed

    try:
        for fut in as_completed(futures):
            fut.result()
            bar.advance()
    except Exception:
        client.cancel(futures)
        deadline = time.monotonic() + 60
        while (any((Path(store) / "blocks").glob(".*.tmp"))
               and time.monotonic() < deadline):
            time.sleep(0.2)
        raise


def _build_block(store: str, pair: GearPair, i: int, j: int, k: int, speed: float,
                 load: float, grade: int, n_healthy: int, n_faulty: int, seed: int,
                 n_points: int, single_thread: bool = False, fault_type: str = "ftff",
                 paired: bool = False, manifest: dict | None = None) -> str:
    """Simulate block (i, j, k) of ``fault_type`` and write it (with its record) as one
    atomic folder; a block already there is kept. Returns the block's name."""
    import xarray as xr

    if single_thread:
        import numba
        numba.set_num_threads(1)
    blocks = Path(store) / "blocks"
    final = blocks / block_name(i, j, k, fault_type)
    if final.exists():
        return final.name
    if manifest is None:   # the builder's manifest, never one found on disk
        raise GearshotError("_build_block needs the build's manifest")
    code = fault_type_record(fault_type).code
    n = n_healthy + n_faulty
    sizes, sig_seeds = block_draws(seed, i, j, k, code, n_healthy, n_faulty)
    kw: dict[str, Any] = dict(speed=speed, load=load, grade=grade, fault_sizes=sizes,
                              n_points=n_points, rng=[int(s) for s in sig_seeds],
                              fault_type=fault_type)
    sa, twins = simulate_sa_paired(pair, **kw) if paired else (simulate_sa(pair, **kw), None)
    data = {"sa": (("signal", "angle"), sa,
                   {"units": "g", "long_name": "vertical acceleration SA"})}
    if twins is not None:
        data["sa_twin"] = (("signal", "angle"), twins, {
            "units": "g", "long_name": "healthy twin SA (same profile errors, no fault)"})
    ds = xr.Dataset(
        data,
        coords={"fault_size": ("signal", sizes), "grade": ("signal", np.full(n, grade)),
                "seed": ("signal", sig_seeds), "speed": float(speed), "load": float(load),
                "angle": ("angle", 2 * np.pi * np.arange(n_points) / n_points,
                          {"units": "rad", "long_name": "driven-gear angle"})},
        attrs={"speed_units": "rev/s (input shaft)", "load_units": "N m",
               "fault_type": fault_type})
    # exist_ok: another worker may have finished the same block first
    with atomic_dir(final, exist_ok=True) as tmp:
        ds.to_zarr(tmp, mode="w", consolidated=False, encoding=_sa_encoding(data, n, n_points))
        write_checksums(tmp, manifest)
    return final.name


_CHUNK_BYTES = 16 << 20     # SA chunk size bound: one chunk per array for a paper block


def _sa_encoding(data: dict, n: int, n_points: int) -> dict:
    """Zarr encoding of the SA arrays: chunks of whole signals up to 16 MiB (one chunk
    for a block of the paper's 800 signals), uncompressed (zstd saved < 5 % on SAs and
    cost more CPU than the simulation's serial steps; fewer files to fsync and check).
    Stores written with other chunks or codecs load the same."""
    rows = min(n, max(1, _CHUNK_BYTES // (8 * n_points)))
    return {name: {"chunks": (rows, n_points), "compressors": None} for name in data}
