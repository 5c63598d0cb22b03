"""Per-signal tables of a helical batch, built for the whole batch at once.

The error force of a tooth pair over the delay tau is the face integral (:func:`box`) of
the spur pair stiffness times the profile error. The error of a tooth is linear in its
parameters: ``slope s + wa sin(2 pi n s) + wb cos(2 pi n s) + sum_j noise_j hat_j(s)``
(:class:`~gearshot.sim.profile_errors.ToothProfileErrors`, ``wa, wb`` the waviness's
sine/cosine amplitudes), so the boxed force of every tooth of every signal is one matrix
product of its parameters with the boxed basis functions, which depend on the pair only
(cached). A fault adds its face bands' terms to its tooth; faults with the same bands
(e.g. every FTFF: the whole face) are boxed in one call.
"""

from __future__ import annotations

import functools

import numpy as np
from threadpoolctl import threadpool_limits

from ._slices import box
from .geometry import GearPair
from .profile_errors import noise_cell, wave_amplitudes
from .stiffness import _N_TABLE, _pair_table, band_arrays, helical_tables

__all__ = ["helical_batch_tables"]


@functools.lru_cache(maxsize=16)
def _error_basis(pair: GearPair, n_waves: float, n_knots: int) -> np.ndarray:
    """Boxed force basis (3 + n_knots, n_tau): spur stiffness times s, sin, cos and the
    noise hat functions, boxed over the face."""
    ea, eb = pair.contact_ratio, pair.overlap_ratio
    span, k, _ = helical_tables(pair)
    tau = np.linspace(0.0, span, k.size)
    s = np.linspace(0.0, 1.0, _N_TABLE)
    i0, frac = noise_cell(s, n_knots)
    hats = np.zeros((n_knots, s.size))
    hats[i0, np.arange(s.size)] += 1 - frac
    hats[i0 + 1, np.arange(s.size)] += frac
    phase = 2 * np.pi * n_waves * s
    funcs = np.vstack([s, np.sin(phase), np.cos(phase), hats])
    out = box(_pair_table(pair, None) * funcs, ea, eb, 0.0, eb, tau)
    out.setflags(write=False)
    return out


def _params(errs) -> np.ndarray:
    """(n, z, 3 + n_knots): slope, waviness sine and cosine amplitudes, noise knots."""
    wa, wb = wave_amplitudes(np.stack([e.waviness for e in errs]),
                             np.stack([e.phase for e in errs]))
    return np.concatenate([np.stack([e.slope for e in errs])[..., None], wa[..., None],
                           wb[..., None], np.stack([e.noise for e in errs])], axis=-1)


def _forces(pair: GearPair, errs, n_pad: int) -> np.ndarray:
    """Boxed error force (z, n_tau, n_pad) of every tooth of every signal (signals last,
    padded by repeating the last signal)."""
    p = _params(errs)
    p = np.concatenate([p, np.repeat(p[-1:], n_pad - p.shape[0], axis=0)])
    basis = _error_basis(pair, float(errs[0].n_waves), errs[0].noise.shape[1])
    p = p.transpose(1, 2, 0).copy()                              # (z, n_basis, n_pad)
    out = np.empty((p.shape[0], basis.shape[1], n_pad))
    bt = np.ascontiguousarray(basis.T)
    # small products: a threaded BLAS only spins (x30 CPU time measured), so one thread
    with threadpool_limits(1, user_api="blas"):
        for t in range(p.shape[0]):                              # one product per tooth
            out[t] = bt @ p[t]
    return out


def helical_batch_tables(pair: GearPair, faults, gear_errs, pin_errs, n_pad: int):
    """Tables of a helical batch.

    Returns
    -------
    span : float
    k : ndarray (n_tau,)
        Healthy pair stiffness over the delay.
    kf : ndarray (n, n_tau)
        Pair stiffness of each signal's faulty tooth (healthy when none).
    tooth : ndarray (n,) int64
        Faulty gear tooth (-1: none).
    fg, fp, fpf : ndarray (n, z_gear, n_tau), (n, z_pinion, n_tau), (n, z_pinion, n_tau)
        Error force of each gear tooth (with the fault's terms on its tooth), of each
        pinion tooth, and of each pinion tooth when meshing with the faulty gear tooth.
    """
    ea, eb = pair.contact_ratio, pair.overlap_ratio
    span, k, _ = helical_tables(pair)
    tau = np.linspace(0.0, span, k.size)
    u = np.linspace(0.0, 1.0, _N_TABLE)
    n = len(faults)
    fg, fp = _forces(pair, gear_errs, n_pad), _forces(pair, pin_errs, n_pad)
    fpf = fp[:, :, :n].transpose(2, 0, 1).copy()       # a copy even for size-1 axes
    kf = np.tile(k, (n, 1))
    tooth = np.full(n, -1, dtype=np.int64)
    groups: dict = {}
    for i, f in enumerate(faults):
        if f is None or f.is_healthy:
            continue
        t = f.tooth % pair.z_gear
        tooth[i] = t
        _, _, bands = helical_tables(pair, f, stiffness=False)
        if not bands:
            kf[i] = helical_tables(pair, f)[1]
            continue
        lo, hi, dk, kd = band_arrays(bands)
        groups.setdefault((lo.tobytes(), hi.tobytes()), []).append((i, t, lo, hi, dk, kd))
    pin_teeth = np.arange(pin_errs[0].slope.size)[:, None]
    for members in groups.values():
        idx = [m[0] for m in members]
        lo, hi = members[0][2], members[0][3]
        dk = np.stack([m[4] for m in members], axis=1)          # (n_bands, n_f, n_u)
        kd = np.stack([m[5] for m in members], axis=1)
        e_g = np.stack([gear_errs[i](t, u) for i, t, *_ in members])        # (n_f, n_u)
        e_p = np.stack([pin_errs[i](pin_teeth, u[None, :]) for i in idx])   # (n_f, z_p, n_u)
        rows = np.array(idx)
        teeth = np.array([m[1] for m in members])
        k_rows = kf[rows]
        for part in box(dk, ea, eb, lo, hi, tau):       # added band by band, in order
            k_rows += part
        kf[rows] = np.maximum(k_rows, 0.0)
        g_rows = fg[teeth, :, rows]                     # (n_f, n_tau)
        for part in box(dk * e_g[None] + kd, ea, eb, lo, hi, tau):
            g_rows += part
        fg[teeth, :, rows] = g_rows
        p_rows = fpf[rows]
        for part in box(dk[:, :, None, :] * e_p[None], ea, eb, lo, hi, tau):
            p_rows += part
        fpf[rows] = p_rows
    return span, k, kf, tooth, fg, fp, fpf
