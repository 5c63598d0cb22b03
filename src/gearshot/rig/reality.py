"""The virtual rig's hidden "reality": what differs from the nominal training model.

A :class:`RigReality` is drawn once per rig from its seed. The estimator never sees it;
tests and benchmarks may :meth:`VirtualRig.reveal` it to check the gap is real.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from .._errors import GearshotError
from .._validation import ATTENUATION_DB_RANGE, check_in_range, check_int
from ..paper import GEAR_TEETH, PINION_TEETH

__all__ = ["RigReality", "draw_reality", "override_reality"]


@dataclass(frozen=True)
class RigReality:
    """Hidden parameters of one virtual rig (SI units; factors multiply nominal values).

    Attributes
    ----------
    grade : int
        True DIN 3962 profile-quality grade of both wheels (1 ... 12).
    profile_seed : int
        Seed of the wheels' tooth-profile errors (fixed for the rig: every recording
        runs the same gears).
    mass_factor, inertia_factor : tuple of float
        (pinion, gear) wheel mass / polar inertia factors, 0.7-1.3 (10-30 % off).
    bearing_stiffness_factor, shaft_stiffness_factor, mesh_stiffness_factor : float
        Stiffness factors (10-30 % off nominal, either sign).
    damping_factor : float
        Modal-damping factor (10-30 % off nominal).
    fault_center : float
        Centre of the fault cut on the active profile (fraction, 0 = root, 1 = tip).
    fault_depth : float
        Mean depth coefficient of the cut (nominal model: 0.5).
    fault_edges : tuple of float
        Offsets of the cut's start and end, as fractions of the fault width.
    fault_roughness : tuple of float
        Relative amplitudes of the cosine terms (1, 2, 3 waves) by which the cut's depth
        varies along the profile: the fault is not a perfect arc.
    speed_drift : float
        Maximum slow speed drift, fraction of nominal (<= 0.01).
    speed_ripple : float
        Once-per-input-revolution speed ripple amplitude, fraction of nominal.
    load_ripple : float
        Once-per-output-revolution load ripple amplitude, fraction of nominal.
    motor_pole_pairs : int
        Pole pairs of the (induction) drive motor.
    motor_slip : float
        Its slip; electrical frequency = pole_pairs x speed / (1 - slip).
    motor_level, extra_level, impact_level : float
        RMS of motor harmonics / extra shaft / bearing-like impacts relative to the RMS of
        the gear vibration.
    extra_order : float
        Order (per input revolution) of an extra shaft; not an integer and not a gear order.
    impact_order : float
        Mean impacts per input revolution of the bearing-like defect (non-integer).
    impact_frequency : float
        Resonance rung by each impact, Hz.
    snr_db : float
        Sensor signal-to-noise ratio, dB (20-30).
    attenuation_db : float
        Overall attenuation of the transfer path, dB (10-30).
    tf_index : int
        Which TF of the bank forms the transfer path.
    tacho_jitter : float
        Standard deviation of the tacho pulse angle, revolutions.
    """

    grade: int
    profile_seed: int
    mass_factor: tuple[float, float]
    inertia_factor: tuple[float, float]
    bearing_stiffness_factor: float
    shaft_stiffness_factor: float
    mesh_stiffness_factor: float
    damping_factor: float
    fault_center: float
    fault_depth: float
    fault_edges: tuple[float, float]
    fault_roughness: tuple[float, float, float]
    speed_drift: float
    speed_ripple: float
    load_ripple: float
    motor_pole_pairs: int
    motor_slip: float
    motor_level: float
    extra_order: float
    extra_level: float
    impact_order: float
    impact_frequency: float
    impact_level: float
    snr_db: float
    attenuation_db: float
    tf_index: int
    tacho_jitter: float

    def as_dict(self) -> dict[str, Any]:
        """Plain dict (JSON-serializable)."""
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self).items()}


def _pair(values: Any) -> tuple[float, float]:
    a, b = values
    return float(a), float(b)


def _triple(values: Any) -> tuple[float, float, float]:
    a, b, c = values
    return float(a), float(b), float(c)


def _factor(rng: np.random.Generator, size: int | None = None):
    """A factor 10-30 % away from 1, random sign."""
    mag = rng.uniform(0.10, 0.30, size)
    sign = rng.choice([-1.0, 1.0], size)
    return 1.0 + sign * mag


def _non_integer_order(rng: np.random.Generator, low: float, high: float,
                       gear_ratio: float) -> float:
    """An order away from integers and from multiples of the gear's order ``gear_ratio``."""
    for _ in range(1000):
        r = float(rng.uniform(low, high))
        near_int = abs(r - round(r)) < 0.08
        g = r / gear_ratio
        near_gear = abs(g - round(g)) * gear_ratio < 0.08
        if not (near_int or near_gear):
            return r
    raise GearshotError("could not draw a non-integer order")  # pragma: no cover


