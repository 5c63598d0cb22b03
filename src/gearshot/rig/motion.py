"""Time-varying speed and load of a rig run: slow drift, once-per-revolution ripple."""

from __future__ import annotations

import numpy as np

from .._errors import GearshotError
from .._validation import check_positive

__all__ = ["motor_angle", "ramp_angle", "load_torque"]


def motor_angle(t: np.ndarray, *, speed: float, drift: float, ripple: float,
                rng: np.random.Generator, start: float = 0.0) -> np.ndarray:
    """Input-shaft angle (revolutions) for a speed with slow drift and per-rev ripple.

    The speed is ``speed * (1 + d(t)) * (1 + ripple * cos(2 pi theta + phi))``: ``d`` is a
    sum of three slow sinusoids (periods 5-40 s, random phases) scaled so that
    ``max |d| = drift`` over the run; the ripple is once per input revolution. The angle is
    integrated in closed form (to first order in ``ripple``), so it is smooth and exact
    at every sample.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Sample times, s (from 0).
    speed : float
        Mean input speed, rev/s.
    drift, ripple : float
        Fractions (e.g. 0.01 = 1 %).
    rng : numpy.random.Generator
        Draws the drift periods and phases and the ripple phase.
    start : float
        Angle at t = 0, revolutions.

    Returns
    -------
    ndarray, shape (n,)
    """
    speed = check_positive(speed, "speed")
    t = np.asarray(t, dtype=np.float64)
    periods = rng.uniform(5.0, 40.0, 3)
    phases = rng.uniform(-np.pi, np.pi, 3)
    weights = rng.uniform(0.5, 1.0, 3)
    w = 2 * np.pi / periods
    d = (weights[:, None] * np.sin(w[:, None] * t + phases[:, None])).sum(0)
    scale = drift / max(float(np.max(np.abs(d))), 1e-12)
    # integral of speed * d(t) dt
    d_int = (weights[:, None] / w[:, None]
             * (np.cos(phases[:, None]) - np.cos(w[:, None] * t + phases[:, None]))).sum(0)
    theta0 = speed * (t + scale * d_int)
    phi = float(rng.uniform(-np.pi, np.pi))
    ripple_term = ripple / (2 * np.pi) * (np.sin(2 * np.pi * theta0 + phi) - np.sin(phi))
    return start + theta0 + ripple_term


def ramp_angle(t: np.ndarray, *, speed: float, end_speed: float, t_start: float,
               t_end: float, ripple: float, rng: np.random.Generator,
               start: float = 0.0) -> np.ndarray:
    """Input-shaft angle (revolutions) of a run-up or run-down with a per-rev ripple.

    The speed is ``speed`` until ``t_start``, changes linearly to ``end_speed`` at
    ``t_end`` and stays there, times ``(1 + ripple * cos(2 pi theta + phi))``; the angle
    is integrated in closed form (to first order in ``ripple``).

    Parameters
    ----------
    t : ndarray, shape (n,)
        Sample times, s.
    speed, end_speed : float
        Speeds before and after the ramp, rev/s (> 0).
    t_start, t_end : float
        Start and end of the ramp, s (``t_start < t_end``).
    ripple : float
        Once-per-revolution speed ripple, a fraction.
    rng : numpy.random.Generator
        Draws the ripple phase.
    start : float
        Angle at t = 0, revolutions.

    Returns
    -------
    ndarray, shape (n,)
    """
    speed = check_positive(speed, "speed")
    end_speed = check_positive(end_speed, "end_speed")
    if not t_end > t_start:
        raise GearshotError(f"t_end must be after t_start; got t_start={t_start}, "
                            f"t_end={t_end}")
    t = np.asarray(t, dtype=np.float64)
    a = (end_speed - speed) / (t_end - t_start)  # rev/s^2
    tc = np.clip(t, t_start, t_end)
    theta0 = speed * t + 0.5 * a * (tc - t_start) ** 2 + (end_speed - speed) * np.maximum(
        t - t_end, 0.0)
    phi = float(rng.uniform(-np.pi, np.pi))
    ripple_term = ripple / (2 * np.pi) * (np.sin(2 * np.pi * theta0 + phi) - np.sin(phi))
    return start + theta0 + ripple_term


def load_torque(gear_revs: np.ndarray, *, load: float, ripple: float,
                rng: np.random.Generator) -> np.ndarray:
    """Load torque (N m) with a once-per-output-revolution ripple of relative size ``ripple``
    (plus a weaker second harmonic), as an eccentric brake coupling would give."""
    phi1, phi2 = rng.uniform(-np.pi, np.pi, 2)
    g = 2 * np.pi * np.asarray(gear_revs, dtype=np.float64)
    return load * (1.0 + ripple * np.sin(g + phi1) + 0.3 * ripple * np.sin(2 * g + phi2))
