"""gearshot: one-fault-shot estimation of gear tooth-fault size from vibration.

Implements the method of Matania et al., *Advanced Engineering Informatics* 56 (2023)
101945: train on a physics simulator, close the sim-to-real gap with one faulty example,
and remove transfer-path effects.

Subpackages (imported on first use):

``gearshot.signal``
    Pure DSP functions (angular resampling, synchronous average, orders, spectra, ...).
``gearshot.features``
    Condition indicators and their registry.
``gearshot.transfer``
    Transfer-function estimation, I/O and propagation.
``gearshot.sim``
    The gear-pair dynamic simulator and simulated databases.
``gearshot.io``
    Reading real recordings (and campaign folders) into SA segments.
``gearshot.rig``
    The virtual test rig.
``gearshot.estimator``
    The one-fault-shot estimator and its eight steps.
``gearshot.experiments``
    The paper's datasets and sweeps.
``gearshot.plotting``
    Figures.
``gearshot.app``
    The ``gearshot`` command line, the demo and report writing.
``gearshot.paper``
    The paper's constants (gear pair 17/38, Table-1 fault sizes, speeds, loads).

:class:`gearshot.Machine` describes a real gearbox (gear train, tacho, sensors, file
layout, monitored gear) and is read from TOML.
"""

from __future__ import annotations

import importlib
from importlib.metadata import PackageNotFoundError, version

from ._errors import GearshotError
from ._paths import data_home
from .machine import Machine

try:
    __version__ = version("gearshot")
except PackageNotFoundError:  # running from a source tree
    __version__ = "0.0.0+unknown"

_SUBMODULES = {"signal", "features", "transfer", "sim", "io", "rig", "estimator",
               "experiments", "plotting", "app", "paper"}

__all__ = ["GearshotError", "Machine", "data_home", "__version__", *sorted(_SUBMODULES)]


def __getattr__(name: str):
    if name in _SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module 'gearshot' has no attribute {name!r}")
