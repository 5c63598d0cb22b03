"""The virtual rig's physical faults of every fault type: irregular, and not the label.

The hidden :class:`~gearshot.rig.RigReality` holds one set of fault fields; each fault type
reads them as follows (``y`` the nominal label, e0/e1 = ``fault_edges``, r =
``fault_roughness``, the relative amplitudes of ``cos(k pi x)``, k = 1, 2, 3, over the
fault's extent x = 0 ... 1):

=================  ===========================================================================
type               the fault actually grown for a label y
=================  ===========================================================================
``"ftff"``         the arc cut of width ``y (1 + (e0 + e1) / 2)`` around ``fault_center``,
                   ``fault_depth`` deep, its depth varying along the profile by r
                   (:class:`~gearshot.rig.IrregularFaceFault`,
                   :func:`~gearshot.rig.sim_engine.physical_fault`).
``"partial_face"`` a band ``y (1 + (e0 + e1) / 2)`` of the face wide, starting ``|e0|`` into the
                   face; its transverse cut centred at ``fault_center`` (kept on the
                   profile), ``fault_depth`` deep, its depth varying along the profile by r
                   (:class:`IrregularPartialFace`).
``"breakage"``     the break of size ``y (1 + (e0 + e1) / 2)`` (clipped to 1), corner
                   ``(2/3) fault_depth / 0.5`` deep, its break line's height varying across
                   the broken face share by r (:class:`IrregularBreakage`).
``"destruction"``  a band ``y (1 + (e0 + e1) / 2)`` of the profile wide around
                   ``fault_center``, pits ``30 um fault_depth / 0.5`` deep at size 1, their
                   depth varying along the band by r (:class:`IrregularDestruction`).
=================  ===========================================================================

No random number is drawn for this: a rig's reality (and every FTFF recording) is the
same as before fault types existed.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from .._errors import GearshotError
from ..sim.fault_types import (
    PartialFaceFault,
    ToothBreakage,
    ToothDestruction,
    _DamagedBand,
    check_fault_type,
    fault_of_type,
)
from ..sim.faults import FullToothFaceFault, ToothFault
from .reality import RigReality

__all__ = ["IrregularFaceFault", "IrregularPartialFace", "IrregularBreakage",
           "IrregularDestruction", "physical_fault_of_type"]


@dataclass(frozen=True)
class IrregularFaceFault(FullToothFaceFault):
    """A full tooth face fault whose depth varies along the profile: the arc-shaped cut of
    :class:`~gearshot.sim.FullToothFaceFault` scaled by
    ``1 + sum_k roughness[k] cos((k + 1) pi x)``, x = 0 ... 1 across the cut, in both the
    section loss (stiffness) and the displacement excitation.

    Parameters
    ----------
    roughness : tuple of float
        Relative amplitudes; their absolute sum must stay below 1 (the cut stays a cut).
    """

    roughness: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "roughness", check_roughness(self.roughness))

    def depth_profile(self, s: np.ndarray) -> np.ndarray:
        """Depth factor at roll fractions ``s`` (:func:`shape_factor` across the cut; its
        edge values beyond it)."""
        s = np.asarray(s, dtype=float)
        s0, s1 = self.window
        if s1 <= s0:
            return np.ones_like(s)
        return shape_factor((s - s0) / (s1 - s0), self.roughness)

    def section_loss(self, pair, x: np.ndarray) -> np.ndarray:
        base = super().section_loss(pair, x)
        if self.is_healthy:
            return base
        (xa, _), (xb, _) = self._edges(pair)
        s0, s1 = self.window
        s = s0 + (np.asarray(x, dtype=float) - xa) / (xb - xa) * (s1 - s0)  # ~linear map
        return base * self.depth_profile(s)

    def displacement(self, pair, s: np.ndarray) -> np.ndarray:
        return super().displacement(pair, s) * self.depth_profile(s)


def check_roughness(roughness) -> tuple[float, ...]:
    """Validate relative amplitudes: finite, absolute sum < 1 (the shape keeps its sign)."""
    try:
        rough = tuple(float(r) for r in roughness)
    except (TypeError, ValueError):
        raise GearshotError(f"roughness must be a sequence of numbers; got "
                            f"{roughness!r}") from None
    if not all(np.isfinite(rough)) or sum(abs(r) for r in rough) >= 1.0:
        raise GearshotError(f"roughness must be finite with absolute sum < 1; got "
                            f"{roughness!r}")
    return rough


def shape_factor(x, roughness) -> np.ndarray:
    """``1 + sum_k roughness[k] cos((k + 1) pi x)`` at ``x`` (clipped to 0 ... 1)."""
    x = np.clip(np.asarray(x, dtype=float), 0.0, 1.0)
    out = np.ones_like(x)
    for k, r in enumerate(roughness):
        out = out + r * np.cos((k + 1) * np.pi * x)
    return out


@dataclass(frozen=True)
class IrregularPartialFace(PartialFaceFault):
    """A partial face fault whose transverse cut's depth varies along the profile
    (``roughness``, as :class:`~gearshot.rig.IrregularFaceFault`)."""

    roughness: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "roughness", check_roughness(self.roughness))
        super().__post_init__()

    @property
    def transverse(self) -> FullToothFaceFault:
        if not self.roughness:     # the nominal cut (and its batch tables, bit for bit)
            return super().transverse
        return IrregularFaceFault(tooth=self.tooth, size=self.profile_size,
                                  center=self.center, depth=self.depth,
                                  roughness=self.roughness)


@dataclass(frozen=True)
class IrregularBreakage(ToothBreakage):
    """A tooth breakage whose break line is not straight: the lost height varies across the
    broken face share by the factor :func:`shape_factor` (x = zeta / face share)."""

    roughness: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "roughness", check_roughness(self.roughness))
        super().__post_init__()

    def line_shape(self, zeta) -> np.ndarray:
        zeta = np.asarray(zeta, dtype=float)
        share = self.share
        return shape_factor(zeta / share if share > 0 else zeta, self.roughness)


@dataclass(frozen=True)
class _IrregularBand(_DamagedBand):
    roughness: tuple[float, ...] = ()

    def displacement(self, pair, s: np.ndarray) -> np.ndarray:
        s = np.asarray(s, dtype=float)
        x = (s - self.s0) / max(self.s1 - self.s0, 1e-12)
        return super().displacement(pair, s) * shape_factor(x, self.roughness)


@dataclass(frozen=True)
class IrregularDestruction(ToothDestruction):
    """Surface destruction whose pits' depth varies along the band (:func:`shape_factor`,
    x = 0 ... 1 across the band)."""

    roughness: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "roughness", check_roughness(self.roughness))
        super().__post_init__()

    def face_bands(self, pair) -> tuple:
        out = []
        for z0, z1, band in super().face_bands(pair):
            kw = {f.name: getattr(band, f.name) for f in dataclasses.fields(band)}
            out.append((z0, z1, _IrregularBand(**kw, roughness=self.roughness)))
        return tuple(out)


def physical_fault_of_type(fault_type: str, size: float,
                           reality: RigReality | None) -> ToothFault:
    """The fault actually grown on the rig for a label ``size`` of ``fault_type`` other
    than ``"ftff"`` (module docstring); the nominal fault when ``reality`` is None."""
    fault_type = check_fault_type(fault_type)
    if fault_type == "ftff":
        raise GearshotError("physical_fault_of_type covers the fault types other than "
                            "'ftff' (see sim_engine.physical_fault)")
    if reality is None or size <= 0:
        return fault_of_type(fault_type, size)
    e0, e1 = reality.fault_edges
    y = float(np.clip(size * (1 + 0.5 * (e0 + e1)), 0.0, 1.0))
    rough = reality.fault_roughness
    if fault_type == "partial_face":
        center = min(max(reality.fault_center, 0.3), 0.7)   # the 0.6-wide cut stays on
        return IrregularPartialFace(size=y, face_start=min(abs(e0), 1.0 - y), center=center,
                                    depth=reality.fault_depth, roughness=rough)
    if fault_type == "breakage":
        return IrregularBreakage(size=y, corner=(2 / 3) * reality.fault_depth / 0.5,
                                 roughness=rough)
    return IrregularDestruction(size=y, center=reality.fault_center,
                                depth=30e-6 * reality.fault_depth / 0.5, roughness=rough)
