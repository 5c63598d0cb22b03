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
from typing import Any

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
                        noise_spectrum: ComplexArray | None = None,
                        rows: NDArray[np.intp] | None = None) -> FloatArray:
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
    rows : ndarray of int, optional
        Only these signals (rows of ``sim_sa`` and of the per-signal arrays); default all.

    Returns
    -------
    ndarray (n_signals, n_features)
        Uncentred features.
    """
    n = sim_sa.shape[-1]
    factor: ComplexArray = np.asarray(1.0 / scale if tf is None
                                      else one_sided_response(tf) / scale, dtype=np.complex128)
    step = max(1, _BLOCK_ELEMENTS // n)
    per_signal = reference.ndim == sim_sa.ndim
    common: ComplexArray = (np.zeros(0, np.complex128) if per_signal
                            else np.fft.rfft(reference, axis=-1) * factor)
    count = sim_sa.shape[0] if rows is None else len(rows)
    spec = np.empty((count, n // 2 + 1), dtype=np.complex128)
    for i in range(0, count, step):
        out = spec[i:i + step]
        block: slice | NDArray[np.intp] = (slice(i, i + step) if rows is None
                                           else rows[i:i + step])
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


def recorded_residue_spectrum(differences: ArrayLike, n_signals: int,
                              rng: np.random.Generator) -> ComplexArray:
    """``rfft`` of ``n_signals`` residue signals drawn from the target's own healthy
    difference signals (n, n_points): each a randomly chosen one, turned by a random whole
    number of points around the cycle and given a random sign.

    Each draw keeps the power spectrum of the difference it comes from, and so the spread
    of levels between runs that a Gaussian draw with their mean power
    (:func:`residue_noise_spectrum`) averages away; the turn puts it anywhere relative to
    the simulated fault.
    """
    d = np.atleast_2d(np.asarray(differences, dtype=float))
    n_points = d.shape[-1]
    pick = rng.integers(0, d.shape[0], n_signals)
    turn = rng.integers(0, n_points, n_signals)
    sign = rng.choice(np.array([-1.0, 1.0]), n_signals)
    k = np.arange(n_points // 2 + 1)
    spec = np.fft.rfft(d, axis=-1)[pick] * np.exp(-2j * np.pi * np.outer(turn, k) / n_points)
    return np.asarray(spec * sign[:, None], dtype=np.complex128)


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


def twin_difference_features(sim_sa: FloatArray, twins: FloatArray, healthy: NDArray[np.bool_],
                             tf: ArrayLike | None, scale: float, *,
                             mesh_order: int | Sequence[int], names: Sequence[str],
                             noise_spectrum: ComplexArray,
                             kept: dict[str, Any]) -> FloatArray:
    """:func:`difference_features` with per-signal twins and a residue spectrum, where the
    healthy rows equal to their twin (a paired database's healthy SAs) take their features
    from ``kept``.

    Such a row's difference is exactly zero, so its spectrum is the residue's row alone
    (whatever ``tf`` and ``scale``): its features depend only on the residue draw, the row
    positions and the features asked for, and a fit's grades (the same draw, the same
    positions) compute them once. ``kept`` holds them (with the draw, against a reuse
    with another one); the numbers are those of :func:`difference_features`.
    """
    same = healthy.copy()
    same[healthy] = np.all(sim_sa[healthy] == twins[healthy], axis=-1)
    if not same.any():
        return difference_features(sim_sa, twins, tf, scale, mesh_order=mesh_order,
                                   names=names, noise_spectrum=noise_spectrum)
    rows = np.flatnonzero(same)
    key = f"noise-only features/{rows.tobytes().hex()}/{tuple(names)}/{mesh_order}"
    if key not in kept or kept[key][0] is not noise_spectrum:
        kept[key] = (noise_spectrum, spectrum_features(noise_spectrum[rows], sim_sa.shape[-1],
                                                       mesh_order, names=names))
    feats = np.empty((len(sim_sa), len(names)))
    feats[rows] = kept[key][1]
    others = np.flatnonzero(~same)
    feats[others] = difference_features(sim_sa, twins, tf, scale, mesh_order=mesh_order,
                                        names=names, noise_spectrum=noise_spectrum,
                                        rows=others)
    return feats
