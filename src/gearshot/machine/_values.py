"""Single values of a machine description, each checked under its key: integers, numbers,
names, sampling rates, sensitivities; and the tables of a parsed machine file."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from fractions import Fraction
from typing import Any

from .._errors import GearshotError
from .._validation import MAX_FS, describe

__all__ = ["DELIMITERS", "int_key", "float_key", "name_key", "unique_names", "rate_key",
           "parse_sensitivity", "check_keys", "table", "tables"]

#: The file's ``delimiter`` words -> the delimiter (``None``: any run of whitespace).
DELIMITERS = {"whitespace": None, "space": None, ",": ",", "comma": ",", ";": ";",
              "semicolon": ";", "tab": "\t", "\t": "\t"}
_PREFIX = {"": 1.0, "m": 1e-3, "u": 1e-6, "µ": 1e-6, "μ": 1e-6, "n": 1e-9, "k": 1e3}


#: Largest integer a machine file may give (teeth, orders, cycles, sidebands): far above
#: any gearbox, far below what would overflow an array size or a float.
MAX_INT_KEY = 100_000


def int_key(value: Any, key: str, *, minimum: int = 1, maximum: int = MAX_INT_KEY) -> int:
    """``value`` as an int in ``minimum … maximum`` (a bool or a float is refused), else an
    error naming ``key``."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise GearshotError(f"{key} must be an integer; got {describe(value)}")
    if value < minimum:
        raise GearshotError(f"{key} must be >= {minimum}; got {value}")
    if value > maximum:
        raise GearshotError(f"{key} must be <= {maximum}; got {describe(value)}")
    return int(value)


def float_key(value: Any, key: str, *, positive: bool = True, allow_zero: bool = False) -> float:
    """``value`` as a finite float (> 0, or >= 0 with ``allow_zero``, unless not
    ``positive``), else an error naming ``key``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise GearshotError(f"{key} must be a number; got {describe(value)}")
    number = float(value)
    if not math.isfinite(number):
        raise GearshotError(f"{key} must be finite; got {number}")
    if positive and (number < 0 or (number == 0 and not allow_zero)):
        raise GearshotError(f"{key} must be {'>= 0' if allow_zero else '> 0'}; got {number}")
    return number


def name_key(value: Any, key: str) -> str:
    """``value`` as a non-empty string, stripped, else an error naming ``key``."""
    if not isinstance(value, str) or not value.strip():
        raise GearshotError(f"{key} must be a non-empty string; got {describe(value)}")
    return value.strip()


def unique_names(values: Sequence[Any], key: str) -> None:
    """Every one of ``values`` a name (``key[]``), none twice (``key``)."""
    for value in values:
        name_key(value, f"{key}[]")
    if len(set(values)) != len(values):
        raise GearshotError(f"{key} must be unique; got {list(values)}")


def rate_key(value: Any, key: str) -> float:
    """A sampling rate: a positive number or an exact fraction written "a/b"."""
    if isinstance(value, str):
        try:
            frac = Fraction(value.replace(" ", ""))
        except (ValueError, ZeroDivisionError):
            raise GearshotError(f"{key} must be a number or a fraction 'a/b' (Hz); got "
                                f"{value!r}") from None
        if frac <= 0:
            raise GearshotError(f"{key} must be > 0 Hz; got {value!r}")
        rate = float(frac) if frac <= MAX_FS else math.inf
    else:
        rate = float_key(value, key)
    if rate > MAX_FS:
        raise GearshotError(f"{key} must be <= {MAX_FS:g} Hz; got {value!r}")
    return rate


def parse_sensitivity(text: Any, *, key: str = "sensitivity") -> tuple[float, str]:
    """Parse a sensor sensitivity such as ``"10 mV/g"``.

    Returns
    -------
    (float, str)
        File units (volts for ``V``) per physical unit, and the physical unit
        (``(0.01, "g")`` for ``"10 mV/g"``).

    Examples
    --------
    >>> parse_sensitivity("10 mV/g")
    (0.01, 'g')
    """
    if not isinstance(text, str):
        raise GearshotError(f"{key} must be a string like '10 mV/g'; got {describe(text)}")
    m = re.fullmatch(r"\s*([0-9.]+(?:[eE][-+]?\d+)?)\s*([munµμk]?)V\s*/\s*(\S+)\s*", text)
    if m is None:
        raise GearshotError(f"{key} must look like '<number> [m|u|n]V/<unit>' (e.g. '10 mV/g'); "
                            f"got {text!r}")
    value = float(m.group(1)) * _PREFIX[m.group(2)]
    if not value > 0:
        raise GearshotError(f"{key} must be > 0; got {text!r}")
    return value, m.group(3)


def check_keys(table: Mapping[str, Any], allowed: set[str], where: str) -> None:
    """Refuse a key of ``table`` outside ``allowed``, naming the table (``where``)."""
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise GearshotError(f"unknown key(s) {unknown} in {where}; allowed: {sorted(allowed)}")


def table(data: Mapping[str, Any], key: str, *, required: bool) -> dict[str, Any] | None:
    """The table ``[key]`` of ``data`` (``None`` when absent and not ``required``)."""
    value = data.get(key)
    if value is None:
        if required:
            raise GearshotError(f"the machine description needs a [{key}] table")
        return None
    if not isinstance(value, Mapping):
        raise GearshotError(f"[{key}] must be a table; got {describe(value)}")
    return dict(value)


def tables(data: Mapping[str, Any], key: str) -> list[Mapping[str, Any]]:
    """The non-empty array of tables ``[[key]]``, each checked to be a table."""
    value = data.get(key)
    if not isinstance(value, list) or not value:
        raise GearshotError(f"the machine needs at least one [[{key}]]; got {describe(value)}")
    for i, item in enumerate(value):
        if not isinstance(item, Mapping):
            raise GearshotError(f"{key}[{i}] must be a table; got {describe(item)}")
    return value
