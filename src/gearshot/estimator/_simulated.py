"""Steps 4–6 of the simulated side in the frequency domain, block by block of signals.

Propagation (step 4), the RMS scale (step 5), the reference subtraction (step 6) and the
matched noise are linear in the signals: a signal's difference is built as its one-sided
spectrum, ``rfft(sa - reference) · H / scale + noise``, and the features start from that
spectrum (:func:`gearshot.features.spectrum_features`): one forward FFT per signal where
the steps one by one in the time domain take two more. Blocks of rows keep every
temporary in the cache.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._errors import GearshotError
from ..features import spectrum_features
from ..transfer.estimation import one_sided_response

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

#: Values per block of signals (1 MB of float64): the block's temporaries stay in cache.
_BLOCK_ELEMENTS = 1 << 17


def difference_features(sim_sa: FloatArray, reference: FloatArray, tf: ArrayLike | None,
                        scale: float, *, mesh_order: int | Sequence[int],
                        names: Sequence[str], noise: FloatArray | None = None,
                        noise_spectrum: ComplexArray | None = None) -> FloatArray:
    """Features of ``(sim_sa - reference)`` through ``tf``, divided by ``scale``, plus noise.

    Parameters
    ----------
    sim_sa : ndarray (n_signals, n_points)
    reference : ndarray (n_signals, n_points) or (n_points,)
        What step 6 subtracts: each signal's twin, or one healthy SA for all.
    tf : ndarray of complex (n_points,) or None
    scale : float
        Step 5's scale (1 without it).
    noise, noise_spectrum : ndarray, optional
        Residue added to the differences, as signals or as their ``rfft``.

    Returns
    -------
    ndarray (n_signals, n_features)
        Uncentred features.
    """
    n = sim_sa.shape[-1]
    factor: ComplexArray = np.asarray(1.0 / scale if tf is None
                                      else one_sided_response(tf) / scale, dtype=np.complex128)
    rows = max(1, _BLOCK_ELEMENTS // n)
    per_signal = reference.ndim == sim_sa.ndim
    common: ComplexArray = (np.zeros(0, np.complex128) if per_signal
                            else np.fft.rfft(reference, axis=-1) * factor)
    spec = np.empty(sim_sa.shape[:-1] + (n // 2 + 1,), dtype=np.complex128)
    for i in range(0, sim_sa.shape[0], rows):
        block = slice(i, i + rows)
        out = spec[block]
        if per_signal:
            np.fft.rfft(sim_sa[block] - reference[block], axis=-1, out=out)
        else:
            np.fft.rfft(sim_sa[block], axis=-1, out=out)
        out *= factor
        if not per_signal:
            out -= common
        if noise is not None:
            out += np.fft.rfft(noise[block], axis=-1)
        if noise_spectrum is not None:
            out += noise_spectrum[block]
    return spectrum_features(spec, n, mesh_order, names=names)


def residue_noise_spectrum(power: ArrayLike, n_signals: int, n_points: int,
                           rng: np.random.Generator) -> ComplexArray:
    """``rfft`` of Gaussian noise signals whose expected power spectrum is ``power``: white
    noise shaped in the frequency domain (:func:`gearshot.estimator.steps.residue_noise`
    is its inverse FFT)."""
    power = np.asarray(power, dtype=float)
    if power.shape != (n_points // 2 + 1,):
        raise GearshotError(f"power must have n_points // 2 + 1 = {n_points // 2 + 1} bins; "
                            f"got shape {power.shape}")
    white = rng.standard_normal((n_signals, n_points))
    return np.asarray(np.fft.rfft(white, axis=-1) * np.sqrt(power / n_points),
                      dtype=np.complex128)
