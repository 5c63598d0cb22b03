"""The anti-alias low-pass of angular resampling.

Angular resampling reads a time signal at the instants of equal angle steps. Content above
the *angular* Nyquist (half the samples per revolution, in shaft orders) folds back onto
lower orders unless it is removed first: :func:`antialias_filter` low-passes (and
optionally up-samples) the time signal below the angular Nyquist at the lowest speed of the
record (:func:`min_shaft_rate`), with an exactly flat pass band;
:func:`bandlimited_resynthesis` does the same and re-synthesizes at a chosen rate.
"""

from __future__ import annotations

import math
from typing import cast

import numpy as np
import scipy.fft
from numpy.typing import ArrayLike

from .._errors import GearshotError
from .._typing import ComplexArray, FloatArray
from .._validation import (
    MAX_POINTS,
    as_signal_array,
    check_fs,
    check_in_range,
    check_int,
    check_positive,
    finite_result,
)

__all__ = ["antialias_filter", "bandlimited_resynthesis", "min_shaft_rate"]


def min_shaft_rate(pulse_times: ArrayLike, *, pulses_per_rev: int = 1) -> float:
    """Lowest speed (revolutions/s of the target shaft) between consecutive tacho pulses.

    Examples
    --------
    The longest pulse interval is 0.15 s:

    >>> from gearshot.signal.antialias import min_shaft_rate
    >>> pulses = [0.0, 0.1, 0.2, 0.35, 0.45]
    >>> print(round(min_shaft_rate(pulses), 4))
    6.6667
    """
    pulses = as_signal_array(pulse_times, "pulse_times", max_ndim=1)
    ppr = check_int(pulses_per_rev, "pulses_per_rev", minimum=1, maximum=MAX_POINTS)
    if pulses.size < 2:
        raise GearshotError(f"pulse_times must hold at least 2 pulses; got {pulses.size}")
    gaps = np.diff(pulses)
    if ppr > 1 and gaps.size >= ppr:  # whole revolutions: insensitive to uneven tacho marks
        gaps = (pulses[ppr:] - pulses[:-ppr]) / ppr
    return float(1.0 / (ppr * gaps.max()))


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
    spec: ComplexArray = np.fft.rfft(xp, n=n_fft, axis=-1)
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
    >>> from gearshot.signal.antialias import bandlimited_resynthesis
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
    fs = check_fs(fs, "fs")
    cutoff = check_fs(cutoff, "cutoff")
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
    y = np.fft.irfft(spec, n=n_out, axis=-1) * (n_out / n_fft)
    return y, fs * n_out / n_fft, -pad / fs


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
    fs = check_fs(fs, "fs")
    cutoff = check_fs(cutoff, "cutoff")
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
    y = np.fft.irfft(spec, n=n_fft * up, axis=-1)
    if up > 1:
        y *= up
    return y[..., pad * up: (pad + n) * up]
