"""Native recording format: HDF5 (via h5py).

Layout (``format_version`` 1)::

    /                       attributes
        gearshot_format     "gearshot.recording"
        format_version      1
        fs                  float64, Hz
        n_samples           int64
        metadata_json       str, ASCII JSON object: speed (input-shaft rev/s or null),
                            load (N m or null), fault_size (y in [0, 1] or null), units,
                            source, tacho_pulses_per_rev, tacho_shaft ("input"/"output"),
                            extras (free-form JSON object)
    /acceleration           (n_samples,) float64 or float32; attributes units and sha256
                            (hex SHA-256 of the stored little-endian samples)
    /tacho                  (n_samples,) same dtype, LZF-compressed (absent = no tacho)

The tacho's chunks carry Fletcher-32 checksums (HDF5 refuses a damaged chunk); the
acceleration carries the SHA-256 digest of its samples, checked on every read (a mismatch
is refused as ``damaged_bytes``; files written before the digest existed have none and are
read as they are). (A chunked acceleration would carry Fletcher-32 checksums instead, but
HDF5 then crashes the process when a write fails on a full disk: it stays contiguous.)

Before HDF5 opens a file, :func:`check_heaps` walks its global heap collections (where the
variable-length string attributes live): a collection whose free-space object has size 0 --
e.g. a file whose tail was overwritten with zeros -- sends libhdf5 (2.0) into an endless
loop that holds Python's global lock, out of reach of any timeout in the process; it is
refused first. Every reader then checks that each dataset's declared bytes lie inside the
file.

Files are written to a temporary name in the target folder and moved into place with
``os.replace``, so a reader never sees a half-written file. A generic HDF5 file (no
``gearshot_format`` attribute) is read as a set of channels: every numeric 1-D (or 2-D, split
along the shorter axis) dataset at the root; ``fs`` from a root attribute or scalar dataset.
"""

from __future__ import annotations

import hashlib
import json
import mmap
import struct
from pathlib import Path
from typing import Any

import numpy as np

from .._errors import GearshotError
from ._fileio import FS_NAMES, RawFile, atomic_path

__all__ = ["read_hdf5", "write_hdf5", "check_heaps", "samples_digest", "FORMAT_NAME",
           "FORMAT_VERSION"]

FORMAT_NAME = "gearshot.recording"
FORMAT_VERSION = 1


def _attr(value: Any) -> Any:
    if isinstance(value, bytes):
        return value.decode("utf-8")
    if isinstance(value, np.ndarray) and value.size == 1:
        return value.item()
    if isinstance(value, np.generic):
        return value.item()
    return value


def _split_2d(name: str, arr: np.ndarray, out: dict[str, np.ndarray]) -> None:
    if arr.ndim == 1:
        out[name] = arr
    elif arr.ndim == 2 and min(arr.shape) == 1:
        out[name] = arr.ravel()
    elif arr.ndim == 2:
        chans = arr if arr.shape[0] < arr.shape[1] else arr.T
        for i, row in enumerate(chans):
            out[f"{name}[{i}]"] = row


def check_extent(path: Path, ds: Any, size: int | None = None) -> None:
    """Raise unless every byte a dataset declares lies inside the file (checked before the
    dataset is read: a truncated file fails at once, naming the dataset)."""
    size = Path(path).stat().st_size if size is None else size
    dsid = ds.id
    spans = []
    if ds.chunks is None:
        offset = dsid.get_offset()
        if offset is not None:
            spans.append((offset, dsid.get_storage_size()))
        if ds.compression is None and dsid.get_storage_size() not in (0, ds.size *
                                                                      ds.dtype.itemsize):
            raise GearshotError(f"{str(path)!r}: dataset {ds.name} declares "
                                f"{ds.size * ds.dtype.itemsize} bytes but stores "
                                f"{dsid.get_storage_size()} (damaged file?)")
    else:
        for i in range(dsid.get_num_chunks()):
            info = dsid.get_chunk_info(i)
            spans.append((info.byte_offset, info.size))
    for offset, length in spans:
        if offset + length > size:
            raise GearshotError(f"{str(path)!r}: dataset {ds.name} declares data up to byte "
                                f"{offset + length} but the file holds {size} bytes "
                                f"(truncated file?)")


#: Signature, version and smallest size of an HDF5 global heap collection (format spec
#: III.E); an object header is 16 bytes with 8-byte lengths.
_GCOL, _GCOL_MIN = b"GCOL\x01\x00\x00\x00", 4096


def check_heaps(path: Path) -> None:
    """Refuse a file whose HDF5 global heap collections would hang libhdf5.

    libhdf5 walks a collection's objects by their sizes; a free-space object (index 0) of
    size 0 never advances the walk, so the library loops forever inside one call that
    holds Python's global interpreter lock. Every collection found in the file (its
    8-byte signature, a size of at least 4 KiB inside the file) is walked here the same way
    first.

    Raises
    ------
    GearshotError
        Naming the file, the byte offsets and ``damaged_bytes``.
    """
    with open(path, "rb") as fh:
        size = fh.seek(0, 2)
        if size == 0:
            return
        with mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as buf:
            at = buf.find(_GCOL)
            while at >= 0:
                if at + 16 <= size:
                    (length,) = struct.unpack_from("<Q", buf, at + 8)
                    if _GCOL_MIN <= length <= size - at:
                        _walk_heap(path, buf, at, at + length)
                at = buf.find(_GCOL, at + 1)


