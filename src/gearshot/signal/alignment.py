"""Harmonic suppression by delay-aligned subtraction of healthy references."""

from __future__ import annotations

import functools
from typing import Literal, cast, overload

import numpy as np
from numpy.typing import ArrayLike

from .._errors import GearshotError
from .._typing import ComplexArray, FloatArray, IntArray
from .._validation import as_signal_array, check_int, describe, finite_result
from . import _fft

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
    spectrum = _fft.fft(x, axis=-1) * _shift_factors(n, -tau)
    return _fft.ifft(spectrum, axis=-1).real


class _LagSearch:
    """Argmax of a circular cross-correlation on a grid of ``1/upsample`` sample.

    The correlation is band-limited, so its maximum on the fine grid lies next to the
    maximum of a ×4 over-sampled version: that coarse curve (a short inverse FFT) picks a few
    candidate peaks, and the fine grid is evaluated only around them (a small matrix
    product), instead of one inverse FFT of ``n * upsample`` points per pair. The values are
    those of frequency-domain ×``upsample`` interpolation with the Nyquist bin split evenly
    (MATLAB ``interpft``), whose first maximum the reference implementation takes.
    """

    n_candidates = 3

    def __init__(self, n: int, upsample: int):
        self.n, self.upsample = n, upsample
        self.coarse = 4 if upsample % 4 == 0 else (2 if upsample % 2 == 0 else 1)
        self.step = upsample // self.coarse  # fine points per coarse point
        self.k = np.arange(n // 2 + 1)
        weights = np.full(self.k.size, 2.0)
        weights[0] = 1.0
        if n % 2 == 0:
            weights[-1] = 0.5  # the two split Nyquist halves multiply to 1/4, twice
        self.weights = weights
        offsets = np.arange(-self.step, self.step + 1)
        # Re(b · exp(iθko)) = Re b · cos θko − Im b · sin θko: cosines are even in the
        # offset o, sines odd, so the products over o ≥ 0 give every offset
        phase = np.exp(2j * np.pi * np.outer(self.k, offsets[self.step:]) / (n * upsample))
        self.cos, self.sin = phase.real.copy(), phase.imag[:, 1:].copy()
        self.offsets = offsets

    def best(self, cross: ComplexArray) -> IntArray:
        """Fine-grid index (0 … n·upsample−1) of the first maximum for each row of ``cross``."""
        n, n_fine = self.n, self.n * self.upsample
        half = cross[:, : n // 2 + 1] * self.weights
        padded = np.zeros((cross.shape[0], n * self.coarse // 2 + 1), dtype=complex)
        padded[:, : half.shape[1]] = half
        padded[:, 1:] *= 0.5  # irfft doubles these bins itself
        coarse = np.fft.irfft(padded, n=n * self.coarse, axis=-1)
        n_cand = min(self.n_candidates, coarse.shape[-1])
        cand = _top_indices(coarse, n_cand)  # overwrites coarse, not used after
        centres = cand * self.step  # (rows, n_candidates) on the fine grid
        # exp(2πi·centre·k/n_fine) = w^(cand·k mod n·coarse), w = exp(2πi/(n·coarse))
        turns = (cand[:, :, None] * self.k) % (n * self.coarse)
        base = _roots(n * self.coarse)[turns] * half[:, None, :]
        even = base.real @ self.cos  # (rows, n_candidates, step + 1): offsets 0 … step
        odd = base.imag @ self.sin  # offsets 1 … step
        values = np.concatenate([(even[..., 1:] + odd)[..., ::-1], even[..., :1],
                                 even[..., 1:] - odd], axis=-1)
        fine = (centres[:, :, None] + self.offsets) % n_fine
        values = values.reshape(len(values), -1)
        fine = fine.reshape(len(fine), -1)
        top = values == values.max(axis=-1, keepdims=True)
        return cast(IntArray, np.where(top, fine, n_fine).min(axis=-1))  # first max., as argmax


def _top_indices(work: FloatArray, count: int) -> IntArray:
    """Column indices of the ``count`` largest values of each row, ascending: ``count``
    row-wise argmax passes (each found maximum masked in place: ``work`` is overwritten),
    cheaper than ``argpartition``."""
    rows = np.arange(len(work))
    found = np.empty((len(work), count), dtype=np.intp)
    for i in range(count):
        found[:, i] = np.argmax(work, axis=-1)
        work[rows, found[:, i]] = -np.inf
    return cast(IntArray, np.sort(found, axis=-1))


@functools.lru_cache(maxsize=8)
def _roots(m: int) -> ComplexArray:
    """The ``m`` roots of unity ``exp(2πi·j/m)``, j = 0 … m−1 (a lookup table; read-only)."""
    table = np.exp(2j * np.pi * np.arange(m) / m)
    table.flags.writeable = False
    return cast(ComplexArray, table)


def _grid_shift_factors(n: int, steps: IntArray, upsample: int) -> ComplexArray:
    """:func:`_shift_factors` for delays ``steps / upsample`` samples with integer ``steps``:
    ``exp(2πi·k·steps/(n·upsample))`` looked up in a table of the ``n·upsample`` roots of
    unity (the argument reduced exactly; equal to the direct ``exp`` to ~1e-12)."""
    k = np.fft.fftfreq(n, 1.0 / n).astype(np.int64)
    factors = _roots(n * upsample)[np.multiply.outer(steps, k) % (n * upsample)]
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
    signals = as_signal_array(signals, "signals", min_length=2)
    refs = as_signal_array(healthy_refs, "healthy_refs", max_ndim=2, min_length=2)
    refs = np.atleast_2d(refs)
    upsample = check_int(upsample, "upsample", minimum=1, maximum=10_000)
    n = signals.shape[-1]
    if refs.shape[-1] != n:
        raise GearshotError(
            f"healthy_refs have {refs.shape[-1]} points per cycle but signals have {n}")
    residual, ref_index, delays, _ = _subtract(signals.reshape(-1, n), refs, upsample)
    residual = residual.reshape(signals.shape)
    if return_details:
        batch_shape = signals.shape[:-1]
        return residual, ref_index.reshape(batch_shape), delays.reshape(batch_shape)
    return residual


def _subtract(flat: FloatArray, refs: FloatArray, upsample: int,
              lags: IntArray | None = None
              ) -> tuple[FloatArray, IntArray, FloatArray, IntArray]:
    """:func:`subtract_healthy` on rows ``flat`` (c, n): residual, chosen reference, its
    delay (samples) and every reference's lag (c, n_refs; 1/upsample samples), found here
    or given as ``lags``."""
    n = flat.shape[-1]
    spec_x = _fft.fft(flat, axis=-1)
    spec_r = _fft.fft(refs, axis=-1)
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
                                           None if lags is None else lags[part])
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
    x = as_signal_array(signals, "signals", max_ndim=2, min_length=2)
    flat = np.atleast_2d(x)
    refs = np.atleast_2d(as_signal_array(healthy_refs, "healthy_refs", max_ndim=2,
                                         min_length=2))
    upsample = check_int(upsample, "upsample", minimum=1, maximum=10_000)
    if refs.shape[-1] != flat.shape[-1]:
        raise GearshotError(f"healthy_refs have {refs.shape[-1]} points per cycle but "
                            f"signals have {flat.shape[-1]}")
    given = None
    if lags is not None:
        given = np.asarray(lags)
        if given.shape != (flat.shape[0], refs.shape[0]) or given.dtype.kind not in "iu":
            raise GearshotError(f"lags must be integers of shape {(flat.shape[0], refs.shape[0])}"
                                f" (signals x references); got {describe(lags)}")
    residual, _, _, found = _subtract(flat, refs, upsample, given)
    return residual.reshape(x.shape), found


def _best_residuals(sx: ComplexArray, spec_r: ComplexArray, search: _LagSearch | None,
                    upsample: int, steps: IntArray | None = None
                    ) -> tuple[FloatArray, IntArray, FloatArray, IntArray]:
    """For each signal spectrum in ``sx`` (c, n): the residual after subtracting the
    delay-aligned reference that leaves the least energy, that reference's index, its
    delay in samples and every reference's lag (c, n_refs; ``steps`` if given, else found
    by ``search``)."""
    n, n_refs = sx.shape[-1], spec_r.shape[0]
    if steps is None:
        assert search is not None
        m = n // 2 + 1  # the lag search reads the non-negative frequencies only
        cross = (sx[:, None, :m] * np.conj(spec_r[:, :m])[None]).reshape(-1, m)
        steps = search.best(cross).reshape(-1, n_refs)  # delays, 1/upsample samples
    tau = steps / upsample  # delays, samples
    advance = _grid_shift_factors(n, steps, upsample)  # (c, n_refs, n)
    res_spec = sx[:, None, :] * advance - spec_r[None]
    energy = np.sum(res_spec.real ** 2 + res_spec.imag ** 2, axis=-1)
    best = np.argmin(energy, axis=-1)
    rows = np.arange(len(sx))
    back = res_spec[rows, best] * np.conj(advance[rows, best])
    return _fft.ifft(back, axis=-1).real, best, tau[rows, best], steps

