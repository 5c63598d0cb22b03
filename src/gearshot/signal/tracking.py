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
   corrected to within the phase noise. Every other harmonic of the shaft's own mesh
   that passes the same checks is averaged in (weights ``snr · o²``,
   :mod:`gearshot.signal.harmonic_phase`): each carries its own transmission error.
   Where a ratio 1/2, 2/3, 3/2 or 2 of the tracked speed also lies in the speed range, the
   record's whole orders decide between them (:mod:`gearshot.signal.ratio_check`).
   Where the ridge path is refused (a run-up smears the lines over many bins of every
   short window), :func:`gearshot.signal.speed_profile.fit_speed_profile` fits a
   quadratic speed profile to the whole record's order spectrum instead (the coherent
   integration a synchronous average does) and step 2 runs around that profile; its
   polynomial angle is kept where the demodulated phase wanders like noise.
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
phase noise over ``|f| < B``). It covers noise only, not a neighbouring line inside the band:
:attr:`ShaftAngle.speed_uncertainty` adds a model term (:data:`SPEED_MODEL_REL` of the speed)
validated against the tacho of real and virtual-rig records.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._errors import GearshotError
from .._validation import as_signal_array, check_in_range, check_int, check_positive
from .demodulation import angle_pulse_times, demodulate_angle
from .harmonic_phase import _db, _fused, _inner, _Pass, _phase_pass
from .ratio_check import whole_order_scores
from .ridge import SpeedRidge, _orders, _ratios_in_range, _speed_range, speed_ridge
from .speed_profile import SpeedProfile, _fit

__all__ = ["SpeedRidge", "ShaftAngle", "speed_ridge", "demodulate_angle", "angle_pulse_times",
           "estimate_shaft_angle", "MIN_SNR_DB", "MAX_WANDER", "MIN_LINES", "SPEED_MODEL_REL"]

