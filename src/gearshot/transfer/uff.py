"""FRF and time-record file I/O: UFF58 (universal file format, via :mod:`pyuff`) and CSV.

UFF58 is what modal-test systems export. Function type 4 holds an FRF (complex ordinate),
function type 1 a time response (real ordinate). CSV files hold one FRF as three columns
``freq_hz, re, im`` with optional ``# key = value`` metadata lines on top.
"""

from __future__ import annotations

import io
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .._atomic import atomic_path
from .._errors import GearshotError
from .._validation import check_int
from .function import TransferFunction

__all__ = ["UffRecord", "read_frf", "write_frf", "read_uff_records", "FRF_SUFFIXES"]

#: File suffixes read as UFF58 (anything else but ``.csv`` is refused).
UFF_SUFFIXES = (".uff", ".unv", ".uf")
#: Suffixes :func:`read_frf` understands.
FRF_SUFFIXES = (*UFF_SUFFIXES, ".csv")

# UFF "specific data type" codes (Field 1 of records 8-11 of dataset 58).
_SPEC_TYPES = {0: "unknown", 1: "general", 2: "stress", 3: "strain", 5: "temperature",
               6: "heat flux", 8: "displacement", 9: "reaction force", 11: "velocity",
               12: "acceleration", 13: "force", 15: "pressure", 16: "mass", 17: "time",
               18: "frequency", 19: "rpm"}
_SPEC_CODES = {v: k for k, v in _SPEC_TYPES.items()}
_FUNC_FRF, _FUNC_TIME = 4, 1
# Header fields copied verbatim into TransferFunction.metadata (and written back).
_KEEP = ("id2", "id3", "id4", "id5", "rsp_ent_name", "ref_ent_name", "load_case_id",
         "func_id", "ver_num", "ordinate_len_unit_exp", "ordinate_force_unit_exp",
         "ordinate_temp_unit_exp", "orddenom_len_unit_exp", "orddenom_force_unit_exp",
         "orddenom_temp_unit_exp", "abscissa_axis_lab", "abscissa_axis_units_lab",
         "ordinate_axis_lab", "orddenom_axis_lab", "orddenom_axis_units_lab")


@dataclass(frozen=True, eq=False)
class UffRecord:
    """One time record (UFF58 function type 1).

    Attributes
    ----------
    data : numpy.ndarray, shape (n_samples,)
        Samples (real).
    fs : float
        Sampling rate in Hz (1 / abscissa increment).
    t0 : float
        Time of the first sample in s.
    name : str
        UFF ``id1`` (e.g. ``"impact 1 force"``).
    quantity : str
        Physical quantity from the ordinate's specific data type (``"force"``,
        ``"acceleration"``, ...; ``"unknown"`` if not given).
    node, direction, reference_node, reference_direction : int
        Response and reference degrees of freedom.
    metadata : Mapping
        The remaining raw header fields.
    """

    data: np.ndarray
    fs: float
    t0: float = 0.0
    name: str = ""
    quantity: str = "unknown"
    node: int = 0
    direction: int = 0
    reference_node: int = 0
    reference_direction: int = 0
    metadata: Mapping[str, Any] = field(default_factory=dict)

    @property
    def time(self) -> np.ndarray:
        """Sample times in s, shape (n_samples,)."""
        return self.t0 + np.arange(self.data.size) / self.fs


# ---------------------------------------------------------------------------- helpers
def _fail(path: Path, problem: str) -> GearshotError:
    return GearshotError(f"{path}: {problem}")


def _as_path(path: Any) -> Path:
    try:
        return Path(os.fspath(path))
    except TypeError:
        raise GearshotError(f"path must be a str or os.PathLike; got {path!r}") from None


def _check_readable(path: Path) -> None:
    if not path.exists():
        raise _fail(path, "file does not exist")
    if not path.is_file():
        raise _fail(path, "not a regular file")
    if path.stat().st_size == 0:
        raise _fail(path, "file is empty")


