"""Shaft speed and angle from the vibration itself, for machines without a tachometer.

A gear mesh makes the vibration repeat ``z`` times per revolution of the shaft that carries
a ``z``-tooth gear, so its harmonics sit at whole *orders* of that shaft: at shaft speed
``s(t)`` (rev/s) the mesh harmonic of order ``o`` is at ``o * s(t)`` Hz. Tracking one such
harmonic gives the speed; its phase divided by the order gives the shaft angle. Three steps:

1. **Time–frequency ridge** (:func:`speed_ridge`, in :mod:`gearshot.signal.ridge`).
   Short-time Fourier transform (:class:`scipy.signal.ShortTimeFFT`, Hann window of
   ``window`` s); every frame's power
   in dB above the frame's median over the searched band. For every candidate shaft speed
   in ``speed_range``, a score sums those levels at ``h * o * s`` for every mesh order
   ``o`` of the shaft (all meshes synchronous with it, known from the gear train) and
   harmonic ``h = 1 … n_harmonics``. The best path through (frame, candidate speed) whose
   speed changes by at most ``max_rate`` rev/s per second is found by dynamic programming.
   Several orders make the choice unambiguous: a candidate at half or double the true speed
   puts only some of its comb teeth on spectral lines.
2. **Phase demodulation** (:func:`demodulate_angle`). The harmonic followed by the ridge
   (order ``o * h`` with the highest level along it) is mixed down to 0 Hz with the ridge's
   own phase (``x(t) exp(-i 2π ∫ o h s_ridge dt)``), decimated and low-passed to
   ``± bandwidth`` shaft orders (zero-phase Butterworth): this is the band-pass around the
   tracked harmonic and its analytic signal, expressed at baseband. The unwrapped phase of
   what is left, added to the ridge's phase, is the harmonic's phase; divided by ``2π`` and
   the order it is the shaft angle (revolutions), with the ridge's coarse frequency
   corrected to within the phase noise.
3. **Virtual tacho** (:func:`angle_pulse_times`). The times at which the angle passes
   ``k / pulses_per_rev`` revolutions: pulses as a tacho would give, for the angular
   re-sampler and :func:`gearshot.signal.shaft_cycle_times`.

The absolute orientation of the shaft cannot be known without a key-phasor: the angle
starts at an arbitrary value (the first virtual pulse is at an arbitrary mark), so
synchronous averages from the vibration angle are circularly shifted against the
tacho-based ones; SAs of one recording are aligned with each other.

Uncertainty: the in-band signal-to-noise ratio ``snr`` (signal power in the ``± bandwidth``
band over the noise floor there, from the median of the decimated baseband spectrum) gives
the phase noise ``σ_φ ≈ (2 snr)^-1/2`` rad, the angle noise ``σ_φ / (2π o)`` rev and the
noise of the instantaneous speed ``σ_φ B / (√3 o)`` rev/s (``B`` the band edge in Hz; white
phase noise over ``|f| < B``). It covers noise only, not a neighbouring line inside the band.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._errors import GearshotError
from .._validation import as_signal_array, check_in_range, check_int, check_positive
from .ridge import SpeedRidge, speed_ridge

__all__ = ["SpeedRidge", "ShaftAngle", "speed_ridge", "demodulate_angle", "angle_pulse_times",
           "estimate_shaft_angle", "MIN_SNR_DB", "MAX_WANDER", "MIN_LINES"]

#: Default in-band SNR (dB) below which no mesh harmonic is taken to stand out.
MIN_SNR_DB = 3.0
#: Largest RMS of the demodulated harmonic's frequency wander, as a fraction of the band
#: half-width, for a lock: noise alone gives 1/sqrt(3) = 0.58 (flat in the band).
MAX_WANDER = 0.3
MIN_LINES = 2  # comb lines that must stand out: one lone line may be any tone
_SETTLED = 0.1  # wander below which a shorter STFT window is not tried
_AUTO_WINDOWS = (0.125, 0.5)  # s: shortest and default STFT window of the automatic choice


@dataclass(frozen=True)
class ShaftAngle:
    """A shaft angle estimated from the vibration (:func:`estimate_shaft_angle`).

    Attributes
    ----------
    times : ndarray, shape (m,)
        Sample times of ``angle``, s (a decimated grid from 0).
    angle : ndarray, shape (m,)
        Shaft angle, revolutions (arbitrary origin), increasing.
    speed : ndarray, shape (m,)
        Instantaneous shaft speed, rev/s.
    order : int
        The demodulated harmonic, in orders of the shaft.
    snr_db : float
        In-band SNR of that harmonic, dB.
    speed_std : float
        Standard uncertainty of the instantaneous speed from the phase noise, rev/s.
    angle_std : float
        Standard uncertainty of the angle from the phase noise, revolutions.
    wander : float
        RMS of the demodulated harmonic's frequency about the ridge, as a fraction of the
        band half-width (noise alone: about 0.58; a clean line: near 0).
    pulse_times : ndarray, shape (n_pulses,)
        Virtual tacho: times at which ``angle`` passes whole multiples of
        ``1 / pulses_per_rev`` revolutions, s.
    pulses_per_rev : int
    ridge : SpeedRidge
        The coarse time–frequency ridge.
    """

    times: np.ndarray
    angle: np.ndarray
    speed: np.ndarray
    order: int
    snr_db: float
    speed_std: float
    angle_std: float
    wander: float
    pulse_times: np.ndarray
    pulses_per_rev: int
    ridge: SpeedRidge

    @property
    def mean_speed(self) -> float:
        """Mean shaft speed over the record, rev/s: the least-squares slope of the angle
        (the speed at mid-record for a steady ramp; less sensitive to the ends, where the
        zero-phase filter has only one side)."""
        return float(np.polyfit(self.times - self.times.mean(), self.angle, 1)[0])



def demodulate_angle(x, fs, *, order, ridge_times, ridge_speed, bandwidth=0.25
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
        Coarse speed (rev/s) at increasing times (s), e.g. from :func:`speed_ridge`;
        held constant outside their span. It must be within ``bandwidth`` orders of the
        truth.
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
    rate = 20.0 * band
    down = max(1, int(fs // rate))
    t = np.arange(n) / fs
    # beyond the first/last frame centre the speed goes on along the end slopes (a ridge
    # held constant there would leave the band during a run-up)
    k = min(5, rt.size)
    if k >= 2 and rt[0] > 0:
        rs = np.r_[np.polyval(np.polyfit(rt[:k], rs[:k], 1), 0.0), rs]
        rt = np.r_[0.0, rt]
    if k >= 2 and rt[-1] < t[-1]:
        rs = np.r_[rs, np.polyval(np.polyfit(rt[-k:], rs[-k:], 1), t[-1])]
        rt = np.r_[rt, t[-1]]
    rs = np.maximum(rs, 0.05 * float(rs.max()))
    freq = order * np.interp(t, rt, rs)
    psi = np.empty(n)
    psi[0] = 0.0
    np.cumsum(freq[:-1] * (2 * np.pi / fs), out=psi[1:])
    base = x * np.exp(-1j * psi)
    if down > 1:
        base = scipy.signal.resample_poly(base, 1, down, padtype="line")
    fs_d = fs / down
    m = base.size
    td = np.arange(m) * (down / fs)
    spec = np.abs(np.fft.fft(base)) ** 2
    f = np.fft.fftfreq(m, 1.0 / fs_d)
    inside = np.abs(f) <= band
    outside = (np.abs(f) > 1.5 * band) & (np.abs(f) <= 0.4 * fs_d)
    noise = float(np.median(spec[outside])) / math.log(2.0) if outside.any() else 0.0
    signal_power = float(spec[inside].sum()) - noise * inside.sum()
    snr = signal_power / (noise * inside.sum()) if noise > 0 else math.inf
    sos = scipy.signal.butter(4, band, fs=fs_d, output="sos")
    padlen = min(m - 1, int(3 * fs_d / band))
    narrow = scipy.signal.sosfiltfilt(sos, base, padtype="odd", padlen=padlen)
    phase = np.unwrap(np.angle(narrow))
    angle = (psi[np.arange(m) * down] + phase - phase[0]) / (2 * np.pi * order)
    return td, angle, max(snr, 1e-3)


def angle_pulse_times(times, angle, *, pulses_per_rev=8) -> np.ndarray:
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


def estimate_shaft_angle(x, fs, *, orders, speed_range, n_harmonics=3, window=None,
                         max_rate=None, smooth=0.5, track=None, bandwidth=0.25,
                         min_snr_db=MIN_SNR_DB, max_wander=MAX_WANDER, min_lines=MIN_LINES,
                         pulses_per_rev=8,
                         label="the vibration") -> ShaftAngle:
    """Shaft angle and instantaneous speed from the vibration: ridge, then phase.

    :func:`speed_ridge` finds the speed coarsely from all mesh orders of the shaft;
    :func:`demodulate_angle` refines it on the strongest harmonic along the ridge;
    :func:`angle_pulse_times` turns the angle into virtual tacho pulses.

    Parameters
    ----------
    x : array_like, shape (n,)
        Vibration sampled at ``fs`` (one sensor).
    fs : float
        Sampling rate, Hz.
    orders : int or sequence of int
        Mesh orders synchronous with the shaft (from the gear train).
    speed_range : (float, float)
        Shaft speeds searched, rev/s.
    n_harmonics, max_rate, smooth, track
        See :func:`speed_ridge`.
    window : float, optional
        STFT window of the ridge, s. Default: 0.5 s; when the phase then wanders more than
        0.1 of the band (a run-up smears the line over many bins of a long window), once
        more with the window the measured chirp allows (``1 / sqrt(chirp in Hz/s)``, at
        least 1/8 s), keeping the steadier result.
    bandwidth : float, default 0.25
        See :func:`demodulate_angle` (shaft orders).
    min_snr_db : float, default 3
        Refuse below this in-band SNR of the tracked harmonic (white noise gives at most
        -4.6 dB in 20 synthetic trials; the threshold was set on those, not on real data).
    max_wander : float, default 0.3
        Refuse when the demodulated harmonic's frequency wanders about the ridge by more
        than this fraction of the band half-width (RMS): noise alone gives about
        ``1/sqrt(3) = 0.58``; the default is about half of that. Catches a lock on a line
        that is not there, or a slipping phase, which the SNR alone may pass.
    min_lines : int, default 2
        Refuse unless at least this many lines of the comb (mesh orders × harmonics) stand
        out along the ridge (mean level >= 6 dB above the median; noise gives about 3):
        a gear mesh has harmonics, a lone tone (an electrical line, another machine) may
        be anything.
    pulses_per_rev : int, default 8
        Virtual pulses per revolution in ``pulse_times``.
    label : str
        Names the signal in the refusal.

    Returns
    -------
    ShaftAngle

    Raises
    ------
    GearshotError
        No mesh harmonic stands out (in-band SNR below ``min_snr_db`` or a phase that
        wanders like noise; the message states both), or bad input.

    Examples
    --------
    >>> import numpy as np
    >>> from gearshot.signal import estimate_shaft_angle
    >>> fs = 20_000.0
    >>> t = np.arange(int(4 * fs)) / fs
    >>> revs = 20.0 * t + 0.5 * t ** 2          # run-up: 20 -> 24 rev/s
    >>> rng = np.random.default_rng(0)
    >>> x = np.sin(2 * np.pi * 32 * revs) + 0.5 * np.sin(2 * np.pi * 64 * revs + 1.0)
    >>> x += 0.3 * rng.standard_normal(t.size)
    >>> est = estimate_shaft_angle(x, fs, orders=[32], speed_range=(15, 30))
    >>> bool(abs(est.mean_speed - 22.0) < 0.01)
    True
    """
    import scipy.signal  # lazy: a one-record call need not import it
    min_snr_db = check_in_range(min_snr_db, "min_snr_db", -100.0, 100.0)
    max_wander = check_positive(max_wander, "max_wander")
    min_lines = check_int(min_lines, "min_lines", minimum=0, maximum=1000)
    ppr = check_int(pulses_per_rev, "pulses_per_rev", minimum=1, maximum=100_000)
    x = as_signal_array(x, "x", max_ndim=1, min_length=16)
    fs = check_positive(fs, "fs")
    def one_pass(win):
        ridge = speed_ridge(x, fs, orders=orders, speed_range=speed_range,
                            n_harmonics=n_harmonics, window=win, max_rate=max_rate,
                            smooth=smooth, track=track)
        times, angle, snr = demodulate_angle(x, fs, order=ridge.order,
                                             ridge_times=ridge.times,
                                             ridge_speed=ridge.speed, bandwidth=bandwidth)
        band = bandwidth * float(ridge.speed.min())
        speed = np.gradient(angle, times)
        # how fast the demodulated phase wanders about the (independent) coarse ridge: a
        # locked line barely moves, noise in the band sweeps it at ~band / sqrt(3)
        span = times[-1] - times[0]
        inner = (times > times[0] + 0.1 * span) & (times < times[-1] - 0.1 * span)
        ridge_at = np.interp(times, ridge.times, ridge.speed)
        # above band/4 only: slow errors of the coarse ridge are not noise (the phase step
        # corrects them), while noise's frequency wander lies almost all (98 %) up there
        diff = ridge.order * (speed - ridge_at)
        if times.size > 30:
            fs_d = 1.0 / (times[1] - times[0])
            hp = scipy.signal.butter(2, band / 4, btype="highpass", fs=fs_d, output="sos")
            diff = scipy.signal.sosfiltfilt(hp, diff)
        wander = float(np.std(diff[inner]) / band) if inner.any() else 0.0
        return ridge, times, angle, snr, speed, wander, band

    result = one_pass(window if window is not None else _AUTO_WINDOWS[-1])
    if window is None and result[5] > _SETTLED:
        # a run-up smears the line over many bins of the long window: retry with the
        # window its chirp allows (the line moves < 1 bin: W <= 1 / sqrt(Hz/s))
        ridge, times, _, _, speed, _, _ = result
        span = times[-1] - times[0]
        inner = (times > times[0] + 0.1 * span) & (times < times[-1] - 0.1 * span)
        slope = np.abs(np.polyfit(times[inner], speed[inner], 2)[1]) if inner.sum() > 3 \
            else 0.0
        slope = max(slope, float(np.max(np.abs(np.gradient(ridge.speed, ridge.times))))
                    if ridge.times.size > 1 else 0.0)
        chirp = ridge.order * slope
        short = float(np.clip(1.0 / math.sqrt(max(chirp, 1e-9)), _AUTO_WINDOWS[0],
                              _AUTO_WINDOWS[-1]))
        if short < 0.75 * _AUTO_WINDOWS[-1]:
            other = one_pass(short)
            if other[5] < result[5]:
                result = other
    ridge, times, angle, snr, speed, wander, band = result
    snr_db = 10.0 * math.log10(snr) if snr > 0 else -math.inf
    if not (snr_db >= min_snr_db and wander <= max_wander and ridge.n_lines >= min_lines):
        raise GearshotError(
            f"no mesh harmonic stands out in {label}: order {ridge.order} of the shaft, "
            f"tracked at {np.median(ridge.speed):.4g} rev/s, is {snr_db:.1f} dB above the "
            f"noise in its band (min_snr_db={min_snr_db:g}), its phase wanders "
            f"{wander:.2f} of the band (noise: 0.58; max_wander={max_wander:g}) and "
            f"{ridge.n_lines} of {ridge.n_comb} comb lines stand out (min_lines="
            f"{min_lines}); the speed cannot be estimated from the vibration (give a tacho, "
            f"another sensor or a narrower speed range)")
    sigma_phi = math.sqrt(1.0 / (2.0 * snr))
    pulses = angle_pulse_times(times, angle, pulses_per_rev=ppr)
    return ShaftAngle(times=times, angle=angle, speed=speed, order=ridge.order,
                      snr_db=snr_db, speed_std=sigma_phi * band / (math.sqrt(3) * ridge.order),
                      angle_std=sigma_phi / (2 * np.pi * ridge.order), wander=wander,
                      pulse_times=pulses,
                      pulses_per_rev=ppr, ridge=ridge)
