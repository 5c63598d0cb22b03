"""The virtual test rig: recordings from a seeded hidden reality.

``VirtualRig``
    Recordings from a seeded hidden reality (grade, perturbed dynamics, irregular fault of
    any fault type (``fault_type=``),
    varying speed and load, interference, transfer path, noise, tacho jitter);
    ``campaign`` writes one Table-1 condition with an index (read it with
    :func:`gearshot.io.read_campaign`).

Reading recordings (real or virtual) lives in :mod:`gearshot.io`; the transfer path is a
:class:`gearshot.transfer.TransferFunction`.
"""

from __future__ import annotations

from .irregular import (
    IrregularBreakage,
    IrregularDestruction,
    IrregularFaceFault,
    IrregularPartialFace,
)
from .path import synthetic_path_tfs
from .reality import RigReality, draw_reality
from .sim_engine import SimulatorEngine
from .surrogate import SurrogateEngine
from .tacho import tacho_signal
from .virtual import VirtualRig

__all__ = ["VirtualRig", "RigReality", "draw_reality", "IrregularFaceFault",
           "IrregularPartialFace", "IrregularBreakage", "IrregularDestruction",
           "SimulatorEngine", "SurrogateEngine", "synthetic_path_tfs", "tacho_signal"]
