"""Tooth faults on the driven gear: an extensible base class and the full tooth face fault.

A fault acts on the gear pair in two ways (DESIGN.md section 2):

* it changes the single-pair stiffness of the pairs its tooth takes part in
  (:meth:`ToothFault.section_loss` thins the tooth; :meth:`ToothFault.contact_roll`
  moves the load point), and
* it adds a displacement excitation along the line of action
  (:meth:`ToothFault.displacement`).

New fault types (tooth breakage, partial-face faults) subclass :class:`ToothFault` and
override these three hooks; the stiffness and dynamics code only calls the hooks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._errors import GearshotError
from .._validation import check_in_range, check_int
from .geometry import GearPair, involute_half_angle

__all__ = ["ToothFault", "Fault", "FullToothFaceFault"]


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

    def contact_roll(self, pair: GearPair, s: np.ndarray) -> np.ndarray:
        """Roll fraction where the load actually acts when the nominal contact is at ``s``
        (0 = lowest contact point, 1 = tip of the gear tooth)."""
        return np.asarray(s, dtype=float)

    def displacement(self, pair: GearPair, s: np.ndarray) -> np.ndarray:
        """Displacement excitation along the line of action (m, negative = material
        missing) when the nominal contact is at gear roll fraction ``s``."""
        return np.zeros_like(np.asarray(s, dtype=float))


@dataclass(frozen=True)
class FullToothFaceFault(ToothFault):
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
        Fraction of the cut's geometric deviation that reaches the mesh as displacement
        excitation. A linear mesh model lets the mating flank follow the whole cut, while
        in the real pair the neighbouring pairs take over part of the load; the default
        0.275 is calibrated so that diff-RMS(y = 0.7) / diff-RMS(healthy) at DIN 7,
        15 rps, 10 Nm matches the lab's model (7.7; benchmarks/RESULTS_sim.md). Use 1.0
        for the purely geometric deviation.
    """

    size: float = 0.0
    center: float = 0.5
    depth: float = 0.5
    transmission: float = 0.275

    def __post_init__(self) -> None:
        super().__post_init__()
        check_in_range(self.size, "size", 0.0, 1.0)
        check_in_range(self.center, "center", 0.0, 1.0)
        check_in_range(self.depth, "depth", 0.0, 1.0, low_inclusive=False)
        check_in_range(self.transmission, "transmission", 0.0, 1.0)
        lo, hi = self.window
        if lo < -1e-12 or hi > 1 + 1e-12:
            raise GearshotError(
                f"FTFF of size {self.size!r} centred at {self.center!r} leaves the active "
                f"profile (spans {lo:.4g} to {hi:.4g}); choose center in "
                f"[{self.size / 2:.4g}, {1 - self.size / 2:.4g}]")

    @property
    def is_healthy(self) -> bool:
        return self.size <= 0.0

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
            psi = float(involute_half_angle(z, pair.pressure_angle, np.array(r), rb))
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
        r_tab = np.linspace(rb, pair.tip_radius(z), 2001)
        psi = involute_half_angle(z, pair.pressure_angle, r_tab, rb)
        x_tab, h_tab = r_tab * np.cos(psi), r_tab * np.sin(psi)
        inside = (x > xa) & (x < xb)
        out = np.zeros_like(x)
        xi = x[inside]
        h_flank = np.interp(xi, x_tab, h_tab)
        h_arc = ch - np.sqrt(np.maximum(radius ** 2 - (xi - cx) ** 2, 0.0))
        out[inside] = np.maximum(h_flank - h_arc, 0.0)
        return out

    def contact_roll(self, pair: GearPair, s: np.ndarray) -> np.ndarray:
        """While the nominal contact lies in the tip-side half of the cut, the mating flank
        bridges the hollow and pivots on the cut's tip-side edge, so the load stays there;
        in the root-side half it follows the cut again (only the thinning acts)."""
        s = np.asarray(s, dtype=float)
        if self.is_healthy:
            return s
        s0, s1 = self.window
        mid = 0.5 * (s0 + s1)
        out = s.copy()
        out[(s > mid) & (s < s1)] = s1
        return out

    def deviation_depth(self, pair: GearPair) -> float:
        """Peak displacement excitation h (m): the cut's sagitta plus the bulge of the
        mating pinion involute over the corresponding stretch of its flank."""
        if self.is_healthy:
            return 0.0
        _, _, _, sag = self._arc(pair)
        # pinion flank stretch that meets the cut
        z1 = pair.z_pinion
        rb1 = pair.base_radius(z1)
        total = pair.center_distance * math.sin(pair.pressure_angle)
        _, (l_lo, l_hi) = pair.roll_limits
        s0, s1 = self.window
        lp = total - (l_lo + np.linspace(s0, s1, 201) * (l_hi - l_lo))
        r = np.hypot(rb1, lp)
        psi = involute_half_angle(z1, pair.pressure_angle, r, rb1)
        px, ph = r * np.cos(psi), r * np.sin(psi)
        dx, dh = px[-1] - px[0], ph[-1] - ph[0]
        norm = math.hypot(dx, dh)
        if norm == 0:
            return sag
        dist = np.abs((px - px[0]) * dh - (ph - ph[0]) * dx) / norm
        return sag + float(dist.max())

    def displacement(self, pair: GearPair, s: np.ndarray) -> np.ndarray:
        """Raised-cosine dip of depth :meth:`deviation_depth` across the cut."""
        s = np.asarray(s, dtype=float)
        if self.is_healthy:
            return np.zeros_like(s)
        s0, s1 = self.window
        h = self.transmission * self.deviation_depth(pair)
        rel = (s1 - s) / (s1 - s0)  # contact runs from tip (s = 1) to root
        inside = (rel > 0) & (rel < 1)
        out = np.zeros_like(s)
        out[inside] = -h * 0.5 * (1 - np.cos(2 * np.pi * rel[inside]))
        return out


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
