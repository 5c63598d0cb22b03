"""Non-synchronous interference and sensor noise added by the virtual rig.

None of these components is periodic in the driven gear's angle, so synchronous averaging
attenuates them (by about sqrt(cycles) for the random ones) -- but never removes them.
"""

from __future__ import annotations

import numpy as np
import scipy.signal

from .._validation import check_positive
from ..signal.level import rms

__all__ = ["motor_harmonics", "extra_shaft", "bearing_impacts", "add_noise"]


def motor_harmonics(t: np.ndarray, *, speed: float, pole_pairs: int, slip: float,
                    rng: np.random.Generator, n_harmonics: int = 3) -> np.ndarray:
    """Electromagnetic vibration of an induction motor, unit RMS.

    The supply runs at ``f_e = pole_pairs * speed / (1 - slip)`` (constant: the drive holds
    its frequency while the shaft speed drifts); the magnetic pull vibrates at 2 f_e and
    its harmonics 4 f_e, 6 f_e, ... with decaying random amplitudes and random phases.
    """
    f_e = pole_pairs * check_positive(speed, "speed") / (1.0 - slip)
    k = np.arange(1, n_harmonics + 1)
    amp = rng.uniform(0.5, 1.0, n_harmonics) / k
    phase = rng.uniform(-np.pi, np.pi, n_harmonics)
    x = np.zeros_like(np.asarray(t, dtype=np.float64))
    for a, h, p in zip(amp, k, phase):
        x += a * np.cos(2 * np.pi * 2 * h * f_e * t + p)
    return x / max(float(rms(x)), 1e-300)


def extra_shaft(input_revs: np.ndarray, *, order: float, rng: np.random.Generator
                ) -> np.ndarray:
    """An extra shaft turning at a non-integer ``order`` of the input shaft (e.g. a belt
    drive or a fan): its first two harmonics, unit RMS. It follows the speed variation."""
    p1, p2 = rng.uniform(-np.pi, np.pi, 2)
    a2 = rng.uniform(0.2, 0.6)
    ang = 2 * np.pi * order * np.asarray(input_revs, dtype=np.float64)
    x = np.cos(ang + p1) + a2 * np.cos(2 * ang + p2)
    return x / max(float(rms(x)), 1e-300)


def bearing_impacts(input_revs: np.ndarray, fs: float, *, order: float, frequency: float,
                    rng: np.random.Generator, damping: float = 0.03,
                    spacing_jitter: float = 0.02) -> np.ndarray:
    """Bearing-like impacts ringing a resonance, unit RMS.

    About ``order`` impacts per input revolution, their spacing jittered by
    ``spacing_jitter`` (relative; slip of rolling elements) and amplitudes log-normal
    (sigma 0.5). Each impact rings a resonance at ``frequency`` Hz with damping ratio
    ``damping``. Impacts are placed to the nearest sample.
    """
    revs = np.asarray(input_revs, dtype=np.float64)
    span = revs[-1] - revs[0]
    n_imp = int(span * order * 1.2) + 2
    steps = (1.0 / order) * (1.0 + spacing_jitter * rng.standard_normal(n_imp))
    at = revs[0] + rng.uniform(0, 1.0 / order) + np.cumsum(np.maximum(steps, 0.1 / order))
    at = at[at < revs[-1]]
    idx = np.clip(np.searchsorted(revs, at), 0, revs.size - 1)
    pulses = np.zeros_like(revs)
    np.add.at(pulses, idx, rng.lognormal(0.0, 0.5, idx.size))
    w0 = 2 * np.pi * check_positive(frequency, "frequency")
    # resonance s*w0 / (s^2 + 2 zeta w0 s + w0^2), discretized (bilinear, prewarped)
    b, a = scipy.signal.bilinear([w0, 0.0], [1.0, 2 * damping * w0, w0 ** 2], fs=fs)
    x = scipy.signal.lfilter(b, a, pulses)
    return x / max(float(rms(x)), 1e-300)


def add_noise(x: np.ndarray, *, snr_db: float, rng: np.random.Generator) -> np.ndarray:
    """``x`` plus white Gaussian noise at signal-to-noise ratio ``snr_db`` (RMS based)."""
    sigma = rms(x) / 10.0 ** (snr_db / 20.0)
    return x + sigma * rng.standard_normal(np.shape(x))
