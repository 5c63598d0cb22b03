"""Simulated SA databases on disk (xarray / Zarr), resumable and Dask-parallel.

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
"""

from __future__ import annotations

import json
import os
import shutil
import sys
import time
import zlib
from pathlib import Path

import numpy as np

from .._atomic import atomic_dir, check_writable, remove_tree, write_json_atomic
from .._errors import GearshotError
from .._paths import data_home
from .._validation import check_finite, check_int, check_load, check_speed, describe
from ..fault_registry import check_fault_type, fault_type_record
from ._block_read import read_block, resume_problem
from ._integrity import (
    block_content_problem,
    block_draws,
    manifest_diff,
    manifest_digest,
    store_lock,
)
from .dynamics import simulate_sa
from .fault_types import FAULT_MODEL_VERSIONS
from .geometry import GearPair

__all__ = ["build_database", "load_database", "default_database_path"]

_FORMAT = 1
_SMALL_BUILD = 16  # blocks; larger builds start a LocalCluster when no client is given


def default_database_path(name: str = "sim-db") -> Path:
    """Default store location: ``gearshot.data_home() / "databases" / name``."""
    return data_home() / "databases" / name


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


def _block_name(i, j, k, fault_type="ftff"):
    if fault_type == "ftff":
        return f"s{i}_l{j}_g{k}.zarr"
    return f"s{i}_l{j}_g{k}_{fault_type}.zarr"


def _pair_repr(pair):
    # a spur pair keeps the text of stores built before helix_angle existed
    text = repr(pair)
    return text.replace(", helix_angle=0.0)", ")") if not pair.is_helical else text


#: Dataset attributes that :func:`load_database` sets from the store's gear pair.
PAIR_ATTRS = ("pinion_teeth", "gear_teeth", "module", "face_width", "pressure_angle",
              "helix_angle")


def _pair_from_manifest(man: dict) -> GearPair | None:
    """The store's gear pair, read back from the manifest's ``pair`` text (a GearPair
    repr, recorded by every store since the first format); None if it cannot be read."""
    import ast

    try:
        call = ast.parse(str(man["pair"]), mode="eval").body
        if not (isinstance(call, ast.Call) and isinstance(call.func, ast.Name)
                and call.func.id == "GearPair" and not call.args):
            return None
        fields = {k.arg: _literal(k.value) for k in call.keywords if k.arg}
        if len(fields) != len(call.keywords):   # a **mapping
            return None
        return GearPair(**fields)   # fields absent from older texts take their defaults
    except (KeyError, SyntaxError, ValueError, TypeError, GearshotError):
        return None


def _literal(node):
    """A literal of a repr, numpy scalars (``np.float64(0.003)``, numpy >= 2) included."""
    import ast

    if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
            and isinstance(node.func.value, ast.Name) and node.func.value.id in ("np", "numpy")
            and node.func.attr in ("float64", "float32", "int64", "int32")
            and len(node.args) == 1 and not node.keywords):
        return ast.literal_eval(node.args[0])
    return ast.literal_eval(node)


def pair_attrs(pair: GearPair) -> dict:
    """A gear pair as database attributes (:data:`PAIR_ATTRS`: teeth, m, rad)."""
    return {"pinion_teeth": int(pair.z_pinion), "gear_teeth": int(pair.z_gear),
            "module": float(pair.module), "face_width": float(pair.face_width),
            "pressure_angle": float(pair.pressure_angle),
            "helix_angle": float(pair.helix_angle)}


def _manifest(pair, speeds, loads, grades, n_healthy, n_faulty, seed, n_points,
              fault_types=("ftff",), paired=False):
    man = {"format": _FORMAT, "pair": _pair_repr(pair), "speeds": [float(s) for s in speeds],
           "loads": [float(x) for x in loads], "grades": [int(g) for g in grades],
           "n_healthy": n_healthy, "n_faulty": n_faulty, "seed": seed, "n_points": n_points}
    if list(fault_types) != ["ftff"]:
        man["fault_types"] = list(fault_types)
        man["fault_models"] = {t: FAULT_MODEL_VERSIONS[t] for t in fault_types}
    if paired:   # only when set: stores built before pairing keep their manifest
        man["paired"] = True
    return man


