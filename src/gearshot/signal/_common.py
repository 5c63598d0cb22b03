"""Private helpers shared by the signal functions."""

from __future__ import annotations

import numpy as np

from .._errors import GearshotError
from .._validation import check_int


def check_mesh_order(mesh_order, n_points: int, name: str = "mesh_order") -> int:
    """Validate a mesh order against the Nyquist order of an ``n_points`` cycle."""
    mesh_order = check_int(mesh_order, name, minimum=1)
    if mesh_order >= n_points / 2:
        raise GearshotError(
            f"{name}={mesh_order} is at or above the Nyquist order {n_points // 2} of a "
            f"{n_points}-point cycle")
    return mesh_order


def mesh_band_orders(n_points: int, mesh_order: int, n_sidebands: int) -> np.ndarray:
    """One-sided orders (0 … n_points//2) of the mesh harmonics and their sidebands.

    Harmonics ``k * mesh_order`` for ``k = 1 … floor((n_points/2) / mesh_order)``, each with
    ``±1 … ±n_sidebands`` sidebands. Orders beyond Nyquist or below zero are folded onto
    their mirror, as zeroing both halves of a two-sided spectrum would do. DC (order 0) is
    not a mesh harmonic and is kept unless a sideband folds onto it.
    """
    k = np.arange(1, (n_points // 2) // mesh_order + 1)
    s = np.arange(-n_sidebands, n_sidebands + 1)
    idx = (k[:, None] * mesh_order + s[None, :]).ravel() % n_points
    folded = np.minimum(idx, n_points - idx)
    return np.unique(folded)
