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

Spectral shape of the difference signal (issue #30):

``band_rms_1`` … ``band_rms_8``  RMS of the difference signal in 8 equal-width order bands
         of ``1 … n_points // 2`` (with the mean, their squares sum to ``rms_diff²``)

Moment ratios of signals whose RMS is below ``1e-10`` are 0 (the reference's convention).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from types import MappingProxyType
from typing import cast

import numpy as np
from numpy.typing import ArrayLike

from ._errors import GearshotError
from ._feature_parts import _SHAFT_ORDERS, _TINY_RMS, _moment_ratio, _Parts
from ._typing import ComplexArray, FloatArray
from ._validation import as_signal_array, check_int, check_positive, describe, finite_result
from .signal.orders import MeshOrders, check_mesh_orders

__all__ = ["FEATURES", "PAPER_FEATURES", "CONDITION_INDICATORS", "available_features",
           "extract_features", "spectrum_features", "na4_baseline_variance"]

PAPER_FEATURES = ("rms_diff", "kurtosis_diff", "rms_env_diff", "skewness_env_diff")
#: Values per block of signals: the features' temporaries of one block (1 MB each) stay in
#: the cache and are reused, where whole batches would stream through memory every step.
_CHUNK_ELEMENTS = 1 << 17


def _rms(x: FloatArray) -> FloatArray:
    """Root mean square along the last axis (:func:`gearshot.signal.rms` without the checks
    of an outside input)."""
    return cast(FloatArray, np.sqrt(np.mean(x * x, axis=-1)))


_Feature = Callable[[_Parts], FloatArray]
_REGISTRY: dict[str, _Feature] = {}


def _register(name: str) -> Callable[[_Feature], _Feature]:
    def deco(func: _Feature) -> _Feature:
        _REGISTRY[name] = func
        return func
    return deco


@_register("rms_diff")
def _rms_diff(p: _Parts) -> FloatArray:
    return p.rms_diff


@_register("kurtosis_diff")
def _kurtosis_diff(p: _Parts) -> FloatArray:
    return cast(FloatArray, np.where(p.rms_diff < _TINY_RMS, 0.0, _moment_ratio(p.diff, 4)))


@_register("rms_env_diff")
def _rms_env_diff(p: _Parts) -> FloatArray:
    return _rms(p.envelope)


@_register("skewness_env_diff")
def _skewness_env_diff(p: _Parts) -> FloatArray:
    skew = _moment_ratio(p.envelope, 3)
    return cast(FloatArray, np.where(p.rms_diff < _TINY_RMS, 0.0, skew))


@_register("fm0")
def _fm0(p: _Parts) -> FloatArray:
    harmonics = np.unique(np.concatenate([np.arange(1, (p.n // 2) // m + 1) * m
                                          for m in p.mesh_orders]))
    amp = 2.0 * np.abs(p.spectrum[..., harmonics]) / p.n
    amp[..., harmonics == p.n // 2] /= 2.0
    total = amp.sum(axis=-1)
    ptp = np.ptp(p.sa, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return cast(FloatArray, np.where(total < _TINY_RMS, 0.0, ptp / total))


@_register("fm4")
def _fm4(p: _Parts) -> FloatArray:
    return _moment_ratio(p.zakrajsek_diff, 4)


@_register("m6a")
def _m6a(p: _Parts) -> FloatArray:
    return _moment_ratio(p.zakrajsek_diff, 6)


@_register("m8a")
def _m8a(p: _Parts) -> FloatArray:
    return _moment_ratio(p.zakrajsek_diff, 8)


@_register("na4")
def _na4(p: _Parts) -> FloatArray:
    return _moment_ratio(p.residual, 4, variance=p.baseline_variance)


@_register("er")
def _er(p: _Parts) -> FloatArray:
    den = _rms(p.regular_mesh)
    with np.errstate(divide="ignore", invalid="ignore"):
        return cast(FloatArray, np.where(den < _TINY_RMS, 0.0, _rms(p.zakrajsek_diff) / den))


#: The condition indicators a user reads (``gearshot indicators``): the paper's four and
#: the eight of the reference toolchain; the order bands below are estimator features.
CONDITION_INDICATORS: tuple[str, ...] = tuple(_REGISTRY)

#: Equal-width order bands of the difference spectrum (``band_rms_1`` … ``band_rms_8``).
N_BANDS = 8


def _band_rms(k: int) -> _Feature:
    """RMS of the difference signal's content in the ``k``-th of :data:`N_BANDS` equal
    order bands of ``1 … n // 2`` (Parseval on the one-sided difference spectrum)."""
    def band(p: _Parts) -> FloatArray:
        edges = np.linspace(1, p.n // 2 + 1, N_BANDS + 1).astype(int)
        part = p.diff_spectrum[..., edges[k - 1]:edges[k]]
        power = 2.0 * np.sum(part.real ** 2 + part.imag ** 2, axis=-1)
        if edges[k] == p.n // 2 + 1 and p.n % 2 == 0:     # Nyquist counted once
            nyq = p.diff_spectrum[..., p.n // 2]
            power -= nyq.real ** 2 + nyq.imag ** 2
        return cast(FloatArray, np.sqrt(np.maximum(power, 0.0)) / p.n)
    return band


for _k in range(1, N_BANDS + 1):
    _register(f"band_rms_{_k}")(_band_rms(_k))

FEATURES = MappingProxyType(_REGISTRY)
"""Read-only mapping of feature name → function of the shared decomposition."""


def available_features() -> tuple[str, ...]:
    """Names of every registered feature, in registry order.

    Examples
    --------
    >>> from gearshot.features import available_features
    >>> available_features()[:4]    # the paper's four come first
    ('rms_diff', 'kurtosis_diff', 'rms_env_diff', 'skewness_env_diff')
    >>> len(available_features())
    18
    """
    return tuple(_REGISTRY)


def _check_names(names: str | Iterable[str] | None) -> tuple[str, ...]:
    if names is None:
        return PAPER_FEATURES
    if isinstance(names, str):
        names = (names,)
    try:
        listed = tuple(names)
    except TypeError:
        raise GearshotError(f"names must be a feature name or a sequence of them; got "
                            f"{describe(names)}") from None
    if not all(isinstance(n, str) for n in listed):
        raise GearshotError(f"names must be feature names (str); got {describe(names)}")
    if not listed:
        raise GearshotError("names must list at least one feature; got an empty list")
    unknown = [n for n in listed if n not in _REGISTRY]
    if unknown:
        raise GearshotError(
            f"unknown feature name(s) {unknown}; valid names are {list(_REGISTRY)}")
    return listed


def _check_shaft_orders(shaft_orders: Iterable[int], n: int) -> tuple[int, ...]:
    if isinstance(shaft_orders, (int, np.integer)) or shaft_orders is None:
        raise GearshotError(f"shaft_orders must be a sequence of integers (may be empty); got "
                            f"{shaft_orders!r}")
    out = tuple(check_int(o, "shaft_orders[]", minimum=1) for o in shaft_orders)
    bad = [o for o in out if o > n // 2]
    if bad:
        raise GearshotError(f"shaft_orders {bad} exceed the Nyquist order {n // 2}")
    return out


def _mesh_arg(mesh_order: MeshOrders, n: int) -> int | tuple[int, ...]:
    orders = check_mesh_orders(mesh_order, n)
    return orders if len(orders) > 1 else orders[0]


@finite_result
def na4_baseline_variance(healthy_sa: ArrayLike, mesh_order: MeshOrders, *,
                          shaft_orders: Sequence[int] = _SHAFT_ORDERS) -> float:
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

    Examples
    --------
    Healthy SAs of a 38-tooth mesh with shaft orders 1 and 5: shaft orders 1–2 and the
    mesh go, the order-5 component (amplitude 0.1, variance 0.005) is the residual.

    >>> import numpy as np
    >>> from gearshot.features import na4_baseline_variance
    >>> theta = np.arange(2048) / 2048
    >>> healthy = (np.cos(2 * np.pi * 38 * theta) + 0.3 * np.cos(2 * np.pi * theta)
    ...            + 0.1 * np.cos(2 * np.pi * 5 * theta))
    >>> print(round(na4_baseline_variance(np.vstack([healthy, healthy]), 38), 6))
    0.005
    """
    sa = as_signal_array(healthy_sa, "healthy_sa", min_length=4)
    orders = _mesh_arg(mesh_order, sa.shape[-1])
    shafts = _check_shaft_orders(shaft_orders, sa.shape[-1])
    residual = _Parts(sa, orders, 0, None, shafts).residual
    centred = residual - residual.mean(axis=-1, keepdims=True)
    return float(np.mean(centred ** 2))


@finite_result
def extract_features(sa: ArrayLike, mesh_order: MeshOrders, *,
                     names: str | Iterable[str] | None = None, n_sidebands: int = 2,
                     baseline_variance: float | None = None,
                     shaft_orders: Sequence[int] = _SHAFT_ORDERS) -> FloatArray:
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

    Examples
    --------
    A pure 38-tooth mesh tone and the same tone with one tooth's impact: the mesh leaves
    nothing in the difference signal (moment ratios of a near-zero signal are 0), the
    impact is a spike there (kurtosis near the 2048 points of one sample's spike).

    >>> import numpy as np
    >>> from gearshot.features import PAPER_FEATURES, extract_features
    >>> theta = np.arange(2048) / 2048
    >>> mesh = np.cos(2 * np.pi * 38 * theta)
    >>> impact = np.zeros(2048)
    >>> impact[1000] = 1.0
    >>> feats = extract_features(np.vstack([mesh, mesh + impact]), 38)
    >>> feats.shape
    (2, 4)
    >>> for name, healthy, faulty in zip(PAPER_FEATURES, *feats):
    ...     print(f"{name:18s} {healthy:6.2f} {faulty:9.2f}")
    rms_diff             0.00      0.02
    kurtosis_diff        0.00   1561.52
    rms_env_diff         0.00      0.03
    skewness_env_diff    0.00     20.95
    >>> fm0, er = extract_features(mesh + impact, 38, names=["fm0", "er"])
    >>> print(f"{fm0:.3f} {er:.3f}")
    1.954 0.030
    """
    x = as_signal_array(sa, "sa", min_length=4)
    return _features(x, None, x.shape[-1], mesh_order, names, n_sidebands, baseline_variance,
                     shaft_orders)


@finite_result
def spectrum_features(spectrum: ArrayLike, n_points: int, mesh_order: MeshOrders, *,
                      names: str | Iterable[str] | None = None, n_sidebands: int = 2,
                      baseline_variance: float | None = None,
                      shaft_orders: Sequence[int] = _SHAFT_ORDERS) -> FloatArray:
    """Condition indicators of synchronous averages given by their one-sided spectra.

    :func:`extract_features` of ``np.fft.irfft(spectrum, n_points)``, to within rounding,
    without that inverse FFT and the forward one the features would take again: for
    signals built in the frequency domain (the estimator's simulated side propagates,
    scales and subtracts there).

    Parameters
    ----------
    spectrum : array_like of complex, shape (..., n_points // 2 + 1)
        ``rfft`` of the SAs along the last axis (the imaginary parts at DC and, for even
        ``n_points``, at Nyquist are ignored, as ``irfft`` ignores them).
    n_points : int
        Points per cycle of the SAs.
    mesh_order, names, n_sidebands, baseline_variance, shaft_orders
        As for :func:`extract_features`.

    Returns
    -------
    ndarray, shape (..., n_features)

    Examples
    --------
    >>> import numpy as np
    >>> from gearshot.features import extract_features, spectrum_features
    >>> theta = np.arange(2048) / 2048
    >>> sa = np.cos(2 * np.pi * 38 * theta) + 0.1 * np.cos(2 * np.pi * 7 * theta) ** 9
    >>> a = spectrum_features(np.fft.rfft(sa), 2048, 38)
    >>> b = extract_features(sa, 38)
    >>> bool(np.allclose(a, b, rtol=1e-12, atol=0))
    True
    """
    n = check_int(n_points, "n_points", minimum=4)
    spec = np.asarray(spectrum)
    if not np.iscomplexobj(spec):
        raise GearshotError(f"spectrum must be complex (an rfft); got dtype {spec.dtype}")
    spec = np.ascontiguousarray(spec, dtype=np.complex128)
    if spec.ndim == 0 or spec.shape[-1] != n // 2 + 1:
        raise GearshotError(f"spectrum must have n_points // 2 + 1 = {n // 2 + 1} bins along "
                            f"its last axis; got shape {spec.shape}")
    as_signal_array(spec.view(np.float64), "spectrum")   # finite and bounded: cheap on a view
    return _features(None, spec, n, mesh_order, names, n_sidebands, baseline_variance,
                     shaft_orders)


def _features(sa: FloatArray | None, spectrum: ComplexArray | None, n: int,
              mesh_order: MeshOrders, names: str | Iterable[str] | None, n_sidebands: int,
              baseline_variance: float | None, shaft_orders: Sequence[int]) -> FloatArray:
    """The features of checked SAs or spectra (the parameters of :func:`extract_features`
    checked here)."""
    wanted = _check_names(names)
    orders = _mesh_arg(mesh_order, n)
    shafts = _check_shaft_orders(shaft_orders, n)
    n_sidebands = check_int(n_sidebands, "n_sidebands", minimum=0, maximum=n)
    if baseline_variance is not None:
        baseline_variance = check_positive(baseline_variance, "baseline_variance")
    lead = (sa if sa is not None else cast(ComplexArray, spectrum)).shape[:-1]
    flat_sa = None if sa is None else sa.reshape(-1, n)
    flat_spec = None if spectrum is None else spectrum.reshape(-1, spectrum.shape[-1])
    rows, out = max(1, _CHUNK_ELEMENTS // n), []
    for i in range(0, int(np.prod(lead, dtype=int)), rows):  # row blocks that stay in cache
        parts = _Parts(None if flat_sa is None else flat_sa[i:i + rows], orders, n_sidebands,
                       baseline_variance, shafts, n_points=n,
                       spectrum=None if flat_spec is None else flat_spec[i:i + rows])
        out.append(np.stack([_REGISTRY[name](parts) for name in wanted], axis=-1))
    return np.concatenate(out).reshape(lead + (len(wanted),))
