"""Recordings and the virtual test rig.

``Recording``
    Acceleration + tacho + metadata; reads HDF5 (native), MATLAB v5/v7.3, WAV and CSV;
    writes all of them atomically; turns the tacho into gear-revolution SA segments.
``VirtualRig``
    Recordings from a seeded hidden reality (grade, perturbed dynamics, irregular fault,
    varying speed and load, interference, transfer path, noise, tacho jitter);
    ``campaign`` writes one Table-1 condition with an index; ``read_campaign`` reads it.
"""

from __future__ import annotations

from .angle import check_pulse_train, gear_cycle_times
from .path import PathTF, synthetic_path_tfs
from .reality import RigReality, draw_reality
from .recording import FORMATS, Recording
from .sim_engine import IrregularFaceFault, SimulatorEngine
from .surrogate import SurrogateEngine
from .tacho import tacho_signal
from .virtual import INDEX_COLUMNS, INDEX_NAME, VirtualRig, read_campaign

__all__ = ["Recording", "FORMATS", "gear_cycle_times", "check_pulse_train", "tacho_signal",
           "VirtualRig", "read_campaign", "INDEX_NAME", "INDEX_COLUMNS", "RigReality",
           "draw_reality", "IrregularFaceFault", "SimulatorEngine", "SurrogateEngine",
           "PathTF", "synthetic_path_tfs"]
