"""Spur and helical gear pair parameters and involute geometry (SI units throughout).

A helical pair (``helix_angle`` > 0) is described by its normal module and normal pressure
angle (``module``, ``pressure_angle``, as on a drawing and in ISO 6336); its transverse
section is an involute spur profile of transverse module ``m_t = m_n / cos(beta)`` and
transverse pressure angle ``alpha_t = atan(tan(alpha_n) / cos(beta))``. Every transverse
quantity (radii, base pitch, roll limits, the transverse contact ratio) is that of the
transverse section; with ``helix_angle == 0`` they are exactly the spur values.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._errors import GearshotError
from .._validation import check_in_range, check_int, check_positive
from ..paper import FACE_WIDTH, GEAR_TEETH, MODULE, PINION_TEETH, PRESSURE_ANGLE_DEG

__all__ = ["GearPair"]


@dataclass(frozen=True)
class GearPair:
    """A spur or helical gear pair on two shafts, with its test-rig surroundings.

    The pinion (``z_pinion`` teeth) drives the gear (``z_gear`` teeth). All values SI.

    Parameters
    ----------
    z_pinion, z_gear : int
        Numbers of teeth (>= 12).
    module : float
        Module, m (the normal module of a helical pair).
    face_width : float
        Face width, m.
    pressure_angle : float
        Nominal pressure angle, rad (the normal pressure angle of a helical pair).
    youngs_modulus : float
        E, Pa.
    poisson : float
        Poisson's ratio.
    density : float
        kg/m^3 (used for default masses).
    bore_radius : float
        Bore (hub) radius of both wheels, m (fillet-foundation term, Sainsot).
    addendum, dedendum : float
        Addendum and dedendum coefficients (x module).
    mass_pinion, mass_gear : float or None
        Wheel masses, kg. ``None``: density x pi r_pitch^2 x face width.
    inertia_pinion, inertia_gear : float or None
        Polar moments of inertia, kg m^2. ``None``: mass x r_pitch^2 / 2.
    inertia_brake : float
        Brake (load) inertia on the output shaft, kg m^2.
    shaft_radius : float
        Radius of both shafts, m.
    shaft_length_in, shaft_length_out : float
        Torsional lengths of input and output shafts, m.
    shear_modulus_shaft : float or None
        G of the shafts, Pa. ``None``: E / (2 (1 + nu)).
    bearing_stiffness : float
        Lateral bearing stiffness per direction per wheel, N/m.
    damping_ratio : float
        Modal damping ratio applied to every mode.
    helix_angle : float
        Helix angle at the pitch circle, rad, in [0, 45 deg]; 0 is a spur pair (every
        result unchanged). The axial bearing stiffness of a helical pair is
        ``bearing_stiffness``.
    """

    z_pinion: int = PINION_TEETH
    z_gear: int = GEAR_TEETH
    module: float = MODULE
    face_width: float = FACE_WIDTH
    pressure_angle: float = math.radians(PRESSURE_ANGLE_DEG)
    youngs_modulus: float = 210e9
    poisson: float = 0.3
    density: float = 7850.0
    bore_radius: float = 10e-3
    addendum: float = 1.0
    dedendum: float = 1.25
    mass_pinion: float | None = None
    mass_gear: float | None = None
    inertia_pinion: float | None = None
    inertia_gear: float | None = None
    inertia_brake: float = 4.5e-3
    shaft_radius: float = 10e-3
    shaft_length_in: float = 0.2
    shaft_length_out: float = 0.6
    shear_modulus_shaft: float | None = None
    bearing_stiffness: float = 1.9e8
    damping_ratio: float = 0.05
    helix_angle: float = 0.0

    def __post_init__(self) -> None:
        check_int(self.z_pinion, "z_pinion", minimum=12)
        check_int(self.z_gear, "z_gear", minimum=12)
        for name in ("module", "face_width", "pressure_angle", "youngs_modulus", "density",
                     "bore_radius", "addendum", "dedendum", "inertia_brake", "shaft_radius",
                     "shaft_length_in", "shaft_length_out", "bearing_stiffness"):
            check_positive(getattr(self, name), name)
        for name in ("mass_pinion", "mass_gear", "inertia_pinion", "inertia_gear",
                     "shear_modulus_shaft"):
            if getattr(self, name) is not None:
                check_positive(getattr(self, name), name)
        check_in_range(self.poisson, "poisson", 0.0, 0.5, high_inclusive=False)
        check_in_range(self.damping_ratio, "damping_ratio", 0.0, 1.0, low_inclusive=False)
        check_in_range(self.pressure_angle, "pressure_angle", math.radians(10), math.radians(35))
        check_in_range(self.helix_angle, "helix_angle", 0.0, math.radians(45))
        if self.bore_radius >= self.root_radius(self.z_pinion) * 0.95:
            raise GearshotError(
                f"bore_radius must be well below the pinion root radius "
                f"({self.root_radius(self.z_pinion):.4g} m); got {self.bore_radius!r}")
        (p_lo, _), (g_lo, _) = self.roll_limits
        if p_lo <= 0 or g_lo <= 0:
            raise GearshotError(
                f"z_pinion={self.z_pinion}, z_gear={self.z_gear}: the path of contact starts "
                f"below a base circle (involute interference); use more pinion teeth or a "
                f"smaller addendum (addendum={self.addendum!r})")
        if not self.total_contact_ratio > 1.0:
            raise GearshotError(f"the pair's contact ratio must exceed 1; got "
                                f"{self.total_contact_ratio:.4g} "
                                f"(z={self.z_pinion}/{self.z_gear})")

    # ------------------------------------------------------------------ constructors
    @classmethod
    def paper(cls, **overrides) -> GearPair:
        """The pair of Matania et al. (2023): 17/38 teeth, m 3 mm, b 15 mm, 20 deg, steel,
        wheel masses 0.8 / 3.2 kg, 5 % modal damping. Keyword overrides are applied."""
        base: dict[str, Any] = dict(z_pinion=PINION_TEETH, z_gear=GEAR_TEETH, module=MODULE,
                    face_width=FACE_WIDTH, pressure_angle=math.radians(PRESSURE_ANGLE_DEG),
                    youngs_modulus=210e9, poisson=0.3, mass_pinion=0.8, mass_gear=3.2,
                    damping_ratio=0.05)
        base.update(overrides)
        return cls(**base)

    def replace(self, **changes) -> GearPair:
        """A copy with some fields changed (validated)."""
        return dataclasses.replace(self, **changes)

    @classmethod
    def helical(cls, helix_angle: float, **overrides) -> GearPair:
        """The paper's pair (:meth:`paper`) cut with helical teeth of ``helix_angle``
        (rad; normal module and pressure angle kept). Keyword overrides are applied."""
        return cls.paper(helix_angle=helix_angle, **overrides)

    # ------------------------------------------------------------------ geometry
    @property
    def is_helical(self) -> bool:
        """True when ``helix_angle`` > 0."""
        return self.helix_angle > 0.0

    @functools.cached_property
    def transverse_module(self) -> float:
        """Transverse module m_n / cos(beta), m (``module`` for a spur pair)."""
        if not self.is_helical:
            return self.module
        return self.module / math.cos(self.helix_angle)

    @functools.cached_property
    def transverse_pressure_angle(self) -> float:
        """Transverse pressure angle atan(tan(alpha_n) / cos(beta)), rad."""
        if not self.is_helical:
            return self.pressure_angle
        return math.atan(math.tan(self.pressure_angle) / math.cos(self.helix_angle))

    @functools.cached_property
    def base_helix_angle(self) -> float:
        """Helix angle at the base circle, rad: sin(beta_b) = sin(beta) cos(alpha_n)."""
        return math.asin(math.sin(self.helix_angle) * math.cos(self.pressure_angle))

    def pitch_radius(self, z: int) -> float:
        return 0.5 * self.transverse_module * z

    def base_radius(self, z: int) -> float:
        return self.pitch_radius(z) * math.cos(self.transverse_pressure_angle)

    def tip_radius(self, z: int) -> float:
        return self.pitch_radius(z) + self.addendum * self.module

    def root_radius(self, z: int) -> float:
        return self.pitch_radius(z) - self.dedendum * self.module

    @functools.cached_property
    def center_distance(self) -> float:
        return 0.5 * self.transverse_module * (self.z_pinion + self.z_gear)

    @functools.cached_property
    def base_pitch(self) -> float:
        """Transverse base pitch, m (distance between successive pairs along the line of
        action)."""
        return math.pi * self.transverse_module * math.cos(self.transverse_pressure_angle)

    @functools.cached_property
    def roll_limits(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """Roll lengths (distance from the base-circle tangency, m) of the active profile,
        ((pinion_low, pinion_tip), (gear_low, gear_tip))."""
        rb1, rb2 = self.base_radius(self.z_pinion), self.base_radius(self.z_gear)
        ra1, ra2 = self.tip_radius(self.z_pinion), self.tip_radius(self.z_gear)
        total = self.center_distance * math.sin(self.transverse_pressure_angle)
        l1_tip = math.sqrt(ra1 ** 2 - rb1 ** 2)
        l2_tip = math.sqrt(ra2 ** 2 - rb2 ** 2)
        return (total - l2_tip, l1_tip), (total - l1_tip, l2_tip)

    @functools.cached_property
    def contact_length(self) -> float:
        """Length of the path of contact along the line of action, m."""
        (p_lo, p_hi), _ = self.roll_limits
        return p_hi - p_lo

    @functools.cached_property
    def contact_ratio(self) -> float:
        """Transverse contact ratio epsilon_alpha (path of contact / transverse base
        pitch); see :attr:`total_contact_ratio` for a helical pair."""
        (p_lo, p_hi), _ = self.roll_limits
        if p_lo <= 0:  # interference: contact would start below the pinion base circle
            return float("nan")
        return self.contact_length / self.base_pitch

    @property
    def transverse_contact_ratio(self) -> float:
        """Transverse contact ratio epsilon_alpha (same as :attr:`contact_ratio`)."""
        return self.contact_ratio

    @functools.cached_property
    def overlap_ratio(self) -> float:
        """Overlap (face) contact ratio epsilon_beta = b sin(beta) / (pi m_n): how many
        base pitches one tooth's contact line advances across the face width (0 for
        spur)."""
        return self.face_width * math.sin(self.helix_angle) / (math.pi * self.module)

    @functools.cached_property
    def total_contact_ratio(self) -> float:
        """Total contact ratio epsilon_gamma = epsilon_alpha + epsilon_beta: the mesh
        periods during which one tooth pair is (partly) in contact."""
        return self.contact_ratio + self.overlap_ratio

    @property
    def masses(self) -> tuple[float, float]:
        """(pinion, gear) masses, kg."""
        def default(z):
            return self.density * math.pi * self.pitch_radius(z) ** 2 * self.face_width
        m1 = self.mass_pinion if self.mass_pinion is not None else default(self.z_pinion)
        m2 = self.mass_gear if self.mass_gear is not None else default(self.z_gear)
        return m1, m2

    @property
    def inertias(self) -> tuple[float, float]:
        """(pinion, gear) polar moments of inertia, kg m^2."""
        m1, m2 = self.masses
        j1 = (self.inertia_pinion if self.inertia_pinion is not None
              else 0.5 * m1 * self.pitch_radius(self.z_pinion) ** 2)
        j2 = (self.inertia_gear if self.inertia_gear is not None
              else 0.5 * m2 * self.pitch_radius(self.z_gear) ** 2)
        return j1, j2

    @property
    def shaft_torsional_stiffness(self) -> tuple[float, float]:
        """(input, output) shaft torsional stiffness pi r^4 G / (2 L), N m/rad."""
        g = (self.shear_modulus_shaft if self.shear_modulus_shaft is not None
             else self.youngs_modulus / (2 * (1 + self.poisson)))
        jp = math.pi * self.shaft_radius ** 4 / 2
        return jp * g / self.shaft_length_in, jp * g / self.shaft_length_out

    @property
    def gear_ratio(self) -> float:
        """z_gear / z_pinion."""
        return self.z_gear / self.z_pinion


def involute_half_angle(z: int, pressure_angle: float, r: np.ndarray, rb: float) -> np.ndarray:
    """Half tooth angle psi(r) (rad) of a standard involute tooth at radius r >= rb."""
    inv0 = math.tan(pressure_angle) - pressure_angle
    a = np.arccos(np.clip(rb / r, -1.0, 1.0))
    return math.pi / (2 * z) + inv0 - (np.tan(a) - a)


def _involute_function(r: np.ndarray, rb: float) -> np.ndarray:
    """inv(alpha) = tan(alpha) - alpha at radius ``r`` of an involute of base radius ``rb``."""
    al = np.arccos(np.clip(rb / r, -1.0, 1.0))
    return np.tan(al) - al


def contact_angles(pair: GearPair, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pinion involute angle at the nominal contact point and the driven gear's tooth
    centre-line angle (rad, gear frame at the centre distance) when the contact lies at
    line-of-action fraction ``u`` (any shape, 0 = start of active contact, 1 = end).
    Elementwise, so one fault's ``u`` and a batch's give the same numbers."""
    z1, z2 = pair.z_pinion, pair.z_gear
    a0 = pair.transverse_pressure_angle
    rb1, rb2 = pair.base_radius(z1), pair.base_radius(z2)
    (p_lo, p_hi), _ = pair.roll_limits
    inv0 = math.tan(a0) - a0
    d0, d1 = math.sin(a0), math.cos(a0)
    t0, t1 = rb1 * math.cos(a0), rb1 * -math.sin(a0)
    lam = p_lo + np.asarray(u, dtype=float) * (p_hi - p_lo)
    cx, cy = t0 + lam * d0, t1 + lam * d1                       # contact points
    phi_p = np.arctan2(cy, cx) + _involute_function(np.hypot(cx, cy), rb1)
    gx, gy = cx - pair.center_distance, cy - 0.0
    phi_g = np.arctan2(gy, gx) + _involute_function(np.hypot(gx, gy), rb2)
    return phi_p, phi_g - math.pi / (2 * z2) - inv0             # gear tooth centre line
