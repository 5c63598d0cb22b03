"""The slice method for helical pairs: thin spur slices staggered along the helix.

A helical pair is cut into thin slices across the face width; each slice is a spur pair of
the transverse profile, and the slice at face position zeta (0 ... 1) meshes
``zeta * epsilon_beta`` mesh periods after the slice at zeta = 0 (epsilon_beta, the
overlap ratio). All terms of the potential-energy pair stiffness scale with the width, so
a slice of width ``b dzeta`` has ``dzeta`` times the full-width spur pair stiffness, and a
tooth pair's stiffness at delay tau (mesh periods since its first slice entered) is the
face average

    k(tau) = integral_0^1 k_spur((tau - zeta eps_beta) / eps_alpha) dzeta
           = (1 / eps_beta) integral_0^eps_beta k_spur((tau - x) / eps_alpha) dx,

a box filter of the spur single-pair curve. It is evaluated in the limit of infinitely
many slices, exactly for the piecewise-linear tables (their exact running integral), and
likewise for the force ``k e`` of the profile errors and for faults that cover part of
the face (:meth:`~gearshot.sim.ToothFault.face_bands`): a band [z0, z1] contributes the
integral over x in [z0 eps_beta, z1 eps_beta] only.
"""

from __future__ import annotations

import numba as nb
import numpy as np

__all__ = ["tau_grid", "box"]


_MAX_TAU = 8193     # table points over tau at most (fine grids only for tiny overlaps)


def tau_grid(eps_alpha: float, eps_beta: float, n_table: int) -> np.ndarray:
    """Delays tau (mesh periods) of the helical tables: from 0 past the total contact
    ratio, on the spur table's step ``eps_alpha / (n_table - 1)``, refined for small
    overlap ratios so that the entry and exit ramps (eps_beta wide) span >= 4 steps."""
    step = eps_alpha / (n_table - 1)
    total = eps_alpha + eps_beta
    step = max(min(step, eps_beta / 4), total / (_MAX_TAU - 2))
    n_tau = int(np.ceil(total / step - 1e-9)) + 1
    return np.arange(n_tau) * step


def box(f: np.ndarray, eps_alpha: float, eps_beta: float, lo, hi,
        tau: np.ndarray) -> np.ndarray:
    """Face integral of a spur single-pair curve over a band of delays.

    Parameters
    ----------
    f : ndarray (..., n_table)
        Curve over the spur contact position u in [0, 1] (0 outside).
    eps_alpha, eps_beta : float
        Transverse and overlap contact ratios (eps_beta > 0).
    lo, hi : float or ndarray (n_bands,)
        Band of delays, mesh periods (0 <= lo <= hi <= eps_beta): face fractions times
        eps_beta. Arrays: one band per entry of ``f``'s first axis (``f`` of shape
        (n_bands, ..., n_table)), each boxed over its own band in one call.
    tau : ndarray (n_tau,)
        Delays (mesh periods) at which to evaluate (:func:`tau_grid`).

    Returns
    -------
    ndarray (..., n_tau)
        ``(1 / eps_beta) integral_lo^hi f((tau - x) / eps_alpha) dx``.
    """
    n = f.shape[-1]
    step = eps_alpha / (n - 1)
    # exact integral of the piecewise-linear curve: cumulative trapezoid at the nodes,
    # quadratic inside a cell (a linear interpolation of the nodes would turn the face
    # average into a staircase for small overlaps)
    fp = np.concatenate([f, f[..., -1:]], axis=-1)      # sentinel cell past the end
    cum = np.zeros(f.shape[:-1] + (n + 1,))
    cum[..., 1:n] = np.cumsum(0.5 * (f[..., 1:] + f[..., :-1]), axis=-1) * step
    cum[..., n] = cum[..., n - 1]
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    rows = int(np.prod(f.shape[:-1], dtype=np.int64))
    per_band = rows // f.shape[0] if lo.ndim > 0 and f.ndim > 1 else rows
    lo_rows = np.repeat(np.broadcast_to(lo, (rows // per_band,)), per_band)
    hi_rows = np.repeat(np.broadcast_to(hi, (rows // per_band,)), per_band)
    out = np.empty((rows, tau.size))
    _box_rows(fp.reshape(rows, n + 1), cum.reshape(rows, n + 1), step,
              np.ascontiguousarray(tau, dtype=float), lo_rows, hi_rows, eps_beta, out)
    return out.reshape(f.shape[:-1] + (tau.size,))


@nb.njit(cache=True, inline="always")
def _running(fp, cum, r, n, step, t):
    """The running integral of row ``r`` at delay ``t`` (mesh periods)."""
    p = min(max(t / step, 0.0), n - 1.0)
    i = min(int(p), n - 1)
    frac = p - i
    f0 = fp[r, i]
    df = fp[r, i + 1] - f0 if i < n - 1 else 0.0
    return cum[r, i] + step * frac * (f0 + 0.5 * df * frac)


@nb.njit(cache=True, nogil=True)
def _box_rows(fp, cum, step, tau, lo, hi, eps_beta, out):
    """:func:`box` of every row (its own band ``lo[r] ... hi[r]``) into ``out``."""
    n = fp.shape[1] - 1
    for r in range(fp.shape[0]):
        for j in range(tau.size):
            out[r, j] = (_running(fp, cum, r, n, step, tau[j] - lo[r])
                         - _running(fp, cum, r, n, step, tau[j] - hi[r])) / eps_beta
