"""Delimited text recordings as labs hand them out: plain, zipped or gzipped; whitespace-,
comma-, semicolon- or tab-separated; with or without a header row.

The reader never guesses silently: a file whose first row is numeric has no header, and its
columns have no names, so :func:`select_channels` can not pick an acceleration or a tacho
by default -- the caller (or the machine description) must name the columns. A non-numeric
first row is a header of channel names.
"""

from __future__ import annotations

import gzip
import io
import re
import zipfile
from collections.abc import Sequence
from pathlib import Path
from types import EllipsisType

import numpy as np

from .._errors import GearshotError
from ._fileio import TIME_NAMES, RawFile, read_sidecar, time_column_fs

__all__ = ["read_text", "TEXT_SUFFIXES", "read_text_bytes"]

#: Suffixes read as delimited text (``.zip``/``.gz`` hold one such file).
TEXT_SUFFIXES = (".txt", ".dat", ".asc", ".tsv", ".zip", ".gz")

_NUMBER = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^[-+]?(nan|inf)$", re.I)


def read_text_bytes(path: Path) -> bytes:
    """The raw bytes of a text recording, unpacking ``.zip`` (one member) and ``.gz``."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".zip":
        try:
            with zipfile.ZipFile(path) as zf:
                members = [i for i in zf.infolist() if not i.is_dir()
                           and not i.filename.startswith("__MACOSX")]
                if len(members) != 1:
                    raise GearshotError(f"{str(path)!r}: a zipped recording must hold exactly one "
                                        f"file; it holds {[m.filename for m in members]}")
                return zf.read(members[0])
        except zipfile.BadZipFile as exc:
            raise GearshotError(f"{str(path)!r} is not a readable zip file: {exc}") from None
    if suffix == ".gz":
        try:
            with gzip.open(path, "rb") as fh:
                return fh.read()
        except OSError as exc:
            raise GearshotError(f"{str(path)!r} is not a readable gzip file: {exc}") from None
    return path.read_bytes()


def _first_rows(text: str, skip_rows: int, n: int = 3) -> list[str]:
    rows = []
    for line in io.StringIO(text):
        if skip_rows > 0:
            skip_rows -= 1
            continue
        if line.strip() and not line.lstrip().startswith("#"):
            rows.append(line.strip())
            if len(rows) == n:
                break
    return rows


def _sniff_delimiter(row: str) -> str | None:
    for cand in (",", ";", "\t"):
        if cand in row:
            return cand
    return None


def _split(row: str, delimiter: str | None) -> list[str]:
    return [c.strip() for c in (row.split() if delimiter is None else row.split(delimiter))]


def _plain_numbers(text: str, skip_rows: int) -> np.ndarray | None:
    """A header-less, whitespace-delimited table of numbers through numpy's C reader (no
    pandas import on the common path: the PHM09 zips, most lab exports); None when numpy
    cannot read it, and pandas then reads it and names the problem."""
    try:
        data = np.loadtxt(io.StringIO(text), comments="#", skiprows=skip_rows, ndmin=2,
                          dtype=np.float64)
    except ValueError:
        return None
    return data if data.size else None


def _read_with_pandas(path, text, delimiter, header, skip_rows):
    """(number of columns, names, float64 columns) read by pandas."""
    import pandas as pd

    sep = r"\s+" if delimiter is None else delimiter
    try:
        frame = pd.read_csv(io.StringIO(text), sep=sep, header=0 if header else None,
                            skiprows=skip_rows, comment="#", engine="c",
                            skipinitialspace=True)
    except (pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
        raise GearshotError(f"{str(path)!r} is not a readable delimited text file: "
                            f"{exc}") from None
    names = [str(c).strip() for c in frame.columns] if header else \
        [str(i) for i in range(frame.shape[1])]
    cols = []
    for i in range(frame.shape[1]):
        col = frame.iloc[:, i]
        if col.dtype.kind not in "fiu":
            col = pd.to_numeric(col, errors="coerce")
        cols.append(col.to_numpy(dtype=np.float64))
    return frame.shape[1], names, cols


def read_text(path: Path, *, delimiter: str | None | EllipsisType = ..., header: bool | None = None,
              columns: Sequence[str] | None = None, skip_rows: int = 0) -> RawFile:
    """Read a delimited text recording into named channels.

    Parameters
    ----------
    path : Path
        ``.txt``/``.dat``/``.asc``/``.tsv``/``.csv``, or a ``.zip``/``.gz`` holding one.
    delimiter : str or None, optional
        ``None``: runs of whitespace; ``","``, ``";"``, ``"\\t"``. Default: sniffed from the
        first data row (a comma, semicolon or tab if present, else whitespace).
    header : bool, optional
        Whether the first row names the columns. Default: a non-numeric first row is a
        header, a numeric one is data.
    columns : sequence of str, optional
        Names of the columns (required in effect for a header-less file: its columns are
        otherwise called ``"0"``, ``"1"``, ... and no channel is picked by default).
    skip_rows : int
        Lines to skip before the first (header or data) row.

    Returns
    -------
    RawFile
        Channels by name; ``fs`` from a sidecar ``<file>.json`` or a uniform time column
        if any; ``positional_defaults`` is False for header-less files.
    """
    path = Path(path)
    data = read_text_bytes(path)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        text = data.decode("latin-1")
    rows = _first_rows(text, skip_rows)
    if not rows:
        raise GearshotError(f"{str(path)!r} holds no data rows")
    if delimiter is ...:
        delimiter = _sniff_delimiter(rows[-1])
    first = _split(rows[0], delimiter)
    numeric_first = all(_NUMBER.match(c) for c in first if c != "")
    if header is None:
        header = not numeric_first
    elif header and numeric_first:
        raise GearshotError(f"{str(path)!r}: header=True but the first row {rows[0][:60]!r} is "
                            f"numeric (no header row?)")
    n_cols = len(_split(rows[1] if len(rows) > 1 else rows[0], delimiter))
    table = None
    if not header and delimiter is None:
        table = _plain_numbers(text, skip_rows)
    if table is not None:
        n_read, cols = table.shape[1], [table[:, i] for i in range(table.shape[1])]
        names = [str(i) for i in range(n_read)]
    else:
        n_read, names, cols = _read_with_pandas(path, text, delimiter, header, skip_rows)
    if n_read != n_cols and not header:
        raise GearshotError(f"{str(path)!r}: rows have {n_cols} values but {n_read} "
                            f"columns were read (ragged file?)")
    return _raw_file(path, names, cols, columns, header=bool(header))


def _raw_file(path: Path, names: list[str], cols: list[np.ndarray],
              columns: Sequence[str] | None, *, header: bool) -> RawFile:
    """The channels read, renamed by ``columns``, checked for missing values, with the
    sampling rate of a sidecar or a time column."""
    n_read = len(cols)
    if columns is not None:
        columns = [str(c) for c in columns]
        if len(columns) != n_read:
            raise GearshotError(f"{str(path)!r} has {n_read} column(s) but columns="
                                f"{columns!r} names {len(columns)}")
        names = columns
    chans: dict[str, np.ndarray] = {}
    for name, arr in zip(names, cols):
        if np.isnan(arr).any():
            bad = int(np.flatnonzero(np.isnan(arr))[0])
            raise GearshotError(f"{str(path)!r}: column {name!r} has a missing or non-numeric "
                                f"value in data row {bad} (truncated or damaged file?)")
        chans[name] = arr
    side = read_sidecar(path)
    fs = side.get("fs")
    time_name = None
    for name in names:
        if name.lower() in TIME_NAMES:
            time_name = name
            if fs is None:
                fs = time_column_fs(path, chans[name])
            break
    return RawFile(path, chans, fs, dict(side.get("metadata", {})),
                   positional_defaults=header and columns is None,
                   time_channel=time_name)
