"""Numba kernels of the batched Newmark integration (no input checking here).

One integration step is split into what every signal of a batch shares and what is its
own:

* :func:`contact_slots` (once per batch): the tooth pairs in contact at every step,
  their anti-aliasing weights and contact positions (the steps' mesh positions are the
  same for the whole batch);
* :func:`spur_shared` / :func:`table_shared` (once per batch): everything of a contact
  that depends on its position only (the healthy pair stiffness, table indices, the phase
  of the profile-error waviness);
* :func:`newmark_spur` / :func:`newmark_tables` (per signal, parallel over the batch): the
  signal's own mesh stiffness and excitation, and the Newmark update
  (:func:`_modal_step`, shared by both).

The Newmark update runs in the mass-normalised modal coordinates of the mean-stiffness
system, where mass and (modal) damping are diagonal and the mesh stiffness is a rank-one
change along the line-of-action vector: the effective stiffness is diagonal plus rank one
and is solved exactly by the Sherman-Morrison formula in O(ndof) per step
(:func:`gearshot.sim._system.integrator` builds the coefficients).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .profile_errors import tooth_error

__all__ = ["G0", "contact_slots", "spur_shared", "table_shared", "newmark_spur",
           "newmark_tables"]

G0 = 9.80665  # m/s^2 per g

# columns of the modal coefficient table ``mc`` (one row per mode)
_ALPHA, _BETA, _GAMMA, _VT, _LOAD, _MOTOR, _INVD, _G, _OUT = range(9)


@nb.njit(cache=True, nogil=True)
def contact_slots(mesh_pos, span):
    """The tooth pairs in contact at every step (shared by a batch).

    A pair's entry/exit is anti-aliased: its contribution is weighted by the fraction of
    a step-wide window around the mesh position that lies inside its contact
    (``0 ... span`` mesh periods after its start).

    Returns
    -------
    pair_id : int64 (n_steps, n_slots)
        Index of the tooth pair (mesh period in which it started contact).
    wgt, pos : float64 (n_steps, n_slots)
        Weight and contact position (fraction of ``span``, clipped to [0, 1]).
    count : int64 (n_steps,)
        Slots in use at each step.
    """
    n_steps = mesh_pos.shape[0]
    n_pairs = int(math.ceil(span)) + 1
    n_slots = n_pairs + 1
    pair_id = np.zeros((n_steps, n_slots), np.int64)
    wgt = np.zeros((n_steps, n_slots))
    pos = np.zeros((n_steps, n_slots))
    count = np.zeros(n_steps, np.int64)
    for n in range(n_steps):
        tm = mesh_pos[n]
        if n > 0:
            half = 0.5 * abs(tm - mesh_pos[n - 1])
        else:
            half = 0.5 * abs(mesh_pos[min(1, n_steps - 1)] - tm)
        base = math.floor(tm)
        c = 0
        for j in range(-1, n_pairs):
            nn = base - j
            lo = tm - half - nn
            hi = tm + half - nn
            if hi <= 0.0 or lo >= span:
                continue
            if hi > lo:
                w = (min(hi, span) - max(lo, 0.0)) / (hi - lo)
            else:
                w = 1.0
            u = (tm - nn) / span
            if u < 0.0:
                u = 0.0
            elif u > 1.0:
                u = 1.0
            pair_id[n, c] = nn
            wgt[n, c] = w
            pos[n, c] = u
            c += 1
        count[n] = c
    return pair_id, wgt, pos, count


@nb.njit(cache=True, inline="always")
def _table_index(n, u):
    """Cell and fraction of position ``u`` in [0, 1] on a table of ``n + 1`` points."""
    p = u * n
    i = int(p)
    if i >= n:
        return n - 1, 1.0
    return i, p - i


@nb.njit(cache=True, nogil=True)
def table_shared(pos, count, k_tab):
    """Per contact: cell and fraction on tables as long as ``k_tab``, and the healthy
    stiffness ``k_tab`` there."""
    n_steps, n_slots = pos.shape
    n = k_tab.shape[0] - 1
    cell = np.zeros((n_steps, n_slots), np.int64)
    frac = np.zeros((n_steps, n_slots))
    k_h = np.zeros((n_steps, n_slots))
    for m in range(n_steps):
        for c in range(count[m]):
            i, f = _table_index(n, pos[m, c])
            cell[m, c] = i
            frac[m, c] = f
            k_h[m, c] = k_tab[i] * (1.0 - f) + k_tab[i + 1] * f
    return cell, frac, k_h


@nb.njit(cache=True, nogil=True)
def spur_shared(pos, count, n_knots, g_nw, p_nw):
    """Per contact: the profile-error noise cell and fraction (``n_knots`` knots, as
    :func:`~gearshot.sim.profile_errors.noise_cell`) and sin/cos of the waviness angle
    ``2 pi n_waves u`` of gear and pinion."""
    n_steps, n_slots = pos.shape
    cell = np.zeros((n_steps, n_slots), np.int64)
    frac = np.zeros((n_steps, n_slots))
    trig = np.zeros((n_steps, n_slots, 4))
    for m in range(n_steps):
        for c in range(count[m]):
            s = pos[m, c]
            cell[m, c], frac[m, c] = _table_index(n_knots - 1, s)
            ag = 2.0 * math.pi * g_nw * s
            ap = 2.0 * math.pi * p_nw * s
            trig[m, c, 0] = math.sin(ag)
            trig[m, c, 1] = math.cos(ag)
            trig[m, c, 2] = math.sin(ap)
            trig[m, c, 3] = math.cos(ap)
    return cell, frac, trig


@nb.njit(cache=True, inline="always")
def _interp_table(tab, u):
    i, f = _table_index(tab.shape[0] - 1, u)
    return tab[i] * (1.0 - f) + tab[i + 1] * f


@nb.njit(cache=True, inline="always")
def _modal_step(x, vel, acc, y, corr, kk, fex, ld, ma, mc, sc, o):
    """One Newmark step (beta 1/4, gamma 1/2) in modal coordinates for a group of
    signals (the last axis, ``lanes``), in place; ``o`` receives the output (vertical
    acceleration, g). ``sc`` = (a0, a2, a3, a6, a7, k_mean, sum vt^2 / D). The signals of
    a group are independent: their arithmetic runs side by side (SIMD lanes), which
    hides the latency of the step's dependency chain."""
    ndof, lanes = x.shape
    for g in range(lanes):
        corr[g] = 0.0
    for i in range(ndof):
        al, be, ga = mc[i, _ALPHA], mc[i, _BETA], mc[i, _GAMMA]
        vt, invd = mc[i, _VT], mc[i, _INVD]
        ext = mc[i, _LOAD] * ld + mc[i, _MOTOR] * ma
        for g in range(lanes):
            yy = (al * x[i, g] + be * vel[i, g] + ga * acc[i, g] + vt * fex[g] + ext) * invd
            y[i, g] = yy
            corr[g] += vt * yy
    k_mean, s_vd = sc[5], sc[6]
    for g in range(lanes):
        dk = kk[g] - k_mean
        corr[g] = dk * corr[g] / (1.0 + dk * s_vd)
        o[g] = 0.0
    a0, a2, a3, a6, a7 = sc[0], sc[1], sc[2], sc[3], sc[4]
    for i in range(ndof):
        gi, oi = mc[i, _G], mc[i, _OUT]
        for g in range(lanes):
            xn = y[i, g] - corr[g] * gi
            an = a0 * (xn - x[i, g]) - a2 * vel[i, g] - a3 * acc[i, g]
            vel[i, g] = vel[i, g] + a6 * acc[i, g] + a7 * an
            acc[i, g] = an
            x[i, g] = xn
            o[g] += oi * an


