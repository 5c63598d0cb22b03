"""Stiffness and displacement tables of many full tooth face faults at once.

A database block simulates hundreds of FTFFs of continuous random sizes, so their tables
are never cache hits. Per fault the work is the bridge of the cut
(:meth:`FullToothFaceFault.bridge`: the mating flank's rigid retreat at 129 contact
positions against 90 points of the cut flank) and the faulty tooth's compliance at the
knots of its smooth segments (potential-energy integrals over 241 Simpson nodes each).
Here the bridge runs as one numpy evaluation over the whole batch (element by element
the same operations as for one fault, so the same numbers) and the compliance integrals
as one numba loop over every knot of every fault (the per-knot sums in sequence instead
of numpy's pairwise order: a last-bit difference). The tables follow
:func:`gearshot.sim.stiffness._faulty_gear_compliance` and
:meth:`FullToothFaceFault.displacement` exactly otherwise; those stay the reference
(generic faults) and the tests compare both.
"""

from __future__ import annotations

import functools
import math
import threading

import numba as nb
import numpy as np

from ._bridge_gap import min_gap
from ._compliance import (
    _N_SEGMENT,
    _U_TABLE,
    _contact_frame,
    _fillet_compliance,
    _healthy_compliances,
    _hertz_stiffness,
    _materials,
    _simpson_nodes,
)
from .geometry import GearPair, contact_angles, involute_half_angle

__all__ = ["bridge_batch", "ftff_gear_compliance"]

_N_KNOTS = 129      # bridge samples across the cut
_MARGIN = 0.04      # FullToothFaceFault._flank_points defaults
_N_ARC = 80
_N_INVOLUTE = 5     # involute points beyond each edge of the cut


def _arcs(pair: GearPair, faults):
    """:meth:`FullToothFaceFault._arc` of every fault, as arrays (n,): window s0, s1 and
    the cut's xa, xb, cx, ch, radius."""
    z = pair.z_gear
    rb = pair.base_radius(z)
    _, (l_lo, l_hi) = pair.roll_limits
    size = np.array([f.size for f in faults], dtype=float)
    centre = np.array([f.center for f in faults], dtype=float)
    depth = np.array([f.depth for f in faults], dtype=float)
    s0, s1 = centre - 0.5 * size, centre + 0.5 * size
    ends = []
    for sv in (s0, s1):
        r = np.hypot(rb, l_lo + sv * (l_hi - l_lo))
        psi = involute_half_angle(z, pair.transverse_pressure_angle, r, rb)
        ends.append((r * np.cos(psi), r * np.sin(psi)))
    (xa, ha), (xb, hb) = ends
    chord = np.hypot(xb - xa, hb - ha)
    radius = chord / 4 * (depth + 1 / depth)
    sag = depth * chord / 2
    tx, th = (xb - xa) / chord, (hb - ha) / chord
    sign = np.where(-tx > 0, -1.0, 1.0)       # normal pointing into the tooth
    nx, nh = sign * th, sign * -tx
    mx, mh = 0.5 * (xa + xb), 0.5 * (ha + hb)
    cx, ch = mx - nx * (radius - sag), mh - nh * (radius - sag)
    return s0, s1, np.column_stack([xa, xb, cx, ch, radius])


def _flank_points(pair: GearPair, s0, s1, arcs):
    """:meth:`FullToothFaceFault._flank_points` of every fault: (n, 90) radius and angle
    from the tooth centre line."""
    z = pair.z_gear
    rb = pair.base_radius(z)
    _, (l_lo, l_hi) = pair.roll_limits
    pieces = [np.linspace(np.maximum(s0 - _MARGIN, -0.02), s0, _N_INVOLUTE, axis=-1),
              np.linspace(s1, np.minimum(s1 + _MARGIN, 1.0), _N_INVOLUTE, axis=-1)]
    ls = l_lo + np.concatenate(pieces, axis=-1) * (l_hi - l_lo)
    r = np.hypot(rb, np.maximum(ls, 0.0))
    psi = involute_half_angle(z, pair.transverse_pressure_angle, r, rb)
    xa, xb, cx, ch, radius = (arcs[:, m:m + 1] for m in range(5))
    xx = np.linspace(xa[:, 0], xb[:, 0], _N_ARC, axis=-1)
    hh = ch - np.sqrt(np.maximum(radius ** 2 - (xx - cx) ** 2, 0.0))
    return (np.concatenate([r, np.hypot(xx, hh)], axis=-1),
            np.concatenate([psi, np.arctan2(hh, xx)], axis=-1))