def _check_fault_models(store: Path, man: dict, types) -> None:
    """Refuse SAs of a fault type simulated with an older model of that type."""
    stored = man.get("fault_models", {"ftff": 1})
    for t in types:
        have, want = stored.get(t), FAULT_MODEL_VERSIONS[t]
        if have != want:
            raise GearshotError(f"store {str(store)!r} holds {t!r} SAs of an older model of "
                                f"that fault type (model version {have}, current {want}); "
                                f"rebuild them into a new store (build_database / "
                                f"gearshot simulate --fault-type {t})")


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


_ROOT = "zarr.json"           # the block group's metadata; holds the checksum list
_ATTR = "gearshot_block"
_MAX_POINTS = 1 << 20          # SA length bound (a block row is 8 MiB at this length)
_MAX_SIGNALS = 1_000_000       # signals per block


def _file_digest(path: Path) -> tuple[int, int]:
    crc = 0
    size = 0
    with open(path, "rb") as fh:
        while chunk := fh.read(1 << 22):
            crc = zlib.crc32(chunk, crc)
            size += len(chunk)
    return size, crc


def _write_checksums(folder: Path, manifest: dict) -> None:
    files = {}
    for root, _dirs, names in os.walk(folder):
        for name in names:
            full = Path(root) / name
            rel = full.relative_to(folder).as_posix()
            if rel != _ROOT and not name.startswith("."):
                files[rel] = list(_file_digest(full))
    meta = json.loads((folder / _ROOT).read_text())
    meta.setdefault("attributes", {})[_ATTR] = {"files": files, "manifest": manifest,
                                                "manifest_sha256": manifest_digest(manifest)}
    write_json_atomic(meta, folder / _ROOT, indent=2, sort_keys=False)


def _block_record(path: Path) -> dict:
    """The checksum list of a block; ``{}`` when it has none."""
    meta = json.loads((path / _ROOT).read_text())
    record = meta.get("attributes", {}).get(_ATTR, {})
    if not isinstance(record, dict):
        raise ValueError(f"attribute {_ATTR!r} is not a mapping")
    return record


def _block_problem(path: Path) -> str | None:
    """What is wrong with a built block (``None``: whole, every file as written)."""
    try:
        record = _block_record(path)
    except FileNotFoundError:
        return f"its metadata file {_ROOT!r} is missing"
    except (OSError, ValueError) as exc:
        return f"its metadata file {_ROOT!r} is unreadable ({exc})"
    if not record:
        return f"its checksum list (attribute {_ATTR!r}) is missing"
    files = record.get("files")
    if not isinstance(files, dict) or not files:
        return f"its checksum list (attribute {_ATTR!r}) is damaged"
    for rel, want in sorted(files.items()):
        full = path / rel
        if not full.is_file():
            return f"file {rel!r} is missing"
        try:
            got = list(_file_digest(full))
        except OSError as exc:
            return f"file {rel!r} cannot be read ({exc.strerror or exc})"
        if got != list(want):
            return f"file {rel!r} is corrupt (size/CRC-32 {got} != recorded {list(want)})"
    return None


def _ownership_problem(path: Path, manifest: dict, i: int, j: int, k: int,
                       fault_type: str) -> str | None:
    """Whether a whole block belongs to the build ``manifest`` (``None``: it does).

    A block records the digest of the manifest its builder was given; a block from before
    digests is checked by its content (coordinates, seeds) once and then given the digest.
    """
    record = _block_record(path)
    digest = record.get("manifest_sha256")
    if digest is not None:
        if digest == manifest_digest(manifest):
            return None
        recorded = record.get("manifest")
        theirs: dict = recorded if isinstance(recorded, dict) else {}
        return f"it was built by another build (differs in {manifest_diff(theirs, manifest)})"
    import xarray as xr

    try:
        ds = xr.open_zarr(path, consolidated=False)
        problem = block_content_problem(ds, manifest, i, j, k, fault_type,
                                        fault_type_record(fault_type).code)
    except Exception as exc:  # a decoder's error on a damaged block
        return f"it cannot be decoded ({type(exc).__name__}: {exc})"
    if problem is None:
        meta = json.loads((path / _ROOT).read_text())
        meta["attributes"][_ATTR].update(manifest=manifest,
                                         manifest_sha256=manifest_digest(manifest))
        write_json_atomic(meta, path / _ROOT, indent=2, sort_keys=False)
    return problem


