"""Steps 2 and 3 of :mod:`gearshot.signal.tracking`: the shaft angle from the phase of one
mesh harmonic around a coarse speed (:func:`demodulate_angle`), and virtual tacho pulses
from an angle (:func:`angle_pulse_times`)."""

from __future__ import annotations

import math

import numpy as np

from .._errors import GearshotError
from .._validation import as_signal_array, check_in_range, check_int, check_positive

__all__ = ["demodulate_angle", "angle_pulse_times"]


def _extended_ridge(rt: np.ndarray, rs: np.ndarray, t_end: float
                    ) -> tuple[np.ndarray, np.ndarray]:
    """The ridge continued along its end slopes to 0 and ``t_end`` (a ridge held constant
    there would leave the band during a run-up)."""
    k = min(5, rt.size)
    if k >= 2 and rt[0] > 0:
        rs = np.r_[np.polyval(np.polyfit(rt[:k], rs[:k], 1), 0.0), rs]
        rt = np.r_[0.0, rt]
    if k >= 2 and rt[-1] < t_end:
        rs = np.r_[rs, np.polyval(np.polyfit(rt[-k:], rs[-k:], 1), t_end)]
        rt = np.r_[rt, t_end]
    return rt, np.maximum(rs, 0.05 * float(rs.max()))


def _in_band_snr(base: np.ndarray, fs_d: float, band: float) -> float:
    """Signal-to-noise power ratio within ``± band`` Hz of a baseband signal (noise: the
    median of its spectrum beyond 1.5 ``band``)."""
    m = base.size
    spec = np.abs(np.fft.fft(base)) ** 2
    f = np.fft.fftfreq(m, 1.0 / fs_d)
    inside = np.abs(f) <= band
    outside = (np.abs(f) > 1.5 * band) & (np.abs(f) <= 0.4 * fs_d)
    noise = float(np.median(spec[outside])) / math.log(2.0) if outside.any() else 0.0
    signal_power = float(spec[inside].sum()) - noise * inside.sum()
    return signal_power / (noise * inside.sum()) if noise > 0 else math.inf