@nb.njit(cache=True, inline="always")
def _open_group(X, V, A, b0, lanes):
    """The modal state of signals ``b0 ... b0 + lanes - 1`` (ndof, lanes) and the step's
    work arrays ``y`` (as the state), ``corr, kk, fex, o`` (lanes)."""
    ndof = X.shape[1]
    x = np.empty((ndof, lanes))
    vel = np.empty((ndof, lanes))
    acc = np.empty((ndof, lanes))
    for g in range(lanes):
        for i in range(ndof):
            x[i, g] = X[b0 + g, i]
            vel[i, g] = V[b0 + g, i]
            acc[i, g] = A[b0 + g, i]
    return (x, vel, acc, np.empty_like(x), np.empty(lanes), np.empty(lanes),
            np.empty(lanes), np.empty(lanes))


@nb.njit(cache=True, inline="always")
def _store_group(X, V, A, b0, x, vel, acc):
    ndof, lanes = x.shape
    for g in range(lanes):
        for i in range(ndof):
            X[b0 + g, i] = x[i, g]
            V[b0 + g, i] = vel[i, g]
            A[b0 + g, i] = acc[i, g]


@nb.njit(cache=True, inline="always")
def _clear(kk, fex):
    """Zero the step's mesh stiffness and excitation sums."""
    for g in range(kk.shape[0]):
        kk[g] = 0.0
        fex[g] = 0.0


