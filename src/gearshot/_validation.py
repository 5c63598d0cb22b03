"""Shared input validators. Every message names the parameter and quotes the value."""

from __future__ import annotations

import functools
import math
import numbers
from collections.abc import Callable
from typing import Any, TypeVar

import numpy as np

from ._errors import GearshotError

__all__ = [
    "as_signal_array",
    "check_finite",
    "check_positive",
    "check_int",
    "check_in_range",
    "check_increasing",
    "describe",
    "finite_result",
    "MAX_ABS",
    "MAX_POINTS",
    "SPEED_RANGE",
    "MAX_LOAD",
    "MAX_FS",
    "check_speed",
    "check_load",
    "MIN_LOAD",
    "ATTENUATION_DB_RANGE",
    "check_attenuation",
    "check_fs",
]

#: Largest magnitude accepted in a signal: its square, sums of squares over millions of
#: samples and FFTs stay far from float64 overflow (1.8e308). Physical data never come near.
MAX_ABS = 1e100
#: Largest length/size argument (points per cycle, FFT length, ...): 16 Mi points.
MAX_POINTS = 1 << 24

#: Physical bounds, checked wherever a speed, load or sampling rate enters: shaft speeds in
#: rev/s (0.5 rps = 30 rpm up to 60 000 rpm), load torques in N m (1 mN m, a watch's
#: gear train, up to 100 kN m), sampling rates in Hz.
SPEED_RANGE = (0.5, 1000.0)
MIN_LOAD = 1e-3
MAX_LOAD = 1e5
MAX_FS = 1e8
#: Path attenuation in dB, wherever one enters (commands, virtual rig, simulated
#: experiment): a loss from 0 dB (none) to 200 dB (a factor 1e-10 in amplitude).
ATTENUATION_DB_RANGE = (0.0, 200.0)

_F = TypeVar("_F", bound=Callable[..., Any])


def describe(value: Any) -> str:
    """Short, readable rendering of a (possibly large) value for error messages."""
    if isinstance(value, np.ndarray):
        if value.size <= 6:
            text = np.array2string(value, precision=4, separator=", ")
            return f"array({text}, shape={value.shape})"
        return f"array(shape={value.shape}, dtype={value.dtype})"
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def check_finite(x: np.ndarray, name: str) -> np.ndarray:
    """Raise if ``x`` holds NaN or inf."""
    if not np.all(np.isfinite(x)):
        bad = np.flatnonzero(~np.isfinite(np.asarray(x).ravel()))
        first = np.asarray(x).ravel()[bad[0]]
        raise GearshotError(
            f"{name} must be finite; it holds {bad.size} non-finite value(s), "
            f"first {first!r} at flat index {bad[0]}"
        )
    return x


def as_signal_array(
    x: Any,
    name: str,
    *,
    min_ndim: int = 1,
    max_ndim: int | None = None,
    min_length: int = 1,
    allow_complex: bool = False,
    max_abs: float | None = MAX_ABS,
) -> np.ndarray:
    """Convert ``x`` to a finite float (or complex) array with signals along the last axis.

    Parameters
    ----------
    x : array_like
        Input.
    name : str
        Parameter name used in error messages.
    min_ndim, max_ndim : int
        Accepted number of dimensions.
    min_length : int
        Minimum length of the last axis.
    allow_complex : bool
        Keep complex input complex; otherwise complex input is an error.
    max_abs : float or None
        Largest accepted magnitude (default :data:`MAX_ABS`, which keeps squares and sums
        far from overflow); ``None`` for containers that only store values.
    """
    try:
        arr = np.asarray(x)
    except Exception as exc:  # ragged lists etc.
        raise GearshotError(f"{name} must be array-like; got {describe(x)} ({exc})") from None
    if arr.dtype == object or not (
        np.issubdtype(arr.dtype, np.number) or np.issubdtype(arr.dtype, np.bool_)
    ):
        raise GearshotError(f"{name} must be numeric; got dtype {arr.dtype}")
    if np.iscomplexobj(arr):
        if not allow_complex:
            raise GearshotError(f"{name} must be real; got complex dtype {arr.dtype}")
        arr = arr.astype(np.complex128, copy=False)
    else:
        arr = arr.astype(np.float64, copy=False)
    if arr.ndim < min_ndim or (max_ndim is not None and arr.ndim > max_ndim):
        want = f"{min_ndim}" if max_ndim == min_ndim else (
            f"at least {min_ndim}" if max_ndim is None else f"{min_ndim} to {max_ndim}")
        raise GearshotError(f"{name} must have {want} dimension(s); got ndim={arr.ndim} "
                            f"(shape {arr.shape})")
    if arr.size == 0:
        raise GearshotError(f"{name} must not be empty; got shape {arr.shape}")
    if arr.ndim >= 1 and arr.shape[-1] < min_length:
        raise GearshotError(
            f"{name} must have at least {min_length} samples along its last axis; "
            f"got {arr.shape[-1]}")
    if np.iscomplexobj(arr):
        check_finite(arr, name)
        peak = float(np.max(np.abs(arr)))
    else:  # two reductions without temporaries: NaN and inf show in the min or the max
        lo, hi = float(arr.min()), float(arr.max())
        if not (math.isfinite(lo) and math.isfinite(hi)):
            check_finite(arr, name)
        peak = max(-lo, hi)
    if max_abs is not None and peak > max_abs:
        raise GearshotError(f"{name} holds a value of magnitude {peak:.3g}; values up to "
                            f"{max_abs:g} are accepted (rescale the units)")
    return arr


