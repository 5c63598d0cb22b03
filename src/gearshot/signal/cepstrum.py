"""Minimum-phase reconstruction from a magnitude by the real cepstrum."""

from __future__ import annotations

from typing import cast

import numpy as np
import scipy.fft
from numpy.typing import ArrayLike

from .._errors import GearshotError
from .._typing import ComplexArray, FloatArray
from .._validation import as_signal_array, finite_result

__all__ = ["real_cepstrum", "minimum_phase"]


@finite_result
def real_cepstrum(magnitude: ArrayLike) -> FloatArray:
    """Real cepstrum ``IDFT(log |H|)`` of a two-sided magnitude, along the last axis.

    Examples
    --------
    The system ``1 + 0.5 z^-1``: its cepstrum is half the series of ``log(1 + 0.5 z^-1)``,
    ``0.5 / 2``, ``-0.125 / 2``, ``0.0417 / 2``, …

    >>> import numpy as np
    >>> from gearshot.signal import real_cepstrum
    >>> h = np.zeros(64)
    >>> h[:2] = [1.0, 0.5]
    >>> print(np.round(real_cepstrum(np.abs(np.fft.fft(h)))[:4], 4) + 0.0)
    [ 0.      0.25   -0.0625  0.0208]
    """
    checked = _checked_magnitude(magnitude)
    return cast(FloatArray, scipy.fft.ifft(np.log(checked), axis=-1).real)


def _checked_magnitude(magnitude: ArrayLike) -> FloatArray:
    mag = np.abs(as_signal_array(magnitude, "magnitude", min_length=2, allow_complex=True))
    peak = mag.max(axis=-1, keepdims=True)
    if np.any(peak == 0):
        raise GearshotError("magnitude is zero everywhere; no minimum-phase response exists")
    # isolated zeros would give log(0) = -inf: floor them 240 dB below the peak
    return cast(FloatArray, np.maximum(mag, peak * 1e-12))


@finite_result
def minimum_phase(magnitude: ArrayLike) -> ComplexArray:
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

    Examples
    --------
    ``0.5 + z^-1`` (maximum phase) and ``1 + 0.5 z^-1`` (minimum phase) share one
    magnitude; the reconstruction is the minimum-phase one:

    >>> import numpy as np
    >>> from gearshot.signal import minimum_phase
    >>> h = np.zeros(64)
    >>> h[:2] = [0.5, 1.0]
    >>> h_mp = minimum_phase(np.abs(np.fft.fft(h)))
    >>> print(np.round(np.fft.ifft(h_mp).real[:4], 3) + 0.0)
    [1.  0.5 0.  0. ]
    """
    checked = _checked_magnitude(magnitude)
    length = checked.shape[-1]
    cep = scipy.fft.ifft(np.log(checked), axis=-1)
    fold = np.zeros(length)
    fold[0] = 1.0
    fold[1:int(np.ceil((length - 1) / 2))] = 2.0
    return cast(ComplexArray, np.exp(scipy.fft.fft(cep * fold, axis=-1)))
