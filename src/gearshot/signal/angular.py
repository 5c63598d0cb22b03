"""Tacho pulses and resampling from time to shaft angle."""

from __future__ import annotations

from collections.abc import Callable
from typing import cast

import numpy as np
from numpy.typing import ArrayLike
from scipy.interpolate import CubicSpline, PchipInterpolator
from scipy.ndimage import map_coordinates, spline_filter1d

from .._errors import GearshotError
from .._typing import FloatArray
from .._validation import (
    MAX_POINTS,
    as_signal_array,
    check_in_range,
    check_increasing,
    check_int,
    check_positive,
    describe,
    finite_result,
)
from .antialias import bandlimited_resynthesis, min_shaft_rate

__all__ = ["pulse_times", "angular_resample", "angle_to_time"]


@finite_result
def pulse_times(tacho: ArrayLike, fs: float, *, threshold: float | None = None,
                hysteresis: float = 0.1) -> FloatArray:
    """Times of the rising edges of a tacho signal, interpolated between samples.

    An edge is where the signal crosses ``threshold`` upwards after having been below
    ``threshold - hysteresis * (high - low)`` since the previous edge (a Schmitt trigger, so
    noise on a slow edge yields one pulse). The crossing time is interpolated linearly
    between the two samples around it.

    Parameters
    ----------
    tacho : array_like, shape (n,)
        TTL or analog once-(or more)-per-revolution signal.
    fs : float
        Sampling rate, Hz.
    threshold : float, optional
        Trigger level. Default: midway between the 1st and 99th percentiles.
    hysteresis : float, default 0.1
        Re-arm margin as a fraction of the percentile range.

    Returns
    -------
    ndarray, shape (n_pulses,)
        Pulse times in seconds from the first sample (strictly increasing).

    Examples
    --------
    A 0/5 V tacho rising every 100 samples at 1 kHz, first at sample 50: each edge is
    placed halfway between the samples around it.

    >>> import numpy as np
    >>> from gearshot.signal import pulse_times
    >>> tacho = np.where(np.arange(1000) % 100 < 50, 0.0, 5.0)
    >>> print(np.round(pulse_times(tacho, 1000.0)[:3], 4))
    [0.0495 0.1495 0.2495]
    """
    tacho = as_signal_array(tacho, "tacho", max_ndim=1, min_length=2)
    fs = check_positive(fs, "fs")
    hysteresis = check_in_range(hysteresis, "hysteresis", 0.0, 1.0)
    low, high = np.percentile(tacho, [1, 99])
    if high <= low:  # fewer than 1 % of the samples away from the baseline: a lone pulse?
        low, high = float(tacho.min()), float(tacho.max())
    if threshold is None:
        if high <= low:
            raise GearshotError("tacho is constant; it holds no pulses")
        threshold = 0.5 * (low + high)
    if isinstance(threshold, bool) or not isinstance(threshold, (int, float, np.number)):
        raise GearshotError(f"threshold must be a number; got {describe(threshold)}")
    threshold = float(threshold)
    if not np.isfinite(threshold):
        raise GearshotError(f"threshold must be finite; got {threshold}")
    rearm = threshold - hysteresis * max(high - low, 0.0)
    above = tacho >= threshold
    up = np.flatnonzero(~above[:-1] & above[1:]) + 1  # first sample at/above threshold
    below = np.flatnonzero(tacho < rearm) if hysteresis > 0 else np.flatnonzero(~above)
    if up.size and below.size:
        last_below = np.searchsorted(below, up) - 1
        valid = last_below >= 0
        up, last_below = up[valid], last_below[valid]
        # keep the first up-crossing after each re-arming
        keep = np.r_[True, last_below[1:] != last_below[:-1]][:up.size]
        up = up[keep]
    else:
        up = up[:0]
    x0, x1 = tacho[up - 1], tacho[up]
    frac = (threshold - x0) / (x1 - x0)
    return cast(FloatArray, (up - 1 + frac) / fs)


def _check_pulses(pulse_times: ArrayLike, name: str = "pulse_times") -> FloatArray:
    pulses = as_signal_array(pulse_times, name, max_ndim=1)
    if pulses.size < 2:
        raise GearshotError(f"{name} must hold at least 2 pulses; got {pulses.size}")
    return check_increasing(pulses, name, unit=" s")