def bridge_batch(pair: GearPair, faults, geometry=None):
    """:meth:`FullToothFaceFault.bridge` of every fault: arrays (n, 129) of knots,
    retreat (m) and touched roll fraction (``geometry``: :func:`_arcs` of the faults)."""
    s0, s1, arcs = _arcs(pair, faults) if geometry is None else geometry
    knots = np.linspace(s0, s1, _N_KNOTS, axis=-1)
    r, ang = _flank_points(pair, s0, s1, arcs)
    ret, radius = _retreat(pair, 1.0 - knots, r, ang)
    rb = pair.base_radius(pair.z_gear)
    _, (l_lo, l_hi) = pair.roll_limits
    contact = (np.sqrt(np.maximum(radius ** 2 - rb ** 2, 0.0)) - l_lo) / (l_hi - l_lo)
    return knots, ret, contact


def _retreat(pair: GearPair, u, r, ang):
    """:meth:`FullToothFaceFault._retreat` over a batch: ``u`` (n, n_u) line-of-action
    fractions, flank points ``r, ang`` (n, n_pts). The per-knot part is numpy (the same
    operations as for one fault); the search over the flank points runs in numba
    (:func:`._bridge_gap.min_gap`)."""
    rb1, ra1 = pair.base_radius(pair.z_pinion), pair.tip_radius(pair.z_pinion)
    phi_p, centre = contact_angles(pair, u)
    return min_gap(np.cos(centre), np.sin(centre), phi_p, r, np.cos(ang), np.sin(ang),
                   pair.center_distance, rb1, ra1)


@functools.lru_cache(maxsize=32)
def _involute_tables(pair: GearPair):
    """The gear's involute (x, h) tables of ``_tooth_compliance`` (1200 points, to 1.001
    of the tip) and of ``FullToothFaceFault.section_loss`` (601 points)."""
    z = pair.z_gear
    rb = pair.base_radius(z)
    a0 = pair.transverse_pressure_angle
    out = []
    for r_tab in (np.linspace(rb, pair.tip_radius(z) * 1.001, 1200),
                  np.linspace(rb, pair.tip_radius(z), 601)):
        psi = involute_half_angle(z, a0, r_tab, rb)
        x, h = r_tab * np.cos(psi), r_tab * np.sin(psi)
        x.setflags(write=False)
        h.setflags(write=False)
        out.append((x, h))
    return tuple(out)


def ftff_gear_compliance(pair: GearPair, roll, arcs):
    """Compliance (m/N) of the faulty gear tooth at roll lengths ``roll`` (m, 1-D), each
    point with its fault's cut ``arcs`` (n_points, 5): xa, xb, cx, ch, radius of
    :meth:`FullToothFaceFault._arc`. As ``_tooth_compliance(pair, z_gear, roll,
    fault.section_loss)``."""

    z = pair.z_gear
    E, G, L = _materials(pair)
    xc, hc, beta, hb, xb, x0 = _contact_frame(pair, z, roll)
    (x_tab, h_tab), (xs_tab, hs_tab) = _involute_tables(pair)
    xi, w = _simpson_nodes()
    inv = _node_sums(xc, hc, np.cos(beta), np.sin(beta), np.ascontiguousarray(arcs), x0,
                     xb, hb, xi, w, x_tab, h_tab, xs_tab, hs_tab, E, G, L)
    return inv + _fillet_compliance(pair, z, xc, hc, beta, hb)


@nb.njit(cache=True, inline="always")
def _interp_walk(x, xp, fp, j):
    """np.interp of one point on an increasing table, searching on from cell ``j``;
    returns (value, cell)."""
    n = xp.shape[0]
    if x < xp[0]:
        return fp[0], 0
    if x >= xp[n - 1]:
        return fp[n - 1], j
    while j < n - 2 and xp[j + 1] <= x:
        j += 1
    while j > 0 and xp[j] > x:
        j -= 1
    slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j])
    return slope * (x - xp[j]) + fp[j], j


