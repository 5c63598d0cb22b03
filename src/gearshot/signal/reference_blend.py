"""Harmonic suppression by a least-squares blend of delay-aligned healthy references.

:func:`~gearshot.signal.subtract_healthy` subtracts the one delay-aligned healthy SA that
leaves the least energy. A healthy SA is not one fixed pattern, though: through a lightly
damped transfer path the gear's own vibration (loud for a rough gear) moves from segment
to segment with the speed's drift and ripple, so that no single reference matches a new
segment well. :func:`subtract_blend` subtracts instead the least-squares combination of
the ``n_blend`` references that each leave the least energy on their own, every one at its
own delay: the part of the segment's pattern that its nearest healthy neighbours span is
removed, a fault component (a shape no healthy SA has) is left nearly whole.
"""

from __future__ import annotations

import numpy as np
import scipy.fft
from numpy.typing import ArrayLike

from .._errors import GearshotError
from .._typing import FloatArray, IntArray
from .._validation import check_int, describe, finite_result
from .alignment import _checked, _grid_shift_factors, _subtract

__all__ = ["subtract_blend"]

#: Ridge on the blend's normal equations, relative to their mean diagonal (keeps nearly
#: equal references from giving large opposite weights).
RIDGE = 1e-6


@finite_result
def subtract_blend(signals: ArrayLike, healthy_refs: ArrayLike, *, n_blend: int = 3,
                   upsample: int = 100, lags: ArrayLike | None = None
                   ) -> tuple[FloatArray, IntArray]:
    """Subtract from each signal the least-squares blend of its best-aligned references.

    Every reference is delay-aligned to the signal as in
    :func:`~gearshot.signal.subtract_healthy` (the cross-correlation maximum on a grid of
    ``1/upsample`` sample); the ``n_blend`` references that leave the least energy on
    their own are then combined with the weights that leave the least energy together
    (ordinary least squares with a tiny ridge), and that combination is subtracted.
    ``n_blend=1`` is :func:`~gearshot.signal.subtract_healthy`'s residual.

    Parameters
    ----------
    signals : array_like, shape (..., n)
        Synchronous averages to treat (leading axes are batch axes).
    healthy_refs : array_like, shape (n_refs, n) or (n,)
        Healthy synchronous averages of the same machine and condition.
    n_blend : int >= 1, default 3
        References combined (at most ``n_refs``).
    upsample : int, default 100
        Delay resolution is ``1/upsample`` sample.
    lags : array_like of int, shape (..., n_refs), optional
        Every reference's lag for every signal in ``1/upsample`` samples, as returned
        here (−1: a reference that cannot be among the ``n_blend`` best, not searched);
        default: search them.

    Returns
    -------
    residual : ndarray, shape of ``signals``
    lags : ndarray of int, shape (..., n_refs)

    Examples
    --------
    A signal made of two references at their own delays, plus a small fault component:
    the best single reference leaves the other one behind, the blend leaves the fault.

    >>> import numpy as np
    >>> from gearshot.signal import fractional_shift, subtract_healthy
    >>> from gearshot.signal import subtract_blend
    >>> theta = np.arange(128) / 128
    >>> refs = np.vstack([np.cos(2 * np.pi * 8 * theta), np.cos(2 * np.pi * 16 * theta),
    ...                   np.cos(2 * np.pi * 24 * theta)])
    >>> fault = 0.05 * np.exp(-((theta - 0.5) / 0.01) ** 2)
    >>> signal = fractional_shift(refs[0], 1.5) + 0.4 * refs[1] + fault
    >>> single = subtract_healthy(signal, refs)
    >>> blend, _ = subtract_blend(signal, refs, n_blend=2)
    >>> bool(np.abs(single - fault).max() > 0.3), bool(np.abs(blend - fault).max() < 0.02)
    (True, True)
    """
    x, refs, upsample = _checked(signals, healthy_refs, upsample, max_ndim=None)
    n_blend = check_int(n_blend, "n_blend", minimum=1)
    flat = x.reshape(-1, x.shape[-1])
    lag_shape = (*x.shape[:-1], refs.shape[0])
    given = None
    if lags is not None:
        given = np.asarray(lags)
        if given.shape != lag_shape or given.dtype.kind not in "iu":
            raise GearshotError(f"lags must be integers of shape {lag_shape} (signals x "
                                f"references); got {describe(lags)}")
        given = given.reshape(flat.shape[0], refs.shape[0])
    k = min(n_blend, refs.shape[0])
    if given is None or k == 1:   # the search, or the single reference's residual
        residual, _, _, found = _subtract(flat, refs, upsample, given,
                                          prune=k if given is None else 0)
    else:                         # lags given: the blend needs nothing else
        found = given
    if k > 1:
        residual = _blended(flat, refs, found, upsample, k)
    return residual.reshape(x.shape), found.reshape(lag_shape)


def _blended(flat: FloatArray, refs: FloatArray, lags: IntArray, upsample: int,
             k: int) -> FloatArray:
    """The residuals of the ``k``-reference blends (spectra, normal equations batched)."""
    n = flat.shape[-1]
    sx = scipy.fft.rfft(flat, axis=-1)
    sr = scipy.fft.rfft(refs, axis=-1)
    half = n // 2 + 1
    # the one-sided bins' weight in the two-sided energy (DC and Nyquist once, others twice)
    bins = np.full(half, 2.0)
    bins[0] = 1.0
    if n % 2 == 0:
        bins[-1] = 1.0
    out = np.empty_like(flat)
    chunk = max(1, 4096 // refs.shape[0])
    for start in range(0, len(flat), chunk):
        part = slice(start, start + chunk)
        steps = lags[part]
        factors = _grid_shift_factors(n, steps, upsample)[..., :half]   # (c, r, half)
        aligned = sr[None] * np.conj(factors)        # every reference moved to the signal
        gap = sx[part, None, :] - aligned
        energy = np.einsum("crk,k->cr", gap.real ** 2 + gap.imag ** 2, bins)
        energy[steps < 0] = np.inf        # not searched: cannot be among the best
        pick = np.argsort(energy, axis=-1)[:, :k]
        basis = np.take_along_axis(aligned, pick[..., None], axis=1)       # (c, k, half)
        weighted = basis * bins
        gram = np.einsum("cik,cjk->cij", np.conj(weighted), basis).real
        rhs = np.einsum("cik,ck->ci", np.conj(weighted), sx[part]).real
        ridge = (RIDGE * np.trace(gram, axis1=1, axis2=2)[:, None, None] / k
                 + np.finfo(float).tiny)       # all-zero references: weights 0
        weights = np.linalg.solve(gram + ridge * np.eye(k), rhs[..., None])[..., 0]
        model = np.einsum("ci,cik->ck", weights, basis)
        out[part] = scipy.fft.irfft(sx[part] - model, n=n, axis=-1)
    return out
