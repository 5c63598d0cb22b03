"""The bridge search of many full tooth face faults: the smallest gap between the mating
pinion flank and the points of the cut flank, per knot.

The search (:func:`min_gap`) returns exactly what a plain loop over every flank point
returns (the plain loop is :func:`min_gap_plain`, kept as the reference the tests compare
with): each point's exact gap costs a ``hypot`` and an ``atan2``, but most points lie far
above the smallest gap, so a point is evaluated exactly only when a cheap lower bound of
its gap (a polynomial arctangent, Abramowitz & Stegun 4.4.49, error <= 2e-8 rad, taken
with a 20-fold margin) does not already exceed the best gap found. The previous knot's
best point is evaluated first (the best point moves little from knot to knot), and ties
go to the lowest point index as in the plain loop, so the result is the same bit for bit.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

__all__ = ["min_gap", "min_gap_plain"]

_ANGLE_MARGIN = 1e-6      # rad: 20 x the bound's error (atan 2e-8, rounding of its inputs <= 3e-8)


@nb.njit(cache=True, inline="always")
def _exact_gap(cth, sth, rk, o2x, rb1, pp, lo_r, hi_r, circ, half):
    """(in range, gap) of one flank point: the plain loop's arithmetic."""
    px = o2x + rk * cth
    py = rk * sth
    rp = math.hypot(px, py)
    if rp < lo_r or rp > hi_r:
        return False, 0.0
    c = rb1 / rp
    s = math.sqrt(max(1.0 - c * c, 0.0))
    theta = math.atan2(py * c - px * s, px * c + py * s) + s / c
    gap = rb1 * (theta - pp)
    t = gap + half                   # (gap + half) % circ - half, the modulo
    if t < 0.0 or t >= circ:         # only where it changes t
        t = t % circ
    return True, t - half


@nb.njit(cache=True, inline="always")
def _atan_01(x):
    x2 = x * x
    p = 0.0028662257
    p = p * x2 - 0.0161657367
    p = p * x2 + 0.0429096138
    p = p * x2 - 0.0752896400
    p = p * x2 + 0.1065626393
    p = p * x2 - 0.1420889944
    p = p * x2 + 0.1999355085
    p = p * x2 - 0.3333314528
    p = p * x2 + 1.0
    return x * p


@nb.njit(cache=True, inline="always")
def _gap_bound(cth, sth, rk, o2x, rb1, pp, lo2, hi2, circ, half, marg):
    """A lower bound of the exact gap of a point: ``inf`` where the point is surely out
    of range, ``-inf`` where the wrap is too close to call."""
    px = o2x + rk * cth
    py = rk * sth
    rp2 = px * px + py * py
    if rp2 < lo2 or rp2 > hi2:
        return np.inf
    # the angle of P turned back by acos(rb1/|P|), from (x, y) scaled by |P| (atan2 does
    # not see the scale), and tan(acos(rb1/|P|)) = q / rb1: no division by |P|
    q = math.sqrt(max(rp2 - rb1 * rb1, 0.0))
    x = px * rb1 + py * q
    y = py * rb1 - px * q
    ax, ay = abs(x), abs(y)
    if ay <= ax:
        a = _atan_01(ay / ax)
    else:
        a = 0.5 * math.pi - _atan_01(ax / ay)
    if x < 0.0:
        a = math.pi - a
    if y < 0.0:
        a = -a
    t = rb1 * (a - pp) + q + half             # rb1 (a + q / rb1 - pp) + half
    if t < 0.0 or t >= circ:
        t = t - circ * math.floor(t / circ)
    if t < marg or t > circ - marg:
        return -np.inf
    return t - half - marg


@nb.njit(cache=True, inline="always")
def _search_setup(cc, r, rb1, ra1):
    """Sizes, outputs, the base circle's circumference and half of it, and the pinion
    flank's radius range (its ends count within a relative 1e-12)."""
    n, n_u = cc.shape
    circ = 2.0 * math.pi * rb1
    return (n, n_u, r.shape[1], np.empty((n, n_u)), np.empty((n, n_u)), circ,
            math.pi * rb1, rb1 * (1.0 - 1e-12), ra1 * (1.0 + 1e-12))