@nb.njit(cache=True, nogil=True, parallel=True)
def _node_sums(xc, hc, cb, sb, arcs, x0, xb, hb, xi, w, x_tab, h_tab, xs_tab, hs_tab,
               E, G, L):
    """Bending + shear + axial compliance: the Simpson sums of ``_tooth_compliance``
    with the FTFF's section loss, one contact point per entry."""
    n = xc.shape[0]
    out = np.empty(n)
    n_nodes = xi.shape[0]
    for p in nb.prange(n):
        xa, xe, cx, ch, rad = arcs[p, 0], arcs[p, 1], arcs[p, 2], arcs[p, 3], arcs[p, 4]
        span = xc[p] - x0
        cbp, sbp = cb[p], sb[p]
        sb_kb = 0.0
        sb_t = 0.0
        j = 0
        js = 0
        for k in range(n_nodes):
            x = x0 + span * xi[k]
            if x <= xb:
                h = hb
            else:
                h, j = _interp_walk(x, x_tab, h_tab, j)
            t = 2.0 * h
            loss = 0.0
            if x > xa and x < xe:
                h_flank, js = _interp_walk(x, xs_tab, hs_tab, js)
                q = rad * rad - (x - cx) * (x - cx)
                h_arc = ch - math.sqrt(q if q > 0.0 else 0.0)
                loss = h_flank - h_arc
                if loss < 0.0:
                    loss = 0.0
            t = max(t - loss, 0.05 * t)
            it = 1.0 / t
            arm = cbp * (xc[p] - x) - sbp * hc[p]
            wk = w[k] * span
            sb_kb += wk * arm * arm * (it * it * it)
            sb_t += wk * it
        # bending 12 / (E L t^3), shear 1.2 cos^2 / (G L t), axial sin^2 / (E L t)
        out[p] = (12.0 / (E * L)) * sb_kb + (1.2 * cbp * cbp / (G * L)
                                              + sbp * sbp / (E * L)) * sb_t
    return out


_RETREAT_CHUNK = 8          # faults per numpy evaluation of the bridge (memory bound)
_CACHE: dict = {}           # (pair, fault) -> (k, ef), insertion-ordered
_CACHE_SIZE = 4096
_LOCK = threading.Lock()     # guards _CACHE


def ftff_tables(pair: GearPair, faults):
    """Tables over the spur contact position u (``_N_TABLE`` points) of non-healthy
    FTFFs: pair stiffness k (N/m) and displacement excitation e_f (m), arrays (n, n_u);
    as ``_pair_table(pair, fault)`` and ``fault.displacement(pair, 1 - u)``."""
    n = len(faults)
    s0s, s1s, arcs_all = _arcs(pair, faults)
    parts = [bridge_batch(pair, faults[i:i + _RETREAT_CHUNK],
                          (s0s[i:i + _RETREAT_CHUNK], s1s[i:i + _RETREAT_CHUNK],
                           arcs_all[i:i + _RETREAT_CHUNK]))
             for i in range(0, n, _RETREAT_CHUNK)]
    knots, ret, contact = (np.concatenate([p[m] for p in parts]) for m in range(3))
    s = 1.0 - _U_TABLE
    inv_p, inv_g = _healthy_compliances(pair)
    _, (g_lo, g_hi) = pair.roll_limits
    seg_fault, seg_ab, kts, rolls = _segment_points(knots, contact, s0s, s1s, s, g_lo,
                                                    g_hi, _N_SEGMENT)
    vals = ftff_gear_compliance(pair, rolls, arcs_all[np.repeat(seg_fault, _N_SEGMENT)])
    inv = np.tile(inv_g, (n, 1))
    ef = np.zeros((n, s.size))
    trans = np.array([f.transmission for f in faults], dtype=float)
    _fill_tables(inv, ef, s, seg_fault, seg_ab, kts, vals.reshape(kts.shape), knots, ret,
                 s0s, s1s, trans)
    k = 1.0 / (1.0 / _hertz_stiffness(pair) + inv_p + inv)
    return k, ef


@nb.njit(cache=True, inline="always")
def _interp_point(x, xp, fp, lo, hi):
    """``np.interp(x, xp[lo:hi], fp[lo:hi])`` of one point (numpy's formula: the
    slope of the cell times the distance from its left node plus that node's value)."""
    if x < xp[lo]:
        return fp[lo]
    if x >= xp[hi - 1]:
        return fp[hi - 1]
    j = lo
    while xp[j + 1] <= x:
        j += 1
    if xp[j] == x:
        return fp[j]
    return (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j]) * (x - xp[j]) + fp[j]