@finite_result
def angle_to_time(pulse_times: ArrayLike, angles: ArrayLike, *,
                  pulses_per_rev: int = 1) -> FloatArray:
    """Time at which the shaft reaches given angles, from its tacho pulses.

    The time-of-angle curve through the pulses (pulse ``k`` at ``k / pulses_per_rev``
    revolutions from the first) is a cubic spline (not-a-knot ends, as
    :class:`scipy.interpolate.CubicSpline`), so speed varies smoothly
    rather than piecewise-constantly; where a spline would not be monotone (extreme speed
    jumps) or with fewer than 4 pulses a monotone PCHIP is used instead.

    Parameters
    ----------
    pulse_times : array_like, shape (n_pulses,)
        Strictly increasing pulse times, s.
    angles : array_like
        Shaft angles in revolutions from the first pulse, within the pulsed span.
    pulses_per_rev : int, default 1

    Returns
    -------
    ndarray
        Times, s.

    Examples
    --------
    A shaft turning once per 0.1 s:

    >>> import numpy as np
    >>> from gearshot.signal import angle_to_time
    >>> print(np.round(angle_to_time(np.arange(11) * 0.1, [0.0, 0.5, 2.25]), 6) + 0.0)
    [0.    0.05  0.225]
    """
    pulses = _check_pulses(pulse_times)
    ppr = check_int(pulses_per_rev, "pulses_per_rev", minimum=1, maximum=MAX_POINTS)
    revs = np.arange(pulses.size) / ppr
    revs_at = as_signal_array(angles, "angles", min_ndim=0)
    span = revs[-1]
    outside = (revs_at < -1e-6) | (revs_at > span + 1e-6)   # rounding slack: 1e-6 rev
    if np.any(outside):
        first = float(revs_at.ravel()[np.flatnonzero(outside.ravel())[0]])
        raise GearshotError(
            f"angles must lie within the pulsed span 0 … {span:g} revolutions "
            f"({pulses.size} pulses at pulses_per_rev={ppr}); got {first!r} "
            f"({int(outside.sum())} value(s) outside)")
    curve: Callable[[FloatArray], FloatArray] | None = None
    if pulses.size >= 4:  # not-a-knot cubic spline
        spline = CubicSpline(revs, pulses)
        if not (np.any(spline(revs[:-1] + 0.5 / ppr, 1) <= 0)
                or np.any(spline(revs, 1) <= 0)):
            curve = spline
    if curve is None:  # too few pulses, or the spline turns back: monotone PCHIP
        curve = PchipInterpolator(revs, pulses)
    return cast(FloatArray, curve(np.clip(revs_at, 0.0, span)))


@finite_result
def angular_resample(x: ArrayLike, fs: float, pulse_times: ArrayLike, *, samples_per_rev: int,
                     pulses_per_rev: int = 1, upsample: int = 2, antialias: bool = True,
                     passband: float = 0.9) -> FloatArray:
    """Resample a time signal at equal steps of shaft angle.

    The signal is over-sampled ×``upsample`` and then read at the instants the shaft passes
    each angle step, by cubic-spline interpolation. The time of each angle comes from
    :func:`angle_to_time` (smooth spline through the pulses). Only whole revolutions from
    the first pulse are returned.

    With ``antialias`` (default) the signal is first low-passed below the angular Nyquist
    (``samples_per_rev / 2`` orders) at the lowest shaft speed of the record -- flat up to
    ``passband`` times that frequency, zero from it on -- and over-sampled by band-limited
    (FFT) interpolation (:func:`gearshot.signal.trains.antialias_filter`); content above the
    angular Nyquist then cannot fold onto lower orders. ``antialias=False`` reproduces the
    unfiltered resampler (polyphase FIR over-sampling), as the reference implementation has.

    Parameters
    ----------
    x : array_like, shape (..., n_samples)
        Time signal(s), sampled at ``fs`` from t = 0.
    fs : float
        Sampling rate, Hz.
    pulse_times : array_like, shape (n_pulses,)
        Tacho pulse times, s (e.g. from :func:`pulse_times`), at least 2, increasing.
    samples_per_rev : int
        Output samples per shaft revolution.
    pulses_per_rev : int, default 1
        Tacho pulses per shaft revolution.
    upsample : int, default 2
        Over-sampling factor before interpolation.
    antialias : bool, default True
        Low-pass below the angular Nyquist before resampling.
    passband : float, default 0.9
        Anti-alias pass-band edge as a fraction of the angular Nyquist (orders up to
        ``passband * samples_per_rev / 2`` are untouched).

    Returns
    -------
    ndarray, shape (..., n_revs * samples_per_rev)
        Angle-domain signal starting at the first pulse.

    Examples
    --------
    A 30 Hz tone on a shaft turning at 10 rev/s is order 3: nine whole revolutions at
    16 samples each, one period of order 3 every 16/3 samples.

    >>> import numpy as np
    >>> from gearshot.signal import angular_resample
    >>> fs = 1000.0
    >>> t = np.arange(1000) / fs
    >>> angle = angular_resample(np.cos(2 * np.pi * 30 * t), fs, np.arange(10) * 0.1,
    ...                          samples_per_rev=16)
    >>> angle.shape
    (144,)
    >>> order3 = np.cos(2 * np.pi * 3 * np.arange(144) / 16)
    >>> bool(np.allclose(angle[16:], order3[16:], atol=0.005))   # after the first turn
    True
    """
    x = as_signal_array(x, "x", min_length=4)
    fs = check_positive(fs, "fs")
    pulses = _check_pulses(pulse_times)
    spr = check_int(samples_per_rev, "samples_per_rev", minimum=1, maximum=MAX_POINTS)
    ppr = check_int(pulses_per_rev, "pulses_per_rev", minimum=1, maximum=MAX_POINTS)
    upsample = check_int(upsample, "upsample", minimum=1, maximum=64)
    n_revs = _whole_revolutions(x, fs, pulses, spr=spr, ppr=ppr, upsample=upsample)
    angles = np.arange(n_revs * spr) / spr
    times = angle_to_time(pulses, angles, pulses_per_rev=ppr)
    if antialias:
        x_fine, position = _bandlimited_fine(x, fs, pulses, times, spr=spr, ppr=ppr,
                                             upsample=upsample, passband=passband)
    else:
        import scipy.signal

        x_fine = scipy.signal.resample_poly(x, upsample, 1, axis=-1) if upsample > 1 else x
        position = times * fs * upsample  # fractional sample index in x_fine
    return _spline_read(x_fine, position).reshape(*x.shape[:-1], position.size)


