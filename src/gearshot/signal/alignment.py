"""Harmonic suppression by delay-aligned subtraction of healthy references."""

from __future__ import annotations

from typing import Literal, cast, overload

import numpy as np
import scipy.fft
from numpy.typing import ArrayLike

from .._errors import GearshotError
from .._typing import ComplexArray, FloatArray, IntArray
from .._validation import as_signal_array, check_int, describe, finite_result
from ._lag_search import _LagSearch, contenders, roots

__all__ = ["fractional_shift", "subtract_with_lags", "subtract_healthy"]


def _shift_factors(n: int, tau: FloatArray) -> ComplexArray:
    """Spectral factors that advance a band-limited n-periodic signal by ``tau`` samples.

    ``x(t + tau)`` ↔ ``X_k exp(2πi k tau / n)``; the Nyquist bin of an even ``n`` is split
    evenly between ±n/2 (as frequency-domain interpolation does), giving ``cos(π tau)``.
    """
    k = np.fft.fftfreq(n, 1.0 / n)
    factors = np.exp(2j * np.pi * np.multiply.outer(tau, k) / n)
    if n % 2 == 0:
        factors[..., n // 2] = np.cos(np.pi * tau)
    return cast(ComplexArray, factors)


@finite_result
def fractional_shift(x: ArrayLike, delay: ArrayLike) -> FloatArray:
    """Circularly delay signals by a (fractional) number of samples.

    Band-limited (Fourier) interpolation: ``y(t) = x(t - delay)`` for the periodic,
    band-limited signal through the samples of ``x``.

    Parameters
    ----------
    x : array_like, shape (..., n)
        One cycle of periodic signal(s).
    delay : float or array_like broadcastable to ``x.shape[:-1]``
        Delay in samples (positive delays move features later).

    Returns
    -------
    ndarray, shape (..., n)

    Examples
    --------
    >>> import numpy as np
    >>> from gearshot.signal import fractional_shift
    >>> print(np.round(fractional_shift([0.0, 1.0, 0.0, 0.0], 1), 3) + 0.0)
    [0. 0. 1. 0.]
    >>> theta = np.arange(64) / 64
    >>> half = fractional_shift(np.cos(2 * np.pi * 3 * theta), 0.5)   # half a sample later
    >>> bool(np.allclose(half, np.cos(2 * np.pi * 3 * (theta - 0.5 / 64))))
    True
    """
    x = as_signal_array(x, "x", min_length=2)
    if isinstance(delay, (str, bytes)):
        raise GearshotError(f"delay must be a number of samples; got {describe(delay)}")
    try:
        tau = np.asarray(delay, dtype=float)
    except (TypeError, ValueError):
        raise GearshotError(f"delay must be a number of samples or an array of them; got "
                            f"{describe(delay)}") from None
    if not np.all(np.isfinite(tau)) or np.any(np.abs(tau) > 1e12):
        raise GearshotError(f"delay must be finite and at most 1e12 samples in magnitude; "
                            f"got {describe(delay)}")
    try:
        fits = np.broadcast_shapes(tau.shape, x.shape[:-1]) == x.shape[:-1]
    except ValueError:
        fits = False
    if not fits:
        raise GearshotError(f"delay of shape {tau.shape} does not broadcast to the batch "
                            f"shape {x.shape[:-1]} of x (shape {x.shape})")
    n = x.shape[-1]
    spectrum = scipy.fft.fft(x, axis=-1) * _shift_factors(n, -tau)
    return cast(FloatArray, scipy.fft.ifft(spectrum, axis=-1).real)


def _grid_shift_factors(n: int, steps: IntArray, upsample: int) -> ComplexArray:
    """:func:`_shift_factors` for delays ``steps / upsample`` samples with integer ``steps``:
    ``exp(2πi·k·steps/(n·upsample))`` looked up in a table of the ``n·upsample`` roots of
    unity (the argument reduced exactly; equal to the direct ``exp`` to ~1e-12)."""
    k = np.fft.fftfreq(n, 1.0 / n).astype(np.int64)
    factors = roots(n * upsample)[np.multiply.outer(steps, k) % (n * upsample)]
    if n % 2 == 0:
        factors[..., n // 2] = np.cos(np.pi * (steps / upsample))
    return cast(ComplexArray, factors)


@overload
def subtract_healthy(signals: ArrayLike, healthy_refs: ArrayLike, *, upsample: int = ...,
                     return_details: Literal[False] = ...) -> FloatArray: ...


@overload
def subtract_healthy(signals: ArrayLike, healthy_refs: ArrayLike, *, upsample: int = ...,
                     return_details: Literal[True]) -> tuple[FloatArray, IntArray, FloatArray]:
    ...


@overload
def subtract_healthy(signals: ArrayLike, healthy_refs: ArrayLike, *, upsample: int = ...,
                     return_details: bool) -> FloatArray | tuple[FloatArray, IntArray,
                                                                 FloatArray]: ...


@finite_result
def subtract_healthy(signals: ArrayLike, healthy_refs: ArrayLike, *, upsample: int = 100,
                     return_details: bool = False
                     ) -> FloatArray | tuple[FloatArray, IntArray, FloatArray]:
    """Suppress the gear-mesh pattern by subtracting the best delay-aligned healthy SA.

    For every signal and every healthy reference, the circular delay that maximizes
    their cross-correlation is found on a grid of ``1/upsample`` sample (frequency-domain
    interpolation ×``upsample``). The signal is advanced by that delay, the reference
    subtracted, and the residual moved back by the same delay. Of all references, the
    one leaving the smallest residual energy is used — the reference implementation's
    harmonic suppression for target signals.

    Parameters
    ----------
    signals : array_like, shape (..., n)
        Synchronous averages to treat.
    healthy_refs : array_like, shape (n_refs, n) or (n,)
        Healthy synchronous averages of the same machine and condition.
    upsample : int, default 100
        Delay resolution is ``1/upsample`` sample.
    return_details : bool, default False
        Also return the chosen reference index and delay (samples) per signal.

    Returns
    -------
    residual : ndarray, shape (..., n)
    ref_index : ndarray of int, shape signals.shape[:-1]
        Only with ``return_details``.
    delay : ndarray of float, shape signals.shape[:-1]
        Delay (samples, in ``[0, n)``) of the chosen reference; only with ``return_details``.

    Examples
    --------
    A signal is the second reference delayed by 2.25 samples plus a small fault
    component: the second reference is chosen, the delay found to 1/100 sample, and
    what is left is the fault component alone.

    >>> import numpy as np
    >>> from gearshot.signal import fractional_shift, subtract_healthy
    >>> theta = np.arange(64) / 64
    >>> refs = np.vstack([np.cos(2 * np.pi * 7 * theta),
    ...                   np.cos(2 * np.pi * 5 * theta) + 0.3 * np.cos(2 * np.pi * 10 * theta)])
    >>> fault = 0.1 * np.sin(2 * np.pi * 2 * theta)
    >>> signal = fractional_shift(refs[1], 2.25) + fault
    >>> residual, index, delay = subtract_healthy(signal, refs, return_details=True)
    >>> print(int(index), round(float(delay), 2), bool(np.allclose(residual, fault)))
    1 2.25 True
    """
    signals, refs, upsample = _checked(signals, healthy_refs, upsample, max_ndim=None)
    n = signals.shape[-1]
    residual, ref_index, delays, _ = _subtract(signals.reshape(-1, n), refs, upsample,
                                               prune=1)
    residual = residual.reshape(signals.shape)
    if return_details:
        batch_shape = signals.shape[:-1]
        return residual, ref_index.reshape(batch_shape), delays.reshape(batch_shape)
    return residual


def _checked(signals: ArrayLike, healthy_refs: ArrayLike, upsample: int, *,
             max_ndim: int | None) -> tuple[FloatArray, FloatArray, int]:
    """The inputs of :func:`subtract_healthy` / :func:`subtract_with_lags`, checked:
    signals, references as rows (n_refs, n) of the same length, ``upsample``."""
    x = as_signal_array(signals, "signals", max_ndim=max_ndim, min_length=2)
    refs = np.atleast_2d(as_signal_array(healthy_refs, "healthy_refs", max_ndim=2,
                                         min_length=2))
    upsample = check_int(upsample, "upsample", minimum=1, maximum=10_000)
    if refs.shape[-1] != x.shape[-1]:
        raise GearshotError(f"healthy_refs have {refs.shape[-1]} points per cycle but "
                            f"signals have {x.shape[-1]}")
    return x, refs, upsample


def _subtract(flat: FloatArray, refs: FloatArray, upsample: int,
              lags: IntArray | None = None, *, prune: int = 0
              ) -> tuple[FloatArray, IntArray, FloatArray, IntArray]:
    """:func:`subtract_healthy` on rows ``flat`` (c, n): residual, chosen reference, its
    delay (samples) and every reference's lag (c, n_refs; 1/upsample samples), found here
    or given as ``lags``. With ``prune`` (≥ 1), references that cannot be among the
    ``prune`` leaving the least energy (:func:`~gearshot.signal._lag_search.contenders`)
    are not searched: their lag is −1 (the residual, reference and delay are the same)."""
    n = flat.shape[-1]
    spec_x = scipy.fft.fft(flat, axis=-1)
    spec_r = scipy.fft.fft(refs, axis=-1)
    search = _LagSearch(n, upsample) if lags is None else None

    residual = np.empty_like(flat)
    ref_index = np.empty(flat.shape[0], dtype=int)
    delays = np.empty(flat.shape[0])
    all_lags = np.empty((flat.shape[0], refs.shape[0]), dtype=np.int64)
    chunk = max(1, 256 // refs.shape[0])
    for start in range(0, flat.shape[0], chunk):
        part = slice(start, start + chunk)
        (residual[part], ref_index[part], delays[part],
         all_lags[part]) = _best_residuals(spec_x[part], spec_r, search, upsample,
                                           None if lags is None else lags[part], prune)
    return residual, ref_index, delays, all_lags


def subtract_with_lags(signals: ArrayLike, healthy_refs: ArrayLike, *, upsample: int = 100,
             lags: ArrayLike | None = None) -> tuple[FloatArray, IntArray]:
    """:func:`subtract_healthy`'s residual and its lag search's result, or the residual
    for lags found before.

    The lag search (the cross-correlation maximum of every signal with every reference on
    the grid of ``1/upsample`` sample) is most of :func:`subtract_healthy`'s cost and does
    not depend on a common scale of ``signals`` and ``healthy_refs``: the lags found on
    one scale serve another (the estimator variants with and without RMS normalization
    share them, :func:`gearshot.estimator._target.shared_target_work`). With ``lags``
    given, the residual is computed exactly as :func:`subtract_healthy` computes it after
    its search (the same operations on the same shapes), so for the lags it would find the
    residual is its residual, bit for bit.

    Parameters
    ----------
    signals : array_like, shape (c, n)
    healthy_refs : array_like, shape (n_refs, n) or (n,)
    upsample : int, default 100
    lags : array_like of int, shape (c, n_refs), optional
        Lags in ``1/upsample`` samples (as returned here); default: search them.

    Returns
    -------
    residual : ndarray, shape (c, n)
    lags : ndarray of int, shape (c, n_refs)

    Examples
    --------
    The lags found on signals and references serve the same arrays at another scale:

    >>> import numpy as np
    >>> from gearshot.signal import fractional_shift, subtract_healthy
    >>> from gearshot.signal.alignment import subtract_with_lags
    >>> theta = np.arange(64) / 64
    >>> refs = np.vstack([np.cos(2 * np.pi * 7 * theta), np.cos(2 * np.pi * 5 * theta)])
    >>> signals = np.vstack([fractional_shift(refs[1], 2.25), fractional_shift(refs[0], 1.5)])
    >>> residual, lags = subtract_with_lags(signals, refs)
    >>> print(lags[0, 1], lags[1, 0])          # delays in 1/100 sample
    225 150
    >>> half, _ = subtract_with_lags(signals / 2, refs / 2, lags=lags)
    >>> bool(np.array_equal(half, subtract_healthy(signals / 2, refs / 2)))
    True
    """
    x, refs, upsample = _checked(signals, healthy_refs, upsample, max_ndim=2)
    flat = np.atleast_2d(x)
    given = None
    if lags is not None:
        given = np.asarray(lags)
        if given.shape != (flat.shape[0], refs.shape[0]) or given.dtype.kind not in "iu":
            raise GearshotError(f"lags must be integers of shape {(flat.shape[0], refs.shape[0])}"
                                f" (signals x references); got {describe(lags)}")
    residual, _, _, found = _subtract(flat, refs, upsample, given)
    return residual.reshape(x.shape), found


def _best_residuals(sx: ComplexArray, spec_r: ComplexArray, search: _LagSearch | None,
                    upsample: int, steps: IntArray | None = None, prune: int = 0
                    ) -> tuple[FloatArray, IntArray, FloatArray, IntArray]:
    """For each signal spectrum in ``sx`` (c, n): the residual after subtracting the
    delay-aligned reference that leaves the least energy, that reference's index, its
    delay in samples and every reference's lag (c, n_refs; ``steps`` if given, else found
    by ``search``; with ``prune`` only for the references that may be among the ``prune``
    best, −1 for the others)."""
    n, n_refs = sx.shape[-1], spec_r.shape[0]
    keep = np.ones((len(sx), n_refs), dtype=bool)
    if steps is None:
        assert search is not None
        m = n // 2 + 1  # the lag search reads the non-negative frequencies only
        cross = (sx[:, None, :m] * np.conj(spec_r[:, :m])[None]).reshape(-1, m)
        curve = search.coarse_curve(cross)
        first = np.argmax(curve, axis=-1)
        if prune and n_refs > 1:
            peak = curve[np.arange(len(curve)), first].reshape(-1, n_refs)
            keep = contenders(sx, spec_r, peak, search, among=int(prune))
            searched = keep.ravel()
            cross, curve, first = cross[searched], curve[searched], first[searched]
        steps = np.full(keep.shape, -1, dtype=np.int64)
        steps[keep] = search.fine(cross, curve, first)  # delays, 1/upsample samples
    sig, ref = np.nonzero(keep)  # the pairs searched, by signal then reference
    advance = _grid_shift_factors(n, steps[sig, ref], upsample)  # (pairs, n)
    res_spec = sx[sig] * advance - spec_r[ref]
    energy = np.full(keep.shape, np.inf)
    energy[sig, ref] = np.sum(res_spec.real ** 2 + res_spec.imag ** 2, axis=-1)
    best = np.argmin(energy, axis=-1)
    rows = np.arange(len(sx))
    pair = np.cumsum(keep.ravel()).reshape(keep.shape)[rows, best] - 1
    back = res_spec[pair] * np.conj(advance[pair])
    return scipy.fft.ifft(back, axis=-1).real, best, steps[rows, best] / upsample, steps
