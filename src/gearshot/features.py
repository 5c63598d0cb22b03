"""Condition indicators of synchronous averages, and a registry of them by name.

The paper's four features (the default set) are computed on the *difference signal*
(mesh harmonics and ±2 sidebands removed, :func:`gearshot.signal.difference_signal`):

``rms_diff``            RMS of the difference signal
``kurtosis_diff``       its (biased, normal = 3) kurtosis
``rms_env_diff``        RMS of its mean-removed envelope
``skewness_env_diff``   skewness of that envelope

The classical indicators follow Zakrajsek (1993) and Decker (2002):

``fm0``  peak-to-peak of the SA ÷ sum of the mesh-harmonic amplitudes
``fm4``  kurtosis of the Zakrajsek difference signal (SA minus shaft orders 1–2, mesh
         harmonics and their first-order sidebands)
``m6a``, ``m8a``  sixth and eighth normalized moments of that difference signal
``na4``  fourth moment of the residual signal (SA minus shaft orders 1–2 and mesh
         harmonics) ÷ the squared variance of a healthy baseline (``baseline_variance``;
         the signal's own variance when not given)
``er``   energy ratio: RMS of the Zakrajsek difference signal ÷ RMS of the regular meshing
         signal (mesh harmonics and first-order sidebands)

Moment ratios of signals whose RMS is below ``1e-10`` are 0 (the reference's convention).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cached_property
from types import MappingProxyType

import numpy as np
import scipy.fft

from ._errors import GearshotError
from ._validation import as_signal_array, check_int, check_positive, describe, finite_result
from .signal.level import rms as _rms
from .signal.orders import check_mesh_orders, mesh_band_orders

__all__ = ["FEATURES", "PAPER_FEATURES", "available_features", "extract_features",
           "na4_baseline_variance"]

PAPER_FEATURES = ("rms_diff", "kurtosis_diff", "rms_env_diff", "skewness_env_diff")
_TINY_RMS = 1e-10
_SHAFT_ORDERS = (1, 2)
_WORKERS = None  # scipy.fft threads: one (Dask workers parallelize across processes)


class _Parts:
    """Lazily computed decompositions of a batch of SAs, shared between features."""

    def __init__(self, sa, mesh_order, n_sidebands, baseline_variance,
                 shaft_orders=_SHAFT_ORDERS):
        self.sa = sa
        self.n = sa.shape[-1]
        self.mesh_orders = tuple(mesh_order) if isinstance(mesh_order, tuple) else (mesh_order,)
        self.mesh_order = self.mesh_orders if len(self.mesh_orders) > 1 else self.mesh_orders[0]
        self.n_sidebands = n_sidebands
        self.baseline_variance = baseline_variance
        self.shaft_orders = tuple(shaft_orders)

    @cached_property
    def spectrum(self):
        return scipy.fft.rfft(self.sa, axis=-1, workers=_WORKERS)

    def _keep(self, orders, *, invert=False):
        mask = np.zeros(self.n // 2 + 1, dtype=bool)
        mask[orders] = True
        if invert:
            mask = ~mask
        return scipy.fft.irfft(self.spectrum * mask, n=self.n, axis=-1, workers=_WORKERS)

    def _mesh(self, n_sidebands):
        return mesh_band_orders(self.n, self.mesh_order, n_sidebands)

    @cached_property
    def diff_spectrum(self):
        mask = np.ones(self.n // 2 + 1, dtype=bool)
        mask[self._mesh(self.n_sidebands)] = False
        return self.spectrum * mask

    @cached_property
    def diff(self):
        return scipy.fft.irfft(self.diff_spectrum, n=self.n, axis=-1, workers=_WORKERS)

    @cached_property
    def rms_diff(self):
        return np.sqrt(np.mean(self.diff ** 2, axis=-1))

    @cached_property
    def envelope(self):
        # |analytic signal| (as scipy.signal.hilbert): its real part is the difference
        # signal, its imaginary part the Hilbert transform, the real inverse FFT of
        # -i X_k over 0 < k < n/2 (DC and Nyquist give no imaginary part)
        n, half = self.n, self.diff_spectrum
        quad = -1j * half
        quad[..., 0] = 0.0
        if n % 2 == 0:
            quad[..., n // 2] = 0.0
        hilb = scipy.fft.irfft(quad, n=n, axis=-1, workers=_WORKERS)
        env = np.hypot(self.diff, hilb)
        env -= env.mean(axis=-1, keepdims=True)
        return env

    @cached_property
    def regular_mesh(self):
        return self._keep(self._mesh(1))

    @cached_property
    def zakrajsek_diff(self):
        orders = np.union1d(self._mesh(1), [0, *self.shaft_orders])
        return self._keep(orders, invert=True)

    @cached_property
    def residual(self):
        orders = np.union1d(self._mesh(0), [0, *self.shaft_orders])
        return self._keep(orders, invert=True)


def _moment_ratio(x, order, *, variance=None):
    """Biased normalized central moment ``mean(m^order) / var^(order/2)``; 0 if RMS tiny."""
    centred = x - x.mean(axis=-1, keepdims=True)
    square = centred * centred
    own_var = np.mean(square, axis=-1)
    var = own_var if variance is None else np.broadcast_to(variance, own_var.shape)
    power = centred if order % 2 else square  # integer powers by multiplication: fast
    for _ in range(order // 2 - (0 if order % 2 else 1)):
        power = power * square
    num = np.mean(power, axis=-1)
    small = np.sqrt(own_var) < _TINY_RMS
    with np.errstate(divide="ignore", invalid="ignore"):
        out = num / var ** (order / 2)
    return np.where(small, 0.0, out)


_REGISTRY: dict[str, Callable[[_Parts], np.ndarray]] = {}


def _register(name):
    def deco(func):
        _REGISTRY[name] = func
        return func
    return deco


@_register("rms_diff")
def _rms_diff(p):
    return p.rms_diff


@_register("kurtosis_diff")
def _kurtosis_diff(p):
    return np.where(p.rms_diff < _TINY_RMS, 0.0, _moment_ratio(p.diff, 4))


@_register("rms_env_diff")
def _rms_env_diff(p):
    return _rms(p.envelope)


@_register("skewness_env_diff")
def _skewness_env_diff(p):
    skew = _moment_ratio(p.envelope, 3)
    return np.where(p.rms_diff < _TINY_RMS, 0.0, skew)


@_register("fm0")
def _fm0(p):
    harmonics = np.unique(np.concatenate([np.arange(1, (p.n // 2) // m + 1) * m
                                          for m in p.mesh_orders]))
    amp = 2.0 * np.abs(p.spectrum[..., harmonics]) / p.n
    amp[..., harmonics == p.n // 2] /= 2.0
    total = amp.sum(axis=-1)
    ptp = np.ptp(p.sa, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(total < _TINY_RMS, 0.0, ptp / total)


@_register("fm4")
def _fm4(p):
    return _moment_ratio(p.zakrajsek_diff, 4)


@_register("m6a")
def _m6a(p):
    return _moment_ratio(p.zakrajsek_diff, 6)


@_register("m8a")
def _m8a(p):
    return _moment_ratio(p.zakrajsek_diff, 8)


@_register("na4")
def _na4(p):
    return _moment_ratio(p.residual, 4, variance=p.baseline_variance)


@_register("er")
def _er(p):
    den = _rms(p.regular_mesh)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(den < _TINY_RMS, 0.0, _rms(p.zakrajsek_diff) / den)


FEATURES = MappingProxyType(_REGISTRY)
"""Read-only mapping of feature name → function of the shared decomposition."""


def available_features() -> tuple[str, ...]:
    """Names of every registered feature, in registry order."""
    return tuple(_REGISTRY)


def _check_names(names):
    if names is None:
        return PAPER_FEATURES
    if isinstance(names, str):
        names = (names,)
    try:
        names = tuple(names)
    except TypeError:
        raise GearshotError(f"names must be a feature name or a sequence of them; got "
                            f"{describe(names)}") from None
    if not all(isinstance(n, str) for n in names):
        raise GearshotError(f"names must be feature names (str); got {describe(names)}")
    if not names:
        raise GearshotError("names must list at least one feature; got an empty list")
    unknown = [n for n in names if n not in _REGISTRY]
    if unknown:
        raise GearshotError(
            f"unknown feature name(s) {unknown}; valid names are {list(_REGISTRY)}")
    return names


def _check_shaft_orders(shaft_orders, n):
    if isinstance(shaft_orders, (int, np.integer)) or shaft_orders is None:
        raise GearshotError(f"shaft_orders must be a sequence of integers (may be empty); got "
                            f"{shaft_orders!r}")
    out = tuple(check_int(o, "shaft_orders[]", minimum=1) for o in shaft_orders)
    bad = [o for o in out if o > n // 2]
    if bad:
        raise GearshotError(f"shaft_orders {bad} exceed the Nyquist order {n // 2}")
    return out


def _mesh_arg(mesh_order, n):
    orders = check_mesh_orders(mesh_order, n)
    return orders if len(orders) > 1 else orders[0]


@finite_result
def na4_baseline_variance(healthy_sa, mesh_order, *, shaft_orders=_SHAFT_ORDERS) -> float:
    """Mean variance of the residual signal of healthy SAs: NA4's baseline.

    Parameters
    ----------
    healthy_sa : array_like, shape (..., n)
    mesh_order : int or sequence of int
        Mesh order(s) of the cycle's shaft.
    shaft_orders : sequence of int, default (1, 2)
        Shaft orders removed from the residual.

    Returns
    -------
    float
    """
    sa = as_signal_array(healthy_sa, "healthy_sa", min_length=4)
    mesh_order = _mesh_arg(mesh_order, sa.shape[-1])
    shaft_orders = _check_shaft_orders(shaft_orders, sa.shape[-1])
    residual = _Parts(sa, mesh_order, 0, None, shaft_orders).residual
    centred = residual - residual.mean(axis=-1, keepdims=True)
    return float(np.mean(centred ** 2))


@finite_result
def extract_features(sa, mesh_order, *, names=None, n_sidebands=2, baseline_variance=None,
                     shaft_orders=_SHAFT_ORDERS) -> np.ndarray:
    """Condition indicators of synchronous averages.

    Parameters
    ----------
    sa : array_like, shape (..., n_points)
        Synchronous averages, one cycle each (e.g. ``(n_signals, 2048)``).
    mesh_order : int or sequence of int
        Gear-mesh order in the cycle; a sequence for a shaft carrying several gears (every
        mesh's harmonics and sidebands are removed from the difference/residual signals,
        FM0 sums every mesh's harmonics).
    names : sequence of str, optional
        Features to compute, in order. Default: the paper's four (:data:`PAPER_FEATURES`).
        See :func:`available_features`.
    n_sidebands : int, default 2
        Sidebands removed around each mesh harmonic for the paper's difference signal.
    baseline_variance : float, optional
        Healthy residual variance for ``na4`` (see :func:`na4_baseline_variance`).
    shaft_orders : sequence of int, default (1, 2)
        Shaft orders removed (with DC) from the Zakrajsek difference signal (FM4, M6A, M8A,
        ER) and the residual signal (NA4).

    Returns
    -------
    ndarray, shape (..., n_features)
        ``(n_signals, n_features)`` for a 2-D input.
    """
    names = _check_names(names)
    sa = as_signal_array(sa, "sa", min_length=4)
    mesh_order = _mesh_arg(mesh_order, sa.shape[-1])
    shaft_orders = _check_shaft_orders(shaft_orders, sa.shape[-1])
    n_sidebands = check_int(n_sidebands, "n_sidebands", minimum=0, maximum=sa.shape[-1])
    if baseline_variance is not None:
        baseline_variance = check_positive(baseline_variance, "baseline_variance")
    parts = _Parts(sa, mesh_order, n_sidebands, baseline_variance, shaft_orders)
    return np.stack([_REGISTRY[name](parts) for name in names], axis=-1)