#: Default in-band SNR (dB) below which no mesh harmonic is taken to stand out.
MIN_SNR_DB = 3.0
#: Largest RMS of the demodulated harmonic's frequency wander, as a fraction of the band
#: half-width, for a lock: noise alone gives 1/sqrt(3) = 0.58 (flat in the band).
MAX_WANDER = 0.3
MIN_LINES = 2  # comb lines that must stand out: one lone line may be any tone
#: Relative model term of the speed uncertainty (fraction of the speed): what the phase
#: noise leaves out (the tracked harmonic's own transmission error, a neighbouring line in
#: the band, the tacho's own jitter in the validation). Chosen so that the tacho's speed
#: over 0.25 s windows lies within 2 standard uncertainties in 95 % of windows of the
#: development records (PHM09 shared 30 Hz records, virtual-rig seeds 1-3; see
#: benchmarks/RESULTS.md, "Trust: machine file and tracked speed").
SPEED_MODEL_REL = 4e-4
_SETTLED = 0.1  # wander below which a shorter STFT window is not tried
_AUTO_WINDOWS = (0.125, 0.5)  # s: shortest and default STFT window of the automatic choice
_RATIO_SWITCH = 1.5  # another ratio's whole orders this much stronger: track it instead
_RATIO_RANGE = 0.1  # ... within this fraction of it


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
        The coarse time–frequency ridge (for a whole-record profile: the profile sampled
        at the demodulation grid, its strongest mesh line's level and line counts).
    profile : SpeedProfile or None
        The whole-record speed profile where the ridge path was refused, else None.
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
    profile: SpeedProfile | None = None

    @property
    def speed_uncertainty(self) -> float:
        """Standard uncertainty of the speed, rev/s: the phase noise (``speed_std``) and a
        model term of :data:`SPEED_MODEL_REL` times the mean speed, in quadrature. It
        holds for a correct lock only: a comb locked on a sideband or a ratio of the
        speed is a gross error that :func:`gearshot.machine.signal_check.speed_check`
        refuses."""
        return float(math.hypot(self.speed_std, SPEED_MODEL_REL * abs(self.mean_speed)))

    @property
    def mean_speed(self) -> float:
        """Mean shaft speed over the record, rev/s: the least-squares slope of the angle
        (the speed at mid-record for a steady ramp; less sensitive to the ends, where the
        zero-phase filter has only one side)."""
        return float(np.polyfit(self.times - self.times.mean(), self.angle, 1)[0])


def estimate_shaft_angle(x: np.ndarray, fs: float, *, orders: object, speed_range: object,
                         n_harmonics: int = 3, window: float | None = None,
                         max_rate: float | None = None, smooth: float = 0.5,
                         track: int | None = None, bandwidth: float = 0.25,
                         min_snr_db: float = MIN_SNR_DB, max_wander: float = MAX_WANDER,
                         min_lines: int = MIN_LINES, pulses_per_rev: int = 8,
                         label: str = "the vibration") -> ShaftAngle:
    """Shaft angle and instantaneous speed from the vibration: ridge, then phase.

    :func:`speed_ridge` finds the speed coarsely from all mesh orders of the shaft;
    :func:`demodulate_angle` refines it on the strongest harmonic along the ridge;
    :func:`angle_pulse_times` turns the angle into virtual tacho pulses; the other
    harmonics of the shaft's own mesh that pass the checks are averaged into the angle
    (unless ``track`` names the order), and where a ratio 1/2 … 2 of the speed is in
    ``speed_range`` too, the whole-order spectrum decides (a ratio 1.5 times as strong:
    the ridge again around it; stronger but less: refused). When that path is
    refused, a speed profile fitted to the whole record
    (:func:`gearshot.signal.speed_profile.fit_speed_profile`) is tried before refusing:
    it is taken when at least ``min_lines`` whole orders of the shaft (mesh lines
    included) stand 15 dB over the floor of the record's order spectrum and no speed
    ratio 1/2, 2/3, 3/2 or 2 of the profile also lies in ``speed_range`` (the whole
    orders of a multi-shaft train may fit such a ratio as well); the phase step
    then runs around it, and the profile's own angle is kept where that phase wanders
    more than ``max_wander`` or its SNR is below ``min_snr_db``.

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
        wanders like noise, and no whole-record profile either; the message states the
        SNR, the wander and the profile's strongest line); or the speed is ambiguous (a
        ratio of the tracked speed in the range puts its whole orders on lines better,
        but not 1.5 times as well, or its own ridge fails; the message names both
        speeds); or bad input.

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
    min_snr_db = check_in_range(min_snr_db, "min_snr_db", -100.0, 100.0)
    max_wander = check_positive(max_wander, "max_wander")
    min_lines = check_int(min_lines, "min_lines", minimum=0, maximum=1000)
    ppr = check_int(pulses_per_rev, "pulses_per_rev", minimum=1, maximum=100_000)
    x = as_signal_array(x, "x", max_ndim=1, min_length=16)
    fs = check_positive(fs, "fs")
    ridge_kw = dict(orders=orders, speed_range=speed_range, n_harmonics=n_harmonics,
                    max_rate=max_rate, smooth=smooth, track=track)
    result = _ridge_pass(x, fs, ridge_kw, window if window is not None
                         else _AUTO_WINDOWS[-1], bandwidth)
    if window is None and result.wander > _SETTLED:
        short = _chirp_window(result)
        if short < 0.75 * _AUTO_WINDOWS[-1]:
            other = _ridge_pass(x, fs, ridge_kw, short, bandwidth)
            if other.wander < result.wander:
                result = other
    snr_db = _db(result.snr)
    if snr_db >= min_snr_db and result.wander <= max_wander and \
            result.ridge.n_lines >= min_lines:
        kw = dict(ridge_kw, window=window, bandwidth=bandwidth, min_snr_db=min_snr_db,
                  max_wander=max_wander, min_lines=min_lines, pulses_per_rev=ppr, label=label)
        result = _fused(x, fs, result, _own_harmonics(result, ridge_kw, fs), bandwidth,
                        min_snr_db, max_wander)
        return _ratio_checked(x, fs, _shaft_angle(result, ppr), kw)
    # the whole-record profile (unrefined where a ratio of it is in the range: refused)
    profile = _fit(x, fs, orders, speed_range, 5, max_rate, guard=True)
    ratio = profile.ambiguous(_speed_range(speed_range), x.size / fs)
    if profile.n_lines >= max(min_lines, 1) and ratio is None:
        fine = _profile_pass(x, fs, profile, bandwidth, track)
        if not (_db(fine.snr) >= min_snr_db and fine.wander <= max_wander):
            fine = fine._replace(angle=profile.angle(fine.times),
                                 speed=profile.speed(fine.times))
        else:
            fine = _fused(x, fs, fine, _own_harmonics(fine, ridge_kw, fs), bandwidth,
                          min_snr_db, max_wander)
        return _shaft_angle(fine, ppr, profile)
    ridge = result.ridge
    raise GearshotError(
        f"no mesh harmonic stands out in {label}: order {ridge.order} of the shaft, "
        f"tracked at {np.median(ridge.speed):.4g} rev/s, is {snr_db:.1f} dB above the "
        f"noise in its band (min_snr_db={min_snr_db:g}), its phase wanders "
        f"{result.wander:.2f} of the band (noise: 0.58; max_wander={max_wander:g}) and "
        f"{ridge.n_lines} of {ridge.n_comb} comb lines stand out (min_lines={min_lines}); "
        f"over the whole record the best speed profile's strongest mesh line is "
        f"{profile.lines[0][1]:.1f} dB over the floor ({profile.n_lines} whole orders at "
        f"15 dB or more{_ambiguity(ratio, profile)}); the speed cannot be estimated from "
        f"the vibration (give a tacho, another sensor or a narrower speed range)")


def _ambiguity(ratio: float | None, profile: SpeedProfile) -> str:
    if ratio is None:
        return ""
    return (f", at {profile.coef[0]:.4g} rev/s mid-record, but {ratio:.3g} times that is "
            f"in the speed range too")


def _ridge_pass(x: np.ndarray, fs: float, ridge_kw: dict[str, Any], window: float,
                bandwidth: float) -> _Pass:
    ridge = speed_ridge(x, fs, window=window, **ridge_kw)
    return _phase_pass(x, fs, ridge, bandwidth)


def _chirp_window(result: _Pass) -> float:
    """The STFT window a run-up's chirp allows (the line moves < 1 bin: W <= 1 /
    sqrt(Hz/s)): a run-up smears the line over many bins of the long window."""
    ridge, times, speed = result.ridge, result.times, result.speed
    inner = _inner(times)
    slope = np.abs(np.polyfit(times[inner], speed[inner], 2)[1]) if inner.sum() > 3 \
        else 0.0
    slope = max(slope, float(np.max(np.abs(np.gradient(ridge.speed, ridge.times))))
                if ridge.times.size > 1 else 0.0)
    chirp = ridge.order * slope
    return float(np.clip(1.0 / math.sqrt(max(chirp, 1e-9)), _AUTO_WINDOWS[0],
                         _AUTO_WINDOWS[-1]))


def _profile_pass(x: np.ndarray, fs: float, profile: SpeedProfile, bandwidth: float,
                  track: int | None) -> _Pass:
    """The phase step around a whole-record profile, on its strongest mesh line."""
    order = int(track) if track is not None else profile.lines[0][0]
    duration = x.size / fs
    times = np.linspace(0.0, duration, max(16, int(duration * 8)) + 1)
    level = dict(profile.lines).get(order, profile.lines[0][1])
    ridge = SpeedRidge(times=times, speed=profile.speed(times), order=order,
                       level_db=float(level), n_lines=profile.n_lines,
                       n_comb=len(profile.lines))
    return _phase_pass(x, fs, ridge, bandwidth)


def _shaft_angle(result: _Pass, ppr: int, profile: SpeedProfile | None = None
                 ) -> ShaftAngle:
    sigma_phi = math.sqrt(1.0 / (2.0 * (result.snr_eff or result.snr)))
    order = result.ridge.order
    pulses = angle_pulse_times(result.times, result.angle, pulses_per_rev=ppr)
    return ShaftAngle(times=result.times, angle=result.angle, speed=result.speed,
                      order=order, snr_db=_db(result.snr),
                      speed_std=sigma_phi * result.band / (math.sqrt(3) * order),
                      angle_std=sigma_phi / (2 * np.pi * order), wander=result.wander,
                      pulse_times=pulses, pulses_per_rev=ppr, ridge=result.ridge,
                      profile=profile)


def _ratio_checked(x: np.ndarray, fs: float, est: ShaftAngle, kw: dict[str, Any]
                   ) -> ShaftAngle:
    """``est``, unless a ratio 1/2, 2/3, 3/2 or 2 of its speed also lies in the speed range
    and puts its whole orders on lines better (:mod:`gearshot.signal.ratio_check`): then
    the ridge again within 10 % of that speed where the evidence is clear (its whole
    orders :data:`_RATIO_SWITCH` times as strong) and that ridge passes every check, else
    a refusal naming both speeds."""
    lo, hi = _speed_range(kw["speed_range"])
    alts = _ratios_in_range((lo, hi), float(est.ridge.speed.min()),
                            float(est.ridge.speed.max()))
    if not alts:
        return est
    top = 2.0 * float(est.order if kw.get("track") is not None else _orders(kw["orders"])[0])
    scores = whole_order_scores(x, fs, est.times, est.angle, ratios=(1.0, *alts),
                                top_order=top)
    r = max(alts, key=lambda k: scores[k])
    own, other = scores[1.0], scores[r]
    if other <= own:
        return est
    speed = est.mean_speed
    if other >= _RATIO_SWITCH * own:
        narrow = (max(lo, (1.0 - _RATIO_RANGE) * r * speed),
                  min(hi, (1.0 + _RATIO_RANGE) * r * speed))
        try:
            return estimate_shaft_angle(x, fs, **dict(kw, speed_range=narrow))
        except GearshotError:
            pass
    raise GearshotError(
        f"the speed is ambiguous in {kw['label']}: the mesh comb locks at {speed:.4g} rev/s "
        f"(order {est.order}, {est.snr_db:.1f} dB above the noise in its band), but "
        f"{r:.3g} times that, {r * speed:.4g} rev/s, is in the speed range too and puts "
        f"its whole orders on lines better ({other:.1f} against {own:.1f} dB per order in "
        f"the record's order spectrum); give a narrower speed range or the nominal speed")


def _own_harmonics(result: _Pass, ridge_kw: dict[str, Any], fs: float) -> list[int]:
    """Harmonics of the shaft's own mesh to fuse (none where ``track`` names the order)."""
    if ridge_kw.get("track") is not None:
        return []
    own = _orders(ridge_kw["orders"])[0]
    top = float(result.ridge.speed.max())
    return [h * own for h in range(1, int(ridge_kw["n_harmonics"]) + 1)
            if h * own * top < 0.45 * fs]
