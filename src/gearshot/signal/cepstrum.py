"""Minimum-phase reconstruction from a magnitude by the real cepstrum."""

from __future__ import annotations

import numpy as np
import scipy.fft

from .._errors import GearshotError
from .._validation import as_signal_array, finite_result

__all__ = ["real_cepstrum", "minimum_phase"]


@finite_result
def real_cepstrum(magnitude) -> np.ndarray:
    """Real cepstrum ``IDFT(log |H|)`` of a two-sided magnitude, along the last axis."""
    magnitude = _checked_magnitude(magnitude)
    return scipy.fft.ifft(np.log(magnitude), axis=-1).real


def _checked_magnitude(magnitude):
    magnitude = np.abs(as_signal_array(magnitude, "magnitude", min_length=2,
                                       allow_complex=True))
    peak = magnitude.max(axis=-1, keepdims=True)
    if np.any(peak == 0):
        raise GearshotError("magnitude is zero everywhere; no minimum-phase response exists")
    # isolated zeros would give log(0) = -inf: floor them 240 dB below the peak
    return np.maximum(magnitude, peak * 1e-12)


@finite_result
def minimum_phase(magnitude) -> np.ndarray:
    """Minimum-phase frequency response with a given magnitude (real-cepstrum method).

    ``c = IDFT(log|H|)``; keep ``c[0]``, double ``c[1 … ceil((L-1)/2) - 1]``, zero the rest
    (the reference implementation's folding, which also zeroes the Nyquist quefrency);
    ``H_mp = exp(DFT(c))``.

    Parameters
    ----------
    magnitude : array_like, shape (..., L)
        Two-sided magnitude response (symmetric for a real system). Complex input is
        reduced to its modulus. Exact zeros are floored 240 dB below the peak.

    Returns
    -------
    ndarray of complex, shape (..., L)
        ``|H_mp| ≈ magnitude`` with the minimum phase.
    """
    magnitude = _checked_magnitude(magnitude)
    length = magnitude.shape[-1]
    cep = scipy.fft.ifft(np.log(magnitude), axis=-1)
    fold = np.zeros(length)
    fold[0] = 1.0
    fold[1:int(np.ceil((length - 1) / 2))] = 2.0
    return np.exp(scipy.fft.fft(cep * fold, axis=-1))