def _block_manifest(path: Path) -> dict | None:
    """The manifest a block records, if its digest vouches for it."""
    try:
        record = _block_record(path)
    except (OSError, ValueError):
        return None
    man = record.get("manifest")
    if not isinstance(man, dict) or record.get("manifest_sha256") != manifest_digest(man):
        return None
    return man


def _rebuild_hint(store: Path, man: dict, blocks=()) -> str:
    def many(opt, values, fmt):
        return " ".join(f"{opt} {fmt(v)}" for v in values)

    cmd = (f"gearshot simulate --store {str(store)} "
           f"{many('--speed', man.get('speeds', []), lambda v: f'{v:g}')} "
           f"{many('--load', man.get('loads', []), lambda v: f'{v:g}')} "
           f"{many('--grade', man.get('grades', []), str)} "
           f"--n-healthy {man.get('n_healthy')} --n-faulty {man.get('n_faulty')} "
           f"--seed {man.get('seed')}"
           + "".join(f" --fault-type {t}" for t in man.get("fault_types", []))
           + ("" if man.get("paired") else " --no-paired"))   # paired is the default
    what = (f"it (re)builds {', '.join(blocks)} and reuses the other blocks" if blocks else
            "it restores manifest.json from the blocks' copies and rebuilds no block")
    return f"run `{cmd}` (or build_database with the same arguments): {what}"


def _check_against_manifest(store: Path, path: Path, part, man: dict, where: str,
                            i: int, j: int, k: int, fault_type: str) -> None:
    """Raise unless a loaded block is the one ``manifest.json`` describes at its position.

    Two checks: the manifest digest the block's builder recorded (absent in blocks built
    before digests) and the block's own coordinates (:func:`block_content_problem`). The
    repair named is the blocks' build when every block vouches for another manifest than
    ``manifest.json`` (the file was edited), else a rebuild of this block.
    """
    digest = _block_record(path).get("manifest_sha256")
    problem: str | None
    if digest is not None and digest != manifest_digest(man):
        problem = ("it records another build than manifest.json (differs in "
                   f"{manifest_diff(_block_manifest(path) or {}, man)})")
    else:
        problem = block_content_problem(part, man, i, j, k, fault_type,
                                        fault_type_record(fault_type).code)
    if problem is None:
        return
    theirs = _block_manifest(path)
    if theirs is not None and theirs != man and all(
            _block_manifest(b) == theirs for b in (store / "blocks").glob("*.zarr")):
        raise GearshotError(f"{where} contradicts manifest.json: {problem}; manifest.json "
                            f"was changed after the build; {_rebuild_hint(store, theirs)}")
    raise GearshotError(f"{where} does not belong to this store's build: {problem}; "
                        f"{_rebuild_hint(store, man, [path.name])}")


def _read_manifest(store: Path) -> dict:
    mpath = store / "manifest.json"
    try:
        man = json.loads(mpath.read_text())
        if not isinstance(man, dict) or not {"speeds", "loads", "grades"} <= set(man):
            raise ValueError("not a gearshot manifest")
    except (OSError, ValueError) as exc:
        raise GearshotError(
            f"store {str(store)!r}: manifest.json is damaged ({exc}); run build_database / "
            f"`gearshot simulate` on this store with its original arguments: the manifest "
            f"is restored from the blocks' copies (no block is rebuilt)") from None
    return man


