"""Recording files → synchronous-average segments."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .._errors import GearshotError
from ..paper import CYCLES_PER_SEGMENT, GEAR_TEETH, PINION_TEETH, SAMPLES_PER_CYCLE
from .input_health import check_input, check_segments
from .recording import Recording

__all__ = ["recording_segments"]


def _speed(rec: Recording) -> float:
    """The recording's mean shaft speed, NaN when it cannot be measured."""
    try:
        return float(rec.shaft_speed())
    except GearshotError:
        return float("nan")


def recording_segments(path: str | Path, *, gear_teeth: int = GEAR_TEETH,
                       pinion_teeth: int = PINION_TEETH,
                       cycles_per_segment: int | None = CYCLES_PER_SEGMENT,
                       samples_per_cycle: int = SAMPLES_PER_CYCLE,
                       long: bool = False, health: dict[str, Any] | None = None
                       ) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """SA segments (and optionally the angle-domain signal) of one recording file.

    ``health``, when given, receives the input checks
    (:mod:`gearshot.io.input_health`): ``"recording"`` (the raw samples') and
    ``"segments"`` (one per SA segment), ``"speed"``: the recording's mean shaft
    speed (:meth:`Recording.shaft_speed`; NaN when it cannot be measured), and
    ``"path"``: its transfer path's resonance pattern
    (:func:`gearshot.signal.path_pattern.path_pattern`).
    """
    from ..signal.path_pattern import path_pattern

    rec = Recording.read(path)
    sa = rec.to_sa_segments(gear_teeth=gear_teeth, pinion_teeth=pinion_teeth,
                            cycles_per_segment=cycles_per_segment,
                            samples_per_cycle=samples_per_cycle)
    if health is not None:
        health.update(recording=check_input(rec.acceleration, units=rec.units),
                      segments=check_segments(sa, units=rec.units), speed=_speed(rec),
                      path=path_pattern(rec.acceleration, rec.fs))
    if not long:
        return sa
    x = rec.angle_domain(gear_teeth=gear_teeth, pinion_teeth=pinion_teeth,
                         samples_per_cycle=samples_per_cycle)
    return sa, x
