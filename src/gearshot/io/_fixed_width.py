"""Fast, exact reading of fixed-width tables of decimal numbers (the PHM 2009 text files,
many lab exports): every row the same length, every column at the same place.

The bytes are viewed as a 2-D array of characters (one row per line) and each column's
digits are turned into numbers with integer arithmetic, without tokenizing. A value is
built as ``mantissa / 10**k`` (or ``mantissa * 10**k``) from an exact integer mantissa of
at most 15 digits and an exact power of ten (``k <= 22``): one correctly rounded
operation, so the result is the float the C library's ``strtod`` returns (Clinger's fast
path). Anything else -- ragged rows, a column whose decimal point or exponent moves, more
digits, ``nan``, comments -- returns None, and the caller's general reader takes over.
"""

from __future__ import annotations

import numpy as np

__all__ = ["read_fixed_width"]

_SPACE, _NL, _CR = 32, 10, 13
_DIGIT0 = 48
_MAX_DIGITS = 15          # an integer below 2**53 holds any 15-digit mantissa exactly
_MAX_POW10 = 22           # 10.0**k is exact for k <= 22
_POW10 = np.array([float(10 ** i) for i in range(_MAX_POW10 + 1)])  # exact, from integers


def _rows(data: bytes) -> np.ndarray | None:
    """The file as an (n_rows, row_length) uint8 array, line ends removed; None unless
    every line has the same length."""
    first = data.find(b"\n")
    if first <= 0 or b"#" in data:
        return None
    width = first + 1
    if len(data) % width:
        if (len(data) + 1) % width:  # the last line may lack its line end
            return None
        data = data + b"\n"
    u = np.frombuffer(data, dtype=np.uint8).reshape(-1, width)
    end = 1
    if width > 1 and u[0, -2] == _CR:
        end = 2
        if not np.all(u[:, -2] == _CR):
            return None
    if not np.all(u[:, -1] == _NL):
        return None
    return u[:, :-end]


def _fields(u: np.ndarray) -> list[tuple[int, int]]:
    """(start, stop) of each column: maximal runs of character positions that are not a
    space in every row."""
    blank = np.all(u == _SPACE, axis=0)
    edges = np.flatnonzero(np.diff(np.concatenate(([1], blank.astype(np.int8), [1]))))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2])]


def _digits(cols: np.ndarray) -> np.ndarray | None:
    """The integer value of a block of digit characters (n_rows, n_digits) as float64
    (exact: at most 15 digits); None if any is not a digit."""
    if cols.size and (cols.min() < _DIGIT0 or cols.max() > _DIGIT0 + 9):
        return None
    value = np.zeros(cols.shape[0])
    for j in range(cols.shape[1]):
        value *= 10.0
        value += cols[:, j]
        value -= _DIGIT0
    return value


def _sign(col: np.ndarray) -> np.ndarray | None:
    """+1/-1 from a sign position holding ' ', '+' or '-' (None otherwise)."""
    if not np.all((col == _SPACE) | (col == ord("+")) | (col == ord("-"))):
        return None
    return np.where(col == ord("-"), -1.0, 1.0)


def _parse_field(f: np.ndarray) -> np.ndarray | None:
    """One column, ``[ |+|-]digits[.digits][(e|E)(+|-)digits]`` at fixed places in every
    row, as exact floats; None for any other layout."""
    sign = np.ones(f.shape[0])
    if not (_DIGIT0 <= f[0, 0] <= _DIGIT0 + 9):
        sign_or_none = _sign(f[:, 0])
        if sign_or_none is None:
            return None
        sign, f = sign_or_none, f[:, 1:]
    row = f[0]
    exp_at = np.flatnonzero((row == ord("e")) | (row == ord("E")))
    body, exponent = f, np.zeros(f.shape[0])
    if exp_at.size:
        e = int(exp_at[0])
        if not np.all((f[:, e] == ord("e")) | (f[:, e] == ord("E"))) or e + 2 > f.shape[1]:
            return None
        esign = _sign(f[:, e + 1])
        mag = _digits(f[:, e + 2:])
        if esign is None or mag is None or f.shape[1] - e - 2 > 4:
            return None
        body, exponent = f[:, :e], esign * mag
    dot_at = np.flatnonzero(body[0] == ord("."))
    n_frac = 0
    if dot_at.size:
        p = int(dot_at[0])
        if not np.all(body[:, p] == ord(".")):
            return None
        n_frac = body.shape[1] - p - 1
        body = np.concatenate((body[:, :p], body[:, p + 1:]), axis=1)
    if not 0 < body.shape[1] <= _MAX_DIGITS:
        return None
    mantissa = _digits(body)
    if mantissa is None:
        return None
    k = (n_frac - exponent).astype(np.int64)   # value = mantissa * 10**-k
    if k.min() < -_MAX_POW10 or k.max() > _MAX_POW10:
        return None
    grow = k < 0
    scale = _POW10[np.abs(k)]
    if np.any(grow) and np.any(mantissa[grow] * scale[grow] >= 2.0 ** 53):
        return None                            # the product would round twice
    value = np.where(grow, mantissa * scale, mantissa / scale)
    return sign * value


def read_fixed_width(data: bytes) -> np.ndarray | None:
    """The table of a fixed-width file of decimal numbers, shape (n_rows, n_columns), or
    None when the file is not such a table (the caller then reads it another way).

    Parameters
    ----------
    data : bytes
        The whole file (ASCII; ``\\n`` or ``\\r\\n`` line ends, no header, no comments).

    Returns
    -------
    ndarray or None
        Float64 values, bit-identical to what ``float()`` gives for each field.

    Examples
    --------
    >>> read_fixed_width(b"  1.5e+000 -2.0e-001\\n  3.0e+000  4.25e-01\\n") is None
    True
    >>> read_fixed_width(b" 1.50e+000 -2.00e-001\\n 3.00e+000  4.25e-001\\n").tolist()
    [[1.5, -0.2], [3.0, 0.425]]
    """
    u = _rows(data)
    if u is None or u.shape[0] == 0:
        return None
    fields = _fields(u)
    if not fields:
        return None
    out = np.empty((len(fields), u.shape[0]))  # columns contiguous
    for i, (a, b) in enumerate(fields):
        col = _parse_field(u[:, a:b])
        if col is None:
            return None
        out[i] = col
    return out.T