@nb.njit(cache=True, nogil=True, parallel=True)
def min_gap(cc, sc, phi_p, r, ca, sa, o2x, rb1, ra1):
    """Smallest normal gap (clipped at 0) and the radius of its flank point, per knot
    (``cc, sc``: cos/sin of the knot's rotation ``centre``; ``ca, sa``: of the points'
    angles ``ang``); equal to :func:`min_gap_plain`."""
    n, n_u, n_pts, ret, rad, circ, half, lo_r, hi_r = _search_setup(cc, r, rb1, ra1)
    lo2, hi2 = (lo_r * (1.0 - 1e-9)) ** 2, (hi_r * (1.0 + 1e-9)) ** 2   # surely outside
    marg = rb1 * _ANGLE_MARGIN + 1e-9 * circ
    for f in nb.prange(n):
        kb = -1
        for m in range(n_u):
            cm, sm, pp = cc[f, m], sc[f, m], phi_p[f, m]
            best = np.inf
            k0 = kb
            kb = 0
            if k0 >= 0:             # the previous knot's best point first
                cth = cm * ca[f, k0] - sm * sa[f, k0]
                sth = sm * ca[f, k0] + cm * sa[f, k0]
                ok, gap = _exact_gap(cth, sth, r[f, k0], o2x, rb1, pp, lo_r, hi_r, circ,
                                     half)
                if ok and gap < best:
                    best = gap
                    kb = k0
            for k in range(n_pts):
                if k == k0:
                    continue
                cth = cm * ca[f, k] - sm * sa[f, k]
                sth = sm * ca[f, k] + cm * sa[f, k]
                if _gap_bound(cth, sth, r[f, k], o2x, rb1, pp, lo2, hi2, circ, half,
                              marg) > best:
                    continue
                ok, gap = _exact_gap(cth, sth, r[f, k], o2x, rb1, pp, lo_r, hi_r, circ,
                                     half)
                if ok and (gap < best or (gap == best and k < kb)):
                    best = gap
                    kb = k
            ret[f, m] = max(best, 0.0)
            rad[f, m] = r[f, kb]
            if best == np.inf:
                kb = -1
    return ret, rad


@nb.njit(cache=True, nogil=True, parallel=True)
def min_gap_plain(cc, sc, phi_p, r, ca, sa, o2x, rb1, ra1):
    """The plain search: every flank point of every knot evaluated exactly.

    A flank point at gear radius r and angle ``centre + ang`` lies at P = o2 + r
    (cos, sin)(centre + ang) (angle addition); its pinion involute angle is
    ``atan2(P) + inv(|P|)``, ``inv(rho) = tan(acos(rb1/rho)) - acos(rb1/rho)``, computed as
    the angle of P turned back by ``acos(rb1/rho)`` (one arctangent) plus
    ``sqrt(1 - c^2) / c``, c = rb1/|P|; the gap is wrapped to one base pitch circle as in
    :meth:`FullToothFaceFault._retreat` (equal up to rounding). Points on the pinion's
    flank ends (base and tip circle) count within a relative 1e-12."""
    n, n_u, n_pts, ret, rad, circ, half, lo_r, hi_r = _search_setup(cc, r, rb1, ra1)
    for fm in nb.prange(n * n_u):          # every knot of every fault on its own
        f, m = fm // n_u, fm % n_u
        best = np.inf
        kb = 0
        cm, sm, pp = cc[f, m], sc[f, m], phi_p[f, m]
        for k in range(n_pts):
            cth = cm * ca[f, k] - sm * sa[f, k]
            sth = sm * ca[f, k] + cm * sa[f, k]
            ok, gap = _exact_gap(cth, sth, r[f, k], o2x, rb1, pp, lo_r, hi_r, circ, half)
            if ok and gap < best:
                best = gap
                kb = k
        ret[f, m] = max(best, 0.0)
        rad[f, m] = r[f, kb]
    return ret, rad
