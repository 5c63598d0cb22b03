"""UFF58 datasets through :mod:`pyuff`: read and checked, built for writing.

The format knowledge behind :mod:`gearshot.transfer.uff`: the specific-data-type codes, the
header fields kept as metadata, the checks every dataset 58 passes (point count, finite
values, increasing abscissa) and the conversion of one dataset to a
:class:`~gearshot.transfer.TransferFunction` or to the fields of a time record.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from .._errors import GearshotError
from .function import TransferFunction

# UFF "specific data type" codes (Field 1 of records 8-11 of dataset 58).
SPEC_TYPES = {0: "unknown", 1: "general", 2: "stress", 3: "strain", 5: "temperature",
              6: "heat flux", 8: "displacement", 9: "reaction force", 11: "velocity",
              12: "acceleration", 13: "force", 15: "pressure", 16: "mass", 17: "time",
              18: "frequency", 19: "rpm"}
SPEC_CODES = {v: k for k, v in SPEC_TYPES.items()}
FUNC_FRF, FUNC_TIME = 4, 1
# Header fields copied verbatim into TransferFunction.metadata (and written back).
KEEP_FIELDS = ("id2", "id3", "id4", "id5", "rsp_ent_name", "ref_ent_name", "load_case_id",
               "func_id", "ver_num", "ordinate_len_unit_exp", "ordinate_force_unit_exp",
               "ordinate_temp_unit_exp", "orddenom_len_unit_exp", "orddenom_force_unit_exp",
               "orddenom_temp_unit_exp", "abscissa_axis_lab", "abscissa_axis_units_lab",
               "ordinate_axis_lab", "orddenom_axis_lab", "orddenom_axis_units_lab")


def fail(path: Path, problem: str) -> GearshotError:
    """The error for a problem with the file ``path`` (named first)."""
    return GearshotError(f"{path}: {problem}")


def as_path(path: Any) -> Path:
    """``path`` as a :class:`~pathlib.Path`; a non-path argument raises."""
    try:
        return Path(os.fspath(path))
    except TypeError:
        raise GearshotError(f"path must be a str or os.PathLike; got {path!r}") from None


def check_readable(path: Path) -> None:
    """Refuse a missing, non-regular or empty file."""
    if not path.exists():
        raise fail(path, "file does not exist")
    if not path.is_file():
        raise fail(path, "not a regular file")
    if path.stat().st_size == 0:
        raise fail(path, "file is empty")


def read_uff_sets(path: Path) -> list[dict]:
    """All datasets of a UFF file as pyuff dicts, with every failure turned into a GearshotError."""
    import pyuff

    check_readable(path)
    try:
        uff = pyuff.UFF(str(path))
        n_sets = uff.get_n_sets()
    except Exception as exc:  # pyuff raises bare Exception
        raise fail(path, f"not a readable UFF file ({exc})") from None
    if n_sets == 0:
        with open(path, "rb") as fh:
            head = fh.read(4096).splitlines()
        if head and head[0].strip() == b"-1":
            raise fail(path, "truncated: a UFF dataset starts but never ends "
                              "(no closing '    -1' line)")
        raise fail(path, "no UFF dataset found (no block delimited by '    -1' lines)")
    types_ = [int(t) for t in uff.get_set_types()]
    sets: list[dict] = []
    for i, t in enumerate(types_):
        if t != 58:
            sets.append({"type": t})
            continue
        try:
            dset = uff.read_sets(i)
        except Exception as exc:
            raise fail(path, f"dataset {i} (UFF58) is corrupt or truncated ({exc})") from None
        sets.append(dset)
    return sets


def check_dataset(path: Path, i: int, dset: dict) -> tuple[np.ndarray, np.ndarray]:
    """Abscissa and ordinate of dataset ``i``: point count as announced, finite values,
    strictly increasing abscissa."""
    x = np.asarray(dset.get("x"), dtype=float)
    y = np.asarray(dset.get("data"))
    n_expected = int(dset.get("num_pts", y.size))
    where = f"dataset {i}"
    if y.size == 0:
        raise fail(path, f"{where} holds no data values")
    if y.size != n_expected or x.size != y.size:
        what = "truncated" if y.size < n_expected else "inconsistent"
        raise fail(path, f"{where} is {what}: header announces {n_expected} points, "
                          f"{y.size} values read")
    if not np.all(np.isfinite(x)):
        raise fail(path, f"{where} has non-finite abscissa values (NaN or inf)")
    if not np.all(np.isfinite(y)):
        k = int(np.flatnonzero(~np.isfinite(y))[0])
        raise fail(path, f"{where} has {int(np.sum(~np.isfinite(y)))} non-finite data "
                          f"value(s) (NaN or inf), first at point {k} (x={float(x[k])!r})")
    steps = np.diff(x)
    if np.any(steps <= 0):
        k = int(np.flatnonzero(steps <= 0)[0])
        raise fail(path, f"{where}: abscissa is not strictly increasing: x[{k}]={float(x[k])!r}, "
                          f"x[{k + 1}]={float(x[k + 1])!r}")
    return x, y


def frf_from_dataset(path: Path, i: int, dset: dict) -> TransferFunction:
    """The checked FRF (function type 4) of dataset ``i`` as a :class:`TransferFunction`."""
    x, y = check_dataset(path, i, dset)
    if x.size < 2:
        raise fail(path, f"dataset {i} has only {x.size} frequency line(s); need >= 2")
    if x[0] < 0:
        raise fail(path, f"dataset {i}: negative frequency {float(x[0])!r} Hz")
    units = str(dset.get("ordinate_axis_units_lab", "") or "").strip()
    meta = {k: dset[k] for k in KEEP_FIELDS if k in dset}
    meta["source"] = str(path)
    return TransferFunction(
        freqs=x, values=np.asarray(y, dtype=np.complex128),
        name=str(dset.get("id1", "") or "").strip() or path.stem,
        response_node=int(dset.get("rsp_node", 0)),
        response_direction=int(dset.get("rsp_dir", 0)),
        reference_node=int(dset.get("ref_node", 0)),
        reference_direction=int(dset.get("ref_dir", 0)),
        response_quantity=SPEC_TYPES.get(int(dset.get("ordinate_spec_data_type", 0)), "unknown"),
        reference_quantity=SPEC_TYPES.get(int(dset.get("orddenom_spec_data_type", 0)), "unknown"),
        units="" if units.upper() == "NONE" else units, metadata=meta)


def ascii_lossless(tf: TransferFunction) -> bool:
    """Would ASCII UFF58 (values %20.11e, abscissa %13.5e) reproduce ``tf`` exactly?"""
    v = np.concatenate([tf.values.real, tf.values.imag])
    if not np.array_equal(np.array([float(f"{a:20.11e}") for a in v]), v):
        return False
    x = tf.freqs
    x0, dx = float(f"{x[0]:13.5e}"), float(f"{x[1] - x[0]:13.5e}")
    even = x0 + np.arange(x.size) * dx
    return bool(np.array_equal(even, x))


def frf_dataset(tf: TransferFunction, *, binary: bool) -> dict[str, Any]:
    """The pyuff dataset-58 dict of one FRF (function type 4), header fields of ``tf`` kept."""
    meta = dict(tf.metadata)
    dset: dict[str, Any] = {
        "type": 58, "binary": int(bool(binary)), "func_type": FUNC_FRF,
        "id1": tf.name or "NONE",
        "rsp_node": tf.response_node, "rsp_dir": tf.response_direction,
        "ref_node": tf.reference_node, "ref_dir": tf.reference_direction,
        "abscissa_spec_data_type": 18,
        "ordinate_spec_data_type": SPEC_CODES.get(tf.response_quantity, 0),
        "orddenom_spec_data_type": SPEC_CODES.get(tf.reference_quantity, 0),
        "ordinate_axis_units_lab": tf.units or "NONE",
        # binary: store the abscissa explicitly (float64); ASCII: even spacing
        "abscissa_spacing": 0 if binary else 1,
        "x": np.array(tf.freqs), "data": np.array(tf.values),
    }
    for k in KEEP_FIELDS:
        if k in meta and k not in dset:
            dset[k] = meta[k]
    return dset


def time_record_fields(path: Path, i: int, dset: dict) -> dict[str, Any]:
    """The fields of one checked time record (UFF58 function type 1): data, fs, t0, DOFs, ..."""
    x, y = check_dataset(path, i, dset)
    if np.iscomplexobj(y):
        raise fail(path, f"dataset {i} is a time record (function type 1) with complex data")
    if x.size < 2:
        raise fail(path, f"dataset {i} has only {x.size} sample(s)")
    dt = np.diff(x)
    if not np.allclose(dt, dt[0], rtol=1e-6, atol=0):
        raise fail(path, f"dataset {i}: time axis is not evenly spaced "
                         f"(steps {dt.min()!r} .. {dt.max()!r} s)")
    meta = {k: dset[k] for k in KEEP_FIELDS if k in dset}
    meta["source"] = str(path)
    data = np.array(y, dtype=float)
    data.flags.writeable = False
    return dict(
        data=data, fs=1.0 / float(dset.get("abscissa_inc") or dt[0]), t0=float(x[0]),
        name=str(dset.get("id1", "") or "").strip(),
        quantity=SPEC_TYPES.get(int(dset.get("ordinate_spec_data_type", 0)), "unknown"),
        node=int(dset.get("rsp_node", 0)), direction=int(dset.get("rsp_dir", 0)),
        reference_node=int(dset.get("ref_node", 0)),
        reference_direction=int(dset.get("ref_dir", 0)), metadata=meta)
