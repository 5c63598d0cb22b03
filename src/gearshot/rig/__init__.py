"""Recordings and the virtual test rig.

``Recording``
    Acceleration + tacho + metadata; reads HDF5 (native), MATLAB v5/v7.3, WAV and CSV;
    writes all of them atomically; turns the tacho into gear-revolution SA segments.
"""

from __future__ import annotations

from .angle import check_pulse_train, gear_cycle_times
from .tacho import tacho_signal
from .recording import FORMATS, Recording

__all__ = ["Recording", "FORMATS", "gear_cycle_times", "check_pulse_train", "tacho_signal"]