def _walk_heap(path: Path, buf: mmap.mmap, start: int, end: int) -> None:
    p = start + 16
    while p + 16 <= end:
        idx, _, size = struct.unpack_from("<HH4xQ", buf, p)
        need = size if idx == 0 else 16 + (size + 7) // 8 * 8
        if need == 0:
            raise GearshotError(f"{str(path)!r}: damaged bytes (input check 'damaged_bytes'): "
                                f"the HDF5 global heap at byte {start} holds an empty object "
                                f"at byte {p} (zeroed or overwritten file?)")
        p += need


def samples_digest(data: np.ndarray) -> str:
    """Hex SHA-256 of an array's samples, stored little-endian (the acceleration's
    ``sha256`` attribute)."""
    arr = np.ascontiguousarray(data)
    return hashlib.sha256(arr.astype(arr.dtype.newbyteorder("<"), copy=False)
                          .tobytes()).hexdigest()


def _check_digest(path: Path, ds: Any, data: np.ndarray) -> None:
    stored = _attr(ds.attrs["sha256"]) if "sha256" in ds.attrs else None
    if stored is None:
        return
    found = samples_digest(data)
    if found != stored:
        raise GearshotError(f"{str(path)!r}: damaged bytes (input check 'damaged_bytes'): "
                            f"/acceleration does not match its SHA-256 digest (stored "
                            f"{str(stored)[:12]}..., read {found[:12]}...)")


def read_hdf5(path: Path, *, walk_heaps: bool = True) -> RawFile:
    """Read a native (or generic) HDF5 recording file (``walk_heaps``: first
    :func:`check_heaps`)."""
    import h5py  # imported on use: text/zip readers never pay for it
    if walk_heaps:
        check_heaps(path)
    with h5py.File(path, "r") as f:
        attrs = {k: _attr(v) for k, v in f.attrs.items()}
        if attrs.get("gearshot_format") == FORMAT_NAME:
            version = attrs.get("format_version")
            if version != FORMAT_VERSION:
                raise GearshotError(f"{str(path)!r}: unsupported gearshot recording "
                                    f"format_version {version!r}")
            if "acceleration" not in f:
                raise GearshotError(f"{str(path)!r}: no /acceleration dataset")
            n = attrs.get("n_samples")
            size = Path(path).stat().st_size
            for k in ("acceleration", "tacho"):
                if k in f:
                    if f[k].shape != (n,):
                        raise GearshotError(f"{str(path)!r}: /{k} has shape {f[k].shape}, "
                                            f"expected ({n},) (truncated or corrupt file?)")
                    check_extent(path, f[k], size)
            chans = {"acceleration": f["acceleration"][()]}
            _check_digest(path, f["acceleration"], chans["acceleration"])
            if "tacho" in f:
                chans["tacho"] = f["tacho"][()]
            meta = json.loads(attrs.get("metadata_json", "{}"))
            if not isinstance(meta, dict):
                raise GearshotError(f"{str(path)!r}: metadata_json is not a JSON object")
            return RawFile(Path(path), chans, attrs.get("fs"), meta)
        # generic HDF5: numeric datasets at the root
        chans = {}
        fs = None
        for key in FS_NAMES:
            for k, v in attrs.items():
                if k.lower() == key and fs is None:
                    fs = float(v)
        for name, obj in f.items():
            if not isinstance(obj, h5py.Dataset) or obj.dtype.kind not in "iuf":
                continue
            check_extent(path, obj)
            data = obj[()]
            if np.ndim(data) == 0 or np.size(data) == 1:
                if name.lower() in FS_NAMES and fs is None:
                    fs = float(np.ravel(data)[0])
                continue
            _split_2d(name, np.asarray(data), chans)
        return RawFile(Path(path), chans, fs, {})


def write_hdf5(rec: Any, path: Path, *, dtype: Any = np.float64) -> None:
    """Write ``rec`` (a Recording) in the native layout, atomically."""
    import h5py
    dtype = np.dtype(dtype)
    if dtype not in (np.dtype(np.float64), np.dtype(np.float32)):
        raise GearshotError(f"dtype for HDF5 must be float64 or float32; got {dtype}")
    with atomic_path(path) as tmp:
        with h5py.File(tmp, "w") as f:
            f.attrs["gearshot_format"] = FORMAT_NAME
            f.attrs["format_version"] = FORMAT_VERSION
            f.attrs["fs"] = float(rec.fs)
            f.attrs["n_samples"] = int(rec.acceleration.size)
            f.attrs["metadata_json"] = json.dumps(rec.metadata, sort_keys=True)
            acc = rec.acceleration.astype(dtype, copy=False)
            d = f.create_dataset("acceleration", data=acc)
            d.attrs["units"] = rec.units
            d.attrs["sha256"] = samples_digest(acc)   # checked on every read
            if rec.tacho is not None:   # Fletcher-32: HDF5 refuses a damaged chunk on read
                f.create_dataset("tacho", data=rec.tacho.astype(dtype, copy=False),
                                 compression="lzf", chunks=(min(rec.tacho.size, 1 << 16),),
                                 fletcher32=True)