def _read_uff_sets(path: Path) -> list[dict]:
    """All datasets of a UFF file as pyuff dicts, with every failure turned into a GearshotError."""
    import pyuff

    _check_readable(path)
    try:
        uff = pyuff.UFF(str(path))
        n_sets = uff.get_n_sets()
    except Exception as exc:  # pyuff raises bare Exception
        raise _fail(path, f"not a readable UFF file ({exc})") from None
    if n_sets == 0:
        with open(path, "rb") as fh:
            head = fh.read(4096).splitlines()
        if head and head[0].strip() == b"-1":
            raise _fail(path, "truncated: a UFF dataset starts but never ends "
                              "(no closing '    -1' line)")
        raise _fail(path, "no UFF dataset found (no block delimited by '    -1' lines)")
    types_ = [int(t) for t in uff.get_set_types()]
    sets: list[dict] = []
    for i, t in enumerate(types_):
        if t != 58:
            sets.append({"type": t})
            continue
        try:
            dset = uff.read_sets(i)
        except Exception as exc:
            raise _fail(path, f"dataset {i} (UFF58) is corrupt or truncated ({exc})") from None
        sets.append(dset)
    return sets


def _check_58(path: Path, i: int, dset: dict) -> tuple[np.ndarray, np.ndarray]:
    x = np.asarray(dset.get("x"), dtype=float)
    y = np.asarray(dset.get("data"))
    n_expected = int(dset.get("num_pts", y.size))
    where = f"dataset {i}"
    if y.size == 0:
        raise _fail(path, f"{where} holds no data values")
    if y.size != n_expected or x.size != y.size:
        what = "truncated" if y.size < n_expected else "inconsistent"
        raise _fail(path, f"{where} is {what}: header announces {n_expected} points, "
                          f"{y.size} values read")
    if not np.all(np.isfinite(x)):
        raise _fail(path, f"{where} has non-finite abscissa values (NaN or inf)")
    if not np.all(np.isfinite(y)):
        k = int(np.flatnonzero(~np.isfinite(y))[0])
        raise _fail(path, f"{where} has {int(np.sum(~np.isfinite(y)))} non-finite data "
                          f"value(s) (NaN or inf), first at point {k} (x={float(x[k])!r})")
    steps = np.diff(x)
    if np.any(steps <= 0):
        k = int(np.flatnonzero(steps <= 0)[0])
        raise _fail(path, f"{where}: abscissa is not strictly increasing: x[{k}]={float(x[k])!r}, "
                          f"x[{k + 1}]={float(x[k + 1])!r}")
    return x, y


def _tf_from_58(path: Path, i: int, dset: dict) -> TransferFunction:
    x, y = _check_58(path, i, dset)
    if x.size < 2:
        raise _fail(path, f"dataset {i} has only {x.size} frequency line(s); need >= 2")
    if x[0] < 0:
        raise _fail(path, f"dataset {i}: negative frequency {float(x[0])!r} Hz")
    units = str(dset.get("ordinate_axis_units_lab", "") or "").strip()
    meta = {k: dset[k] for k in _KEEP if k in dset}
    meta["source"] = str(path)
    return TransferFunction(
        freqs=x, values=np.asarray(y, dtype=np.complex128),
        name=str(dset.get("id1", "") or "").strip() or path.stem,
        response_node=int(dset.get("rsp_node", 0)),
        response_direction=int(dset.get("rsp_dir", 0)),
        reference_node=int(dset.get("ref_node", 0)),
        reference_direction=int(dset.get("ref_dir", 0)),
        response_quantity=_SPEC_TYPES.get(int(dset.get("ordinate_spec_data_type", 0)), "unknown"),
        reference_quantity=_SPEC_TYPES.get(int(dset.get("orddenom_spec_data_type", 0)), "unknown"),
        units="" if units.upper() == "NONE" else units, metadata=meta)


