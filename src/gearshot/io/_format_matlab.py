"""MATLAB ``.mat`` recordings: v5 (scipy.io) and v7.3 (HDF5: read with h5py, written with
hdf5storage).

Variables: every numeric vector (or each row/column of a numeric matrix, named
``name[i]``) is a channel; ``fs`` (or ``Fs``, ``sample_rate``, ...) is the sampling rate;
``metadata_json`` (an ASCII JSON object with all metadata fields) holds the metadata. Files
from elsewhere may instead carry scalar/string variables ``speed``, ``load``,
``fault_size``, ``units``, ``source``, ``tacho_pulses_per_rev``, ``tacho_shaft``; they are
read when there is no ``metadata_json``. The writers store ``acceleration``, ``tacho``,
``fs``, ``metadata_json`` and, for MATLAB users' convenience, ``speed``, ``load`` and
``fault_size`` when known (v7.3: HDF5 with the 512-byte MATLAB user block,
``MATLAB_class`` attributes, UTF-16 chars and MATLAB's reversed dimension order, as
hdf5storage writes them).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._errors import GearshotError
from ._fileio import FS_NAMES, RawFile, atomic_path
from ._format_hdf5 import check_extent, check_heaps

if TYPE_CHECKING:
    import h5py

__all__ = ["read_mat", "write_mat"]

_STR_META = ("units", "source", "tacho_shaft")
_FLOAT_META = ("speed", "load", "fault_size")


def _is_v73(path: Path) -> bool:
    import h5py  # imported on use (as scipy.io): other formats never pay for them
    with open(path, "rb") as fh:
        head = fh.read(128)
    return head.startswith(b"MATLAB 7.3") or (h5py.is_hdf5(path) and not
                                              head.startswith(b"MATLAB 5.0"))


def _collect(path: Path, variables: dict[str, Any]) -> RawFile:
    chans: dict[str, np.ndarray] = {}
    meta: dict[str, Any] = {}
    full: dict[str, Any] | None = None
    fs = None
    for name, value in variables.items():
        if name.startswith("__"):
            continue
        low = name.lower()
        if isinstance(value, str) or (isinstance(value, np.ndarray) and value.dtype.kind == "U"):
            text = str(value) if not isinstance(value, np.ndarray) else "".join(value.ravel())
            if name in _STR_META:
                meta[name] = text
            elif name == "metadata_json":
                try:
                    full = json.loads(text)
                except ValueError as exc:
                    raise GearshotError(f"{str(path)!r}: variable metadata_json is not valid "
                                        f"JSON ({exc})") from None
                if not isinstance(full, dict):
                    raise GearshotError(f"{str(path)!r}: metadata_json is not a JSON object")
            continue
        arr = np.asarray(value)
        if arr.dtype.kind not in "iufb":
            continue
        if low in FS_NAMES and arr.size == 1 and fs is None:
            fs = float(arr.ravel()[0])
            continue
        if name in _FLOAT_META and arr.size == 1:
            meta[name] = float(arr.ravel()[0])
            continue
        if name == "tacho_pulses_per_rev" and arr.size == 1:
            meta[name] = int(arr.ravel()[0])
            continue
        if arr.size <= 1 or arr.ndim > 2:
            continue
        arr = arr.astype(np.float64)
        if arr.ndim == 1 or min(arr.shape) == 1:
            chans[name] = arr.ravel()
        else:
            rows = arr if arr.shape[0] < arr.shape[1] else arr.T
            for i, row in enumerate(rows):
                chans[f"{name}[{i}]"] = row
    return RawFile(Path(path), chans, fs, full if full is not None else meta)


def _read_v73_dataset(ds: h5py.Dataset) -> Any:
    cls = ds.attrs.get("MATLAB_class", b"")
    cls = cls.decode() if isinstance(cls, bytes) else str(cls)
    if ds.attrs.get("MATLAB_empty", 0):
        return "" if cls == "char" else np.zeros(0)
    data = np.asarray(ds[()])
    if cls == "char":
        return data.T.ravel().astype("<u2").tobytes().decode("utf-16-le", "surrogatepass")
    return data.T  # MATLAB stores column-major: h5py sees the dimensions reversed


def read_mat(path: Path) -> RawFile:
    """Read a v5 or v7.3 MAT-file into channels, fs and metadata."""
    import h5py
    import scipy.io
    path = Path(path)
    if _is_v73(path):
        variables: dict[str, Any] = {}
        check_heaps(path)   # a zeroed heap would hang libhdf5
        with h5py.File(path, "r") as f:
            for name, obj in f.items():
                if isinstance(obj, h5py.Dataset) and not name.startswith("#"):
                    check_extent(path, obj)
                    variables[name] = _read_v73_dataset(obj)
        return _collect(path, variables)
    variables = scipy.io.loadmat(path, squeeze_me=True, chars_as_strings=True)
    return _collect(path, variables)


def _mat_variables(rec: Any) -> dict[str, Any]:
    out: dict[str, Any] = {"acceleration": rec.acceleration}
    if rec.tacho is not None:
        out["tacho"] = rec.tacho
    out["fs"] = float(rec.fs)
    out["metadata_json"] = json.dumps(rec.metadata, sort_keys=True)  # ASCII
    for key in _FLOAT_META:
        if getattr(rec, key) is not None:
            out[key] = float(getattr(rec, key))
    return out


def _write_v73(variables: dict[str, Any], path: Path) -> None:
    import hdf5storage

    hdf5storage.savemat(str(path), variables, appendmat=False, format="7.3", oned_as="row",
                        matlab_compatible=True, store_python_metadata=False,
                        truncate_existing=True)


def write_mat(rec: Any, path: Path, *, version: str = "5") -> None:
    """Write ``rec`` as a MAT-file (``version`` "5" or "7.3"), atomically."""
    import scipy.io
    variables = _mat_variables(rec)
    with atomic_path(path) as tmp:
        if version == "5":
            scipy.io.savemat(tmp, variables, appendmat=False, format="5", oned_as="column",
                             do_compression=False)
        elif version == "7.3":
            _write_v73(variables, tmp)
        else:
            raise GearshotError(f"MAT version must be '5' or '7.3'; got {version!r}")
