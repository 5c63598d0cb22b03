"""Numba kernels of the batched Newmark integration (no input checking here).

:func:`newmark_batch` advances a batch of signals that share one integrator (the
Newmark matrices of :mod:`gearshot.sim._system`) through given mesh positions, with
per-signal fault tables and profile errors; the effective-stiffness inverse for the
current mesh stiffness follows from one precomputed inverse by the Sherman-Morrison
formula (a rank-one update along the line-of-action vector).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

__all__ = ["G0", "newmark_batch", "newmark_batch_tables"]

G0 = 9.80665  # m/s^2 per g


@nb.njit(cache=True, fastmath=False)
def _interp_table(tab, u):
    n = tab.shape[0] - 1
    p = u * n
    i = int(p)
    if i >= n:
        return tab[n]
    f = p - i
    return tab[i] * (1.0 - f) + tab[i + 1] * f


@nb.njit(cache=True)
def _tooth_error(slope, wav, phase, noise, nwaves, t, s):
    knots = noise.shape[1]
    p = s * (knots - 1)
    i = int(p)
    if i > knots - 2:
        i = knots - 2
    f = p - i
    return (slope[t] * s + 0.5 * wav[t] * math.sin(2.0 * math.pi * nwaves * s + phase[t])
            + noise[t, i] * (1.0 - f) + noise[t, i + 1] * f)


@nb.njit(cache=True, parallel=True, fastmath=True)
def newmark_batch(mesh_pos, motor_acc, load, k_tab, kf_tab, ef_tab, f_tooth,
                  g_slope, g_wav, g_phase, g_noise, g_nw,
                  p_slope, p_wav, p_phase, p_noise, p_nw,
                  eps, z_gear, B1, B2, B3, w, s, v, c_load, c_motor, X, V, A, coef,
                  rec_start, out):
    """Integrate ``out.shape[0]`` signals over ``mesh_pos`` (in mesh periods); the state
    ``X, V, A`` (n_batch, ndof) is updated in place and the vertical acceleration (g) of
    steps ``rec_start ... rec_start + out.shape[1] - 1`` is written into ``out``."""
    n_batch = out.shape[0]
    n_steps = mesh_pos.shape[0]
    n_rec = out.shape[1]
    ndof = X.shape[1]
    a0, a2, a3, a6, a7 = coef[0], coef[1], coef[2], coef[3], coef[4]
    n_pairs = int(math.ceil(eps)) + 1
    z_pin = p_slope.shape[1]
    for b in nb.prange(n_batch):
        x = X[b].copy()
        vel = V[b].copy()
        acc = A[b].copy()
        xb = np.zeros(ndof)
        for n in range(n_steps):
            tm = mesh_pos[n]
            # a pair's entry/exit is anti-aliased: its contribution is weighted by the
            # fraction of a step-wide window around tm that lies inside its contact
            if n > 0:
                half = 0.5 * abs(tm - mesh_pos[n - 1])
            else:
                half = 0.5 * abs(mesh_pos[min(1, n_steps - 1)] - tm)
            base = math.floor(tm)
            kk = 0.0
            fex = 0.0
            for j in range(-1, n_pairs):
                nn = base - j
                lo = tm - half - nn
                hi = tm + half - nn
                if hi <= 0.0 or lo >= eps:
                    continue
                if hi > lo:
                    wgt = (min(hi, eps) - max(lo, 0.0)) / (hi - lo)
                else:
                    wgt = 1.0
                u = (tm - nn) / eps
                if u < 0.0:
                    u = 0.0
                elif u > 1.0:
                    u = 1.0
                gt = int(nn % z_gear)
                pt = int(nn % z_pin)
                faulty = gt == f_tooth[b]
                if faulty:
                    k = _interp_table(kf_tab[b], u)
                else:
                    k = _interp_table(k_tab, u)
                # both wheels' errors run along the path of contact (as in the lab's
                # model): their slope terms add into a mesh-periodic sawtooth
                e = (_tooth_error(g_slope[b], g_wav[b], g_phase[b], g_noise[b], g_nw, gt, u)
                     + _tooth_error(p_slope[b], p_wav[b], p_phase[b], p_noise[b], p_nw, pt,
                                    u))
                if faulty:
                    e += _interp_table(ef_tab[b], u)
                kk += wgt * k
                fex += wgt * k * e
            ld = load[n]
            ma = motor_acc[n]
            for i in range(ndof):
                acc_i = w[i] * fex + c_load[i] * ld + c_motor[i] * ma
                for jj in range(ndof):
                    acc_i += B1[i, jj] * x[jj] + B2[i, jj] * vel[jj] + B3[i, jj] * acc[jj]
                xb[i] = acc_i
            proj = 0.0
            for i in range(ndof):
                proj += v[i] * xb[i]
            corr = kk * proj / (1.0 + kk * s)
            for i in range(ndof):
                xn = xb[i] - corr * w[i]
                an = a0 * (xn - x[i]) - a2 * vel[i] - a3 * acc[i]
                vel[i] = vel[i] + a6 * acc[i] + a7 * an
                acc[i] = an
                x[i] = xn
            r = n - rec_start
            if r >= 0 and r < n_rec:
                out[b, r] = (acc[1] + acc[4]) / G0
        X[b] = x
        V[b] = vel
        A[b] = acc


@nb.njit(cache=True, parallel=True, fastmath=True)
def newmark_batch_tables(mesh_pos, motor_acc, load, k_tab, kf_tab, f_tooth, fg_tab, fp_tab,
                         fpf_tab, span, B1, B2, B3, w, s, v, c_load, c_motor, X, V, A, coef,
                         rec_start, out):
    """As :func:`newmark_batch`, with every tooth pair's stiffness and error force read
    from tables over the delay since the pair's first contact (0 ... ``span`` mesh
    periods): ``k_tab`` (healthy) or ``kf_tab[b]`` (the faulty gear tooth
    ``f_tooth[b]``); force ``fg_tab[b, gear tooth] + fp_tab[b, pinion tooth]`` (or
    ``fpf_tab`` when the gear tooth is the faulty one). Used for helical pairs."""
    n_batch = out.shape[0]
    n_steps = mesh_pos.shape[0]
    n_rec = out.shape[1]
    ndof = X.shape[1]
    a0, a2, a3, a6, a7 = coef[0], coef[1], coef[2], coef[3], coef[4]
    n_pairs = int(math.ceil(span)) + 1
    z_gear = fg_tab.shape[1]
    z_pin = fp_tab.shape[1]
    for b in nb.prange(n_batch):
        x = X[b].copy()
        vel = V[b].copy()
        acc = A[b].copy()
        xb = np.zeros(ndof)
        for n in range(n_steps):
            tm = mesh_pos[n]
            if n > 0:
                half = 0.5 * abs(tm - mesh_pos[n - 1])
            else:
                half = 0.5 * abs(mesh_pos[min(1, n_steps - 1)] - tm)
            base = math.floor(tm)
            kk = 0.0
            fex = 0.0
            for j in range(-1, n_pairs):
                nn = base - j
                lo = tm - half - nn
                hi = tm + half - nn
                if hi <= 0.0 or lo >= span:
                    continue
                if hi > lo:
                    wgt = (min(hi, span) - max(lo, 0.0)) / (hi - lo)
                else:
                    wgt = 1.0
                u = (tm - nn) / span
                if u < 0.0:
                    u = 0.0
                elif u > 1.0:
                    u = 1.0
                gt = int(nn % z_gear)
                pt = int(nn % z_pin)
                if gt == f_tooth[b]:
                    k = _interp_table(kf_tab[b], u)
                    f = _interp_table(fg_tab[b, gt], u) + _interp_table(fpf_tab[b, pt], u)
                else:
                    k = _interp_table(k_tab, u)
                    f = _interp_table(fg_tab[b, gt], u) + _interp_table(fp_tab[b, pt], u)
                kk += wgt * k
                fex += wgt * f
            ld = load[n]
            ma = motor_acc[n]
            for i in range(ndof):
                acc_i = w[i] * fex + c_load[i] * ld + c_motor[i] * ma
                for jj in range(ndof):
                    acc_i += B1[i, jj] * x[jj] + B2[i, jj] * vel[jj] + B3[i, jj] * acc[jj]
                xb[i] = acc_i
            proj = 0.0
            for i in range(ndof):
                proj += v[i] * xb[i]
            corr = kk * proj / (1.0 + kk * s)
            for i in range(ndof):
                xn = xb[i] - corr * w[i]
                an = a0 * (xn - x[i]) - a2 * vel[i] - a3 * acc[i]
                vel[i] = vel[i] + a6 * acc[i] + a7 * an
                acc[i] = an
                x[i] = xn
            r = n - rec_start
            if r >= 0 and r < n_rec:
                out[b, r] = (acc[1] + acc[4]) / G0
        X[b] = x
        V[b] = vel
        A[b] = acc
