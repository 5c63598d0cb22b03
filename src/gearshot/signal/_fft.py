"""FFTs for the signal steps, on :mod:`numpy.fft` (no SciPy import on the one-record path).

``numpy.fft`` and :mod:`scipy.fft` run the same pocketfft code: ``rfft``/``irfft`` and the
complex transforms of complex input agree bit for bit. For *real* input SciPy's complex
transforms take the real-input algorithm and fill the negative frequencies by conjugate
symmetry; :func:`fft` and :func:`ifft` do the same, so every result stays identical to the
SciPy one it replaces. :func:`next_fast_len` is SciPy's ``next_fast_len(n, real=True)``:
the smallest 5-smooth number (2^a 3^b 5^c) not below ``n``.
"""

from __future__ import annotations

import numpy as np

from .._typing import ComplexArray

__all__ = ["fft", "ifft", "next_fast_len"]


def next_fast_len(n: int) -> int:
    """Smallest 2^a 3^b 5^c ≥ ``n`` (``n`` ≥ 1): a fast real-FFT length.

    Examples
    --------
    >>> from gearshot.signal._fft import next_fast_len
    >>> [next_fast_len(n) for n in (1, 7, 97, 1001, 266656)]
    [1, 8, 100, 1024, 270000]
    """
    best = 1 << max(0, (n - 1).bit_length())
    p5 = 1
    while p5 < best:
        p35 = p5
        while p35 < best:
            m = p35
            while m < n:
                m *= 2
            best = min(best, m)
            p35 *= 3
        p5 *= 5
    return best


def _real_to_full(half: ComplexArray, n: int) -> ComplexArray:
    """The full spectrum of a real signal of ``n`` points from its one-sided half."""
    out = np.empty(half.shape[:-1] + (n,), dtype=half.dtype)
    k = half.shape[-1]
    out[..., :k] = half
    np.conjugate(half[..., 1:n - k + 1][..., ::-1], out=out[..., k:])
    return out


def fft(x: np.ndarray, axis: int = -1) -> ComplexArray:
    """Discrete Fourier transform along ``axis`` (as :func:`scipy.fft.fft`, bit for bit)."""
    if np.iscomplexobj(x):
        return np.fft.fft(x, axis=axis)
    x = np.moveaxis(np.asarray(x, dtype=np.float64), axis, -1)
    full = _real_to_full(np.fft.rfft(x, axis=-1), x.shape[-1])
    return np.moveaxis(full, -1, axis)


def ifft(x: np.ndarray, axis: int = -1) -> ComplexArray:
    """Inverse discrete Fourier transform along ``axis`` (as :func:`scipy.fft.ifft`)."""
    if np.iscomplexobj(x):
        return np.fft.ifft(x, axis=axis)
    x = np.moveaxis(np.asarray(x, dtype=np.float64), axis, -1)
    n = x.shape[-1]
    full = _real_to_full(np.conj(np.fft.rfft(x, axis=-1)) / n, n)
    return np.moveaxis(full, -1, axis)
