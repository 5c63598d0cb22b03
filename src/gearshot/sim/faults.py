"""Tooth faults on the driven gear: an extensible base class and the full tooth face fault.

A fault acts on the gear pair in two ways (DESIGN.md section 2):

* it changes the single-pair stiffness of the pairs its tooth takes part in
  (:meth:`ToothFault.section_loss` thins the tooth; :meth:`ToothFault.contact_roll`
  moves the load point), and
* it adds a displacement excitation along the line of action
  (:meth:`ToothFault.displacement`).

New fault types subclass :class:`ToothFault` (a frozen dataclass, so faults are
hashable and their tables can be cached) and override ``is_healthy`` and these hooks, plus
:meth:`ToothFault.affected_range` to tell where the stiffness changes and where it jumps,
:meth:`ToothFault.stiffness_scale` where contact is lost and
:meth:`ToothFault.face_bands` when the fault is not uniform across the face width; the
stiffness and dynamics code only calls the hooks (:mod:`gearshot.sim.fault_types` holds
the partial-face, breakage and surface-destruction faults). Pass such faults to
:func:`~gearshot.sim.simulate_sa` / :func:`~gearshot.sim.simulate` with ``faults=[...]``.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from .._errors import GearshotError
from .._validation import check_in_range, check_int
from .geometry import GearPair, _involute_function, contact_angles, involute_half_angle

__all__ = ["ToothFault", "SizedToothFault", "Fault", "FullToothFaceFault"]


@dataclass(frozen=True)
class ToothFault:
    """Base class of faults on one tooth of the driven gear (healthy by itself).

    Parameters
    ----------
    tooth : int
        Index of the faulty gear tooth; tooth 0 enters contact at pinion angle 0.
    """

    tooth: int = 0

    def __post_init__(self) -> None:
        check_int(self.tooth, "tooth", minimum=0)

    @property
    def is_healthy(self) -> bool:
        return True

    def section_loss(self, pair: GearPair, x: np.ndarray) -> np.ndarray:
        """Material removed from the tooth section (m of thickness) at axial positions
        ``x`` (m from the gear centre along the tooth's centre line)."""
        return np.zeros_like(np.asarray(x, dtype=float))

    def affected_range(self, pair: GearPair) -> tuple[float, np.ndarray]:
        """(s_min, breakpoints): the pair stiffness may differ from healthy only for gear
        roll fractions s >= s_min and is smooth between the breakpoints. The default (the
        whole profile, no jumps) is safe; overriding it makes the tables exact at jumps
        and cheaper."""
        return 0.0, np.array([])

    def contact_roll(self, pair: GearPair, s: np.ndarray) -> np.ndarray:
        """Roll fraction where the load actually acts when the nominal contact is at ``s``
        (0 = lowest contact point, 1 = tip of the gear tooth)."""
        return np.asarray(s, dtype=float)

    def displacement(self, pair: GearPair, s: np.ndarray) -> np.ndarray:
        """Displacement excitation along the line of action (m, negative = material
        missing) when the nominal contact is at gear roll fraction ``s``."""
        return np.zeros_like(np.asarray(s, dtype=float))

    #: True when :meth:`stiffness_scale` is not 1 everywhere (contact area lost).
    scales_contact = False

    def stiffness_scale(self, pair: GearPair, s: np.ndarray) -> np.ndarray:
        """Factor (0 ... 1) on the pair stiffness when the nominal contact is at gear roll
        fraction ``s``: the share of the contact line that still bears (0 where the
        flank is gone, e.g. a broken tip). Only used when :attr:`scales_contact`."""
        return np.ones_like(np.asarray(s, dtype=float))

    def face_bands(self, pair: GearPair) -> tuple:
        """The fault along the face width: ``((start, end, transverse_fault), ...)`` with
        start/end fractions of the face width (0 ... 1) and the fault of the transverse
        section over that band (whose hooks above act on a slice of the face). Outside
        the bands the tooth is healthy. Default: this fault over the whole face."""
        return ((0.0, 1.0, self),)


@dataclass(frozen=True)
class SizedToothFault(ToothFault):
    """Base class of the fault types (:mod:`gearshot.fault_registry`): a fault of size
    y = ``size`` in [0, 1] (0 = healthy), whose meaning each type defines.

    Parameters
    ----------
    size : float
        y in [0, 1].
    tooth : int
        Faulty gear tooth.
    """

    size: float = 0.0

    def __post_init__(self) -> None:
        super().__post_init__()
        check_in_range(self.size, "size", 0.0, 1.0)

    @property
    def is_healthy(self) -> bool:
        return self.size <= 0.0

    @classmethod
    def of_size(cls, size: float, **options) -> SizedToothFault:
        """The fault of size ``size`` with the type's other fields from ``options``
        (the constructor of :data:`gearshot.sim.FAULT_TYPES`)."""
        return cls(size=size, **options)


@dataclass(frozen=True)
class FullToothFaceFault(SizedToothFault):
    """Full tooth face fault (FTFF): the flank of one gear tooth is cut by a circular arc
    over the whole face width.

    Parameters
    ----------
    size : float
        y in [0, 1]: removed width along the active profile / active profile width
        (fractions of the roll length of the active profile).
    center : float
        Centre of the cut as a fraction of the active profile (0 = lowest contact point,
        1 = tip).
    depth : float
        Depth coefficient in (0, 1]: the arc's sagitta is ``depth x chord / 2``
        (1 = semicircle).
    tooth : int
        Faulty gear tooth.
    transmission : float
        Scale of the displacement excitation (1 = the geometric value of
        :meth:`deviation_depth`; 0 = stiffness change only). For sensitivity studies.
    """

    center: float = 0.5
    depth: float = 0.5
    transmission: float = 1.0

    def __post_init__(self) -> None:
        super().__post_init__()
        check_in_range(self.center, "center", 0.0, 1.0)
        check_in_range(self.depth, "depth", 0.0, 1.0, low_inclusive=False)
        check_in_range(self.transmission, "transmission", 0.0, 10.0)
        lo, hi = self.window
        if lo < -1e-12 or hi > 1 + 1e-12:
            raise GearshotError(
                f"FTFF of size {self.size!r} centred at {self.center!r} leaves the active "
                f"profile (spans {lo:.4g} to {hi:.4g}); choose center in "
                f"[{self.size / 2:.4g}, {1 - self.size / 2:.4g}]")

    @classmethod
    def of_size(cls, size: float, *, tooth: int = 0, center: float = 0.5,
                depth: float = 0.5, **options) -> FullToothFaceFault:
        """The FTFF of size ``size`` with its centre moved (when needed) so that the cut
        stays on the active profile (``fault_of_type("ftff", ...)``)."""
        if size > 0:
            center = min(max(center, 0.5 * size), 1.0 - 0.5 * size)
        else:
            size = 0.0
        return cls(tooth=tooth, size=size, center=center, depth=depth, **options)

    @property
    def window(self) -> tuple[float, float]:
        """(start, end) roll fractions of the cut on the gear's active profile."""
        return self.center - 0.5 * self.size, self.center + 0.5 * self.size

    # -- geometry helpers -------------------------------------------------------------
    def _edges(self, pair: GearPair):
        z = pair.z_gear
        rb = pair.base_radius(z)
        _, (l_lo, l_hi) = pair.roll_limits
        s0, s1 = self.window
        pts = []
        for s in (s0, s1):
            r = math.hypot(rb, l_lo + s * (l_hi - l_lo))
            psi = float(involute_half_angle(z, pair.transverse_pressure_angle, np.array(r), rb))
            pts.append((r * math.cos(psi), r * math.sin(psi)))
        return np.array(pts)  # [[x_start, h_start], [x_end, h_end]]

    def _arc(self, pair: GearPair):
        (xa, ha), (xb, hb) = self._edges(pair)
        chord = math.hypot(xb - xa, hb - ha)
        radius = chord / 4 * (self.depth + 1 / self.depth)
        sag = self.depth * chord / 2
        tx, th = (xb - xa) / chord, (hb - ha) / chord
        nx, nh = th, -tx          # normal pointing into the tooth (towards h = 0)
        if nh > 0:
            nx, nh = -nx, -nh
        mx, mh = 0.5 * (xa + xb), 0.5 * (ha + hb)
        cx, ch = mx - nx * (radius - sag), mh - nh * (radius - sag)
        return (xa, xb), (cx, ch), radius, sag

    def section_loss(self, pair: GearPair, x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        if self.is_healthy:
            return np.zeros_like(x)
        (xa, xb), (cx, ch), radius, _ = self._arc(pair)
        z = pair.z_gear
        rb = pair.base_radius(z)
        # healthy flank half-thickness at x (invert x(r) on a fine table)
        r_tab = np.linspace(rb, pair.tip_radius(z), 601)
        psi = involute_half_angle(z, pair.transverse_pressure_angle, r_tab, rb)
        x_tab, h_tab = r_tab * np.cos(psi), r_tab * np.sin(psi)
        inside = (x > xa) & (x < xb)
        out = np.zeros_like(x)
        xi = x[inside]
        h_flank = np.interp(xi, x_tab, h_tab)
        h_arc = ch - np.sqrt(np.maximum(radius ** 2 - (xi - cx) ** 2, 0.0))
        out[inside] = np.maximum(h_flank - h_arc, 0.0)
        return out

    def affected_range(self, pair: GearPair) -> tuple[float, np.ndarray]:
        s0, s1 = self.window
        if self.is_healthy:
            return 1.0, np.array([])
        return s0, np.array([s0, self._switch(pair), s1])

    def _switch(self, pair: GearPair) -> float:
        """Nominal roll fraction where the load jumps from one edge of the cut to the
        other (largest jump of the touched point)."""
        knots, _, contact = self.bridge(pair)
        i = int(np.argmax(np.abs(np.diff(contact))))
        return 0.5 * (knots[i] + knots[i + 1])

    def contact_roll(self, pair: GearPair, s: np.ndarray) -> np.ndarray:
        """Where the load acts: inside the cut, the gear point the bridging mating flank
        touches (:meth:`bridge`): the tip-side edge first, then the root-side edge."""
        s = np.asarray(s, dtype=float)
        if self.is_healthy:
            return s
        s0, s1 = self.window
        knots, _, contact = self.bridge(pair)
        sw = self._switch(pair)
        out = s.copy()
        hi = (s > sw) & (s < s1)
        lo = (s > s0) & (s <= sw)
        k_hi, k_lo = knots > sw, knots <= sw      # interpolate within each side only
        if hi.any():
            out[hi] = np.interp(s[hi], knots[k_hi], contact[k_hi])
        if lo.any():
            out[lo] = np.interp(s[lo], knots[k_lo], contact[k_lo])
        return out

    def _flank_points(self, pair: GearPair, margin: float = 0.04, n: int = 80):
        """Polar (radius, angle from the tooth centre line) of the cut flank near the cut:
        ``n`` points on the arc, plus a few on the involute up to ``margin`` of the active
        profile beyond its edges (on conjugate flanks the gap grows away from the nominal
        contact, so the edges bound the healthy part)."""
        z = pair.z_gear
        rb = pair.base_radius(z)
        _, (l_lo, l_hi) = pair.roll_limits
        s0, s1 = self.window
        pieces_s = [np.linspace(max(s0 - margin, -0.02), s0, 5),
                    np.linspace(s1, min(s1 + margin, 1.0), 5)]
        ls = l_lo + np.concatenate(pieces_s) * (l_hi - l_lo)
        r = np.hypot(rb, np.maximum(ls, 0.0))
        psi = involute_half_angle(z, pair.transverse_pressure_angle, r, rb)
        (xa, xb), (cx, ch), radius, _ = self._arc(pair)
        xx = np.linspace(xa, xb, n)
        hh = ch - np.sqrt(np.maximum(radius ** 2 - (xx - cx) ** 2, 0.0))
        return (np.concatenate([r, np.hypot(xx, hh)]),
                np.concatenate([psi, np.arctan2(hh, xx)]))

    def _retreat(self, pair: GearPair, u: np.ndarray):
        """Rigid-body retreat (m, >= 0) of the mating pinion flank when the nominal
        contact is at line-of-action fraction ``u``: the smallest normal gap between the
        pinion involute (through the nominal contact point) and the remaining gear flank
        (cut arc and the involute beyond its edges), points within the pinion's flank;
        and the gear radius (m) of the point where the pinion then touches."""
        rb1, ra1 = pair.base_radius(pair.z_pinion), pair.tip_radius(pair.z_pinion)
        phi_p, centre = contact_angles(pair, u)
        o2 = np.array([pair.center_distance, 0.0])
        r, ang = self._flank_points(pair)
        px = o2[0] + r[None, :] * np.cos(centre[:, None] + ang[None, :])
        py = o2[1] + r[None, :] * np.sin(centre[:, None] + ang[None, :])
        rp = np.hypot(px, py)
        gap = rb1 * (np.arctan2(py, px) + _involute_function(np.maximum(rp, rb1), rb1)
                     - phi_p[:, None])
        gap = (gap + math.pi * rb1) % (2 * math.pi * rb1) - math.pi * rb1
        gap = np.where((rp >= rb1) & (rp <= ra1), gap, np.inf)
        best = np.argmin(gap, axis=1)
        return np.clip(gap[np.arange(gap.shape[0]), best], 0.0, None), r[best]

    def deviation_depth(self, pair: GearPair) -> float:
        """Peak displacement excitation (m) over the cut (see :meth:`displacement`)."""
        if self.is_healthy:
            return 0.0
        s0, s1 = self.window
        s = np.linspace(s0, s1, 257)
        return float(-self.displacement(pair, s).min())

    def bridge(self, pair: GearPair):
        """The cut bridged by the mating flank, sampled across the cut (cached).

        Returns
        -------
        s : ndarray (129,)
            Nominal contact positions (gear roll fractions), cut start to end.
        retreat : ndarray (129,)
            Rigid retreat of the mating flank, m (:meth:`_retreat`).
        contact : ndarray (129,)
            Roll fraction of the gear point actually touched (an edge of the cut, or its
            floor for shallow cuts).
        """
        return _bridge(self, pair)

    def displacement(self, pair: GearPair, s: np.ndarray) -> np.ndarray:
        """Loss of approach along the line of action while the nominal contact lies in
        the cut: the mating flank bridges the hollow and bears on the cut's edges (or its
        floor, for shallow cuts), so the pair's transmission error drops by the rigid
        gap computed from the exact involute geometry (:meth:`bridge`)."""
        s = np.asarray(s, dtype=float)
        out = np.zeros_like(s)
        if self.is_healthy:
            return out
        s0, s1 = self.window
        inside = (s > s0) & (s < s1)
        if inside.any():
            knots, ret, _ = self.bridge(pair)
            out[inside] = -self.transmission * np.interp(s[inside], knots, ret)
        return out


@functools.lru_cache(maxsize=1024)
def _bridge(fault: FullToothFaceFault, pair: GearPair):
    from ._ftff_batch import bridge_batch  # one code path for one fault and a batch

    knots, ret, contact = (a[0] for a in bridge_batch(pair, [fault]))
    for arr in (knots, ret, contact):
        arr.setflags(write=False)
    return knots, ret, contact


class Fault:
    """Namespace of fault constructors (``Fault.ftff(0.5)``)."""

    @staticmethod
    def ftff(size: float, *, center: float = 0.5, depth: float = 0.5,
             tooth: int = 0) -> FullToothFaceFault:
        """Full tooth face fault of size ``y`` on gear tooth ``tooth`` (see
        :class:`FullToothFaceFault`)."""
        return FullToothFaceFault(tooth=tooth, size=_as_float(size, "size"),
                                  center=_as_float(center, "center"),
                                  depth=_as_float(depth, "depth"))

    @staticmethod
    def healthy() -> ToothFault:
        """No fault."""
        return ToothFault()


def _as_float(value, name):
    try:
        return float(value)
    except (TypeError, ValueError):
        raise GearshotError(f"{name} must be a real number; got {value!r}") from None


def is_ftff(fault: object) -> bool:
    """True for a non-healthy full-tooth-face fault (exactly the FTFF class: its tables are
    built by :mod:`gearshot.sim._ftff_batch`)."""
    return type(fault) is FullToothFaceFault and not fault.is_healthy
