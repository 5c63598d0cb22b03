"""Amplitude spectrum and its ACS background (the smooth floor under tones)."""

from __future__ import annotations

from typing import cast

import numpy as np
import scipy.fft
from numpy.lib.stride_tricks import sliding_window_view
from numpy.typing import ArrayLike

from .._errors import GearshotError
from .._typing import FloatArray
from .._validation import MAX_POINTS, as_signal_array, check_in_range, check_int, finite_result

__all__ = ["amplitude_spectrum", "acs_background"]


@finite_result
def amplitude_spectrum(x: ArrayLike, *, nfft: int = 2**15) -> FloatArray:
    """Averaged amplitude spectrum over non-overlapping rectangular segments.

    ``sqrt(sum_s |FFT(x_s)|^2 / (n_segments * nfft))`` over the ``n_segments = len(x) // nfft``
    consecutive segments ``x_s`` (a trailing partial segment is ignored).

    Parameters
    ----------
    x : array_like, shape (..., n_samples)
        Long signal(s), ``n_samples >= nfft``.
    nfft : int, default 2**15
        Segment (and FFT) length.

    Returns
    -------
    ndarray, shape (..., nfft)
        Two-sided amplitude spectrum (index k ↔ k/nfft of the sampling rate).

    Examples
    --------
    A unit cosine at bin 4 of 16-point segments: amplitude sqrt(nfft)/2 = 2 at bins 4
    and 16 - 4, nothing elsewhere.

    >>> import numpy as np
    >>> from gearshot.signal import amplitude_spectrum
    >>> x = np.cos(2 * np.pi * 4 * np.arange(64) / 16)
    >>> print(np.round(amplitude_spectrum(x, nfft=16), 3) + 0.0)
    [0. 0. 0. 0. 2. 0. 0. 0. 0. 0. 0. 0. 2. 0. 0. 0.]
    """
    nfft = check_int(nfft, "nfft", minimum=2, maximum=MAX_POINTS)
    x = as_signal_array(x, "x")
    n_seg = x.shape[-1] // nfft
    if n_seg < 1:
        raise GearshotError(
            f"x has {x.shape[-1]} samples, fewer than one segment of nfft={nfft}")
    segs = x[..., : n_seg * nfft].reshape(*x.shape[:-1], n_seg, nfft)
    if np.iscomplexobj(segs):
        power = (np.abs(scipy.fft.fft(segs, axis=-1)) ** 2).sum(axis=-2)
    else:  # |X_{n-k}| = |conj X_k| = |X_k|: the one-sided half, mirrored
        half = (np.abs(np.fft.rfft(segs, axis=-1)) ** 2).sum(axis=-2)
        power = np.empty(half.shape[:-1] + (nfft,))
        k = half.shape[-1]
        power[..., :k] = half
        power[..., k:] = half[..., 1:nfft - k + 1][..., ::-1]
    return cast(FloatArray, np.sqrt(power / (n_seg * nfft)))


@finite_result
def acs_background(spectrum: ArrayLike, *, segment_size: int = 200, overlap: float = 0.75,
                   percentile: float = 50, symmetric: bool = True) -> FloatArray:
    """Background of a spectrum by segment percentiles (the reference's ACS).

    The spectrum is cut into segments of ``segment_size`` bins advancing by
    ``round(segment_size * (1 - overlap))``; each segment's ``percentile`` (Hazen
    definition, as MATLAB's ``prctile``) is placed at the segment centre and the centres are
    joined by PCHIP interpolation. Bins before the first centre take the first segment's
    value, bins after the last centre the last one's. With ``symmetric=True`` the first half
    (bins ``0 … L/2``) is mirrored onto the second, so the result is the background of a
    real signal's two-sided spectrum.

    Parameters
    ----------
    spectrum : array_like, shape (..., L)
        Amplitude spectrum (e.g. from :func:`amplitude_spectrum`).
    segment_size : int, default 200
        Bins per segment; at most ``L``.
    overlap : float, default 0.75
        Fraction of a segment shared with the next, in [0, 1).
    percentile : float, default 50
        Percentile taken in each segment, in [0, 100].
    symmetric : bool, default True
        Mirror the first half onto the second.

    Returns
    -------
    ndarray, shape (..., L)

    Examples
    --------
    A flat floor with one tone: the median of each segment ignores the tone.

    >>> import numpy as np
    >>> from gearshot.signal import acs_background
    >>> spectrum = np.ones(100)
    >>> spectrum[30] = 50.0
    >>> background = acs_background(spectrum, segment_size=20)
    >>> print(np.round(background[[0, 30, 70]], 3))
    [1. 1. 1.]
    """
    spectrum = as_signal_array(spectrum, "spectrum", min_length=2)
    length = spectrum.shape[-1]
    segment_size = check_int(segment_size, "segment_size", minimum=2)
    if segment_size > length:
        raise GearshotError(
            f"segment_size={segment_size} is larger than the spectrum ({length} bins)")
    overlap = check_in_range(overlap, "overlap", 0.0, 1.0, high_inclusive=False)
    percentile = check_in_range(percentile, "percentile", 0.0, 100.0)
    step = max(1, int(round(segment_size * (1.0 - overlap))))

    windows = sliding_window_view(spectrum, segment_size, axis=-1)[..., ::step, :]
    values = np.percentile(windows, percentile, axis=-1, method="hazen")
    centres = (segment_size - 1) / 2.0 + step * np.arange(values.shape[-1])  # 0-based
    grid = np.arange(length, dtype=float)
    if values.shape[-1] == 1:
        background = np.broadcast_to(values, spectrum.shape).copy()
    else:
        from scipy.interpolate import PchipInterpolator

        background = PchipInterpolator(centres, values, axis=-1, extrapolate=False)(grid)
        before, after = grid < centres[0], grid > centres[-1]
        background[..., before] = values[..., :1]
        background[..., after] = values[..., -1:]
    if symmetric and length > 2:
        half = length // 2
        background[..., half + 1:] = background[..., 1:length - half][..., ::-1]
    return background
