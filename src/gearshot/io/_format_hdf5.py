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
    /acceleration           (n_samples,) float64 or float32; attribute units
    /tacho                  (n_samples,) same dtype, LZF-compressed (absent = no tacho)

The tacho's chunks carry Fletcher-32 checksums (HDF5 refuses a damaged chunk); every reader
first checks that each dataset's declared bytes lie inside the file. (A chunked acceleration
would carry checksums too, but HDF5 then crashes the process when a write fails on a full
disk: it stays contiguous.)

Files are written to a temporary name in the target folder and moved into place with
``os.replace``, so a reader never sees a half-written file. A generic HDF5 file (no
``gearshot_format`` attribute) is read as a set of channels: every numeric 1-D (or 2-D, split
along the shorter axis) dataset at the root; ``fs`` from a root attribute or scalar dataset.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from .._errors import GearshotError
from ._fileio import FS_NAMES, RawFile, atomic_path

__all__ = ["read_hdf5", "write_hdf5", "FORMAT_NAME", "FORMAT_VERSION"]

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


def read_hdf5(path: Path) -> RawFile:
    """Read a native (or generic) HDF5 recording file."""
    import h5py  # imported on use: text/zip readers never pay for it
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
            d = f.create_dataset("acceleration", data=rec.acceleration.astype(dtype, copy=False))
            d.attrs["units"] = rec.units
            if rec.tacho is not None:   # Fletcher-32: HDF5 refuses a damaged chunk on read
                f.create_dataset("tacho", data=rec.tacho.astype(dtype, copy=False),
                                 compression="lzf", chunks=(min(rec.tacho.size, 1 << 16),),
                                 fletcher32=True)
