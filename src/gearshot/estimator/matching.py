"""Tuning the simulated side to the target's healthy recordings beyond the DIN grade.

A target SA is the gear's synchronous vibration through the path **plus** what averaging
50 cycles leaves of everything non-synchronous (sensor noise, other machine parts, the
path's ringing). Simulated SAs carry none of it. After step 6 a healthy target SA is
reduced to that residue alone (the aligned healthy reference of the same gear removes the
synchronous part), so the residue's power spectrum, per order, is measured directly from
the healthy recordings. :func:`residual_noise_power` estimates it; :func:`add_matched_noise`
adds noise of that spectrum to the simulated SAs (after steps 4–5, in the same RMS-
normalized units), so that both domains see the same noise in the difference signal.

This is the noise-level quantity of the lab's simulation tuning (PHM-BGU), measured from
the healthy data instead of searched.
"""

from __future__ import annotations

import numpy as np

from .._errors import GearshotError

__all__ = ["residual_noise_power", "add_matched_noise", "shrink_tf"]


def residual_noise_power(residuals):
    """Per-order noise power of one target SA from healthy step-6 residuals.

    Parameters
    ----------
    residuals : ndarray (n, n_points)
        Healthy target SAs after harmonic suppression (each minus an aligned healthy
        reference: the difference of two independent noise residues).

    Returns
    -------
    ndarray (n_points // 2 + 1,)
        ``E |rfft(noise)|²`` of the non-synchronous residue of **one** SA (half the
        residuals' mean power, which holds two residues).
    """
    res = np.atleast_2d(np.asarray(residuals, float))
    if res.shape[0] < 1 or res.shape[1] < 4:
        raise GearshotError(f"residuals must be (n >= 1, n_points >= 4); got {res.shape}")
    return 0.5 * np.mean(np.abs(np.fft.rfft(res, axis=-1)) ** 2, axis=0)


def add_matched_noise(signals, noise_power, rng):
    """Signals plus independent Gaussian noise whose per-order power is ``noise_power``.

    Parameters
    ----------
    signals : ndarray (m, n_points)
    noise_power : ndarray (n_points // 2 + 1,)
        One-sided ``E |rfft|²`` per order (from :func:`residual_noise_power`).
    rng : numpy.random.Generator

    Returns
    -------
    ndarray (m, n_points)
    """
    x = np.atleast_2d(np.asarray(signals, float))
    n = x.shape[-1]
    p = np.asarray(noise_power, float)
    if p.shape != (n // 2 + 1,):
        raise GearshotError(f"noise_power must have {n // 2 + 1} lines; got {p.shape}")
    z = (rng.standard_normal((x.shape[0], p.size))
         + 1j * rng.standard_normal((x.shape[0], p.size))) / np.sqrt(2)
    z[:, 0] = z[:, 0].real * np.sqrt(2)
    if n % 2 == 0:
        z[:, -1] = z[:, -1].real * np.sqrt(2)
    return x + np.fft.irfft(z * np.sqrt(p), n, axis=-1)


def shrink_tf(tf, exponent):
    """Minimum-phase TF of magnitude ``|tf| ** exponent``: the blind estimate shrunk
    towards a flat path (log-magnitude scaled by ``exponent``; 1 returns ``tf``)."""
    from .._validation import check_in_range
    from ..signal import minimum_phase

    exponent = check_in_range(exponent, "tf_exponent", 0, 1)
    if exponent == 1:
        return tf
    mag = np.abs(np.asarray(tf))
    return minimum_phase(np.maximum(mag, 1e-300) ** exponent)