def _build_block(store: str, pair: GearPair, i: int, j: int, k: int, speed: float,
                 load: float, grade: int, n_healthy: int, n_faulty: int, seed: int,
                 n_points: int, single_thread: bool = False, fault_type: str = "ftff",
                 paired: bool = False, manifest: dict | None = None) -> str:
    import xarray as xr

    if single_thread:
        import numba
        numba.set_num_threads(1)
    blocks = Path(store) / "blocks"
    final = blocks / _block_name(i, j, k, fault_type)
    if final.exists():
        return final.name
    if manifest is None:   # the builder's manifest, never one found on disk
        raise GearshotError("_build_block needs the build's manifest")
    code = fault_type_record(fault_type).code
    n = n_healthy + n_faulty
    sizes, sig_seeds = block_draws(seed, i, j, k, code, n_healthy, n_faulty)
    sa = simulate_sa(pair, speed=speed, load=load, grade=grade, fault_sizes=sizes,
                     n_points=n_points, rng=[int(s) for s in sig_seeds],
                     fault_type=fault_type)
    data = {"sa": (("signal", "angle"), sa.astype(np.float64),
                   {"units": "g", "long_name": "vertical acceleration SA"})}
    if paired:
        data["sa_twin"] = (("signal", "angle"), _healthy_twins(
            pair, sa, sizes, sig_seeds, speed=speed, load=load, grade=grade,
            n_points=n_points), {"units": "g", "long_name": "healthy twin SA (same "
                                 "profile errors, no fault)"})
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
        ds.to_zarr(tmp, mode="w", consolidated=False)
        _write_checksums(tmp, manifest)
    return final.name


def _healthy_twins(pair, sa, sizes, sig_seeds, *, speed, load, grade, n_points):
    """The healthy SA of each signal's own gear pair: the same seed (so the same profile
    errors of both wheels), fault size 0. A healthy signal is its own twin."""
    twins = np.array(sa, dtype=np.float64, copy=True)
    faulty = np.flatnonzero(sizes > 0)
    if faulty.size:
        twins[faulty] = simulate_sa(pair, speed=speed, load=load, grade=grade,
                                    fault_sizes=np.zeros(faulty.size), n_points=n_points,
                                    rng=[int(sig_seeds[i]) for i in faulty])
    return twins


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
        in-process (numba threads over the batch) otherwise; ``False``: always in-process.
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
    store = Path(store).expanduser()
    if not isinstance(paired, (bool, np.bool_)):
        raise GearshotError(f"paired must be True or False; got {describe(paired)}")
    manifest = _manifest(pair, speeds, loads, grades, n_healthy, n_faulty, seed, n_points,
                         fault_types, bool(paired))
    check_writable(store, "store", folder=True)
    try:
        store.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise GearshotError(f"store {str(store)!r} cannot be created "
                            f"({exc.strerror or exc})") from None
    with store_lock(store, manifest, progress=progress):
        try:
            _prepare_store(store, manifest, progress)
            _build_locked(store, pair, manifest, speeds, loads, grades, fault_types,
                          n_healthy, n_faulty, seed, n_points, client, progress,
                          bool(paired))
        finally:   # temporaries of this run (a failed or killed worker): we hold the lock
            _remove_temporaries(store)
    return store


def _build_locked(store, pair, manifest, speeds, loads, grades, fault_types, n_healthy,
                  n_faulty, seed, n_points, client, progress, paired):
    tasks = [(i, j, k, float(s), float(ld), int(g), ft)
             for i, s in enumerate(speeds) for j, ld in enumerate(loads)
             for k, g in enumerate(grades) for ft in fault_types]
    blocks = store / "blocks"
    todo = []
    damaged = []
    for t in tasks:
        path = blocks / _block_name(*t[:3], t[6])
        if path.exists():
            problem = resume_problem(path) or _ownership_problem(path, manifest, *t[:3],
                                                                 t[6])
            if problem is None:
                continue
            damaged.append(f"{path.name} ({problem})")
            remove_tree(path)
        todo.append(t)
    if damaged and progress:
        print(f"rebuilding {len(damaged)} damaged block(s) of {str(store)!r}: "
              + "; ".join(damaged), file=sys.stderr)
    own_cluster = None
    if client is None and len(todo) > _SMALL_BUILD:
        from dask.distributed import Client, LocalCluster
        own_cluster = LocalCluster(n_workers=os.cpu_count() or 1, threads_per_worker=1,
                                   processes=True, dashboard_address=":0")
        client = Client(own_cluster)
    try:
        _run_tasks(store, pair, todo, len(tasks), n_healthy, n_faulty, seed, n_points,
                   client if client else None, progress, paired, manifest)
    finally:
        if own_cluster is not None:
            client.close()
            own_cluster.close()


