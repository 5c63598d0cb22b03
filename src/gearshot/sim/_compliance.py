"""Tooth compliance of the potential-energy method (the terms of
:mod:`gearshot.sim.stiffness`).

Bending, shear and axial-compressive energies integrated along the tooth's centre line by
composite Simpson sums, the fillet-foundation term of Sainsot et al. (2004), the Hertzian
contact stiffness, and the smooth segments a faulty tooth's compliance is evaluated on.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from .geometry import GearPair, involute_half_angle

_N_SEGMENT = 24  # exact evaluations per smooth segment of a faulty tooth's compliance

# Sainsot et al. (2004) fillet-foundation coefficients: rows L*, M*, P*, Q*;
# columns A, B, C, D, E, F of X* = A/theta^2 + B h^2 + C h/theta + D/theta + E h + F.
_SAINSOT = np.array([
    [-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045],
    [60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086],
    [-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236],
    [-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904],
])

_N_NODES = 240  # integration nodes along the tooth

_N_TABLE = 1025
_U_TABLE = np.linspace(0.0, 1.0, _N_TABLE)      # the tables' contact positions u
_U_TABLE.setflags(write=False)


def _tooth_compliance(pair: GearPair, z: int, roll: np.ndarray,
                      section_loss=None) -> np.ndarray:
    """Bending + shear + axial + fillet compliance (m/N) of one tooth of a ``z``-tooth wheel
    loaded along the line of action at roll lengths ``roll`` (m)."""
    E, G, L = _materials(pair)
    rb = pair.base_radius(z)
    a0 = pair.transverse_pressure_angle
    xc, hc, beta, hb, xb, x0 = _contact_frame(pair, z, roll)
    # involute table for h(x)
    r_tab = np.linspace(rb, pair.tip_radius(z) * 1.001, 1200)
    psi_t = involute_half_angle(z, a0, r_tab, rb)
    x_tab, h_tab = r_tab * np.cos(psi_t), r_tab * np.sin(psi_t)
    # composite Simpson nodes from the root circle to each contact point
    xi, w = _simpson_nodes()
    span = (xc - x0)[:, None]
    x = x0 + span * xi[None, :]
    h = np.where(x <= xb, hb, np.interp(x, x_tab, h_tab))
    t = 2.0 * h
    if section_loss is not None:
        t = np.maximum(t - section_loss(x), 0.05 * t)
    area = t * L
    inertia = t ** 3 * L / 12.0
    cb, sb = np.cos(beta)[:, None], np.sin(beta)[:, None]
    moment_arm = cb * (xc[:, None] - x) - sb * hc[:, None]
    wk = w[None, :] * span
    inv_kb = np.sum(wk * moment_arm ** 2 / (E * inertia), axis=1)
    inv_ks = np.sum(wk * 1.2 * cb ** 2 / (G * area), axis=1)
    inv_ka = np.sum(wk * sb ** 2 / (E * area), axis=1)
    return inv_kb + inv_ks + inv_ka + _fillet_compliance(pair, z, xc, hc, beta, hb)


def _materials(pair: GearPair) -> tuple[float, float, float]:
    """Young's modulus, shear modulus (Pa) and face width (m) of the pair."""
    E, nu, L = pair.youngs_modulus, pair.poisson, pair.face_width
    return E, E / (2 * (1 + nu)), L


def _contact_frame(pair: GearPair, z: int,
                   roll) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, float, float]:
    """Contact point ``xc, hc`` (m, tooth frame), load angle ``beta`` to the tooth's
    transverse axis at roll lengths ``roll`` (m), and the base-circle point ``hb, xb`` and
    integration start ``x0`` of a ``z``-tooth wheel's tooth."""
    rb, rf = pair.base_radius(z), pair.root_radius(z)
    a0 = pair.transverse_pressure_angle
    roll = np.asarray(roll, dtype=float)
    rc = np.hypot(rb, roll)
    psi_c = involute_half_angle(z, a0, rc, rb)
    xc, hc = rc * np.cos(psi_c), rc * np.sin(psi_c)
    beta = np.arccos(rb / rc) - psi_c          # load angle to the tooth's transverse axis
    psi_b = float(involute_half_angle(z, a0, np.array(rb), rb))
    hb = rb * math.sin(psi_b)
    xb = rb * math.cos(psi_b)
    return xc, hc, beta, hb, xb, float(min(rf, xb))


def _simpson_nodes() -> tuple[np.ndarray, np.ndarray]:
    """Composite Simpson nodes on [0, 1] and their weights (``_N_NODES`` intervals)."""
    xi = np.linspace(0.0, 1.0, _N_NODES + 1)
    w = np.ones(_N_NODES + 1)
    w[1:-1:2], w[2:-1:2] = 4.0, 2.0
    w /= 3.0 * _N_NODES
    return xi, w


def _fillet_compliance(pair: GearPair, z: int, xc, hc, beta, hb) -> np.ndarray:
    """Fillet-foundation compliance (m/N) of a ``z``-tooth wheel's tooth (Sainsot 2004)."""
    E, _, L = _materials(pair)
    rf = pair.root_radius(z)
    theta_f = math.asin(min(hb / rf, 1.0))
    s_f = 2 * rf * theta_f
    h_fi = rf / pair.bore_radius
    basis = np.array([1 / theta_f ** 2, h_fi ** 2, h_fi / theta_f, 1 / theta_f, h_fi, 1.0])
    Ls, Ms, Ps, Qs = _SAINSOT @ basis
    u_f = xc - hc * np.tan(beta) - rf
    cbeta = np.cos(beta)
    return cbeta ** 2 / (E * L) * (Ls * (u_f / s_f) ** 2 + Ms * (u_f / s_f)
                                   + Ps * (1 + Qs * np.tan(beta) ** 2))


def _segments(s: np.ndarray, edges: np.ndarray):
    """The smooth segments ``[a, b]`` between consecutive ``edges`` of the table's roll
    fractions ``s``: per segment holding table points, those points (a mask) and
    ``_N_SEGMENT`` evaluation points just inside it (so one-sided limits are respected)."""
    for a, b in zip(edges[:-1], edges[1:]):
        if b - a <= 0:
            continue
        sel = (s >= a) & (s <= b) if b == 1.0 else (s >= a) & (s < b)
        if not sel.any():
            continue
        eta = 1e-9 * (b - a)
        yield sel, np.linspace(a + eta, b - eta, _N_SEGMENT)


def _hertz_stiffness(pair: GearPair) -> float:
    """The Hertzian contact stiffness of the pair (N/m)."""
    return math.pi * pair.youngs_modulus * pair.face_width / (4 * (1 - pair.poisson ** 2))


@functools.lru_cache(maxsize=32)
def _healthy_compliances(pair: GearPair):
    """Pinion and gear tooth compliance tables over u (the healthy pair)."""
    u = np.linspace(0.0, 1.0, _N_TABLE)
    (p_lo, p_hi), (g_lo, g_hi) = pair.roll_limits
    inv_p = _tooth_compliance(pair, pair.z_pinion, p_lo + u * (p_hi - p_lo))
    inv_g = _tooth_compliance(pair, pair.z_gear, g_lo + (1.0 - u) * (g_hi - g_lo))
    return inv_p, inv_g
