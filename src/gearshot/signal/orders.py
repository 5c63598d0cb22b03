"""Order-domain separation of a synchronous average into mesh and residual parts."""

from __future__ import annotations

import numpy as np
import scipy.fft

from .._errors import GearshotError
from .._validation import MAX_POINTS, as_signal_array, check_int, finite_result

__all__ = ["harmonic_signal", "difference_signal", "order_mask", "mesh_band_orders",
           "check_mesh_order", "check_mesh_orders"]


def check_mesh_order(mesh_order, n_points: int, name: str = "mesh_order") -> int:
    """Validate a mesh order against the Nyquist order of an ``n_points`` cycle."""
    mesh_order = check_int(mesh_order, name, minimum=1)
    if mesh_order >= n_points / 2:
        raise GearshotError(
            f"{name}={mesh_order} is at or above the Nyquist order {n_points // 2} of a "
            f"{n_points}-point cycle")
    return mesh_order


def check_mesh_orders(mesh_order, n_points: int, name: str = "mesh_order") -> tuple[int, ...]:
    """Validate one mesh order or a sequence of them (a shaft carrying several gears).

    Returns
    -------
    tuple of int
        The distinct orders, in the given order.
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


def mesh_band_orders(n_points: int, mesh_order, n_sidebands: int) -> np.ndarray:
    """One-sided orders (0 … n_points//2) of the mesh harmonics and their sidebands.

    ``mesh_order`` may be a sequence (a shaft carrying several gears): the union of the
    bands of every mesh.

    Harmonics ``k * mesh_order`` for ``k = 1 … floor((n_points/2) / mesh_order)``, each with
    ``±1 … ±n_sidebands`` sidebands. Orders beyond Nyquist or below zero are folded onto
    their mirror, as zeroing both halves of a two-sided spectrum would do. DC (order 0) is
    not a mesh harmonic and is kept unless a sideband folds onto it.
    """
    n_points = check_int(n_points, "n_points", minimum=2, maximum=MAX_POINTS)
    n_sidebands = check_int(n_sidebands, "n_sidebands", minimum=0, maximum=n_points)
    if isinstance(mesh_order, (list, tuple, np.ndarray)):
        return _unique_orders(np.concatenate([
            mesh_band_orders(n_points, m, n_sidebands)
            for m in check_mesh_orders(mesh_order, n_points)]), n_points)
    mesh_order = check_mesh_order(mesh_order, n_points)
    k = np.arange(1, (n_points // 2) // mesh_order + 1)
    width = 2 * n_sidebands + 1
    if width >= n_points:
        return np.arange(n_points // 2 + 1)      # every order is in a band
    else:   # the union of the bands k*m ± n_sidebands (mod n_points), in O(n_points) memory
        diff = np.zeros(n_points + 1, dtype=np.int64)
        lo = (k * mesh_order - n_sidebands) % n_points
        hi = lo + width
        wrap = hi > n_points
        np.add.at(diff, lo, 1)
        np.add.at(diff, np.minimum(hi, n_points), -1)
        np.add.at(diff, np.zeros(int(wrap.sum()), dtype=np.int64), 1)
        np.add.at(diff, hi[wrap] - n_points, -1)
        idx = np.flatnonzero(np.cumsum(diff[:-1]) > 0)
    return _unique_orders(np.minimum(idx, n_points - idx), n_points)


def _unique_orders(orders: np.ndarray, n_points: int) -> np.ndarray:
    """Sorted distinct orders in ``0 … n_points//2`` (a count, not a hash: linear time)."""
    return np.flatnonzero(np.bincount(orders, minlength=n_points // 2 + 1))


def order_mask(n_points, mesh_order, *, n_sidebands=2) -> np.ndarray:
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
    """
    n_points = check_int(n_points, "n_points", minimum=2, maximum=MAX_POINTS)
    mesh_order = list(check_mesh_orders(mesh_order, n_points))
    n_sidebands = check_int(n_sidebands, "n_sidebands", minimum=0, maximum=n_points)
    mask = np.zeros(n_points // 2 + 1, dtype=bool)
    mask[mesh_band_orders(n_points, mesh_order, n_sidebands)] = True
    return mask


def _split(sa, mesh_order, n_sidebands, keep_mesh: bool):
    sa = as_signal_array(sa, "sa", min_length=4)
    n = sa.shape[-1]
    mask = order_mask(n, mesh_order, n_sidebands=n_sidebands)
    spectrum = scipy.fft.rfft(sa, axis=-1)
    spectrum *= mask if keep_mesh else ~mask
    return scipy.fft.irfft(spectrum, n=n, axis=-1)


@finite_result
def harmonic_signal(sa, mesh_order, *, n_sidebands=2) -> np.ndarray:
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
    """
    return _split(sa, mesh_order, n_sidebands, keep_mesh=True)


@finite_result
def difference_signal(sa, mesh_order, *, n_sidebands=2) -> np.ndarray:
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

    Returns
    -------
    ndarray, shape (..., n_points), real
    """
    return _split(sa, mesh_order, n_sidebands, keep_mesh=False)