def _remove_temporaries(store: Path) -> None:
    """Remove hidden temporary folders/files (``.*.tmp``) of blocks and the manifest."""
    for folder in (store, store / "blocks"):
        if folder.is_dir():
            for leftover in folder.glob(".*.tmp*"):
                if leftover.is_dir():
                    shutil.rmtree(leftover, ignore_errors=True)
                else:
                    leftover.unlink(missing_ok=True)


def _prepare_store(store: Path, manifest: dict, progress: bool = True) -> None:
    """Check (or write, or restore) the manifest; called with the store's lock held."""
    _remove_temporaries(store)          # of killed runs
    mpath = store / "manifest.json"
    if mpath.exists():
        try:
            old = _read_manifest(store)
        except GearshotError:
            old = None
        if old != manifest:
            # manifest.json is damaged or says another build: restore it only when the
            # blocks (by their recorded digests) all vouch for this build
            copies = [_block_manifest(b) for b in (store / "blocks").glob("*.zarr")]
            if copies and all(c == manifest for c in copies):
                if progress:
                    what = ("is damaged" if old is None else
                            f"contradicts its blocks (differs in {manifest_diff(old, manifest)})")
                    print(f"store {str(store)!r}: manifest.json {what}; restored from the "
                          f"blocks' copies", file=sys.stderr)
                write_json_atomic(manifest, mpath, sort_keys=False)
            elif old is None:
                _read_manifest(store)     # raises its error
            else:
                diff = sorted(k for k in manifest if old.get(k) != manifest[k])
                hint = ""
                if diff == ["paired"]:
                    hint = (" (it was built without healthy twins: finish it with "
                            "paired=False / --no-paired)" if manifest.get("paired") else
                            " (it was built with healthy twins: finish it with paired=True"
                            " / --paired)")
                raise GearshotError(f"store {str(store)!r} holds a different build "
                                    f"(differs in {', '.join(diff)}){hint}; use a new store "
                                    f"(--store / store=)")
    try:
        (store / "blocks").mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise GearshotError(f"store {str(store)!r} is not writable ({exc.strerror or exc})") \
            from None
    if not mpath.exists():
        write_json_atomic(manifest, mpath, sort_keys=False)


def _run_tasks(store, pair, todo, n_total, n_healthy, n_faulty, seed, n_points, client,
               progress, paired=False, manifest=None):
    from .._progress import progress as progress_of

    with progress_of("simulating blocks", n_total, completed=n_total - len(todo),
                     enabled=progress) as bar:
        if client is None:
            for t in todo:
                _build_block(str(store), pair, *t[:6], n_healthy, n_faulty, seed, n_points,
                             fault_type=t[6], paired=paired, manifest=manifest)
                bar.advance()
            return
        from dask.distributed import as_completed
        futures = [client.submit(_build_block, str(store), pair, *t[:6], n_healthy,
                                 n_faulty, seed, n_points, True, t[6], paired, manifest,
                                 pure=False)
                   for t in todo]
        try:
            for fut in as_completed(futures):
                fut.result()
                bar.advance()
        except Exception:
            # a failed block (a full disk, ...): drop the queued blocks, and give the
            # running ones a minute to finish or to remove their temporary folders
            client.cancel(futures)
            deadline = time.monotonic() + 60
            while (any((Path(store) / "blocks").glob(".*.tmp"))
                   and time.monotonic() < deadline):
                time.sleep(0.2)
            raise


