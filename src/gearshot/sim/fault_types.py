"""Fault types beyond the full tooth face fault, each with a size in [0, 1].

=================  ===========================================================================
name               geometry (size y: 0 = healthy ... 1)
=================  ===========================================================================
``"ftff"``         :class:`~gearshot.sim.FullToothFaceFault`: the flank cut by a circular arc
                   over the whole face width; y = cut width along the active profile / its
                   width (1: the whole active profile).
``"partial_face"`` :class:`PartialFaceFault`: the same arc cut (``profile_size`` of the
                   active profile, default 0.6) over part of the face width; y = the cut
                   band's width / the face width (1: an FTFF of size ``profile_size``).
``"breakage"``     :class:`ToothBreakage`: a broken tip with a chipped corner, grown from one
                   face end: over the face share ``face_share`` (default: y) from the
                   chipped end the tooth above a break line is lost; the lost height at
                   face position zeta (0 ... 1) is ``H min(1, y max(1, (1 + c)
                   (1 - zeta / w)))`` for zeta <= face_share and 0 beyond (H: height of the
                   tooth above its lowest contact point, c: ``corner``, w:
                   ``corner_width``): a tip loss ``y H`` deepening to ``(1 + c) y H`` at
                   the chipped face end. The break grows across the face and down the
                   tooth together; y = 1: the whole tooth lost down to the lowest contact
                   point over the whole face; what lies below never touches the mating
                   tooth, so y = 1 acts as a missing tooth. ``face_share=1`` gives the lab
                   model's geometry (a tip loss over the whole face plus a corner chip).
``"destruction"``  :class:`ToothDestruction`: surface destruction (pitting / wear): a band
                   of the active profile, centred at ``center``, over the whole face,
                   pitted with craters ``y depth`` deep (the damage deepens as it
                   spreads) and bearing only ``1 - contact_loss`` of the contact line;
                   y = the band's width / the active profile's (1: the whole active profile
                   destroyed, pits ``depth`` deep).
=================  ===========================================================================

How each acts on the pair (hooks of :class:`~gearshot.sim.ToothFault`): the partial face
fault and the breakage change only the slices of their face band
(:meth:`~gearshot.sim.ToothFault.face_bands`, the slice method); a lost tip takes the
slice's contact away where the gear contact would lie above the break
(:meth:`~gearshot.sim.ToothFault.stiffness_scale` = 0, so the neighbouring pairs carry
the load) and the break edge, where contact re-enters, falls short of the involute by
``edge_relief`` times the lost height (the excitation that makes a broken tooth loud,
:meth:`_TipLoss.displacement`); the destroyed band lowers the pair stiffness by the lost
contact share and adds a displacement excitation of its craters (raised-cosine pits 5 % of
the active profile wide), tapered at the band's edges where the mating flank bridges onto
the intact surface.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._errors import GearshotError
from .._validation import check_in_range, check_int
from ..fault_registry import FAULT_TYPE_RECORDS, check_fault_type, fault_type_record
from .faults import FullToothFaceFault, SizedToothFault, ToothFault
from .geometry import GearPair

__all__ = ["PartialFaceFault", "ToothBreakage", "ToothDestruction", "FAULT_TYPES",
           "FAULT_MODEL_VERSIONS", "check_fault_type", "fault_class", "fault_of_type"]


@dataclass(frozen=True)
class PartialFaceFault(SizedToothFault):
    """A flank cut (as the FTFF's circular arc) over part of the face width.

    Parameters
    ----------
    size : float
        y in [0, 1]: width of the cut band / face width.
    profile_size : float
        Extent of the cut along the active profile (the FTFF size), (0, 1].
    center, depth : float
        Centre along the active profile and depth coefficient of the cut (as the FTFF).
    face_start : float
        Face position (0 ... 1) where the band starts; it spans
        ``face_start ... face_start + size`` (<= 1).
    tooth : int
        Faulty gear tooth.
    """

    profile_size: float = 0.6
    center: float = 0.5
    depth: float = 0.5
    face_start: float = 0.0

    def __post_init__(self) -> None:
        super().__post_init__()
        check_in_range(self.face_start, "face_start", 0.0, 1.0)
        if self.face_start + self.size > 1 + 1e-12:
            raise GearshotError(f"a partial face fault of size {self.size!r} starting at "
                                f"face_start={self.face_start!r} leaves the face; choose "
                                f"face_start <= {1 - self.size:.4g}")
        _ = self.transverse                     # validates profile_size, center, depth

    @property
    def transverse(self) -> FullToothFaceFault:
        """The cut of the transverse section inside the band."""
        return FullToothFaceFault(tooth=self.tooth, size=self.profile_size,
                                  center=self.center, depth=self.depth)

    @property
    def is_healthy(self) -> bool:
        return self.size <= 0.0 or self.profile_size <= 0.0

    def face_bands(self, pair: GearPair) -> tuple:
        if self.is_healthy:
            return ()
        z0 = self.face_start
        return ((z0, min(z0 + self.size, 1.0), self.transverse),)


@dataclass(frozen=True)
class _ContactLoss(ToothFault):
    """A transverse section whose tooth body is intact (its compliance unchanged) and
    whose flank loses contact (:meth:`stiffness_scale`): a broken tip, a pitted band."""

    scales_contact = True

    def affected_range(self, pair: GearPair):
        return 1.0, np.array([])     # the tooth section (its compliance) is unchanged


@dataclass(frozen=True)
class _TipLoss(_ContactLoss):
    """The transverse section of a broken tooth: everything above ``height`` (m, measured
    down from the tip circle) is gone."""

    height: float = 0.0
    edge_relief: float = 0.0
    edge_width: float = 0.1

    @property
    def is_healthy(self) -> bool:
        return self.height <= 0.0

    def cut_fraction(self, pair: GearPair) -> float:
        """Gear roll fraction of the break radius (contact above it is lost)."""
        z = pair.z_gear
        rb = pair.base_radius(z)
        r_cut = pair.tip_radius(z) - self.height
        _, (l_lo, l_hi) = pair.roll_limits
        if r_cut <= rb:
            return -1.0
        return (math.sqrt(r_cut ** 2 - rb ** 2) - l_lo) / (l_hi - l_lo)

    def stiffness_scale(self, pair: GearPair, s: np.ndarray) -> np.ndarray:
        s = np.asarray(s, dtype=float)
        if self.is_healthy:
            return np.ones_like(s)
        return np.where(s <= self.cut_fraction(pair), 1.0, 0.0)

    def displacement(self, pair: GearPair, s: np.ndarray) -> np.ndarray:
        """The break edge met by the mating flank: the fracture leaves no sharp involute
        corner, so the intact flank just below the break line falls short of the
        involute by ``edge_relief x height`` at the line, tapering linearly to nothing
        ``edge_width`` (fraction of the active profile) further down. The pair takes
        over its load abruptly and short of its place when the contact re-enters at the
        break line."""
        s = np.asarray(s, dtype=float)
        if self.is_healthy or self.edge_relief <= 0:
            return np.zeros_like(s)
        sc = self.cut_fraction(pair)
        ramp = np.clip(1.0 - (sc - s) / self.edge_width, 0.0, 1.0)
        return np.where(s <= sc, -self.edge_relief * self.height * ramp, 0.0)


@dataclass(frozen=True)
class ToothBreakage(SizedToothFault):
    """Tooth breakage: a broken tip with a chipped corner (module docstring for the
    geometry).

    Parameters
    ----------
    size : float
        y in [0, 1]: the tip loss as a fraction of the tooth height above the lowest
        contact point, over the face share ``face_share`` (default y: the break grows
        across the face as it deepens); 1 = the whole tooth lost down to the lowest
        contact point over the whole face (acts as a missing tooth).
    corner : float
        c >= 0: the chipped corner at face position 0 goes ``1 + c`` times deeper than the
        tip loss, tapering linearly across the face (default 2/3: the lab model's example,
        a 3 mm tip loss and a 5 mm corner chip, is ``size = 3 mm / H = 0.61``,
        ``face_share=1``).
    edge_relief : float
        Shortfall of the flank at the break edge per lost height (default 0.01: 30 um
        for a 3 mm tip loss), :meth:`_TipLoss.displacement`.
    edge_width : float
        Length of the edge's relief along the active profile, (0, 1].
    face_share : float or None
        Share of the face width (from the chipped end, zeta = 0) that the break spans,
        (0, 1]; None (default): ``size``. ``face_share=1`` with ``size = 3 mm / H`` is the
        lab model's example (a tip loss over the whole face).
    n_bands : int
        Face bands the break is resolved into (piecewise-constant height).
    tooth : int
        Faulty gear tooth.
    """

    corner: float = 2.0 / 3.0
    corner_width: float = 0.8
    edge_relief: float = 0.01
    edge_width: float = 0.1
    n_bands: int = 16
    face_share: float | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.face_share is not None:
            check_in_range(self.face_share, "face_share", 0.0, 1.0, low_inclusive=False)
        check_in_range(self.corner, "corner", 0.0, 100.0)
        check_in_range(self.corner_width, "corner_width", 0.0, 1.0, low_inclusive=False)
        check_in_range(self.edge_relief, "edge_relief", 0.0, 0.1)
        check_in_range(self.edge_width, "edge_width", 0.0, 1.0, low_inclusive=False)
        check_int(self.n_bands, "n_bands", minimum=1, maximum=256)

    @property
    def share(self) -> float:
        """Face share spanned by the break (``face_share``, default ``size``)."""
        return self.size if self.face_share is None else float(self.face_share)

    def lost_height(self, pair: GearPair, zeta) -> np.ndarray:
        """Lost height (m, from the tip) at face positions ``zeta`` (0 ... 1)."""
        zeta = np.asarray(zeta, dtype=float)
        chip = (1 + self.corner) * np.clip(1 - zeta / self.corner_width, 0.0, None)
        h = self.active_height(pair) * np.clip(
            self.size * np.maximum(1.0, chip) * self.line_shape(zeta), 0.0, 1.0)
        return np.where(zeta <= self.share + 1e-12, h, 0.0)

    def line_shape(self, zeta) -> np.ndarray | float:
        """Factor on the lost height along the break line at face positions ``zeta``
        (1: a straight break line; a rig's irregular break overrides it)."""
        return 1.0

    @staticmethod
    def active_height(pair: GearPair) -> float:
        """H: height (m) of the gear tooth above its lowest contact point."""
        z = pair.z_gear
        _, (l_lo, _) = pair.roll_limits
        return pair.tip_radius(z) - math.hypot(pair.base_radius(z), l_lo)

    def face_bands(self, pair: GearPair) -> tuple:
        if self.is_healthy:
            return ()
        # the broken face share, resolved into n_bands bands
        edges = np.linspace(0.0, self.share, self.n_bands + 1)
        # band height: the exact mean of the lost height over the band
        fine = np.linspace(0.0, self.share, 32 * self.n_bands + 1)
        h = self.lost_height(pair, 0.5 * (fine[1:] + fine[:-1])).reshape(self.n_bands, 32)
        out = []
        for z0, z1, hb in zip(edges[:-1], edges[1:], h.mean(axis=1)):
            if hb > 0:
                out.append((float(z0), float(z1), _TipLoss(
                    tooth=self.tooth, height=float(hb), edge_relief=self.edge_relief,
                    edge_width=self.edge_width)))
        return tuple(out)


@dataclass(frozen=True)
class _DamagedBand(_ContactLoss):
    """The transverse section of surface destruction: a band [s0, s1] of the active
    profile, ``depth`` deep, bearing ``1 - contact_loss`` of its contact line."""

    s0: float = 0.0
    s1: float = 0.0
    depth: float = 0.0
    contact_loss: float = 0.0
    ramp: float = 0.03
    pit: float = 0.05

    @property
    def is_healthy(self) -> bool:
        return self.s1 <= self.s0

    def _inside(self, s):
        """Smooth 0 ... 1 indicator of the band (linear ramps ``ramp`` wide inside)."""
        s = np.asarray(s, dtype=float)
        w = min(self.ramp, 0.5 * (self.s1 - self.s0))
        if w <= 0:
            return np.zeros_like(s)
        return np.clip(np.minimum(s - self.s0, self.s1 - s) / w, 0.0, 1.0)

    def stiffness_scale(self, pair: GearPair, s: np.ndarray) -> np.ndarray:
        return 1.0 - self.contact_loss * self._inside(s)

    def displacement(self, pair: GearPair, s: np.ndarray) -> np.ndarray:
        # pits: craters ``pit`` wide (fraction of the active profile), ``depth`` deep
        s = np.asarray(s, dtype=float)
        pits = 0.5 - 0.5 * np.cos(2 * np.pi * (s - self.s0) / self.pit)
        return -self.depth * self._inside(s) * pits


@dataclass(frozen=True)
class ToothDestruction(SizedToothFault):
    """Surface destruction (pitting, wear) in a band along the profile, whole face.

    Parameters
    ----------
    size : float
        y in [0, 1]: the band's width along the active profile / the active profile.
    center : float
        Band centre along the active profile (0 = lowest contact point, 1 = tip); the band
        is kept inside the profile (shifted when it would leave it).
    depth : float
        Crater depth at size 1, m (default 30 um); a size-y band is ``y depth`` deep.
    contact_loss : float
        Share of the contact line lost in the band, [0, 1).
    tooth : int
        Faulty gear tooth.
    """

    center: float = 0.5
    depth: float = 30e-6
    contact_loss: float = 0.5

    def __post_init__(self) -> None:
        super().__post_init__()
        check_in_range(self.center, "center", 0.0, 1.0)
        check_in_range(self.depth, "depth", 0.0, 1e-3)
        check_in_range(self.contact_loss, "contact_loss", 0.0, 1.0, high_inclusive=False)

    @property
    def window(self) -> tuple[float, float]:
        """(start, end) of the band along the active profile."""
        lo = min(max(self.center - 0.5 * self.size, 0.0), 1.0 - self.size)
        return lo, lo + self.size

    def face_bands(self, pair: GearPair) -> tuple:
        if self.is_healthy:
            return ()
        s0, s1 = self.window
        return ((0.0, 1.0, _DamagedBand(tooth=self.tooth, s0=s0, s1=s1,
                                        depth=self.size * self.depth,
                                        contact_loss=self.contact_loss)),)


_CLASSES: dict[str, type[SizedToothFault]] = {
    c.__name__: c for c in (FullToothFaceFault, PartialFaceFault, ToothBreakage,
                            ToothDestruction)}


def fault_class(name: str) -> type[SizedToothFault]:
    """The class of fault type ``name`` (its record's ``class_``,
    :mod:`gearshot.fault_registry`)."""
    return _CLASSES[fault_type_record(name).class_]


#: name -> constructor ``f(size, **options)`` of the fault types (the classes'
#: :meth:`~gearshot.sim.faults.SizedToothFault.of_size`), in code order
#: (:data:`gearshot.fault_registry.FAULT_TYPE_RECORDS` holds each type's record).
FAULT_TYPES = {name: fault_class(name).of_size for name in FAULT_TYPE_RECORDS}

#: name -> version of the type's model (the records' ``version``): databases built with
#: an older model of a type are refused (``load_database``) instead of silently mixed with
#: new SAs.
FAULT_MODEL_VERSIONS = {name: r.version for name, r in FAULT_TYPE_RECORDS.items()}


def fault_of_type(name: str, size: float, **options) -> ToothFault:
    """A fault of type ``name`` (:data:`FAULT_TYPES`) and size ``size`` in [0, 1].

    Options go to the type's class (e.g. ``tooth``, ``center``, ``depth``); an FTFF's
    centre is moved so that the cut stays on the active profile
    (:meth:`FullToothFaceFault.of_size`).
    """
    check_fault_type(name)
    try:
        size = float(size)
    except (TypeError, ValueError):
        raise GearshotError(f"size must be a real number; got {size!r}") from None
    check_in_range(size, "size", 0.0, 1.0)
    try:
        return FAULT_TYPES[name](size, **options)
    except TypeError as exc:
        raise GearshotError(f"bad option for fault_type {name!r}: {exc}") from None