@nb.njit(cache=True, inline="always")
def _contact(n, c, wgt, gtooth, ptooth, k_h, cell, frac, f_tooth, b0, lanes):
    """Contact ``c`` of step ``n``: gear and pinion tooth, table cell, fraction and its
    complement, weight, healthy stiffness, and whether the gear tooth is the faulty one
    of any signal of the group."""
    gt = gtooth[n, c]
    hit = False
    for g in range(lanes):
        if f_tooth[b0 + g] == gt:
            hit = True
    f = frac[n, c]
    return gt, ptooth[n, c], cell[n, c], f, 1.0 - f, wgt[n, c], k_h[n, c], hit


@nb.njit(cache=True, inline="always")
def _advance(x, vel, acc, y, corr, kk, fex, ld, ma, mc, sc, o, out, b0, r):
    """The Newmark step of a group, its output written to column ``r`` of ``out``
    (when it is one)."""
    _modal_step(x, vel, acc, y, corr, kk, fex, ld, ma, mc, sc, o)
    if r >= 0 and r < out.shape[1]:
        for g in range(o.shape[0]):
            out[b0 + g, r] = o[g]


_tooth_error = nb.njit(cache=True, inline="always")(tooth_error)


@nb.njit(cache=True, inline="always")
def _spur_mesh(n, b0, lanes, count, wgt, pos, gtooth, ptooth, k_h, n_cell, n_frac, trig,
               kf_tab, ef_tab, f_tooth, g_slope, g_wa, g_wb, g_noise, p_slope, p_wa, p_wb,
               p_noise, kk, fex):
    """Mesh stiffness ``kk`` and excitation ``fex`` of step ``n`` of a spur group."""
    _clear(kk, fex)
    for c in range(count[n]):
        u = pos[n, c]
        sg, cg, sp, cp = trig[n, c, 0], trig[n, c, 1], trig[n, c, 2], trig[n, c, 3]
        gt, pt, i, f, _, w, kh, hit = _contact(n, c, wgt, gtooth, ptooth, k_h, n_cell,
                                               n_frac, f_tooth, b0, lanes)
        for g in range(lanes):
            b = b0 + g
            e = (_tooth_error(u, g_slope[gt, b], g_wa[gt, b], g_wb[gt, b], sg, cg,
                              g_noise[gt, i, b], g_noise[gt, i + 1, b], f)
                 + _tooth_error(u, p_slope[pt, b], p_wa[pt, b], p_wb[pt, b], sp, cp,
                                p_noise[pt, i, b], p_noise[pt, i + 1, b], f))
            k = kh
            if hit and f_tooth[b] == gt:
                k = _interp_table(kf_tab[b], u)
                e += _interp_table(ef_tab[b], u)
            kk[g] += w * k
            fex[g] += w * k * e