def demodulate_angle(x: np.ndarray, fs: float, *, order: int, ridge_times: np.ndarray,
                     ridge_speed: np.ndarray, bandwidth: float = 0.25
                     ) -> tuple[np.ndarray, np.ndarray, float]:
    """Shaft angle from the phase of one harmonic, refined around a speed ridge.

    Parameters
    ----------
    x : array_like, shape (n,)
        Vibration sampled at ``fs``.
    fs : float
        Sampling rate, Hz.
    order : int
        Order of the harmonic (per shaft revolution).
    ridge_times, ridge_speed : array_like, shape (n_frames,)
        Coarse speed (rev/s) at increasing times (s), e.g. from
        :func:`gearshot.signal.speed_ridge`; continued along its end slopes outside their
        span. It must be within ``bandwidth`` orders of the truth.
    bandwidth : float, default 0.25
        Half-width of the kept band around the harmonic, in shaft orders at the lowest
        ridge speed (speed changes faster than this many cycles per revolution are
        smoothed away; keep it below the nearest sideband, e.g. 1/3 order for a 1:3 idler).

    Returns
    -------
    times : ndarray, shape (m,)
        Decimated sample times, s.
    angle : ndarray, shape (m,)
        Shaft angle, revolutions, starting near 0.
    snr : float
        In-band signal-to-noise power ratio of the harmonic (linear).

    Examples
    --------
    A shaft at a steady 10 rev/s seen through its 8th order: the angle grows by 10
    revolutions per second.

    >>> import numpy as np
    >>> from gearshot.signal.tracking import demodulate_angle
    >>> t = np.arange(4000) / 2000.0
    >>> times, angle, snr = demodulate_angle(np.cos(2 * np.pi * 80 * t), 2000.0, order=8,
    ...                                      ridge_times=np.array([0.0, 2.0]),
    ...                                      ridge_speed=np.array([10.0, 10.0]))
    >>> print(round(float(np.polyfit(times, angle, 1)[0]), 3), bool(snr > 100))
    10.0 True
    """
    import scipy.signal  # lazy: a one-record call need not import it
    x = as_signal_array(x, "x", max_ndim=1, min_length=16)
    fs = check_positive(fs, "fs")
    order = check_int(order, "order", minimum=1, maximum=1_000_000)
    bandwidth = check_in_range(bandwidth, "bandwidth", 0.0, 10.0, low_inclusive=False)
    rt = as_signal_array(ridge_times, "ridge_times", max_ndim=1)
    rs = as_signal_array(ridge_speed, "ridge_speed", max_ndim=1)
    if rt.size != rs.size or rt.size < 1 or np.any(np.diff(rt) <= 0) or np.any(rs <= 0):
        raise GearshotError(f"ridge_times must increase and ridge_speed be > 0 with the same "
                            f"length; got {rt.size} times and {rs.size} speeds")
    n = x.size
    band = bandwidth * float(rs.min())  # Hz
    down = max(1, int(fs // (20.0 * band)))
    t = np.arange(n) / fs
    rt, rs = _extended_ridge(rt, rs, float(t[-1]))
    freq = order * np.interp(t, rt, rs)
    psi = np.empty(n)
    psi[0] = 0.0
    np.cumsum(freq[:-1] * (2 * np.pi / fs), out=psi[1:])
    base = x * np.exp(-1j * psi)
    if down > 1:
        base = scipy.signal.resample_poly(base, 1, down, padtype="line")
    fs_d = fs / down
    m = base.size
    snr = _in_band_snr(base, fs_d, band)
    sos = scipy.signal.butter(4, band, fs=fs_d, output="sos")
    padlen = min(m - 1, int(3 * fs_d / band))
    narrow = scipy.signal.sosfiltfilt(sos, base, padtype="odd", padlen=padlen)
    phase = np.unwrap(np.angle(narrow))
    angle = (psi[np.arange(m) * down] + phase - phase[0]) / (2 * np.pi * order)
    return np.arange(m) * (down / fs), angle, max(snr, 1e-3)


def angle_pulse_times(times: np.ndarray, angle: np.ndarray, *, pulses_per_rev: int = 8
                      ) -> np.ndarray:
    """Times at which a shaft angle passes whole multiples of ``1 / pulses_per_rev`` rev.

    Parameters
    ----------
    times : array_like, shape (m,)
        Increasing sample times, s.
    angle : array_like, shape (m,)
        Shaft angle at ``times``, revolutions, strictly increasing.
    pulses_per_rev : int, default 8
        Virtual pulses per revolution.

    Returns
    -------
    ndarray, shape (n_pulses,)
        Pulse times, s (a cubic spline of time against angle, read at the marks).

    Examples
    --------
    >>> import numpy as np
    >>> from gearshot.signal import angle_pulse_times
    >>> t = np.linspace(0.0, 1.0, 101)
    >>> angle_pulse_times(t, 10.0 * t + 0.05, pulses_per_rev=1)[:3]
    array([0.095, 0.195, 0.295])
    """
    from scipy.interpolate import CubicSpline  # lazy: a one-record call need not import it
    t = as_signal_array(times, "times", max_ndim=1, min_length=2)
    a = as_signal_array(angle, "angle", max_ndim=1, min_length=2)
    ppr = check_int(pulses_per_rev, "pulses_per_rev", minimum=1, maximum=100_000)
    if t.size != a.size:
        raise GearshotError(f"times and angle must have the same length; got {t.size} and "
                            f"{a.size}")
    if np.any(np.diff(a) <= 0):
        i = int(np.flatnonzero(np.diff(a) <= 0)[0])
        raise GearshotError(f"angle must increase (a shaft turning one way); it stops or "
                            f"reverses at t={t[i]:.4g} s")
    marks = np.arange(math.ceil(a[0] * ppr), math.floor(a[-1] * ppr) + 1) / ppr
    return np.asarray(CubicSpline(a, t)(marks))
