"""FRF and time-record file I/O: UFF58 (universal file format, via :mod:`pyuff`) and CSV.

UFF58 is what modal-test systems export. Function type 4 holds an FRF (complex ordinate),
function type 1 a time response (real ordinate). CSV files hold one FRF as three columns
``freq_hz, re, im`` with optional ``# key = value`` metadata lines on top.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .._atomic import atomic_path
from .._errors import GearshotError
from .._validation import check_int
from ._frf_csv import read_frf_csv, write_frf_csv
from ._uff58 import (
    FUNC_FRF,
    FUNC_TIME,
    as_path,
    ascii_lossless,
    fail,
    frf_dataset,
    frf_from_dataset,
    read_uff_sets,
    time_record_fields,
)
from .function import TransferFunction

__all__ = ["UffRecord", "read_frf", "write_frf", "read_uff_records", "FRF_SUFFIXES"]

#: File suffixes read as UFF58 (anything else but ``.csv`` is refused).
UFF_SUFFIXES = (".uff", ".unv", ".uf")
#: Suffixes :func:`read_frf` understands.
FRF_SUFFIXES = (*UFF_SUFFIXES, ".csv")


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
    p = as_path(path)
    index = check_int(index, "index", minimum=0)
    suffix = p.suffix.lower()
    if suffix == ".csv":
        if index != 0:
            raise GearshotError(f"index must be 0 for a CSV file (one FRF per file); got {index}")
        return read_frf_csv(p)
    if suffix not in UFF_SUFFIXES:
        raise fail(p, f"unknown FRF file suffix {p.suffix!r}; expected one of {FRF_SUFFIXES}")
    sets = read_uff_sets(p)
    frfs = [(i, s) for i, s in enumerate(sets)
            if s.get("type") == 58 and int(s.get("func_type", -1)) == FUNC_FRF]
    if not frfs:
        found = sorted({(s.get("type"), s.get("func_type")) for s in sets}, key=str)
        desc = ", ".join(f"dataset {t}" + (f" function type {ft}" if ft is not None else "")
                         for t, ft in found)
        raise fail(p, "wrong dataset type: no UFF58 FRF (function type 4) found; "
                       f"file holds {desc}")
    if index >= len(frfs):
        raise fail(p, f"index={index} but the file holds {len(frfs)} FRF dataset(s)")
    i, dset = frfs[index]
    if not np.iscomplexobj(np.asarray(dset.get("data"))):
        raise fail(p, f"dataset {i} is function type 4 (FRF) but its ordinate is real "
                       f"(ord_data_type {dset.get('ord_data_type')}); expected complex")
    return frf_from_dataset(p, i, dset)


# ---------------------------------------------------------------------------- FRF write
def _atomic_write(path: Path, writer) -> None:
    """Write through :func:`gearshot._atomic.atomic_path` (folders created)."""
    with atomic_path(path, make_parents=True) as tmp:
        writer(tmp)


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
    p = as_path(path)
    if not isinstance(tf, TransferFunction):
        raise GearshotError(f"tf must be a TransferFunction; got {type(tf).__name__}")
    suffix = p.suffix.lower()
    if suffix == ".csv":
        _atomic_write(p, lambda tmp: write_frf_csv(tmp, tf))
        return
    if suffix not in UFF_SUFFIXES:
        raise fail(p, f"unknown FRF file suffix {p.suffix!r}; expected one of {FRF_SUFFIXES}")
    if binary is None:
        binary = not ascii_lossless(tf)
    import pyuff

    dset = frf_dataset(tf, binary=binary)

    def _write(tmp: Path) -> None:
        try:
            # 'add' into the fresh empty temp file: pyuff's 'overwrite' mode truncates the
            # ASCII header of a binary 58b dataset when it reopens the file for the data.
            pyuff.UFF(str(tmp)).write_sets(dset, mode="add")
        except Exception as exc:
            raise fail(p, f"pyuff could not write the dataset ({exc})") from None

    _atomic_write(p, _write)


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
    p = as_path(path)
    if p.suffix.lower() not in UFF_SUFFIXES:
        raise fail(p, f"unknown UFF file suffix {p.suffix!r}; expected one of {UFF_SUFFIXES}")
    sets = read_uff_sets(p)
    out: list[UffRecord] = []
    for i, dset in enumerate(sets):
        if dset.get("type") != 58 or int(dset.get("func_type", -1)) != FUNC_TIME:
            continue
        out.append(UffRecord(**time_record_fields(p, i, dset)))
    if not out:
        kinds = sorted({(s.get("type"), s.get("func_type")) for s in sets}, key=str)
        raise fail(p, f"wrong dataset type: no UFF58 time record (function type 1) found; "
                       f"file holds {kinds}")
    return out