def _whole_revolutions(x: FloatArray, fs: float, pulses: FloatArray, *, spr: int, ppr: int,
                       upsample: int) -> int:
    """Whole revolutions from the first pulse, after checking that the pulses lie inside
    the signal and that the work stays within the size limits."""
    if x.size * upsample > 16 * MAX_POINTS:
        raise GearshotError(f"x ({x.size} samples) × upsample={upsample} exceeds "
                            f"{16 * MAX_POINTS} samples; resample shorter pieces")
    duration = x.shape[-1] / fs
    if pulses[0] < 0 or pulses[-1] > (x.shape[-1] - 1) / fs:
        raise GearshotError(
            f"pulse_times span [{pulses[0]:.6g}, {pulses[-1]:.6g}] s, outside the signal "
            f"(0 … {duration:.6g} s at fs={fs:g} Hz); is fs right?")
    n_revs = (pulses.size - 1) // ppr
    if n_revs < 1:
        raise GearshotError(
            f"pulse_times hold {pulses.size} pulses, less than one revolution at "
            f"pulses_per_rev={ppr}")
    if n_revs * spr * max(1, x.size // x.shape[-1]) > 16 * MAX_POINTS:
        raise GearshotError(f"the output would hold {n_revs} revolutions × samples_per_rev="
                            f"{spr} points per signal, more than {16 * MAX_POINTS} in all")
    return n_revs


def _bandlimited_fine(x: FloatArray, fs: float, pulses: FloatArray, times: FloatArray, *,
                      spr: int, ppr: int, upsample: int,
                      passband: float) -> tuple[FloatArray, FloatArray]:
    """The signal band-limited below the angular Nyquist at the slowest shaft speed, re-
    synthesized at ``upsample`` × the Nyquist rate of what is left (coarser than ``fs`` for
    slow shafts: cheaper, equally exact), and the fractional sample index of ``times`` in it."""
    cutoff = 0.5 * spr * min_shaft_rate(pulses, pulses_per_rev=ppr)
    rate = 2.0 * upsample * min(cutoff, fs / 2)
    x_fine, fs_fine, t0 = bandlimited_resynthesis(x, fs, cutoff=cutoff, passband=passband,
                                                  rate=rate)
    return x_fine, (times - t0) * fs_fine


def _spline_read(x_fine: FloatArray, position: FloatArray) -> FloatArray:
    """Cubic B-spline values of each signal (last axis, mirror boundaries) at fractional
    sample ``position`` (:func:`scipy.ndimage.map_coordinates` on the coefficients of
    :func:`scipy.ndimage.spline_filter1d`); shape (n_signals, position.size)."""
    flat = x_fine.reshape(-1, x_fine.shape[-1])
    coeffs = spline_filter1d(flat, order=3, axis=-1, mode="mirror")
    out = np.empty((flat.shape[0], position.size))
    where = position[None]
    for i, row in enumerate(coeffs):
        out[i] = map_coordinates(row, where, order=3, mode="mirror", prefilter=False)
    return out
