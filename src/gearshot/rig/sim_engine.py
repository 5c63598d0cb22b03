"""The virtual rig's physics engine on top of the gear-pair simulator
(:func:`gearshot.sim.simulate`), which integrates the whole run with the time-varying
speed and load.

How the hidden reality reaches the simulator:

* masses, inertias, bearing stiffness, shaft stiffness (shear modulus), mesh stiffness
  (Young's modulus of the wheels) and modal damping of :meth:`GearPair.paper` are scaled by
  the reality's factors;
* the true DIN grade, with profile errors drawn from the reality's ``profile_seed`` on
  every run (the rig always runs the same wheels);
* the fault: the reality's centre and depth coefficient; its edge offsets widen/narrow and
  shift the cut, so the physical fault differs from the nominal label ``y``; the reality's
  ``fault_roughness`` makes the depth vary along the cut. The fault reaches the physics as
  an :class:`IrregularFaceFault` through ``simulate(faults=...)``;
* the other fault types (``fault_type``): their irregular physical fault
  (:func:`gearshot.rig.irregular.physical_fault_of_type`), from the same reality fields.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._validation import check_int
from ..fault_registry import check_fault_type
from .irregular import IrregularFaceFault, physical_fault_of_type
from .reality import RigReality

__all__ = ["SimulatorEngine", "perturbed_pair", "physical_fault"]


def perturbed_pair(pair, reality: RigReality | None):
    """``pair`` with the reality's mass/inertia/stiffness/damping factors applied."""
    if reality is None:
        return pair
    m1, m2 = pair.masses
    j1, j2 = pair.inertias
    g = (pair.shear_modulus_shaft if pair.shear_modulus_shaft is not None
         else pair.youngs_modulus / (2 * (1 + pair.poisson)))
    mp, mg = reality.mass_factor
    ip, ig = reality.inertia_factor
    return pair.replace(
        mass_pinion=m1 * mp, mass_gear=m2 * mg,
        inertia_pinion=j1 * ip, inertia_gear=j2 * ig,
        bearing_stiffness=pair.bearing_stiffness * reality.bearing_stiffness_factor,
        shear_modulus_shaft=g * reality.shaft_stiffness_factor,
        youngs_modulus=pair.youngs_modulus * reality.mesh_stiffness_factor,
        damping_ratio=min(pair.damping_ratio * reality.damping_factor, 0.5))


def physical_fault(size: float, reality: RigReality | None) -> tuple[float, float, float]:
    """(size, centre, depth) of the cut actually made for a fault labelled ``size``."""
    if reality is None or size <= 0:
        return float(size), 0.5, 0.5
    e0, e1 = reality.fault_edges
    lo = reality.fault_center - 0.5 * size * (1 + e0)
    hi = reality.fault_center + 0.5 * size * (1 + e1)
    lo, hi = max(lo, 0.0), min(hi, 1.0)
    return hi - lo, 0.5 * (lo + hi), reality.fault_depth


@dataclass(frozen=True)
class SimulatorEngine:
    """Physics engine for :class:`~gearshot.rig.VirtualRig` backed by the simulator.

    Parameters
    ----------
    pair : GearPair, optional
        Nominal gear pair (default :meth:`GearPair.paper`).
    nominal_grade : int
        DIN grade used when ``reality`` is None (the nominal model).
    fault_type : str
        The fault the rig grows (:data:`gearshot.fault_registry.FAULT_TYPE_NAMES`;
        default ``"ftff"``).
    """

    pair: object = field(default=None)
    nominal_grade: int = 7
    fault_type: str = "ftff"

    def __post_init__(self) -> None:
        check_int(self.nominal_grade, "nominal_grade", minimum=1, maximum=12)
        check_fault_type(self.fault_type)

    def __call__(self, *, motor_revs: np.ndarray, load_torque: np.ndarray, fs: float,
                 fault_size: float, reality: RigReality | None,
                 rng: np.random.Generator) -> np.ndarray:
        from ..sim import GearPair, simulate

        nominal = self.pair if self.pair is not None else GearPair.paper()
        pair = perturbed_pair(nominal, reality)
        revs = np.asarray(motor_revs, dtype=np.float64)
        speed = np.gradient(revs) * fs
        size, center, depth = physical_fault(fault_size, reality)
        if reality is None:
            grade, prng = self.nominal_grade, rng
        else:
            grade, prng = reality.grade, np.random.default_rng(reality.profile_seed)
        fault: dict[str, Any]
        if self.fault_type != "ftff":
            fault = (dict(faults=[physical_fault_of_type(self.fault_type, fault_size,
                                                         reality)])
                     if fault_size > 0 else dict(fault_sizes=[0.0]))
        elif reality is not None and size > 0 and any(reality.fault_roughness):
            fault = dict(faults=[IrregularFaceFault(size=size, center=center, depth=depth,
                                                    roughness=reality.fault_roughness)])
        else:
            fault = dict(fault_sizes=[size], fault_center=center, fault_depth=depth)
        res = simulate(pair, speed=speed, load=np.asarray(load_torque, dtype=np.float64),
                       grade=grade, fs=fs, duration=revs.size / fs, rng=prng, **fault)
        return res.acceleration[0]
