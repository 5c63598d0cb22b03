"""A database block's record: its checksum list and the manifest of the build that made it.

Each block carries, in the attribute ``gearshot_block`` (:data:`ATTR`) of its root
``zarr.json`` (:data:`ROOT`), the size and CRC-32 of every other file in it, the manifest
its builder was given and that manifest's SHA-256. :func:`write_checksums` writes the
record into a finished block; :func:`block_problem` checks every file against it;
:func:`ownership_problem` decides whether a whole block belongs to a build;
:func:`block_manifest` is the manifest a block vouches for (to restore a lost
``manifest.json``).
"""

from __future__ import annotations

import hashlib
import json
import os
import zlib
from pathlib import Path

from .._atomic import write_json_atomic
from ..fault_registry import fault_type_record
from ._integrity import block_content_problem, manifest_diff, manifest_digest

__all__ = ["ROOT", "ATTR", "write_checksums", "block_record", "block_problem",
           "block_manifest", "ownership_problem", "files_digest", "record_problem"]

ROOT = "zarr.json"           # the block group's metadata; holds the record
ATTR = "gearshot_block"


def _file_digest(path: Path) -> tuple[int, int]:
    crc = 0
    size = 0
    with open(path, "rb") as fh:
        while chunk := fh.read(1 << 22):
            crc = zlib.crc32(chunk, crc)
            size += len(chunk)
    return size, crc


def write_checksums(folder: Path, manifest: dict) -> None:
    """Record the size and CRC-32 of every file of the block ``folder`` and the build's
    ``manifest`` (with its digest) in the block's root metadata."""
    files = {}
    for root, _dirs, names in os.walk(folder):
        for name in names:
            full = Path(root) / name
            rel = full.relative_to(folder).as_posix()
            if rel != ROOT and not name.startswith("."):
                files[rel] = list(_file_digest(full))
    meta = json.loads((folder / ROOT).read_text())
    meta.setdefault("attributes", {})[ATTR] = {"files": files, "files_sha256":
                                               files_digest(files), "manifest": manifest,
                                               "manifest_sha256": manifest_digest(manifest)}
    write_json_atomic(meta, folder / ROOT, indent=2, sort_keys=False)


def files_digest(files: dict) -> str:
    """SHA-256 of a checksum list (canonical JSON): an edited size or CRC in the list
    shows without reading a chunk."""
    text = json.dumps(files, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


def record_problem(record: dict) -> str | None:
    """Whether a block's checksum list was changed after it was written (its recorded
    digest no longer matches it); ``None`` also for a list from before digests."""
    digest = record.get("files_sha256")
    files = record.get("files")
    if digest is not None and (not isinstance(files, dict) or files_digest(files) != digest):
        return (f"its checksum list (attribute {ATTR!r}) was changed after the build (its "
                f"digest no longer matches)")
    return None


def block_record(path: Path) -> dict:
    """The record of a block; ``{}`` when it has none."""
    meta = json.loads((path / ROOT).read_text())
    record = meta.get("attributes", {}).get(ATTR, {})
    if not isinstance(record, dict):
        raise ValueError(f"attribute {ATTR!r} is not a mapping")
    return record


def block_problem(path: Path) -> str | None:
    """What is wrong with a built block (``None``: whole, every file as written)."""
    try:
        record = block_record(path)
    except FileNotFoundError:
        return f"its metadata file {ROOT!r} is missing"
    except (OSError, ValueError) as exc:
        return f"its metadata file {ROOT!r} is unreadable ({exc})"
    if not record:
        return f"its checksum list (attribute {ATTR!r}) is missing"
    files = record.get("files")
    if not isinstance(files, dict) or not files:
        return f"its checksum list (attribute {ATTR!r}) is damaged"
    edited = record_problem(record)
    if edited is not None:
        return edited
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


def block_manifest(path: Path) -> dict | None:
    """The manifest a block records, if its digest vouches for it."""
    try:
        record = block_record(path)
    except (OSError, ValueError):
        return None
    man = record.get("manifest")
    if not isinstance(man, dict) or record.get("manifest_sha256") != manifest_digest(man):
        return None
    return man


def ownership_problem(path: Path, manifest: dict, i: int, j: int, k: int,
                      fault_type: str) -> str | None:
    """Whether a whole block belongs to the build ``manifest`` (``None``: it does).

    A block records the digest of the manifest its builder was given; a block from before
    digests is checked by its content (coordinates, seeds) once and then given the digest.
    """
    record = block_record(path)
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
        meta = json.loads((path / ROOT).read_text())
        meta["attributes"][ATTR].update(manifest=manifest,
                                        manifest_sha256=manifest_digest(manifest))
        write_json_atomic(meta, path / ROOT, indent=2, sort_keys=False)
    return problem
