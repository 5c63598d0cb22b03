"""The phase step of :mod:`gearshot.signal.tracking`: one mesh harmonic demodulated around a
coarse speed (how much its phase wanders tells a line from noise), and the angle fused
from every harmonic of the shaft's own mesh that passes the same checks.

Each harmonic ``o`` of the mesh gives the shaft angle as its phase over ``2π o``; its noise
is ``σ_φ / (2π o)`` revolutions with ``σ_φ² = 1 / (2 snr)``, so the harmonics' angles are
averaged with weights ``snr · o²`` (inverse variances). A harmonic joins when its in-band
SNR and wander pass the tracker's thresholds and its angle never leaves the first one's
by half of its own cycle in the middle 80 % of the record (a slipped cycle, or another
line in its band, would); over the first and last 5 % of the record the first harmonic
alone (the zero-phase filters' edge errors grow with the order), with a half-cosine
over the next 2.5 %. On the PHM09 records the transmission error of each harmonic
differs, so their average follows the shaft better than any one of them
(``benchmarks/RESULTS.md``, "Machines without a tachometer").
"""

from __future__ import annotations

import dataclasses
import math
from typing import NamedTuple

import numpy as np

from .demodulation import demodulate_angle
from .ridge import SpeedRidge

__all__: list[str] = []

_SLIP = 0.5  # cycles of a harmonic its angle may leave the first one's by (a slip: 1)
_EDGE = 0.05  # the first harmonic alone over this fraction of the record at either end


class _Pass(NamedTuple):
    """One ridge (or profile) + phase pass of
    :func:`gearshot.signal.tracking.estimate_shaft_angle`; ``snr_eff``: the SNR the fused
    angle's noise corresponds to at ``ridge.order`` (None: one harmonic)."""

    ridge: SpeedRidge
    times: np.ndarray
    angle: np.ndarray
    snr: float
    speed: np.ndarray
    wander: float
    band: float
    snr_eff: float | None = None


def _db(snr: float) -> float:
    return 10.0 * math.log10(snr) if snr > 0 else -math.inf


def _inner(times: np.ndarray) -> np.ndarray:
    """The middle 80 % of the record (the zero-phase filters have both sides there)."""
    span = times[-1] - times[0]
    return np.asarray((times > times[0] + 0.1 * span) & (times < times[-1] - 0.1 * span))


def _phase_pass(x: np.ndarray, fs: float, ridge: SpeedRidge, bandwidth: float) -> _Pass:
    """Phase demodulation around ``ridge`` and how much the phase wanders about it."""
    import scipy.signal  # lazy: a one-record call need not import it
    times, angle, snr = demodulate_angle(x, fs, order=ridge.order, ridge_times=ridge.times,
                                         ridge_speed=ridge.speed, bandwidth=bandwidth)
    band = bandwidth * float(ridge.speed.min())
    speed = np.gradient(angle, times)
    # how fast the demodulated phase wanders about the (independent) coarse ridge: a
    # locked line barely moves, noise in the band sweeps it at ~band / sqrt(3)
    inner = _inner(times)
    ridge_at = np.interp(times, ridge.times, ridge.speed)
    # above band/4 only: slow errors of the coarse ridge are not noise (the phase step
    # corrects them), while noise's frequency wander lies almost all (98 %) up there
    diff = ridge.order * (speed - ridge_at)
    if times.size > 30:
        fs_d = 1.0 / (times[1] - times[0])
        hp = scipy.signal.butter(2, band / 4, btype="highpass", fs=fs_d, output="sos")
        diff = scipy.signal.sosfiltfilt(hp, diff)
    wander = float(np.std(diff[inner]) / band) if inner.any() else 0.0
    return _Pass(ridge, times, angle, snr, speed, wander, band)


def _fused(x: np.ndarray, fs: float, first: _Pass, harmonics: list[int], bandwidth: float,
           min_snr_db: float, max_wander: float) -> _Pass:
    """``first`` with its angle averaged with every one of ``harmonics`` (orders of the
    shaft's own mesh) that passes the checks (weights ``snr · o²``)."""
    inner = _inner(first.times)
    base = first.angle - first.angle[0]
    w0 = first.snr * first.ridge.order ** 2
    total, acc, gained = np.full(base.size, w0), w0 * base, 0.0
    taper = _taper(first.times)
    for order in harmonics:
        if order == first.ridge.order:
            continue
        other = _phase_pass(x, fs, dataclasses.replace(first.ridge, order=order), bandwidth)
        if _db(other.snr) < min_snr_db or other.wander > max_wander or \
                other.times.size != first.times.size:
            continue
        diff = other.angle - other.angle[0] - base
        diff -= np.median(diff[inner])
        if np.max(np.abs(diff[inner])) * order >= _SLIP:
            continue
        w = other.snr * order ** 2
        acc = acc + w * taper * (base + diff)  # its angle, aligned with the first's
        total = total + w * taper
        gained += w
    if gained == 0.0:
        return first
    angle = first.angle[0] + acc / total
    return first._replace(angle=angle, speed=np.gradient(angle, first.times),
                          snr_eff=(w0 + gained) / first.ridge.order ** 2)


def _taper(times: np.ndarray) -> np.ndarray:
    """0 over the first and last :data:`_EDGE` of the record, 1 from 1.5 ``_EDGE`` on, half a
    cosine between: the higher harmonics join only where their zero-phase filters have
    both sides (at the ends their angle errors grow with the order; on a synthetic
    run-up: 0.5, 1.5, 2.1 degrees at most for harmonics 1, 2, 3)."""
    span = times[-1] - times[0]
    u = np.minimum(times - times[0], times[-1] - times) / span  # 0 at the ends, 0.5 mid
    ramp = np.clip((u - _EDGE) / (0.5 * _EDGE), 0.0, 1.0)
    return np.asarray(0.5 - 0.5 * np.cos(np.pi * ramp))
