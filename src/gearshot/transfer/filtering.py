"""Filter long time-domain recordings through a transfer function at physical frequencies."""

from __future__ import annotations

import numpy as np
from scipy.signal import oaconvolve

from .._errors import GearshotError
from .._validation import as_signal_array, check_in_range, check_int, check_positive
from .function import TransferFunction

__all__ = ["fir_from_transfer_function", "filter_signal"]


def fir_from_transfer_function(tf: TransferFunction, fs: float, *, n_taps: int | None = None,
                               outside: str = "error", method: str = "linear") -> np.ndarray:
    """Periodic impulse response of ``tf`` at sampling rate ``fs`` (one period).

    The TF is interpolated (:meth:`TransferFunction.at`) on the ``n_taps``-point DFT grid
    0, fs/n_taps, …, fs/2 and inverse-transformed. Sample ``k`` is the response at time
    ``k / fs`` for ``k < n_taps - n_acausal`` and at ``(k - n_taps) / fs`` (before the input)
    for the last samples; :func:`filter_signal` places them accordingly.

    Parameters
    ----------
    tf : TransferFunction
        The FRF, in output units per input unit.
    fs : float
        Sampling rate in Hz.
    n_taps : int, optional
        FIR length (even). Default: the smallest even length whose grid spacing fs/n_taps is
        at most the TF's line spacing, i.e. an impulse response as long as the record the
        FRF was measured from.
    outside, method
        Passed to :meth:`TransferFunction.at` (what to do above the measured band when
        fs/2 exceeds it, and how to interpolate between lines).

    Returns
    -------
    numpy.ndarray, shape (n_taps,)
        Impulse response samples (per sample: a unit-sample input gives this output).

    Examples
    --------
    A flat gain of 0.5 up to 500 Hz at 1 kHz: a single tap of 0.5.

    >>> import numpy as np
    >>> from gearshot.transfer import TransferFunction, fir_from_transfer_function
    >>> flat = TransferFunction(np.linspace(0.0, 500.0, 501), np.full(501, 0.5 + 0j))
    >>> taps = fir_from_transfer_function(flat, 1000.0)
    >>> taps.shape
    (1000,)
    >>> print(np.round(taps[:3], 3) + 0.0)
    [0.5 0.  0. ]
    """
    if not isinstance(tf, TransferFunction):
        raise GearshotError(f"tf must be a TransferFunction; got {type(tf).__name__}")
    fs = check_positive(fs, "fs")
    if n_taps is None:
        n_taps = 2 * int(np.ceil(fs / (2 * tf.df) - 1e-9))
    n_taps = check_int(n_taps, "n_taps", minimum=2)
    if n_taps % 2:
        raise GearshotError(f"n_taps must be even; got {n_taps}")
    grid = np.fft.rfftfreq(n_taps, 1.0 / fs)
    h = tf.at(grid, outside=outside, method=method)
    h[-1] = h[-1].real  # the Nyquist line of a real filter is real
    return np.fft.irfft(h, n_taps)


def filter_signal(x, fs: float, tf: TransferFunction, *, n_taps: int | None = None,
                  acausal_fraction: float = 0.125, outside: str = "error",
                  method: str = "linear") -> np.ndarray:
    """Pass a long recording through ``tf`` (linear convolution, no wrap-around).

    The periodic impulse response from :func:`fir_from_transfer_function` is unwrapped into
    a linear FIR covering times ``-n_acausal/fs … (n_taps - n_acausal - 1)/fs`` with
    ``n_acausal = round(acausal_fraction * n_taps)`` (a measured or band-limited FRF rings a
    little before t = 0: the Nyquist-line truncation of a non-band-limited response, or an
    estimation artefact), and applied by overlap-add (:func:`scipy.signal.oaconvolve`).
    The output is aligned with the input (sample ``t`` of the output is the response at
    ``t / fs``) and computed by full linear convolution: the system starts at rest and
    nothing from the end of the record leaks back to its start.

    Parameters
    ----------
    x : array_like, shape (..., n_samples)
        Input signal(s) along the last axis (e.g. force in N), sampled at ``fs``.
    fs : float
        Sampling rate in Hz.
    tf : TransferFunction
        Frequency axis in Hz (physical frequencies, unlike
        :meth:`~TransferFunction.to_signal_grid`).
    n_taps : int, optional
        See :func:`fir_from_transfer_function`.
    acausal_fraction : float
        Share of the impulse-response period treated as negative time, in [0, 0.5].
        0 gives a strictly causal FIR.
    outside, method
        See :func:`fir_from_transfer_function`.

    Returns
    -------
    numpy.ndarray, shape (..., n_samples)
        The filtered signal(s) in the TF's output units.

    Examples
    --------
    >>> import numpy as np
    >>> from gearshot.transfer import TransferFunction, filter_signal
    >>> flat = TransferFunction(np.linspace(0.0, 500.0, 501), np.full(501, 0.5 + 0j))
    >>> x = np.sin(2 * np.pi * 50 * np.arange(1000) / 1000.0)
    >>> bool(np.allclose(filter_signal(x, 1000.0, flat), 0.5 * x))
    True
    """
    x = as_signal_array(x, "x", min_ndim=1)
    acausal_fraction = check_in_range(acausal_fraction, "acausal_fraction", 0.0, 0.5)
    h = fir_from_transfer_function(tf, fs, n_taps=n_taps, outside=outside, method=method)
    n_acausal = int(round(acausal_fraction * h.size))
    h = np.roll(h, n_acausal)          # now h[j] is the response at (j - n_acausal) / fs
    n = x.shape[-1]
    h = h.reshape((1,) * (x.ndim - 1) + (-1,))
    y = oaconvolve(x, h, mode="full", axes=-1)
    return np.ascontiguousarray(y[..., n_acausal:n_acausal + n])