# ---------------------------------------------------------------------------- FRF read
def read_frf(path: str | os.PathLike, *, index: int = 0) -> TransferFunction:
    """Read one FRF from a UFF58 file (function type 4) or a CSV file.

    Parameters
    ----------
    path : str or path-like
        ``.uff``/``.unv``/``.uf`` (UFF58, ASCII or binary 58b) or ``.csv``
        (columns ``freq_hz, re, im``; see :func:`write_frf`).
    index : int
        Which FRF to return when a UFF file holds several (0-based among the type-4 sets).

    Returns
    -------
    TransferFunction

    Raises
    ------
    GearshotError
        Naming the file and the problem: missing or empty file, unknown suffix, a truncated or
        corrupt dataset, no dataset 58 of function type 4, NaN/inf values, a frequency axis that
        is not strictly increasing.

    Examples
    --------
    >>> import pathlib
    >>> import tempfile
    >>> import numpy as np
    >>> from gearshot.transfer import TransferFunction, read_frf, write_frf
    >>> tf = TransferFunction(np.arange(8.0), np.arange(8.0) + 1j, name="small")
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     write_frf(pathlib.Path(folder) / "small.uff", tf)
    ...     back = read_frf(pathlib.Path(folder) / "small.uff")
    >>> back.name, back.n_lines, back == tf
    ('small', 8, True)
    """
    p = _as_path(path)
    index = check_int(index, "index", minimum=0)
    suffix = p.suffix.lower()
    if suffix == ".csv":
        if index != 0:
            raise GearshotError(f"index must be 0 for a CSV file (one FRF per file); got {index}")
        return _read_csv(p)
    if suffix not in UFF_SUFFIXES:
        raise _fail(p, f"unknown FRF file suffix {p.suffix!r}; expected one of {FRF_SUFFIXES}")
    sets = _read_uff_sets(p)
    frfs = [(i, s) for i, s in enumerate(sets)
            if s.get("type") == 58 and int(s.get("func_type", -1)) == _FUNC_FRF]
    if not frfs:
        found = sorted({(s.get("type"), s.get("func_type")) for s in sets}, key=str)
        desc = ", ".join(f"dataset {t}" + (f" function type {ft}" if ft is not None else "")
                         for t, ft in found)
        raise _fail(p, "wrong dataset type: no UFF58 FRF (function type 4) found; "
                       f"file holds {desc}")
    if index >= len(frfs):
        raise _fail(p, f"index={index} but the file holds {len(frfs)} FRF dataset(s)")
    i, dset = frfs[index]
    if not np.iscomplexobj(np.asarray(dset.get("data"))):
        raise _fail(p, f"dataset {i} is function type 4 (FRF) but its ordinate is real "
                       f"(ord_data_type {dset.get('ord_data_type')}); expected complex")
    return _tf_from_58(p, i, dset)


def _is_number_row(line: str) -> bool:
    try:
        [float(v) for v in line.split(",")]
    except ValueError:
        return False
    return True


