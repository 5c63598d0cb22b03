"""Order-domain separation of a synchronous average into mesh and residual parts.

The three classical parts of a synchronous average (SA), with the reference toolchain's
names (MATLAB Predictive Maintenance Toolbox) for orientation:

* :func:`regular_signal` -- the shaft orders and every mesh harmonic (with optional
  sidebands), everything else zeroed: ``tsaregular`` with the shaft orders and the mesh
  orders in its order list (here the shaft orders are listed one by one, since all
  harmonics of order 1 would be every order).
* :func:`difference_signal` -- the SA with the mesh harmonics and ``n_sidebands``
  sidebands removed; with ``shaft_orders=`` also those shaft orders and DC, which is
  ``tsadifference`` (regular signal and first-order sidebands removed: ``n_sidebands=1,
  shaft_orders=(1, 2)``). Without ``shaft_orders`` it is the paper's difference signal.
* :func:`residual_signal` -- the SA minus its regular signal (shaft orders, DC and mesh
  harmonics removed, sidebands kept): ``tsaresidual``; NA4 is its normalized kurtosis.

The *non-synchronous* part of the angle-domain signal -- what every revolution does
differently, invisible in any SA -- is :func:`gearshot.signal.nonsynchronous_signal`.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import cast

import numpy as np
from numpy.typing import ArrayLike

from .._errors import GearshotError
from .._typing import BoolArray, FloatArray, IntArray
from .._validation import MAX_POINTS, as_signal_array, check_int, finite_result

__all__ = ["harmonic_signal", "difference_signal", "regular_signal", "residual_signal",
           "order_mask", "mesh_band_orders", "check_mesh_order", "check_mesh_orders"]


#: One mesh order or several (a shaft carrying several gears).
MeshOrders = int | Sequence[int] | ArrayLike


def check_mesh_order(mesh_order: object, n_points: int, name: str = "mesh_order") -> int:
    """Validate a mesh order against the Nyquist order of an ``n_points`` cycle.

    Examples
    --------
    >>> from gearshot.signal.orders import check_mesh_order
    >>> check_mesh_order(38, 2048)
    38
    >>> check_mesh_order(1024, 2048)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    gearshot._errors.GearshotError: mesh_order=1024 is at or above the Nyquist order 1024 ...
    """
    mesh_order = check_int(mesh_order, name, minimum=1)
    if mesh_order >= n_points / 2:
        raise GearshotError(
            f"{name}={mesh_order} is at or above the Nyquist order {n_points // 2} of a "
            f"{n_points}-point cycle")
    return mesh_order


def check_mesh_orders(mesh_order: MeshOrders, n_points: int,
                      name: str = "mesh_order") -> tuple[int, ...]:
    """Validate one mesh order or a sequence of them (a shaft carrying several gears).

    Returns
    -------
    tuple of int
        The distinct orders, in the given order.

    Examples
    --------
    >>> from gearshot.signal.orders import check_mesh_orders
    >>> check_mesh_orders([38, 16, 38], 2048)
    (38, 16)
    >>> check_mesh_orders(38, 2048)
    (38,)
    """
    if isinstance(mesh_order, (list, tuple, np.ndarray)):
        orders = (mesh_order.ravel().tolist() if isinstance(mesh_order, np.ndarray)
                  else list(mesh_order))
        if not orders:
            raise GearshotError(f"{name} must name at least one mesh order; got {mesh_order!r}")
        out = []
        for i, o in enumerate(orders):
            o = check_mesh_order(o, n_points, f"{name}[{i}]")
            if o not in out:
                out.append(o)
        return tuple(out)
    return (check_mesh_order(mesh_order, n_points, name),)


def mesh_band_orders(n_points: int, mesh_order: MeshOrders, n_sidebands: int) -> IntArray:
    """One-sided orders (0 … n_points//2) of the mesh harmonics and their sidebands.

    ``mesh_order`` may be a sequence (a shaft carrying several gears): the union of the
    bands of every mesh.

    Harmonics ``k * mesh_order`` for ``k = 1 … floor((n_points/2) / mesh_order)``, each with
    ``±1 … ±n_sidebands`` sidebands. Orders beyond Nyquist or below zero are folded onto
    their mirror, as zeroing both halves of a two-sided spectrum would do. DC (order 0) is
    not a mesh harmonic and is kept unless a sideband folds onto it.

    Examples
    --------
    Mesh order 10 in a 64-point cycle (Nyquist order 32), one sideband each side:

    >>> from gearshot.signal import mesh_band_orders
    >>> print(mesh_band_orders(64, 10, 1))
    [ 9 10 11 19 20 21 29 30 31]
    >>> print(mesh_band_orders(64, [10, 16], 0))    # two meshes on the shaft
    [10 16 20 30 32]
    """
    n_points = check_int(n_points, "n_points", minimum=2, maximum=MAX_POINTS)
    n_sidebands = check_int(n_sidebands, "n_sidebands", minimum=0, maximum=n_points)
    if isinstance(mesh_order, (list, tuple, np.ndarray)):
        return _unique_orders(np.concatenate([
            mesh_band_orders(n_points, m, n_sidebands)
            for m in check_mesh_orders(mesh_order, n_points)]), n_points)
    order = check_mesh_order(mesh_order, n_points)
    k = np.arange(1, (n_points // 2) // order + 1)
    width = 2 * n_sidebands + 1
    if width >= n_points:
        return cast(IntArray, np.arange(n_points // 2 + 1))   # every order is in a band
    else:   # the union of the bands k*m ± n_sidebands (mod n_points), in O(n_points) memory
        diff = np.zeros(n_points + 1, dtype=np.int64)
        lo = (k * order - n_sidebands) % n_points
        hi = lo + width
        wrap = hi > n_points
        np.add.at(diff, lo, 1)
        np.add.at(diff, np.minimum(hi, n_points), -1)
        np.add.at(diff, np.zeros(int(wrap.sum()), dtype=np.int64), 1)
        np.add.at(diff, hi[wrap] - n_points, -1)
        idx = np.flatnonzero(np.cumsum(diff[:-1]) > 0)
    return _unique_orders(np.minimum(idx, n_points - idx), n_points)


def _unique_orders(orders: IntArray, n_points: int) -> IntArray:
    """Sorted distinct orders in ``0 … n_points//2`` (a count, not a hash: linear time)."""
    return cast(IntArray, np.flatnonzero(np.bincount(orders, minlength=n_points // 2 + 1)))


def order_mask(n_points: int, mesh_order: MeshOrders, *, n_sidebands: int = 2) -> BoolArray:
    """Boolean mask over one-sided orders ``0 … n_points//2``; True on mesh bands.

    Parameters
    ----------
    n_points : int
        Samples per cycle.
    mesh_order : int or sequence of int
        Mesh order(s) in the cycle (teeth of the wheel(s) on the shaft whose revolution is
        the cycle).
    n_sidebands : int
        Sidebands on each side of every mesh harmonic.

    Returns
    -------
    mask : ndarray of bool, shape (n_points // 2 + 1,)

    Examples
    --------
    >>> import numpy as np
    >>> from gearshot.signal import order_mask
    >>> mask = order_mask(64, 10, n_sidebands=1)
    >>> mask.shape
    (33,)
    >>> print(np.flatnonzero(mask))
    [ 9 10 11 19 20 21 29 30 31]
    """
    n_points = check_int(n_points, "n_points", minimum=2, maximum=MAX_POINTS)
    mesh_order = list(check_mesh_orders(mesh_order, n_points))
    n_sidebands = check_int(n_sidebands, "n_sidebands", minimum=0, maximum=n_points)
    mask = np.zeros(n_points // 2 + 1, dtype=bool)
    mask[mesh_band_orders(n_points, mesh_order, n_sidebands)] = True
    return mask


def _shaft_orders(shaft_orders: int | Sequence[int], n: int) -> list[int]:
    listed: object = shaft_orders
    if isinstance(shaft_orders, (int, np.integer)) and not isinstance(shaft_orders, bool):
        listed = [shaft_orders]
    try:
        orders = list(listed)  # type: ignore[call-overload]
    except TypeError:
        raise GearshotError(f"shaft_orders must be a sequence of integers; got "
                            f"{shaft_orders!r}") from None
    out = []
    for i, o in enumerate(orders):
        o = check_int(o, f"shaft_orders[{i}]", minimum=0)
        if o > n // 2:
            raise GearshotError(f"shaft_orders[{i}]={o} is above the Nyquist order {n // 2} "
                                f"of a {n}-point cycle")
        out.append(o)
    return out


def _split(sa: ArrayLike, mesh_order: MeshOrders, n_sidebands: int, keep_mesh: bool,
           shaft_orders: int | Sequence[int] | None = None) -> FloatArray:
    sa = as_signal_array(sa, "sa", min_length=4)
    n = sa.shape[-1]
    mask = order_mask(n, mesh_order, n_sidebands=n_sidebands)
    if shaft_orders is not None:
        mask[[0, *_shaft_orders(shaft_orders, n)]] = True
    spectrum = np.fft.rfft(sa, axis=-1)
    spectrum *= mask if keep_mesh else ~mask
    return np.fft.irfft(spectrum, n=n, axis=-1)


@finite_result
def harmonic_signal(sa: ArrayLike, mesh_order: MeshOrders, *,
                    n_sidebands: int = 2) -> FloatArray:
    """The mesh harmonics of a synchronous average and their sidebands.

    Keeps orders ``k * mesh_order + s`` (``k >= 1``, ``|s| <= n_sidebands``) in both halves of
    the spectrum and zeroes every other order, DC included. ``harmonic_signal + difference_signal
    == sa`` exactly.

    Parameters
    ----------
    sa : array_like, shape (..., n_points)
        Synchronous average(s), one cycle each.
    mesh_order : int or sequence of int
        Gear-mesh order(s) in the cycle (38 for the paper's gear revolution).
    n_sidebands : int, default 2
        Sidebands kept on each side of every harmonic.

    Returns
    -------
    ndarray, shape (..., n_points), real

    Examples
    --------
    A mesh tone at order 10 and a fault component at order 3:

    >>> import numpy as np
    >>> from gearshot.signal import difference_signal, harmonic_signal, rms
    >>> theta = np.arange(64) / 64
    >>> sa = np.cos(2 * np.pi * 10 * theta) + 0.5 * np.cos(2 * np.pi * 3 * theta)
    >>> print(round(float(rms(harmonic_signal(sa, 10))), 4))    # the unit mesh tone
    0.7071
    >>> bool(np.allclose(harmonic_signal(sa, 10) + difference_signal(sa, 10), sa))
    True
    """
    return _split(sa, mesh_order, n_sidebands, keep_mesh=True)


@finite_result
def difference_signal(sa: ArrayLike, mesh_order: MeshOrders, *, n_sidebands: int = 2,
                      shaft_orders: int | Sequence[int] | None = None) -> FloatArray:
    """A synchronous average with its mesh harmonics and sidebands removed.

    Zeroes orders ``k * mesh_order + s`` for ``k = 1 … floor(n/2 / mesh_order)`` and
    ``|s| <= n_sidebands`` in both halves of the spectrum, keeps every other order (DC
    included) untouched — the reference implementation's difference signal.

    Parameters
    ----------
    sa : array_like, shape (..., n_points)
        Synchronous average(s).
    mesh_order : int or sequence of int
        Gear-mesh order in the cycle; several for a shaft carrying several gears (e.g.
        ``[96, 48]`` for an idler shaft: every mesh's harmonics and sidebands go).
    n_sidebands : int, default 2
        Sidebands removed on each side of every harmonic.
    shaft_orders : sequence of int, optional
        Shaft orders removed too, with DC (the regular signal's shaft part): with
        ``n_sidebands=1, shaft_orders=(1, 2)`` this is Zakrajsek's difference signal (FM4),
        the reference toolchain's ``tsadifference``. Default: none (the paper's).

    Returns
    -------
    ndarray, shape (..., n_points), real

    Examples
    --------
    The mesh tone at order 10 goes, the order-3 component stays:

    >>> import numpy as np
    >>> from gearshot.signal import difference_signal
    >>> theta = np.arange(64) / 64
    >>> fault = 0.5 * np.cos(2 * np.pi * 3 * theta)
    >>> diff = difference_signal(np.cos(2 * np.pi * 10 * theta) + fault, 10)
    >>> bool(np.allclose(diff, fault))
    True
    >>> print(np.round(diff[:3], 3))
    [0.5   0.478 0.416]
    """
    return _split(sa, mesh_order, n_sidebands, keep_mesh=False, shaft_orders=shaft_orders)


@finite_result
def regular_signal(sa: ArrayLike, mesh_order: MeshOrders, *,
                   shaft_orders: int | Sequence[int] | None = (1, 2),
                   n_sidebands: int = 0) -> FloatArray:
    """The regular part of a synchronous average: shaft orders and mesh harmonics.

    Keeps the listed shaft orders and every harmonic of every mesh order (with
    ``n_sidebands`` sidebands each), zeroes everything else, DC included. The reference
    toolchain's ``tsaregular`` with the shaft and mesh orders in its order list.
    ``regular_signal(sa, m) + residual_signal(sa, m) == sa - mean(sa)``.

    Parameters
    ----------
    sa : array_like, shape (..., n_points)
        Synchronous average(s), one cycle each.
    mesh_order : int or sequence of int
        Mesh order(s) of the cycle (every mesh synchronous with the shaft,
        :meth:`gearshot.Machine.mesh_orders`).
    shaft_orders : sequence of int, default (1, 2)
        Shaft orders kept (each one alone, not its harmonics).
    n_sidebands : int, default 0
        Sidebands kept on each side of every mesh harmonic.

    Returns
    -------
    ndarray, shape (..., n_points), real

    Examples
    --------
    >>> import numpy as np
    >>> from gearshot.signal import regular_signal, residual_signal
    >>> k = np.arange(64) / 64
    >>> other = 0.1 * np.cos(2 * np.pi * 5 * k)  # order 5: neither shaft nor mesh
    >>> sa = np.cos(2 * np.pi * 8 * k) + 0.5 * np.cos(2 * np.pi * k) + other
    >>> bool(np.allclose(regular_signal(sa, 8), sa - other))
    True
    >>> bool(np.allclose(residual_signal(sa, 8), other))
    True
    """
    out = _split(sa, mesh_order, n_sidebands, keep_mesh=True,
                 shaft_orders=() if shaft_orders is None else shaft_orders)
    return cast(FloatArray, out - out.mean(axis=-1, keepdims=True))


@finite_result
def residual_signal(sa: ArrayLike, mesh_order: MeshOrders, *,
                    shaft_orders: int | Sequence[int] = (1, 2)) -> FloatArray:
    """The residual of a synchronous average: shaft orders, DC and mesh harmonics removed.

    What is left of the SA once its regular signal (:func:`regular_signal`, no sidebands)
    is taken out: the mesh sidebands and every other synchronous order. The reference
    toolchain's ``tsaresidual``; the signal whose normalized kurtosis is NA4.

    Parameters
    ----------
    sa : array_like, shape (..., n_points)
    mesh_order : int or sequence of int
    shaft_orders : sequence of int, default (1, 2)
        Shaft orders removed.

    Returns
    -------
    ndarray, shape (..., n_points), real

    Examples
    --------
    The shaft orders 1–2, DC and the mesh go; an order that is neither stays:

    >>> import numpy as np
    >>> from gearshot.signal import residual_signal
    >>> k = np.arange(64) / 64
    >>> other = 0.1 * np.cos(2 * np.pi * 5 * k)
    >>> sa = 2.0 + np.cos(2 * np.pi * 8 * k) + 0.5 * np.cos(2 * np.pi * k) + other
    >>> bool(np.allclose(residual_signal(sa, 8), other))
    True
    """
    return _split(sa, mesh_order, 0, keep_mesh=False,
                  shaft_orders=() if shaft_orders is None else shaft_orders)
