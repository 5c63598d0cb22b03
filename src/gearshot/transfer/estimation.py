"""Transfer-function estimate from one healthy signal, resampling and propagation."""

from __future__ import annotations

import numpy as np
import scipy.fft
from scipy.interpolate import CubicSpline

from .._errors import GearshotError
from .._validation import as_signal_array, check_int
from ..signal.cepstrum import minimum_phase
from ..signal.level import mean_rms, rms
from ..signal.spectra import acs_background, amplitude_spectrum

__all__ = [
    "estimate_transfer_function",
    "resample_transfer_function",
    "propagate",
    "propagate_spectrum",
    "one_sided_response",
    "rms",
    "mean_rms",
    "rms_normalize",
]


def resample_transfer_function(tf_one_sided, n_out) -> np.ndarray:
    """Resample a one-sided frequency response to the DFT grid of an ``n_out``-point signal.

    The reference implementation's normalized-axis resampling: the one-sided response
    ``H[0] (DC) … H[L-1] (last line, taken as Nyquist)`` is extended by its conjugate mirror
    to ``2L - 1`` points spread evenly over ``[0, 1]``; magnitude and unwrapped phase are
    interpolated by not-a-knot cubic splines at ``n_out`` points spread evenly over
    ``[0, 1]``; the first ``n_out // 2 + 1`` values are kept and completed with their
    conjugates so that bins ``1 … n_out - 1`` are Hermitian.

    Parameters
    ----------
    tf_one_sided : array_like of complex, shape (L,)
        One-sided frequency response, ``L >= 2``.
    n_out : int
        Length of the signals it will multiply in the DFT domain.

    Returns
    -------
    ndarray of complex, shape (n_out,)

    Examples
    --------
    >>> import numpy as np
    >>> from gearshot.transfer import resample_transfer_function
    >>> tf = resample_transfer_function(np.full(5, 2.0 + 0j), 8)    # a constant gain of 2
    >>> print(np.round(np.abs(tf), 3))
    [2. 2. 2. 2. 2. 2. 2. 2.]
    >>> bool(np.allclose(tf[1:], np.conj(tf[1:][::-1])))          # Hermitian: real signals
    True
    """
    tf = as_signal_array(tf_one_sided, "tf_one_sided", max_ndim=1, min_length=2,
                         allow_complex=True).astype(complex)
    n_out = check_int(n_out, "n_out", minimum=2)
    full = np.concatenate([tf, np.conj(tf[:0:-1])])
    axis_in = np.linspace(0.0, 1.0, full.size)
    axis_out = np.linspace(0.0, 1.0, n_out)
    with np.errstate(over="ignore"):
        modulus = np.abs(full)
    peak = float(np.max(modulus))
    if not np.isfinite(peak):
        raise GearshotError("tf_one_sided has magnitudes beyond the float range")
    # splines are linear in the data: scaling by a power of two is exact and keeps
    # slopes of huge values finite
    scale = 2.0 ** np.round(np.log2(peak)) if peak > 0 else 1.0
    magnitude = CubicSpline(axis_in, modulus / scale)(axis_out)
    phase = CubicSpline(axis_in, np.unwrap(np.angle(full)))(axis_out)
    with np.errstate(over="ignore", invalid="ignore"):
        half = (scale * magnitude * np.exp(1j * phase))[: n_out // 2 + 1]
    if not np.all(np.isfinite(half)):
        raise GearshotError("tf_one_sided is too large: its resampled values overflow")
    n_mirror = n_out - half.size
    return np.concatenate([half, np.conj(half[1:n_mirror + 1][::-1])])


def estimate_transfer_function(healthy_signal, n_out, *, nfft=2**15, segment_size=200,
                               overlap=0.75, percentile=50) -> np.ndarray:
    """Estimate the transfer path from one long healthy signal (paper step 3).

    Amplitude spectrum (rectangular segments of ``nfft``) → ACS background →
    cepstral minimum phase → one-sided half resampled to ``n_out`` points with
    :func:`resample_transfer_function`.

    Parameters
    ----------
    healthy_signal : array_like, shape (n_samples,)
        Long healthy signal in the cycle (angle) domain, ``n_samples >= nfft``.
    n_out : int
        Points per cycle of the signals to propagate (2048).
    nfft : int, default 2**15
    segment_size : int, default 200
    overlap : float, default 0.75
    percentile : float, default 50
        ACS parameters (see :func:`gearshot.signal.acs_background`).

    Returns
    -------
    ndarray of complex, shape (n_out,)
        Minimum-phase transfer-function estimate on the ``n_out``-point DFT grid.

    Examples
    --------
    White noise has a flat spectrum: the estimate is flat, near the noise's unit level
    (the median background sits a little below the mean). Noise through a low-pass is
    estimated falling with frequency.

    >>> import numpy as np
    >>> import scipy.signal
    >>> from gearshot.transfer import estimate_transfer_function
    >>> noise = np.random.default_rng(0).standard_normal(2**16)
    >>> tf = estimate_transfer_function(noise, 2048)
    >>> tf.shape
    (2048,)
    >>> bool(np.all((np.abs(tf) > 0.8) & (np.abs(tf) < 1.1)))
    True
    >>> low = estimate_transfer_function(scipy.signal.lfilter([1.0], [1.0, -0.9], noise), 2048)
    >>> bool(np.abs(low[1]) > 10 * np.abs(low[1024]))     # order 1 against Nyquist
    True
    """
    x = as_signal_array(healthy_signal, "healthy_signal", max_ndim=1)
    spectrum = amplitude_spectrum(x, nfft=nfft)
    background = acs_background(spectrum, segment_size=segment_size, overlap=overlap,
                                percentile=percentile)
    if not np.any(background > 0):
        raise GearshotError(
            "healthy_signal has no spectral background (a strictly periodic signal has "
            "energy only at its orders); the TF estimate needs non-synchronous content "
            "such as a real recording's noise")
    tf_mp = minimum_phase(background)
    return resample_transfer_function(tf_mp[: tf_mp.size // 2 + 1], n_out)


def propagate(signals, tf) -> np.ndarray:
    """Pass one-cycle periodic signals through a transfer function: ``real(IDFT(tf · DFT(x)))``.

    Parameters
    ----------
    signals : array_like, shape (..., n)
    tf : array_like of complex, shape (n,)
        Frequency response on the ``n``-point DFT grid (e.g. from
        :func:`resample_transfer_function`).

    Returns
    -------
    ndarray, shape (..., n)

    Examples
    --------
    A one-sample delay, ``exp(-2πi k / n)``, moves a cycle one sample later (circularly):

    >>> import numpy as np
    >>> from gearshot.transfer import propagate
    >>> k = np.fft.fftfreq(8, 1 / 8)
    >>> print(np.round(propagate(np.arange(8.0), np.exp(-2j * np.pi * k / 8)), 3) + 0.0)
    [7. 0. 1. 2. 3. 4. 5. 6.]
    """
    spectrum = propagate_spectrum(signals, tf)
    n = np.shape(signals)[-1]
    return scipy.fft.irfft(spectrum, n=n, axis=-1)


def propagate_spectrum(signals, tf) -> np.ndarray:
    """One-sided spectrum (``rfft``) of :func:`propagate` ``(signals, tf)``.

    For work that goes on in the frequency domain (the features start from a spectrum):
    ``propagate(x, tf)`` is ``irfft(propagate_spectrum(x, tf), n)`` bit for bit.

    Parameters
    ----------
    signals : array_like, shape (..., n)
    tf : array_like of complex, shape (n,)

    Returns
    -------
    ndarray of complex, shape (..., n // 2 + 1)

    Examples
    --------
    >>> import numpy as np
    >>> from gearshot.transfer import propagate, propagate_spectrum
    >>> x = np.random.default_rng(0).standard_normal((2, 16))
    >>> tf = np.fft.fft(np.r_[1.0, 0.5, np.zeros(14)])     # y[t] = x[t] + x[t - 1] / 2
    >>> y = np.fft.irfft(propagate_spectrum(x, tf), n=16)
    >>> bool(np.array_equal(y, propagate(x, tf)))
    True
    >>> bool(np.allclose(y, x + 0.5 * np.roll(x, 1, axis=-1)))
    True
    """
    signals = as_signal_array(signals, "signals", min_length=2)
    tf = as_signal_array(tf, "tf", max_ndim=1, allow_complex=True)
    if tf.shape[-1] != signals.shape[-1]:
        raise GearshotError(
            f"tf has {tf.shape[-1]} points but signals have {signals.shape[-1]} per cycle")
    return scipy.fft.rfft(signals, axis=-1) * one_sided_response(tf)


def one_sided_response(tf) -> np.ndarray:
    """The factor :func:`propagate` multiplies a real signal's ``rfft`` by.

    A real signal through ``tf`` is ``real(IDFT(tf X))``, the inverse DFT of the Hermitian
    part of ``tf X``, whose positive half is ``X_k (tf_k + conj(tf_{-k})) / 2``: one real
    FFT pair instead of complex ones.

    Parameters
    ----------
    tf : array_like of complex, shape (n,)
        Frequency response on the ``n``-point DFT grid.

    Returns
    -------
    ndarray of complex, shape (n // 2 + 1,)

    Examples
    --------
    A Hermitian response (that of a real impulse response) is its own Hermitian part:

    >>> import numpy as np
    >>> from gearshot.transfer import one_sided_response
    >>> tf = np.fft.fft([1.0, 0.5, 0.0, 0.0])
    >>> print(one_sided_response(tf))
    [1.5+0.j  1. -0.5j 0.5+0.j ]
    """
    tf = as_signal_array(tf, "tf", max_ndim=1, allow_complex=True)
    n = tf.shape[-1]
    return 0.5 * (tf + np.conj(tf[(-np.arange(n)) % n]))[: n // 2 + 1]


def rms_normalize(signals, reference) -> np.ndarray:
    """Divide signals by the mean RMS of reference signals (paper step 5).

    Parameters
    ----------
    signals : array_like, shape (..., n)
    reference : array_like, shape (..., m)
        Healthy signals of the same domain (target healthy SAs for target signals,
        healthy simulated SAs for simulated ones); the mean of their RMS values is the scale.

    Returns
    -------
    ndarray, shape (..., n)

    Examples
    --------
    The references' RMS values are 1 and 3, their mean 2:

    >>> from gearshot.transfer import rms_normalize
    >>> print(rms_normalize([[2.0, -2.0, 2.0, -2.0]], [[1.0, -1.0], [3.0, -3.0]]))
    [[ 1. -1.  1. -1.]]
    """
    signals = as_signal_array(signals, "signals")
    scale = mean_rms(as_signal_array(reference, "reference"))
    if scale <= 0:
        raise GearshotError("reference signals have zero RMS; cannot normalize by them")
    return signals / scale
