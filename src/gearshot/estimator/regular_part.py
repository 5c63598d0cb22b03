"""The regular part of a synchronous average, as comparability describes it.

A fault changes a gear's *difference* signal; the *regular* part is set by the machine
itself: its build, its speed and load, the path to the sensor. :func:`regular_features`
describes it per SA (the groups of :data:`FEATURE_GROUPS`); :func:`harmonic_profile` is the
unit-norm amplitude vector of the mesh harmonics that the load choice of ``predict``
compares (:mod:`gearshot.app.load_choice`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import cast

import numpy as np
import scipy.fft
import scipy.stats
from numpy.typing import ArrayLike, NDArray

from .._validation import as_signal_array
from ..signal.orders import check_mesh_orders

__all__ = ["FEATURE_GROUPS", "harmonic_orders", "harmonic_profile", "healthy_spread",
           "regular_features"]

FloatArray = NDArray[np.float64]

#: The feature groups of :func:`regular_features`, in column order.
FEATURE_GROUPS = ("level", "harmonics", "shaft_orders", "background", "sidebands",
                  "kurtosis")

_SHAFT_ORDERS = (1, 2, 3)
_SIDEBANDS = (1, 2)
_FIRST_BAND = 4
_TINY = 1e-30
def harmonic_orders(n_points: int, mesh_order: int | Sequence[int]) -> np.ndarray:
    """The distinct mesh-harmonic orders ``k * m`` (every mesh ``m``, ``k ≥ 1``) below the
    Nyquist order of an ``n_points`` cycle, sorted."""
    meshes = check_mesh_orders(mesh_order, n_points)
    nyquist = n_points // 2
    return np.unique(np.concatenate([np.arange(m, nyquist, m) for m in meshes]))


def harmonic_profile(sa: ArrayLike, mesh_order: int | Sequence[int]) -> FloatArray:
    """Unit-norm amplitudes of SAs at their mesh-harmonic orders.

    Parameters
    ----------
    sa : array_like (n_signals, n_points) or (n_points,)
        Synchronous averages, one cycle each.
    mesh_order : int or sequence of int
        Mesh order(s) of the cycle (:meth:`gearshot.Machine.mesh_orders`).

    Returns
    -------
    ndarray (n_signals, n_orders)
        ``|DFT(sa)|`` at :func:`harmonic_orders`, each row divided by its norm (a row
        without any harmonic content stays zero).
    """
    arr = np.atleast_2d(as_signal_array(sa, "sa", max_ndim=2, min_length=4))
    orders = harmonic_orders(arr.shape[-1], mesh_order)
    amp = np.abs(scipy.fft.rfft(arr, axis=-1))[:, orders]
    norm = np.linalg.norm(amp, axis=1, keepdims=True)
    return cast(FloatArray, np.divide(amp, norm, out=np.zeros_like(amp), where=norm > 0))


def healthy_spread(profiles: FloatArray) -> float:
    """RMS leave-one-out distance of each profile from the mean of the others (at least
    1e-6); needs 2 profiles."""
    n = len(profiles)
    loo = (n * profiles.mean(axis=0) - profiles) / (n - 1)  # the mean of the others
    return max(float(np.sqrt(np.mean(np.sum((profiles - loo) ** 2, axis=1)))), 1e-6)


def _octave_bands(nyquist: int) -> list[tuple[int, int]]:
    edges = [_FIRST_BAND]
    while edges[-1] * 2 < nyquist:
        edges.append(edges[-1] * 2)
    edges.append(nyquist + 1)
    return list(zip(edges[:-1], edges[1:]))


def _log_band_levels(power: FloatArray, orders: np.ndarray,
                     bands: list[tuple[int, int]]) -> FloatArray:
    """``log10`` RMS amplitude of ``orders`` in each band holding any (bands without one
    are left out)."""
    cols = []
    for low, high in bands:
        inside = orders[(orders >= low) & (orders < high)]
        if inside.size:
            cols.append(0.5 * np.log10(power[:, inside].mean(axis=1) + _TINY))
    return np.array(cols).T if cols else np.zeros((len(power), 0))


def regular_features(sa: ArrayLike, mesh_order: int | Sequence[int]
                     ) -> tuple[FloatArray, tuple[str, ...]]:
    """The description of the regular part that comparability compares.

    Parameters
    ----------
    sa : array_like (n_signals, n_points) or (n_points,)
        Synchronous averages, one cycle each (physical units: the level is a feature).
    mesh_order : int or sequence of int
        Mesh order(s) of the cycle (:meth:`gearshot.Machine.mesh_orders`).

    Returns
    -------
    features : ndarray (n_signals, n_features)
        Columns in the order of :data:`FEATURE_GROUPS`: ``log10 RMS``; ``log10``
        amplitude at each mesh-harmonic order, at shaft orders 1-3, of the background and
        of the ±1, ±2 sidebands in octave bands of order (each minus ``log10 RMS``); the
        kurtosis (biased, normal = 3; 0 for a constant SA).
    groups : tuple of str
        The group of each column.
    """
    arr = np.atleast_2d(as_signal_array(sa, "sa", max_ndim=2, min_length=64))
    n = arr.shape[-1]
    nyquist = n // 2
    harm = harmonic_orders(n, mesh_order)
    amp = np.abs(scipy.fft.rfft(arr, axis=-1)) * (2.0 / n)
    power = amp ** 2
    level = np.log10(np.sqrt(np.mean(arr ** 2, axis=1)) + _TINY)[:, None]
    near = np.concatenate([harm + d for d in (0, *_SIDEBANDS, *(-s for s in _SIDEBANDS))])
    sidebands = np.setdiff1d(np.concatenate([harm + d for d in (*_SIDEBANDS,
                                                                *(-s for s in _SIDEBANDS))]),
                             np.concatenate([harm, _SHAFT_ORDERS]))
    sidebands = sidebands[(sidebands >= _FIRST_BAND) & (sidebands <= nyquist)]
    background = np.setdiff1d(np.arange(_FIRST_BAND, nyquist + 1),
                              np.concatenate([near, _SHAFT_ORDERS]))
    bands = _octave_bands(nyquist)
    with np.errstate(invalid="ignore", divide="ignore"):
        kurt = scipy.stats.kurtosis(arr, axis=1, fisher=False, bias=True)
    parts = {
        "level": level,
        "harmonics": np.log10(amp[:, harm] + _TINY) - level,
        "shaft_orders": np.log10(amp[:, list(_SHAFT_ORDERS)] + _TINY) - level,
        "background": _log_band_levels(power, background, bands) - level,
        "sidebands": _log_band_levels(power, sidebands, bands) - level,
        "kurtosis": np.nan_to_num(kurt, nan=0.0, posinf=0.0, neginf=0.0)[:, None],
    }
    groups = tuple(g for g in FEATURE_GROUPS for _ in range(parts[g].shape[1]))
    return np.hstack([parts[g] for g in FEATURE_GROUPS]).astype(float), groups