def _read_csv(path: Path) -> TransferFunction:
    _check_readable(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise _fail(path, f"cannot read as UTF-8 text ({exc})") from None
    meta: dict[str, Any] = {}
    body: list[str] = []
    for line in text.splitlines():
        s = line.strip()
        if not s:
            continue
        if s.startswith("#"):
            key, sep, val = s[1:].partition("=")
            if sep:
                meta[key.strip()] = val.strip()
            continue
        body.append(s)
    if body and not _is_number_row(body[0]):
        body = body[1:]  # column header line, e.g. "freq_hz,re,im"
    if not body:
        raise _fail(path, "no data rows (expected columns freq_hz, re, im)")
    try:
        arr = np.loadtxt(io.StringIO("\n".join(body)), delimiter=",", dtype=float, ndmin=2)
    except ValueError as exc:
        raise _fail(path, f"malformed CSV data ({exc})") from None
    if arr.shape[1] != 3:
        raise _fail(path, f"expected 3 columns (freq_hz, re, im); got {arr.shape[1]}")
    x, y = arr[:, 0], arr[:, 1] + 1j * arr[:, 2]
    _check_58(path, 0, {"x": x, "data": y, "num_pts": x.size})
    if x.size < 2:
        raise _fail(path, f"only {x.size} frequency line(s); need >= 2")
    if x[0] < 0:
        raise _fail(path, f"negative frequency {float(x[0])!r} Hz")

    def _int(key: str) -> int:
        try:
            return int(meta.pop(key, 0))
        except ValueError:
            raise _fail(path, f"metadata {key!r} must be an integer") from None

    kw = dict(response_node=_int("response_node"), response_direction=_int("response_direction"),
              reference_node=_int("reference_node"),
              reference_direction=_int("reference_direction"))
    name = meta.pop("name", "") or path.stem
    return TransferFunction(
        freqs=x, values=y, name=name,
        response_quantity=meta.pop("response_quantity", "acceleration"),
        reference_quantity=meta.pop("reference_quantity", "force"),
        units=meta.pop("units", ""), metadata={**meta, "source": str(path)}, **kw)


# ---------------------------------------------------------------------------- FRF write
def _atomic_write(path: Path, writer) -> None:
    """Write through :func:`gearshot._atomic.atomic_path` (folders created)."""
    with atomic_path(path, make_parents=True) as tmp:
        writer(tmp)


def _ascii_lossless(tf: TransferFunction) -> bool:
    """Would ASCII UFF58 (values %20.11e, abscissa %13.5e) reproduce ``tf`` exactly?"""
    v = np.concatenate([tf.values.real, tf.values.imag])
    if not np.array_equal(np.array([float(f"{a:20.11e}") for a in v]), v):
        return False
    x = tf.freqs
    x0, dx = float(f"{x[0]:13.5e}"), float(f"{x[1] - x[0]:13.5e}")
    even = x0 + np.arange(x.size) * dx
    return bool(np.array_equal(even, x))


def write_frf(path: str | os.PathLike, tf: TransferFunction, *,
              binary: bool | None = None) -> None:
    """Write one FRF as UFF58 (function type 4) or CSV, chosen by the suffix of ``path``.

    Parameters
    ----------
    path : str or path-like
        Destination (``.uff``/``.unv``/``.uf`` or ``.csv``). Written atomically (temporary file
        in the same folder, then renamed), so a failure never leaves a half-written file.
    tf : TransferFunction
        The FRF to write.
    binary : bool or None
        UFF only. ASCII UFF58 stores values with 12 significant digits and an evenly spaced
        abscissa as a start and increment with 6 significant digits; binary 58b stores
        float64. ``None`` (default) writes ASCII when that reproduces ``tf`` exactly (as for
        the measured files) and binary 58b otherwise, so :func:`read_frf` always returns the
        same numbers. CSV is written with 17 significant digits (exact round trip).

    Examples
    --------
    CSV and UFF58 both give the same numbers back:

    >>> import pathlib
    >>> import tempfile
    >>> import numpy as np
    >>> from gearshot.transfer import TransferFunction, read_frf, write_frf
    >>> tf = TransferFunction(np.linspace(0.0, 100.0, 11), np.exp(-1j * np.arange(11) / 3))
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     for name in ("tf.csv", "tf.uff"):
    ...         write_frf(pathlib.Path(folder) / name, tf)
    ...         back = read_frf(pathlib.Path(folder) / name)
    ...         print(name, np.array_equal(back.freqs, tf.freqs),
    ...               np.array_equal(back.values, tf.values))
    tf.csv True True
    tf.uff True True
    """
    p = _as_path(path)
    if not isinstance(tf, TransferFunction):
        raise GearshotError(f"tf must be a TransferFunction; got {type(tf).__name__}")
    suffix = p.suffix.lower()
    if suffix == ".csv":
        _atomic_write(p, lambda tmp: _write_csv(tmp, tf))
        return
    if suffix not in UFF_SUFFIXES:
        raise _fail(p, f"unknown FRF file suffix {p.suffix!r}; expected one of {FRF_SUFFIXES}")
    if binary is None:
        binary = not _ascii_lossless(tf)
    import pyuff

    meta = dict(tf.metadata)
    dset: dict[str, Any] = {
        "type": 58, "binary": int(bool(binary)), "func_type": _FUNC_FRF,
        "id1": tf.name or "NONE",
        "rsp_node": tf.response_node, "rsp_dir": tf.response_direction,
        "ref_node": tf.reference_node, "ref_dir": tf.reference_direction,
        "abscissa_spec_data_type": 18,
        "ordinate_spec_data_type": _SPEC_CODES.get(tf.response_quantity, 0),
        "orddenom_spec_data_type": _SPEC_CODES.get(tf.reference_quantity, 0),
        "ordinate_axis_units_lab": tf.units or "NONE",
        # binary: store the abscissa explicitly (float64); ASCII: even spacing
        "abscissa_spacing": 0 if binary else 1,
        "x": np.array(tf.freqs), "data": np.array(tf.values),
    }
    for k in _KEEP:
        if k in meta and k not in dset:
            dset[k] = meta[k]

    def _write(tmp: Path) -> None:
        try:
            # 'add' into the fresh empty temp file: pyuff's 'overwrite' mode truncates the
            # ASCII header of a binary 58b dataset when it reopens the file for the data.
            pyuff.UFF(str(tmp)).write_sets(dset, mode="add")
        except Exception as exc:
            raise _fail(p, f"pyuff could not write the dataset ({exc})") from None

    _atomic_write(p, _write)


def _write_csv(path: Path, tf: TransferFunction) -> None:
    lines = [f"# name = {tf.name}", f"# response_node = {tf.response_node}",
             f"# response_direction = {tf.response_direction}",
             f"# reference_node = {tf.reference_node}",
             f"# reference_direction = {tf.reference_direction}",
             f"# response_quantity = {tf.response_quantity}",
             f"# reference_quantity = {tf.reference_quantity}", f"# units = {tf.units}"]
    for k, v in tf.metadata.items():
        if k != "source" and "\n" not in str(v) and "=" not in str(k):
            lines.append(f"# {k} = {v}")
    lines.append("freq_hz,re,im")
    body = np.column_stack([tf.freqs, tf.values.real, tf.values.imag])
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("\n".join(lines) + "\n")
        np.savetxt(fh, body, fmt="%.17g", delimiter=",")


# ---------------------------------------------------------------------------- time records
def read_uff_records(path: str | os.PathLike) -> list[UffRecord]:
    """Read every time record (UFF58, function type 1) of a UFF file.

    Parameters
    ----------
    path : str or path-like
        UFF file, e.g. an impact-hammer export holding force and response records.

    Returns
    -------
    list of UffRecord
        In file order; ``quantity`` tells force from response (``"force"``,
        ``"acceleration"``, ...).

    Raises
    ------
    GearshotError
        Naming the file and the problem (as :func:`read_frf`; also when no time record exists
        or a record's abscissa is not evenly spaced).

    Examples
    --------
    A hammer-test export with one force and one acceleration record (written here with
    pyuff, as a measurement system would):

    >>> import pathlib
    >>> import tempfile
    >>> import numpy as np
    >>> import pyuff
    >>> from gearshot.transfer import impact_arrays, read_uff_records
    >>> def record(quantity_code, data):
    ...     return {"type": 58, "func_type": 1, "binary": 0, "rsp_node": 1, "rsp_dir": 3,
    ...             "ref_node": 1, "ref_dir": 3, "abscissa_spacing": 1,
    ...             "abscissa_spec_data_type": 17, "ordinate_spec_data_type": quantity_code,
    ...             "orddenom_spec_data_type": 0,
    ...             "x": np.arange(data.size) / 1000.0, "data": data}
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = pathlib.Path(folder) / "hammer.uff"
    ...     uff = pyuff.UFF(str(path))
    ...     uff.write_sets(record(13, np.r_[1.0, np.zeros(15)]), mode="add")
    ...     uff.write_sets(record(12, np.linspace(0.0, 1.0, 16)), mode="add")
    ...     records = read_uff_records(path)
    >>> [(r.quantity, r.data.size, r.fs) for r in records]
    [('force', 16, 1000.0), ('acceleration', 16, 1000.0)]
    """
    p = _as_path(path)
    if p.suffix.lower() not in UFF_SUFFIXES:
        raise _fail(p, f"unknown UFF file suffix {p.suffix!r}; expected one of {UFF_SUFFIXES}")
    sets = _read_uff_sets(p)
    out: list[UffRecord] = []
    for i, dset in enumerate(sets):
        if dset.get("type") != 58 or int(dset.get("func_type", -1)) != _FUNC_TIME:
            continue
        x, y = _check_58(p, i, dset)
        if np.iscomplexobj(y):
            raise _fail(p, f"dataset {i} is a time record (function type 1) with complex data")
        if x.size < 2:
            raise _fail(p, f"dataset {i} has only {x.size} sample(s)")
        dt = np.diff(x)
        if not np.allclose(dt, dt[0], rtol=1e-6, atol=0):
            raise _fail(p, f"dataset {i}: time axis is not evenly spaced "
                           f"(steps {dt.min()!r} .. {dt.max()!r} s)")
        meta = {k: dset[k] for k in _KEEP if k in dset}
        meta["source"] = str(p)
        data = np.array(y, dtype=float)
        data.flags.writeable = False
        out.append(UffRecord(
            data=data, fs=1.0 / float(dset.get("abscissa_inc") or dt[0]), t0=float(x[0]),
            name=str(dset.get("id1", "") or "").strip(),
            quantity=_SPEC_TYPES.get(int(dset.get("ordinate_spec_data_type", 0)), "unknown"),
            node=int(dset.get("rsp_node", 0)), direction=int(dset.get("rsp_dir", 0)),
            reference_node=int(dset.get("ref_node", 0)),
            reference_direction=int(dset.get("ref_dir", 0)), metadata=meta))
    if not out:
        kinds = sorted({(s.get("type"), s.get("func_type")) for s in sets}, key=str)
        raise _fail(p, f"wrong dataset type: no UFF58 time record (function type 1) found; "
                       f"file holds {kinds}")
    return out
