"""Reading database blocks: one read per file, checked while decoding; resume checks.

:func:`read_block` reads every file of a block once, checks its size and CRC-32 (the
block's checksum list, :mod:`gearshot.sim._db_checksums`) on the bytes read and decodes the
block from those bytes; :func:`resume_problem` decides from file sizes and times alone
whether a block can be kept when a build resumes (and from the digest of its checksum
list, whether that list was edited).
"""

from __future__ import annotations

import json
import zlib
from pathlib import Path

from ._db_checksums import (
    ATTR,
    ROOT,
    block_problem,
    block_record,
    files_digest,
    record_problem,
)

__all__ = ["read_block", "resume_problem"]


def read_block(path: Path):
    """Read a built block once: ``(dataset, None)`` or ``(None, problem)``.

    Every file of the checksum list is read into memory once, its size and CRC-32
    checked on those bytes, and the block decoded from them (a zarr memory store); a
    block without a checksum list is an error (it is rebuilt by the next build)."""
    import xarray as xr
    import zarr.storage
    from zarr.core.buffer import default_buffer_prototype

    try:
        root = (path / ROOT).read_bytes()
        record = json.loads(root).get("attributes", {}).get(ATTR, {})
        if not isinstance(record, dict):
            raise ValueError(f"attribute {ATTR!r} is not a mapping")
    except FileNotFoundError:
        return None, f"its metadata file {ROOT!r} is missing"
    except (OSError, ValueError) as exc:
        return None, f"its metadata file {ROOT!r} is unreadable ({exc})"
    if not record:     # never decoded unchecked (issue #22): rebuilt by the next build
        return None, f"its checksum list (attribute {ATTR!r}) is missing"
    files = record.get("files")
    if not isinstance(files, dict) or not files:
        return None, f"its checksum list (attribute {ATTR!r}) is damaged"
    if record_problem(record) is not None:
        return None, record_problem(record)
    buf = default_buffer_prototype().buffer
    content = {ROOT: buf.from_bytes(root)}
    for rel, want in sorted(files.items()):
        try:
            data = (path / rel).read_bytes()
        except FileNotFoundError:
            return None, f"file {rel!r} is missing"
        except OSError as exc:
            return None, f"file {rel!r} cannot be read ({exc.strerror or exc})"
        got = [len(data), zlib.crc32(data)]
        if got != list(want):
            return None, (f"file {rel!r} is corrupt (size/CRC-32 {got} != recorded "
                          f"{list(want)})")
        content[rel] = buf.from_bytes(data)
    try:
        # chunks=None: decoded straight into numpy, no dask graph, so no scheduler is
        # involved (on a Dask worker a lazy read would go to the scheduler and back)
        ds = xr.open_zarr(zarr.storage.MemoryStore(content), consolidated=False,
                          chunks=None).load()
    except Exception as exc:  # a decoder's error on a damaged chunk
        return None, f"it cannot be decoded ({type(exc).__name__}: {exc})"
    return ds, None


def resume_problem(path: Path) -> str | None:
    """What is wrong with a built block, by file sizes and times only (resuming a build
    reads no chunk): every listed file present with its recorded size and not modified
    after the checksum list was written; a block failing that is checked in full
    (:func:`~gearshot.sim._db_checksums.block_problem`). A damage that keeps a file's size
    and time (bit rot) is caught when the block is read (:func:`read_block`)."""
    try:
        record = block_record(path)
        stamp = (path / ROOT).stat().st_mtime_ns
    except (OSError, ValueError):
        return block_problem(path)
    files = record.get("files") if record else None
    if not isinstance(files, dict) or not files or "files_sha256" not in record:
        # a list from before its digest: checked in full once, then given the digest
        problem = block_problem(path)
        if problem is None and isinstance(files, dict) and files:
            _add_files_digest(path)
        return problem
    if record_problem(record) is not None:
        return record_problem(record)
    for rel, want in files.items():
        try:
            st = (path / rel).stat()
        except OSError:
            return block_problem(path)
        if [st.st_size] != list(want)[:1] or st.st_mtime_ns > stamp:
            return block_problem(path)
    return None


def _add_files_digest(path: Path) -> None:
    """Record the digest of a (fully checked) block's checksum list in its metadata."""
    from .._atomic import write_json_atomic

    meta = json.loads((path / ROOT).read_text())
    record = meta["attributes"][ATTR]
    record["files_sha256"] = files_digest(record["files"])
    write_json_atomic(meta, path / ROOT, indent=2, sort_keys=False)