@nb.njit(cache=True, nogil=True, parallel=True, fastmath=True)
def newmark_spur(load, motor_acc, count, wgt, pos, gtooth, ptooth, k_h, n_cell, n_frac,
                 trig, kf_tab, ef_tab, f_tooth, g_slope, g_wa, g_wb, g_noise, p_slope, p_wa,
                 p_wb, p_noise, mc, sc, X, V, A, lanes, rec_start, out):
    """Integrate ``X.shape[0]`` spur signals (a multiple of ``lanes``, integrated
    ``lanes`` at a time) over the steps of :func:`contact_slots`.

    Per signal ``b``: faulty gear tooth ``f_tooth[b]`` (-1: none) with stiffness
    ``kf_tab[b]`` and displacement excitation ``ef_tab[b]`` over the contact position;
    profile errors of tooth t at position s
    (:func:`~gearshot.sim.profile_errors.tooth_error`): ``slope[t, b] s + wa[t, b]
    sin(2 pi n s) + wb[t, b] cos(2 pi n s) + noise[t, :, b](s)`` (tooth-major, signals
    last). The modal state ``X, V, A`` (n_batch, ndof) is updated in place and the output
    of steps ``rec_start ... rec_start + out.shape[1] - 1`` is written into ``out``."""
    for grp in nb.prange(X.shape[0] // lanes):
        b0 = grp * lanes
        x, vel, acc, y, corr, kk, fex, o = _open_group(X, V, A, b0, lanes)
        for n in range(count.shape[0]):
            _spur_mesh(n, b0, lanes, count, wgt, pos, gtooth, ptooth, k_h, n_cell, n_frac,
                       trig, kf_tab, ef_tab, f_tooth, g_slope, g_wa, g_wb, g_noise, p_slope,
                       p_wa, p_wb, p_noise, kk, fex)
            _advance(x, vel, acc, y, corr, kk, fex, load[n], motor_acc[n], mc, sc, o, out,
                     b0, n - rec_start)
        _store_group(X, V, A, b0, x, vel, acc)


@nb.njit(cache=True, inline="always")
def _table_mesh(n, b0, lanes, count, wgt, gtooth, ptooth, k_h, cell, frac, kf_tab, f_tooth,
                fg_tab, fp_tab, fpf_tab, kk, fex):
    """Mesh stiffness ``kk`` and excitation ``fex`` of step ``n`` of a table group."""
    _clear(kk, fex)
    for c in range(count[n]):
        gt, pt, i, f, fm, w, kh, hit = _contact(n, c, wgt, gtooth, ptooth, k_h, cell, frac,
                                                f_tooth, b0, lanes)
        for g in range(lanes):
            b = b0 + g
            fo = (fg_tab[gt, i, b] * fm + fg_tab[gt, i + 1, b] * f) + (
                fp_tab[pt, i, b] * fm + fp_tab[pt, i + 1, b] * f)
            k = kh
            if hit and f_tooth[b] == gt:
                k = kf_tab[b, i] * fm + kf_tab[b, i + 1] * f
                fo = (fg_tab[gt, i, b] * fm + fg_tab[gt, i + 1, b] * f) + (
                    fpf_tab[b, pt, i] * fm + fpf_tab[b, pt, i + 1] * f)
            kk[g] += w * k
            fex[g] += w * fo


@nb.njit(cache=True, nogil=True, parallel=True, fastmath=True)
def newmark_tables(load, motor_acc, count, wgt, gtooth, ptooth, k_h, cell, frac, kf_tab,
                   f_tooth, fg_tab, fp_tab, fpf_tab, mc, sc, X, V, A, lanes, rec_start, out):
    """As :func:`newmark_spur`, with every tooth pair's stiffness and error force read
    from tables over the delay since the pair's first contact: ``k_h`` (healthy, per
    contact) or ``kf_tab[b]`` (the faulty gear tooth ``f_tooth[b]``); force
    ``fg_tab[gear tooth, :, b] + fp_tab[pinion tooth, :, b]`` (``fpf_tab[b, pinion
    tooth]`` instead of ``fp_tab`` when the gear tooth is the faulty one; tables
    tooth-major, signals last). Used for helical pairs."""
    for grp in nb.prange(X.shape[0] // lanes):
        b0 = grp * lanes
        x, vel, acc, y, corr, kk, fex, o = _open_group(X, V, A, b0, lanes)
        for n in range(count.shape[0]):
            _table_mesh(n, b0, lanes, count, wgt, gtooth, ptooth, k_h, cell, frac, kf_tab,
                        f_tooth, fg_tab, fp_tab, fpf_tab, kk, fex)
            _advance(x, vel, acc, y, corr, kk, fex, load[n], motor_acc[n], mc, sc, o, out,
                     b0, n - rec_start)
        _store_group(X, V, A, b0, x, vel, acc)