def draw_reality(rng: np.random.Generator, *, n_tfs: int = 1,
                 gear_teeth: int = GEAR_TEETH, pinion_teeth: int = PINION_TEETH) -> RigReality:
    """Draw a rig's hidden reality from ``rng`` (ranges as in the issue)."""
    n_tfs = check_int(n_tfs, "n_tfs", minimum=1)
    ratio = pinion_teeth / gear_teeth  # gear revolutions per input revolution
    grade = int(rng.integers(4, 9))  # 4 ... 8: around the nominal DIN 7
    return RigReality(
        grade=grade,
        profile_seed=int(rng.integers(2**31)),
        mass_factor=_pair(_factor(rng, 2)),
        inertia_factor=_pair(_factor(rng, 2)),
        bearing_stiffness_factor=float(_factor(rng)),
        shaft_stiffness_factor=float(_factor(rng)),
        mesh_stiffness_factor=float(_factor(rng)),
        damping_factor=float(_factor(rng)),
        fault_center=float(rng.uniform(0.42, 0.58)),
        fault_depth=float(rng.uniform(0.35, 0.65)),
        fault_edges=_pair(rng.uniform(-0.12, 0.12, 2)),
        fault_roughness=_triple(rng.uniform(-0.25, 0.25, 3)),
        speed_drift=float(rng.uniform(0.005, 0.01)),
        speed_ripple=float(rng.uniform(0.002, 0.008)),
        load_ripple=float(rng.uniform(0.02, 0.08)),
        motor_pole_pairs=int(rng.integers(1, 3)),
        motor_slip=float(rng.uniform(0.02, 0.05)),
        motor_level=float(rng.uniform(0.05, 0.15)),
        extra_order=_non_integer_order(rng, 1.2, 3.8, ratio),
        extra_level=float(rng.uniform(0.05, 0.15)),
        impact_order=_non_integer_order(rng, 3.1, 5.9, ratio),
        impact_frequency=float(rng.uniform(3000.0, 8000.0)),
        impact_level=float(rng.uniform(0.05, 0.2)),
        snr_db=float(rng.uniform(20.0, 30.0)),
        attenuation_db=float(rng.uniform(10.0, 30.0)),
        tf_index=int(rng.integers(n_tfs)),
        tacho_jitter=float(rng.uniform(1e-4, 5e-4)),
    )


_RANGES = {  # field -> (low, high) accepted by with_reality / reality_overrides
    "snr_db": (0.0, 200.0), "attenuation_db": ATTENUATION_DB_RANGE, "speed_drift": (0.0, 0.05),
    "speed_ripple": (0.0, 0.05), "load_ripple": (0.0, 0.5), "motor_level": (0.0, 10.0),
    "extra_level": (0.0, 10.0), "impact_level": (0.0, 10.0), "tacho_jitter": (0.0, 0.01),
    "fault_center": (0.0, 1.0), "fault_depth": (0.01, 1.0), "damping_factor": (0.1, 10.0),
    "bearing_stiffness_factor": (0.1, 10.0), "shaft_stiffness_factor": (0.1, 10.0),
    "mesh_stiffness_factor": (0.1, 10.0), "motor_slip": (0.0, 0.5),
    "impact_frequency": (1.0, 1e6), "extra_order": (0.01, 1000.0),
    "impact_order": (0.01, 1000.0),
}


def override_reality(reality: RigReality, changes: Mapping[str, Any], *,
                     n_tfs: int) -> RigReality:
    """``reality`` with validated field changes (``VirtualRig.with_reality``,
    ``reality_overrides``); ``n_tfs``: the size of the rig's TF bank."""
    fields = set(reality.as_dict())
    out: dict[str, Any] = {}
    for key, value in changes.items():
        if key not in fields:
            raise GearshotError(f"reality has no field {key!r}; fields: {sorted(fields)}")
        if key == "grade":
            out[key] = check_int(value, "grade", minimum=1, maximum=12)
        elif key == "tf_index":
            out[key] = check_int(value, "tf_index", minimum=0, maximum=n_tfs - 1)
        elif key in ("profile_seed", "motor_pole_pairs"):
            out[key] = check_int(value, key, minimum=0 if key == "profile_seed" else 1)
        elif key in _RANGES:
            out[key] = check_in_range(value, key, *_RANGES[key])
        else:  # tuples: mass/inertia factors, fault edges/roughness
            arr = tuple(float(v) for v in value)
            if len(arr) != len(getattr(reality, key)):
                raise GearshotError(f"{key} must hold {len(getattr(reality, key))} numbers; "
                                    f"got {value!r}")
            out[key] = arr
    return dataclasses.replace(reality, **out)