@nb.njit(cache=True, nogil=True)
def _segment_points(knots, contact, s0s, s1s, s, g_lo, g_hi, n_seg):
    """The smooth segments of every fault's compliance (``stiffness._segments`` between
    the cut's start, load switch, end and the tip) and the gear roll (m) at their
    evaluation points (``FullToothFaceFault.contact_roll``): segment's fault (n_segs,),
    ends (n_segs, 2), points (n_segs, n_seg), rolls (n_segs * n_seg,)."""
    n, n_k = knots.shape
    seg_fault = np.empty(4 * n, np.int64)
    seg_ab = np.empty((4 * n, 2))
    kts = np.empty((4 * n, n_seg))
    rolls = np.empty(4 * n * n_seg)
    m = 0
    for i in range(n):
        s0, s1 = s0s[i], s1s[i]
        j = 0                                          # FullToothFaceFault._switch
        for q in range(1, n_k - 1):
            if abs(contact[i, q + 1] - contact[i, q]) > abs(contact[i, j + 1] - contact[i, j]):
                j = q
        sw = 0.5 * (knots[i, j] + knots[i, j + 1])
        n_lo = 0                                       # knots <= sw: a prefix
        while n_lo < n_k and knots[i, n_lo] <= sw:
            n_lo += 1
        edges = np.unique(np.minimum(np.maximum(np.array([s0, 1.0, s0, sw, s1]), s0), 1.0))
        for e in range(edges.size - 1):
            a, b = edges[e], edges[e + 1]
            if b - a <= 0 or not _holds_point(s, a, b):
                continue
            eta = 1e-9 * (b - a)
            start, step = a + eta, ((b - eta) - (a + eta)) / (n_seg - 1)
            for q in range(n_seg):
                x = q * step + start if q < n_seg - 1 else b - eta
                cr = x
                if x > sw and x < s1:
                    cr = _interp_point(x, knots[i], contact[i], n_lo, n_k)
                elif x > s0 and x <= sw:
                    cr = _interp_point(x, knots[i], contact[i], 0, n_lo)
                kts[m, q] = x
                rolls[m * n_seg + q] = g_lo + cr * (g_hi - g_lo)
            seg_fault[m] = i
            seg_ab[m, 0], seg_ab[m, 1] = a, b
            m += 1
    return seg_fault[:m], seg_ab[:m], kts[:m], rolls[:m * n_seg]


@nb.njit(cache=True, inline="always")
def _in_segment(x, a, b):
    return x >= a and (x <= b if b == 1.0 else x < b)


@nb.njit(cache=True, nogil=True)
def _holds_point(s, a, b):
    for x in s:
        if _in_segment(x, a, b):
            return True
    return False


@nb.njit(cache=True, nogil=True)
def _fill_tables(inv, ef, s, seg_fault, seg_ab, kts, vals, knots, ret, s0s, s1s, trans):
    """The faulty gear tooth's compliance ``inv`` (interpolated from each segment's
    points, healthy elsewhere) and the displacement excitation ``ef``
    (``FullToothFaceFault.displacement``), in place."""
    n_seg = kts.shape[1]
    for m in range(seg_fault.shape[0]):
        i = seg_fault[m]
        a, b = seg_ab[m, 0], seg_ab[m, 1]
        for p in range(s.shape[0]):
            if _in_segment(s[p], a, b):
                inv[i, p] = _interp_point(s[p], kts[m], vals[m], 0, n_seg)
    for i in range(ef.shape[0]):
        for p in range(s.shape[0]):
            if s[p] > s0s[i] and s[p] < s1s[i]:
                ef[i, p] = -trans[i] * _interp_point(s[p], knots[i], ret[i], 0,
                                                     knots.shape[1])


def ftff_cached(pair: GearPair, faults):
    """``[(k, ef), ...]`` of non-healthy FTFFs (read-only arrays), the missing ones
    computed in one :func:`ftff_tables` call and kept (the last 4096). Safe to call from
    several threads (an in-process build runs blocks side by side)."""
    with _LOCK:
        found = {f: _CACHE.get((pair, f)) for f in dict.fromkeys(faults)}
    missing = [f for f, v in found.items() if v is None]
    if missing:
        k, ef = ftff_tables(pair, missing)
        for f, kr, er in zip(missing, k, ef, strict=True):
            kr.setflags(write=False)
            er.setflags(write=False)
            found[f] = (kr, er)
        with _LOCK:
            _CACHE.update(((pair, f), found[f]) for f in missing)
            while len(_CACHE) > _CACHE_SIZE:
                del _CACHE[next(iter(_CACHE))]
    return [found[f] for f in faults]
