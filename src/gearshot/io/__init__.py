"""Reading and writing real recordings.

``Recording``
    Acceleration + tacho + metadata; reads HDF5 (native), MATLAB v5/v7.3, WAV and CSV;
    writes all of them atomically; turns the tacho into gear-revolution SA segments.
``read_campaign``
    The index of a folder of recordings (one row per file: speed, load, fault size).
``recording_segments``
    One recording file → its SA segments (and optionally its angle-domain signal).
``check_input`` / ``check_segments``
    Input health before any estimate (:mod:`gearshot.io.input_health`): non-numeric,
    implausible level, dead, constant, clipped; an :class:`InputCheck` each.
"""

from __future__ import annotations

from .campaign import INDEX_COLUMNS, INDEX_NAME, read_campaign
from .input_health import InputCheck, check_input, check_segments
from .recording import FORMATS, Recording
from .segments import recording_segments

__all__ = ["Recording", "FORMATS", "read_campaign", "INDEX_NAME", "INDEX_COLUMNS",
           "recording_segments", "check_input", "check_segments", "InputCheck"]
