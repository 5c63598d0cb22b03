"""Loading a database condition: every block read once, checked, and concatenated.

:func:`load_database` (public as :func:`gearshot.sim.load_database`) finds the blocks of
one (speed, load) condition in ``manifest.json``, reads each once with its checksums
(:func:`~gearshot.sim._block_read.read_block`), checks it against the manifest (the digest
its builder recorded and its own coordinates) and names the repair command whenever a block
is missing, damaged or of another build.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._errors import GearshotError
from ..fault_registry import fault_type_record
from ._block_read import read_block
from ._db_checksums import ATTR, block_manifest, block_record
from ._db_manifest import (
    block_name,
    blocks_manifest,
    check_fault_models,
    pair_attrs,
    pair_from_manifest,
    read_manifest,
    rebuild_hint,
    repair_command,
)
from ._integrity import block_content_problem, manifest_diff, manifest_digest

__all__ = ["load_database"]


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
    if not (store / "manifest.json").exists():
        if any((store / "blocks").glob("*.zarr")) if (store / "blocks").is_dir() else False:
            raise GearshotError(f"store {str(store)!r} has lost its manifest.json; run "
                                f"`gearshot simulate --repair --store {str(store)}`: it "
                                f"restores it from the blocks' copies")
        raise GearshotError(f"store {str(store)!r} holds no gearshot database "
                            f"(no manifest.json)")
    man = read_manifest(store)
    try:
        i = _index(man["speeds"], speed, "speed")
        j = _index(man["loads"], load, "load")
        ks = (range(len(man["grades"])) if grade is None
              else [_index(man["grades"], grade, "grade")])
    except GearshotError:
        _refuse_edited_manifest(store, man)
        raise
    types = _types_to_load(store, man, fault_type)
    parts = [_load_block(store, man, i, j, k, ft, speed, load) for k in ks for ft in types]
    parts = [p.drop_vars(["speed", "load"]) for p in parts]
    ds = parts[0] if len(parts) == 1 else xr.concat(parts, dim="signal", coords="minimal",
                                                    compat="override")
    pair = pair_from_manifest(man)
    if pair is not None:
        ds.attrs.update(pair_attrs(pair))
    return ds.assign_coords(speed=float(man["speeds"][i]), load=float(man["loads"][j]))


def _refuse_edited_manifest(store: Path, man: dict) -> None:
    """Raise when every block vouches for another build than ``manifest.json``: a condition
    missing from an edited manifest is tampering, not the caller's wrong argument."""
    theirs, _, _ = blocks_manifest(store)
    if theirs is not None and theirs != man:
        raise GearshotError(f"store {str(store)!r}: manifest.json was changed after the "
                            f"build (differs from what its blocks record in "
                            f"{manifest_diff(man, theirs)}); run `{repair_command(store)}` "
                            f"to restore it from the blocks' copies")


def _index(values, want, name) -> int:
    hits = np.flatnonzero(np.isclose(values, want, rtol=1e-9, atol=1e-12))
    if hits.size == 0:
        raise GearshotError(f"{name} {want!r} is not in the database (has {values})")
    return int(hits[0])


def _types_to_load(store: Path, man: dict, fault_type: str | None) -> list[str]:
    """The build's fault types (or the one asked for), each of the current model."""
    types = man.get("fault_types", ["ftff"])
    if fault_type is not None:
        if fault_type not in types:
            raise GearshotError(f"fault_type {fault_type!r} is not in the database "
                                f"(has {types})")
        types = [fault_type]
    check_fault_models(store, man, types)
    return types


def _load_block(store: Path, man: dict, i: int, j: int, k: int, ft: str, speed, load):
    """Block (i, j, k) of fault type ``ft``, read, checked, with its ``fault_type`` coord."""
    path = store / "blocks" / block_name(i, j, k, ft)
    where = (f"block {path.name} (speed={speed!r}, load={load!r}, "
             f"grade={man['grades'][k]!r}, fault_type={ft!r}) of store {str(store)!r}")
    if not path.exists():
        raise GearshotError(f"{where} is not built yet; "
                            f"{rebuild_hint(store, man, [path.name])}")
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
                            f"{rebuild_hint(store, man, [path.name])}")
    part.attrs.pop(ATTR, None)
    part.attrs.pop("fault_type", None)
    return part.assign_coords(
        fault_type=("signal", np.full(part.sizes["signal"], ft, dtype=object)))


def _check_against_manifest(store: Path, path: Path, part, man: dict, where: str,
                            i: int, j: int, k: int, fault_type: str) -> None:
    """Raise unless a loaded block is the one ``manifest.json`` describes at its position.

    Two checks: the manifest digest the block's builder recorded (absent in blocks built
    before digests) and the block's own coordinates (:func:`block_content_problem`). The
    repair named is the blocks' build when every block vouches for another manifest than
    ``manifest.json`` (the file was edited), else a rebuild of this block.
    """
    digest = block_record(path).get("manifest_sha256")
    problem: str | None
    if digest is not None and digest != manifest_digest(man):
        problem = ("it records another build than manifest.json (differs in "
                   f"{manifest_diff(block_manifest(path) or {}, man)})")
    else:
        problem = block_content_problem(part, man, i, j, k, fault_type,
                                        fault_type_record(fault_type).code)
    if problem is None:
        return
    theirs = block_manifest(path)
    if theirs is not None and theirs != man and all(
            block_manifest(b) == theirs for b in (store / "blocks").glob("*.zarr")):
        raise GearshotError(f"{where} contradicts manifest.json: {problem}; manifest.json "
                            f"was changed after the build; {rebuild_hint(store, theirs)}")
    raise GearshotError(f"{where} does not belong to this store's build: {problem}; "
                        f"{rebuild_hint(store, man, [path.name])}")
