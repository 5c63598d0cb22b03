"""Time-varying mesh stiffness of a spur pair by the potential-energy method.

Single pair: ``1/k = 1/k_h + sum over both wheels (1/k_b + 1/k_s + 1/k_a + 1/k_f)`` with
the Hertzian term ``k_h = pi E L / (4 (1 - nu^2))``, bending, shear and axial-compressive
energies integrated along the tooth's centre line (involute flank above the base circle,
constant section between root and base circle) and the fillet-foundation term of Sainsot
et al. (2004). Pairs in contact follow from the contact ratio.

Helical pairs: the slice method (:mod:`gearshot.sim._slices`): the transverse profile's
spur single-pair stiffness is averaged over the face width with the slices staggered by the
overlap ratio, so one tooth pair is in contact for ``epsilon_alpha + epsilon_beta`` mesh
periods. Faults that cover part of the face (:meth:`~gearshot.sim.ToothFault.face_bands`)
change only their band's slices.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np

from .._errors import GearshotError
from .._validation import as_signal_array
from ._compliance import (
    _N_TABLE,
    _U_TABLE,
    _healthy_compliances,
    _hertz_stiffness,
    _segments,
    _tooth_compliance,
)
from ._ftff_batch import ftff_cached
from ._slices import box, tau_grid
from .faults import ToothFault, is_ftff
from .geometry import GearPair

__all__ = ["mesh_stiffness", "pair_stiffness", "contact_ratio"]

def contact_ratio(pair: GearPair, *, kind: str = "total") -> float:
    """Contact ratio of ``pair``.

    Parameters
    ----------
    pair : GearPair
    kind : {"total", "transverse", "overlap"}
        ``"transverse"``: epsilon_alpha (path of contact / transverse base pitch);
        ``"overlap"``: epsilon_beta = b sin(beta) / (pi m_n) (0 for spur);
        ``"total"``: their sum (the transverse ratio for a spur pair).
    """
    if kind == "total":
        return pair.total_contact_ratio
    if kind == "transverse":
        return pair.contact_ratio
    if kind == "overlap":
        return pair.overlap_ratio
    raise GearshotError(f"kind must be 'total', 'transverse' or 'overlap'; got {kind!r}")


def pair_stiffness(pair: GearPair, u: np.ndarray, *, fault: ToothFault | None = None
                   ) -> np.ndarray:
    """Stiffness (N/m) of one tooth pair at contact positions ``u``.

    Parameters
    ----------
    pair : GearPair
    u : array_like
        Position along the path of contact, 0 (entry: gear tip) to 1 (exit: pinion tip).
    fault : ToothFault, optional
        Fault on the gear tooth of this pair; a fault over part of the face width
        (:meth:`~gearshot.sim.ToothFault.face_bands`) weights its bands by their width.

    For a helical pair this is the stiffness of the transverse profile over the whole
    face width (all slices in phase); :func:`mesh_stiffness` staggers the slices.
    """
    if fault is not None and not fault.is_healthy and not _whole_face(fault, pair):
        healthy = pair_stiffness(pair, u)
        out = healthy.copy()
        for z0, z1, f in fault.face_bands(pair):
            out += (z1 - z0) * (pair_stiffness(pair, u, fault=f) - healthy)
        return out
    u = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
    (p_lo, p_hi), (g_lo, g_hi) = pair.roll_limits
    s_gear = 1.0 - u
    s_pin = u
    sec = None
    if fault is not None and not fault.is_healthy:
        s_gear = fault.contact_roll(pair, s_gear)
        sec = functools.partial(fault.section_loss, pair)
    inv_p = _tooth_compliance(pair, pair.z_pinion, p_lo + s_pin * (p_hi - p_lo))
    inv_g = _tooth_compliance(pair, pair.z_gear, g_lo + s_gear * (g_hi - g_lo), sec)
    k_h = _hertz_stiffness(pair)
    k = 1.0 / (1.0 / k_h + inv_p + inv_g)
    if fault is not None and not fault.is_healthy and fault.scales_contact:
        k = k * fault.stiffness_scale(pair, 1.0 - u)
    return k


def _whole_face(fault: ToothFault, pair: GearPair) -> bool:
    """True when ``fault`` is its own transverse fault over the whole face width."""
    bands = fault.face_bands(pair)        # not the cache: its band may be an equal copy
    return len(bands) == 1 and bands[0][0] == 0.0 and bands[0][1] == 1.0 and bands[0][2] is fault


@functools.lru_cache(maxsize=256)
def face_bands(pair: GearPair, fault: ToothFault) -> tuple:
    """``fault.face_bands(pair)``, computed once per (pair, fault) (a batch asks twice:
    for its FTFF bands and for its tables)."""
    return fault.face_bands(pair)


def _faulty_gear_compliance(pair: GearPair, fault: ToothFault) -> np.ndarray:
    """Gear-tooth compliance over the u table for a faulty tooth: exact on a few points
    of each smooth segment (between the fault's breakpoints) and interpolated, healthy
    outside the affected range."""
    _, inv_g = _healthy_compliances(pair)
    s_min, breaks = fault.affected_range(pair)
    if s_min >= 1.0 and len(breaks) == 0:       # a surface or tip fault: section unchanged
        return inv_g.copy()
    s = 1.0 - _U_TABLE
    out = inv_g.copy()
    (_, _), (g_lo, g_hi) = pair.roll_limits
    edges = np.unique(np.clip(np.concatenate([[s_min, 1.0], breaks]), s_min, 1.0))
    sec = functools.partial(fault.section_loss, pair)
    for sel, knots in _segments(s, edges):
        roll = g_lo + fault.contact_roll(pair, knots) * (g_hi - g_lo)
        vals = _tooth_compliance(pair, pair.z_gear, roll, sec)
        out[sel] = np.interp(s[sel], knots, vals)
    return out


@functools.lru_cache(maxsize=256)
def _pair_table(pair: GearPair, fault: ToothFault | None) -> np.ndarray:
    if is_ftff(fault):                  # FTFFs: batch tables (gearshot.sim._ftff_batch)
        return ftff_cached(pair, [fault])[0][0]
    inv_p, inv_g = _healthy_compliances(pair)
    if fault is not None and not fault.is_healthy:
        inv_g = _faulty_gear_compliance(pair, fault)
    k_h = _hertz_stiffness(pair)
    tab = 1.0 / (1.0 / k_h + inv_p + inv_g)
    if fault is not None and not fault.is_healthy and fault.scales_contact:
        tab = tab * fault.stiffness_scale(pair, 1.0 - _U_TABLE)
    tab.setflags(write=False)
    return tab


@functools.lru_cache(maxsize=256)
def _band_tables(pair: GearPair, fault: ToothFault):
    """The fault's face bands as ``((z0, z1, k, d), ...)``: face fractions, the band's
    transverse pair stiffness (N/m, full-width scale) and displacement excitation (m)
    over the spur contact position u."""
    u = _U_TABLE
    out = []
    for z0, z1, f in face_bands(pair, fault):
        if z1 <= z0 or f is None or f.is_healthy:
            continue
        if is_ftff(f):
            d = ftff_cached(pair, [f])[0][1]
        else:
            d = np.asarray(f.displacement(pair, 1.0 - u), dtype=float)
            d.setflags(write=False)
        out.append((float(z0), float(z1), _pair_table(pair, f), d))
    return tuple(out)


@functools.lru_cache(maxsize=256)
def fault_tables(pair: GearPair, fault: ToothFault):
    """Spur (all slices in phase) tables over u of the faulty tooth pair: stiffness k_f
    (N/m) and the displacement excitation e_f (m) such that the pair's force is
    ``k_f (e + e_f)`` for profile errors e; bands weighted by their face width."""
    u = np.linspace(0.0, 1.0, _N_TABLE)
    if is_ftff(fault):
        return ftff_cached(pair, [fault])[0]
    if _whole_face(fault, pair):
        ef = np.asarray(fault.displacement(pair, 1.0 - u), dtype=float)
        return _pair_table(pair, fault), ef
    healthy = _pair_table(pair, None)
    k = healthy.copy()
    kd = np.zeros(_N_TABLE)
    for z0, z1, kb, d in _band_tables(pair, fault):
        k += (z1 - z0) * (kb - healthy)
        kd += (z1 - z0) * kb * d
    k = np.maximum(k, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        ef = np.where(k > 0, kd / np.where(k > 0, k, 1.0), 0.0)
    return k, ef


def helical_tables(pair: GearPair, fault: ToothFault | None = None, *,
                   stiffness: bool = True):
    """Slice-method tables of one helical tooth pair over the delay tau.

    Returns
    -------
    span : float
        Length of the tables, mesh periods (>= the total contact ratio).
    k : ndarray (n_tau,)
        Pair stiffness (N/m) of the faulty tooth, or the healthy one.
    bands : tuple of (lo, hi, dk, kd)
        Per face band (delays lo ... hi in mesh periods): the band's stiffness change
        ``k_band - k_healthy`` and force per displacement ``k_band d_band`` over u (spur
        tables, full-width scale), to be boxed with the profile errors.

    ``stiffness=False`` leaves the faulty tooth's stiffness out (``k`` is then the
    healthy one): a batch boxes its faults' bands together.
    """
    ea, eb = pair.contact_ratio, pair.overlap_ratio
    tau = tau_grid(ea, eb, _N_TABLE)
    span = float(tau[-1])
    healthy = _pair_table(pair, None)
    k = _helical_healthy(pair)
    bands: tuple[tuple[Any, Any, Any, Any], ...] = ()
    if fault is not None and not fault.is_healthy:
        bands = tuple((z0 * eb, z1 * eb, kb - healthy, kb * d)
                      for z0, z1, kb, d in _band_tables(pair, fault))
        if not stiffness:
            return span, k, bands
        k = k.copy()
        if bands:
            lo, hi, dk, _ = band_arrays(bands)
            for part in box(dk, ea, eb, lo, hi, tau):   # all bands at once, added in order
                k += part
        k = np.maximum(k, 0.0)
    return span, k, bands


def band_arrays(bands):
    """``helical_tables``'s bands as arrays: lo (n_bands,), hi (n_bands,), dk and kd
    (n_bands, n_table)."""
    lo, hi, dk, kd = zip(*bands, strict=True)
    return np.array(lo), np.array(hi), np.stack(dk), np.stack(kd)


@functools.lru_cache(maxsize=32)
def _helical_healthy(pair: GearPair) -> np.ndarray:
    ea, eb = pair.contact_ratio, pair.overlap_ratio
    tab = box(_pair_table(pair, None), ea, eb, 0.0, eb, tau_grid(ea, eb, _N_TABLE))
    tab.setflags(write=False)
    return tab


def mesh_stiffness(pair: GearPair, pinion_angle, *, fault: ToothFault | None = None
                   ) -> np.ndarray:
    """Mesh stiffness k_m (N/m): sum of the stiffnesses of all tooth pairs in contact.

    Parameters
    ----------
    pair : GearPair
    pinion_angle : array_like
        Pinion rotation, rad (any shape). At angle 0 gear tooth 0 enters contact (for a
        helical pair: the first slice of gear tooth 0, at face position 0).
    fault : ToothFault, optional
        Fault on one gear tooth (e.g. ``Fault.ftff(0.5)``).

    Returns
    -------
    ndarray, same shape as ``pinion_angle``
    """
    theta = as_signal_array(pinion_angle, "pinion_angle", min_ndim=0)
    if pair.is_helical:
        return _helical_mesh_stiffness(pair, theta, fault)
    eps = pair.contact_ratio
    t_mesh = np.asarray(theta) * pair.z_pinion / (2 * math.pi)
    u_grid = np.linspace(0.0, 1.0, _N_TABLE)
    k_healthy = _pair_table(pair, None)
    k_fault = None
    if fault is not None and not fault.is_healthy:
        k_fault = fault_tables(pair, fault)[0]
    total = np.zeros_like(t_mesh, dtype=float)
    base = np.floor(t_mesh)
    for j in range(int(math.ceil(eps)) + 1):
        n = base - j
        u = (t_mesh - n) / eps
        inside = (u >= 0) & (u < 1)
        k = np.interp(u, u_grid, k_healthy)
        if k_fault is not None and fault is not None:
            faulty = np.mod(n, pair.z_gear) == fault.tooth % pair.z_gear
            k = np.where(faulty, np.interp(u, u_grid, k_fault), k)
        total += np.where(inside, k, 0.0)
    return total


def _helical_mesh_stiffness(pair, theta, fault):
    span, k_healthy, _ = helical_tables(pair)
    k_fault = None
    if fault is not None and not fault.is_healthy:
        k_fault = helical_tables(pair, fault)[1]
    t_mesh = np.asarray(theta) * pair.z_pinion / (2 * math.pi)
    grid = np.linspace(0.0, span, k_healthy.size)
    total = np.zeros_like(t_mesh, dtype=float)
    base = np.floor(t_mesh)
    for j in range(int(math.ceil(span)) + 1):
        n = base - j
        tau = t_mesh - n
        inside = (tau >= 0) & (tau < span)
        k = np.interp(tau, grid, k_healthy)
        if k_fault is not None:
            faulty = np.mod(n, pair.z_gear) == fault.tooth % pair.z_gear
            k = np.where(faulty, np.interp(tau, grid, k_fault), k)
        total += np.where(inside, k, 0.0)
    return total
