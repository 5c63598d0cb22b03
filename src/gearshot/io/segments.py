"""Recording files → synchronous-average segments."""

from __future__ import annotations

import numpy as np

from .recording import Recording

__all__ = ["recording_segments"]


def recording_segments(path, *, gear_teeth=38, pinion_teeth=17, cycles_per_segment=50,
                       samples_per_cycle=2048,
                       long=False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """SA segments (and optionally the angle-domain signal) of one recording file."""
    rec = Recording.read(path)
    sa = rec.to_sa_segments(gear_teeth=gear_teeth, pinion_teeth=pinion_teeth,
                            cycles_per_segment=cycles_per_segment,
                            samples_per_cycle=samples_per_cycle)
    if not long:
        return sa
    x = rec.angle_domain(gear_teeth=gear_teeth, pinion_teeth=pinion_teeth,
                         samples_per_cycle=samples_per_cycle)
    return sa, x
