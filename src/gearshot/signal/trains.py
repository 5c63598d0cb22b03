"""Order tracking through gear trains, and the anti-alias low-pass of angular resampling.

A tacho on one shaft gives the angle of every other shaft of a gear train through an exact
speed ratio -- a fraction of tooth counts (e.g. one idler revolution = 3 input revolutions
for 32 -> 96 teeth; one output revolution = 5 input revolutions for 32 -> 96, 48 -> 80).
:func:`shaft_cycle_times` turns tacho pulses into the times at which the target shaft
completes whole revolutions, computing the tacho angle of cycle ``m`` as the exact
``m * p / q`` before it becomes a float, so no ratio rounding accumulates over a record.

Angular resampling reads a time signal at the instants of equal angle steps. Content above
the *angular* Nyquist (half the samples per revolution, in shaft orders) folds back onto
lower orders unless it is removed first: :func:`antialias_filter` low-passes (and
optionally up-samples) the time signal below the angular Nyquist at the lowest speed of the
record, with an exactly flat pass band.
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import cast

import numpy as np
import scipy.fft
from numpy.typing import ArrayLike

from .._errors import GearshotError
from .._typing import ComplexArray, FloatArray
from .._validation import (
    MAX_POINTS,
    as_signal_array,
    check_in_range,
    check_int,
    check_positive,
    finite_result,
)
from .angular import angle_to_time

__all__ = ["shaft_cycle_times", "as_ratio", "antialias_filter", "bandlimited_resynthesis",
           "min_shaft_rate"]


#: What :func:`as_ratio` takes.
RatioLike = Fraction | int | str | tuple[int, int] | float | np.integer | np.floating


def as_ratio(value: RatioLike, name: str = "revs_per_cycle") -> Fraction:
    """An exact positive ratio from a Fraction, an int, a ``"p/q"`` string or a (p, q) pair.

    Floats are accepted only when they are exact small fractions (e.g. 2.5); pass tooth
    counts as a fraction to stay exact.

    Examples
    --------
    >>> from gearshot.signal.trains import as_ratio
    >>> print(as_ratio("96/32"), as_ratio((38, 17)), as_ratio(2.5))
    3 38/17 5/2
    """
    try:
        if isinstance(value, bool):
            raise TypeError
        if isinstance(value, tuple) and len(value) == 2:
            frac = Fraction(int(value[0]), int(value[1]))
        elif isinstance(value, (Fraction, int, np.integer, str)):
            frac = Fraction(value) if not isinstance(value, np.integer) else Fraction(int(value))
        elif isinstance(value, (float, np.floating)):
            frac = Fraction(float(value)).limit_denominator(10_000)
            if abs(float(frac) - float(value)) > 1e-12 * abs(float(value)):
                raise TypeError
        else:
            raise TypeError
    except (TypeError, ValueError, ZeroDivisionError):
        raise GearshotError(f"{name} must be an exact ratio (Fraction, int, 'p/q' or (p, q)); "
                            f"got {value!r}") from None
    if frac <= 0:
        raise GearshotError(f"{name} must be > 0; got {value!r}")
    return frac


@finite_result
def shaft_cycle_times(pulse_times: ArrayLike, *, revs_per_cycle: RatioLike,
                      pulses_per_rev: int = 1) -> FloatArray:
    """Times (s) at which a shaft completes whole revolutions, from a tacho on another shaft.

    Parameters
    ----------
    pulse_times : array_like, shape (n_pulses,)
        Tacho pulse times in s, increasing, ``pulses_per_rev`` per tacho-shaft revolution.
    revs_per_cycle : Fraction, int, str or (int, int)
        Tacho-shaft revolutions per revolution of the target shaft, exact (e.g.
        ``Fraction(96, 32)`` for an idler driven 32 -> 96 from a tacho on the input).
    pulses_per_rev : int, default 1
        Tacho pulses per tacho-shaft revolution.

    Returns
    -------
    ndarray, shape (n_cycles + 1,)
        Start of target revolution 0 (at the first pulse), 1, ..., up to the last
        revolution that ends by the last pulse.

    Examples
    --------
    An idler turning once per three revolutions of a tacho shaft pulsing every 0.1 s:

    >>> import numpy as np
    >>> from gearshot.signal import shaft_cycle_times
    >>> print(np.round(shaft_cycle_times(np.arange(10) * 0.1, revs_per_cycle="3"), 6) + 0.0)
    [0.  0.3 0.6 0.9]
    """
    pulses = as_signal_array(pulse_times, "pulse_times", max_ndim=1)
    ratio = as_ratio(revs_per_cycle)
    ppr = check_int(pulses_per_rev, "pulses_per_rev", minimum=1, maximum=MAX_POINTS)
    if pulses.size < 2:
        raise GearshotError(f"pulse_times must hold at least 2 pulses; got {pulses.size}")
    if np.any(np.diff(pulses) <= 0):
        raise GearshotError("pulse_times must be strictly increasing")
    # cycle m ends at tacho pulse index m * p * ppr / q: count whole cycles exactly
    p, q = ratio.numerator, ratio.denominator
    n_cycles = ((pulses.size - 1) * q) // (p * ppr)
    if n_cycles > MAX_POINTS:
        raise GearshotError(f"revs_per_cycle={ratio} gives {n_cycles} cycles from "
                            f"{pulses.size} pulses, more than {MAX_POINTS}")
    m = np.arange(n_cycles + 1, dtype=np.int64)
    targets = (m * p) / q  # exact integers times p, one rounding in the division
    return angle_to_time(pulses, targets, pulses_per_rev=ppr)


def min_shaft_rate(pulse_times: ArrayLike, *, pulses_per_rev: int = 1,
                   revs_per_cycle: RatioLike = 1) -> float:
    """Lowest speed (revolutions/s of the target shaft) between consecutive tacho pulses.

    Examples
    --------
    The longest pulse interval is 0.15 s:

    >>> from gearshot.signal.trains import min_shaft_rate
    >>> pulses = [0.0, 0.1, 0.2, 0.35, 0.45]
    >>> print(round(min_shaft_rate(pulses), 4), round(min_shaft_rate(pulses, revs_per_cycle=3), 4))
    6.6667 2.2222
    """
    pulses = as_signal_array(pulse_times, "pulse_times", max_ndim=1)
    ppr = check_int(pulses_per_rev, "pulses_per_rev", minimum=1, maximum=MAX_POINTS)
    ratio = as_ratio(revs_per_cycle)
    if pulses.size < 2:
        raise GearshotError(f"pulse_times must hold at least 2 pulses; got {pulses.size}")
    gaps = np.diff(pulses)
    if ppr > 1 and gaps.size >= ppr:  # whole revolutions: insensitive to uneven tacho marks
        gaps = (pulses[ppr:] - pulses[:-ppr]) / ppr
    return float(1.0 / (ppr * gaps.max()) / float(ratio))


def _lowpass_spectrum(x: FloatArray, fs: float, cutoff: float,
                      passband: float) -> tuple[ComplexArray, int, int]:
    """Padded, low-passed one-sided spectrum: (spectrum, n_fft, pad)."""
    n = x.shape[-1]
    f1 = passband * cutoff
    width = max(cutoff - f1, fs / n)
    pad = min(n - 1, int(math.ceil(6.0 * fs / width)))
    widths = [(0, 0)] * (x.ndim - 1) + [(pad, pad)]
    xp = np.pad(x, widths, mode="reflect", reflect_type="odd")
    n_fft = scipy.fft.next_fast_len(xp.shape[-1], real=True)
    spec: ComplexArray = scipy.fft.rfft(xp, n=n_fft, axis=-1)
    f = np.arange(spec.shape[-1]) * (fs / n_fft)
    gain = np.ones(f.size)
    ramp = (f > f1) & (f < cutoff)
    gain[ramp] = 0.5 * (1.0 + np.cos(np.pi * (f[ramp] - f1) / (cutoff - f1)))
    gain[f >= cutoff] = 0.0
    spec *= gain
    return spec, n_fft, pad


def bandlimited_resynthesis(x: ArrayLike, fs: float, *, cutoff: float, passband: float = 0.9,
                            rate: float) -> tuple[FloatArray, float, float]:
    """Low-pass ``x`` below ``cutoff`` and re-synthesize it at (about) ``rate`` Hz.

    The band-limited signal is evaluated on a uniform grid of ``n_out`` points over the
    padded record (``n_out`` a fast FFT length with ``n_out / n_fft * fs >= rate``); it may
    be coarser than the input when ``rate < fs`` (decimation) or finer (interpolation).

    Returns
    -------
    y : ndarray, shape (..., n_out)
    fs_out : float
        Sampling rate of ``y``, Hz.
    t0 : float
        Time of ``y[..., 0]`` relative to ``x[..., 0]``, s (negative: the padding).

    Examples
    --------
    Two seconds at 1 kHz of a 10 Hz tone plus a 300 Hz one, low-passed below 100 Hz and
    re-synthesized at 400 Hz: the 10 Hz tone alone, on the padded time grid.

    >>> import numpy as np
    >>> from gearshot.signal.trains import bandlimited_resynthesis
    >>> t = np.arange(2000) / 1000.0
    >>> x = np.sin(2 * np.pi * 10 * t) + np.sin(2 * np.pi * 300 * t)
    >>> y, fs_out, t0 = bandlimited_resynthesis(x, 1000.0, cutoff=100.0, rate=400.0)
    >>> print(fs_out, t0)
    400.0 -0.6
    >>> ty = t0 + np.arange(y.size) / fs_out
    >>> inside = (ty >= 0.1) & (ty < 1.9)
    >>> bool(np.allclose(y[inside], np.sin(2 * np.pi * 10 * ty[inside]), atol=0.01))
    True
    """
    x = as_signal_array(x, "x", min_length=4)
    fs = check_positive(fs, "fs")
    cutoff = check_positive(cutoff, "cutoff")
    rate = check_positive(rate, "rate")
    if x.shape[-1] * rate / fs > 16 * MAX_POINTS:
        raise GearshotError(f"rate={rate:g} Hz would re-synthesize {x.shape[-1]} samples at "
                            f"fs={fs:g} Hz into more than {16 * MAX_POINTS} points")
    passband = check_in_range(passband, "passband", 0.0, 1.0, low_inclusive=False,
                              high_inclusive=False)
    spec, n_fft, pad = _lowpass_spectrum(x, fs, min(cutoff, fs / 2), passband)
    n_out = scipy.fft.next_fast_len(int(math.ceil(n_fft * rate / fs)), real=True)
    n_out += n_out % 2
    half = n_out // 2 + 1
    if half <= spec.shape[-1]:
        spec = spec[..., :half].copy()
        if n_out < n_fft:
            spec[..., -1] = spec[..., -1].real  # the new Nyquist bin of a real signal
    y = scipy.fft.irfft(spec, n=n_out, axis=-1) * (n_out / n_fft)
    return cast(FloatArray, y), fs * n_out / n_fft, -pad / fs


@finite_result
def antialias_filter(x: ArrayLike, fs: float, *, cutoff: float, passband: float = 0.9,
                     upsample: int = 1) -> FloatArray:
    """Zero-phase low-pass (and up-sampling) of a time signal, flat to ``passband * cutoff``.

    The gain is exactly 1 up to ``passband * cutoff`` Hz, falls as a raised cosine to 0 at
    ``cutoff`` and is 0 above: applied in the frequency domain on the signal padded by odd
    reflection at both ends (so the ends do not wrap onto each other). With ``upsample > 1``
    the result is the band-limited interpolation at ``upsample * fs``.

    Parameters
    ----------
    x : array_like, shape (..., n)
        Time signal(s).
    fs : float
        Sampling rate, Hz.
    cutoff : float
        Stop-band edge, Hz (the angular Nyquist at the lowest speed for angular resampling).
    passband : float, default 0.9
        Pass-band edge as a fraction of ``cutoff`` (0 < passband < 1).
    upsample : int, default 1
        Output samples per input sample.

    Returns
    -------
    ndarray, shape (..., n * upsample)

    Examples
    --------
    A 10 Hz tone survives a 100 Hz low-pass untouched, a 300 Hz one goes (away from the
    record's ends: the last samples see a step of the cut content's end value, which the
    odd reflection puts there):

    >>> import numpy as np
    >>> from gearshot.signal import antialias_filter
    >>> t = np.arange(2000) / 1000.0
    >>> low = np.sin(2 * np.pi * 10 * t)
    >>> y = antialias_filter(low + np.sin(2 * np.pi * 300 * t), 1000.0, cutoff=100.0)
    >>> bool(np.allclose(y[:1800], low[:1800], atol=1e-3))
    True
    >>> antialias_filter(low, 1000.0, cutoff=100.0, upsample=2).shape
    (4000,)
    """
    x = as_signal_array(x, "x", min_length=4)
    fs = check_positive(fs, "fs")
    cutoff = check_positive(cutoff, "cutoff")
    passband = check_in_range(passband, "passband", 0.0, 1.0, low_inclusive=False,
                              high_inclusive=False)
    up = check_int(upsample, "upsample", minimum=1, maximum=64)
    if x.size * up > 16 * MAX_POINTS:
        raise GearshotError(f"x ({x.size} samples) × upsample={up} exceeds {16 * MAX_POINTS} "
                            f"samples")
    n = x.shape[-1]
    if passband * cutoff >= fs / 2 and up == 1:
        return cast(FloatArray, x.copy())
    spec, n_fft, pad = _lowpass_spectrum(x, fs, cutoff, passband)
    if n_fft % 2 == 0 and up > 1:
        spec[..., -1] *= 0.5  # the Nyquist bin splits in two when zero-padded
    y = scipy.fft.irfft(spec, n=n_fft * up, axis=-1)
    if up > 1:
        y *= up
    return cast(FloatArray, y[..., pad * up: (pad + n) * up])