def _all_finite(out: Any) -> bool:
    if isinstance(out, tuple):
        return all(_all_finite(o) for o in out)
    if isinstance(out, (np.ndarray, np.generic, float, complex)):
        arr = np.asarray(out)
        return not np.issubdtype(arr.dtype, np.inexact) or bool(np.all(np.isfinite(arr)))
    return True


def finite_result(func: _F) -> _F:
    """Decorator: run ``func`` without floating-point warnings and refuse a non-finite result.

    Inputs are finite and bounded by :data:`MAX_ABS`, so a NaN or inf in the result means an
    overflow (e.g. an 8th moment of large values) or a degenerate input (a constant signal
    where a ratio needs a spread); either is a :class:`GearshotError`, never a silent NaN.
    """
    @functools.wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with np.errstate(all="ignore"):
            out = func(*args, **kwargs)
        if not _all_finite(out):
            raise GearshotError(
                f"{func.__name__} gives non-finite values for this input: an overflow "
                f"(rescale the input to smaller values) or a degenerate input (e.g. a "
                f"constant signal, whose moment ratios are 0/0)")
        return out
    return wrapper  # type: ignore[return-value]


def check_int(value: Any, name: str, *, minimum: int | None = None,
              maximum: int | None = None) -> int:
    """Validate an integer parameter (bools are rejected)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        if isinstance(value, numbers.Real) and float(value).is_integer():
            value = int(float(value))
        else:
            raise GearshotError(f"{name} must be an integer; got {describe(value)}")
    value = int(value)
    if minimum is not None and value < minimum:
        raise GearshotError(f"{name} must be >= {minimum}; got {value}")
    if maximum is not None and value > maximum:
        raise GearshotError(f"{name} must be <= {maximum}; got {value}")
    return value


def check_positive(value: Any, name: str, *, allow_zero: bool = False) -> float:
    """Validate a finite positive real scalar."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise GearshotError(f"{name} must be a real number; got {describe(value)}")
    value = float(value)
    if not np.isfinite(value):
        raise GearshotError(f"{name} must be finite; got {value}")
    if value < 0 or (value == 0 and not allow_zero):
        raise GearshotError(f"{name} must be {'>= 0' if allow_zero else '> 0'}; got {value}")
    return value


def check_in_range(value: Any, name: str, low: float, high: float, *,
                   low_inclusive: bool = True, high_inclusive: bool = True) -> float:
    """Validate a finite real scalar inside an interval."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise GearshotError(f"{name} must be a real number; got {describe(value)}")
    value = float(value)
    ok_low = value >= low if low_inclusive else value > low
    ok_high = value <= high if high_inclusive else value < high
    if not (np.isfinite(value) and ok_low and ok_high):
        lb = "[" if low_inclusive else "("
        hb = "]" if high_inclusive else ")"
        raise GearshotError(f"{name} must lie in {lb}{low}, {high}{hb}; got {value}")
    return value


def check_increasing(x: np.ndarray, name: str, *, unit: str = "") -> np.ndarray:
    """Raise unless the 1-D array ``x`` is strictly increasing; names the first offender."""
    steps = np.diff(x)
    if np.any(steps <= 0):
        i = int(np.flatnonzero(steps <= 0)[0])
        raise GearshotError(
            f"{name} must be strictly increasing; {name}[{i + 1}]={float(x[i + 1])!r}{unit} "
            f"does not follow {name}[{i}]={float(x[i])!r}{unit}")
    return x


def check_speed(value: Any, name: str = "speed") -> float:
    """A shaft speed in rev/s within :data:`SPEED_RANGE`."""
    value = check_positive(value, name)
    lo, hi = SPEED_RANGE
    if not lo <= value <= hi:
        raise GearshotError(f"{name} must lie in [{lo:g}, {hi:g}] rev/s; got {value:g}")
    return value


def check_load(value: Any, name: str = "load") -> float:
    """A load torque in N m in [:data:`MIN_LOAD`, :data:`MAX_LOAD`]."""
    load: float = check_positive(value, name)
    if not MIN_LOAD <= load <= MAX_LOAD:
        raise GearshotError(f"{name} must lie in [{MIN_LOAD:g}, {MAX_LOAD:g}] N m; got "
                            f"{load:g}")
    return load


def check_attenuation(value: Any, name: str = "attenuation_db") -> float:
    """A path attenuation in dB within :data:`ATTENUATION_DB_RANGE` (every command and API
    function applies these bounds through this check)."""
    lo, hi = ATTENUATION_DB_RANGE
    return check_in_range(value, name, lo, hi)


def check_fs(value: Any, name: str = "fs") -> float:
    """A sampling rate (or a frequency) in Hz in (0, :data:`MAX_FS`]."""
    rate: float = check_positive(value, name)
    if rate > MAX_FS:
        raise GearshotError(f"{name} must lie in (0, {MAX_FS:g}] Hz; got {rate:g}")
    return rate