def load_database(store, *, speed: float, load: float, grade: int | None = None,
                  fault_type: str | None = None):
    """The SAs of one (speed, load) condition, optionally one grade and one fault type.

    Parameters
    ----------
    store : str or Path
    speed, load : float
        The condition (must be in the build).
    grade : int, optional
        One grade; ``None``: all, in the build's grade order.
    fault_type : str, optional
        One fault type of the build; ``None``: all, in the build's order.

    Returns
    -------
    xarray.Dataset
        ``sa`` (signal, angle) float64 in g (and ``sa_twin``, the healthy twins, in a
        store built with ``paired=True``); coords ``fault_size``, ``grade``, ``seed``
        and ``fault_type`` along ``signal``; scalar ``speed`` (rev/s) and ``load`` (N m).
        Blocks are concatenated along ``signal`` (grades outer, fault types inner).
        Attributes: the store's gear pair (:data:`PAIR_ATTRS`: ``pinion_teeth``,
        ``gear_teeth``, ``module`` and ``face_width`` in m, ``pressure_angle`` and
        ``helix_angle`` in rad), read from the pair every store's manifest records
        (fields missing from an older store's text take the :class:`GearPair`
        defaults; a manifest whose pair cannot be read gives no pair attributes, and
        the estimator then falls back as :class:`~gearshot.estimator.OneFaultShotEstimator`
        says). The SAs' cycle is one revolution of the ``gear_teeth`` wheel, so
        ``gear_teeth`` is their gear-mesh order.
    """
    import xarray as xr

    store = Path(store).expanduser()
    mpath = store / "manifest.json"
    if not mpath.exists():
        raise GearshotError(f"store {str(store)!r} holds no gearshot database "
                            f"(no manifest.json)")
    man = _read_manifest(store)

    def index(values, want, name):
        hits = np.flatnonzero(np.isclose(values, want, rtol=1e-9, atol=1e-12))
        if hits.size == 0:
            raise GearshotError(f"{name} {want!r} is not in the database (has {values})")
        return int(hits[0])

    i = index(man["speeds"], speed, "speed")
    j = index(man["loads"], load, "load")
    ks = (range(len(man["grades"])) if grade is None
          else [index(man["grades"], grade, "grade")])
    types = man.get("fault_types", ["ftff"])
    if fault_type is not None:
        if fault_type not in types:
            raise GearshotError(f"fault_type {fault_type!r} is not in the database "
                                f"(has {types})")
        types = [fault_type]
    _check_fault_models(store, man, types)
    parts = []
    for k in ks:
        for ft in types:
            path = store / "blocks" / _block_name(i, j, k, ft)
            where = (f"block {path.name} (speed={speed!r}, load={load!r}, "
                     f"grade={man['grades'][k]!r}, fault_type={ft!r}) of store {str(store)!r}")
            if not path.exists():
                raise GearshotError(f"{where} is not built yet; "
                                    f"{_rebuild_hint(store, man, [path.name])}")
            part, problem = read_block(path)
            if part is not None and (
                    "sa" not in part or any(
                        name in part and not np.all(np.isfinite(part[name].values))
                        for name in ("sa", "sa_twin"))):
                problem = "its SA array is incomplete (non-finite values)"
            elif part is not None and problem is None:
                _check_against_manifest(store, path, part, man, where, i, j, k, ft)
            if problem is not None:
                if "is corrupt" in problem:   # resuming checks sizes and times only
                    problem += (f" (should the rebuild find nothing to do, remove "
                                f"{str(path)!r} first)")
                raise GearshotError(f"{where} is damaged: {problem}; "
                                    f"{_rebuild_hint(store, man, [path.name])}")
            part.attrs.pop(_ATTR, None)
            part.attrs.pop("fault_type", None)
            parts.append(part.assign_coords(
                fault_type=("signal", np.full(part.sizes["signal"], ft, dtype=object))))
    parts = [p.drop_vars(["speed", "load"]) for p in parts]
    ds = parts[0] if len(parts) == 1 else xr.concat(parts, dim="signal", coords="minimal",
                                                    compat="override")
    pair = _pair_from_manifest(man)
    if pair is not None:
        ds.attrs.update(pair_attrs(pair))
    return ds.assign_coords(speed=float(man["speeds"][i]), load=float(man["loads"][j]))
