"""The spur and helical gear-pair dynamic simulator and simulated SA databases.

Pieces (SI units; angles in rad; accelerations in g):

* :class:`GearPair` — frozen parameter set (``GearPair.paper()`` is the paper's pair).
* :func:`mesh_stiffness`, :func:`pair_stiffness` — potential-energy mesh stiffness
  (Hertz, bending, shear, axial, Sainsot fillet foundation).
* :class:`ToothFault` (extensible base), :class:`FullToothFaceFault` via ``Fault.ftff``;
  :class:`PartialFaceFault`, :class:`ToothBreakage`, :class:`ToothDestruction` and
  :func:`fault_of_type` (``simulate_sa(..., fault_type=NAME)``; the types' records, codes
  and versions in :mod:`gearshot.fault_registry`).
* :func:`draw_profile_errors` — DIN 3962 profile errors per tooth.
* :func:`simulate` — time signals with constant or time-varying speed and load;
  :func:`simulate_sa` — batched steady-state synchronous averages.
* :func:`build_database` / :func:`load_database` — resumable Zarr databases;
  :func:`repair_database` (``gearshot simulate --repair --store S``) restores a store's
  manifest from its blocks and rebuilds exactly its damaged or missing blocks.

Example
-------
>>> from gearshot.sim import GearPair, simulate_sa
>>> sa = simulate_sa(GearPair.paper(), speed=15, load=10, grade=7,
...                  fault_sizes=[0.0, 0.5], rng=0)
>>> sa.shape
(2, 2048)
"""

from ._db_repair import repair_database
from .database import build_database, default_database_path, load_database, pair_attrs
from .dynamics import DEFAULT_MIN_FS, SimulationResult, simulate, simulate_sa, system_matrices
from .fault_types import (
                          FAULT_TYPES,
                          PartialFaceFault,
                          ToothBreakage,
                          ToothDestruction,
                          fault_of_type,
)
from .faults import Fault, FullToothFaceFault, ToothFault
from .geometry import GearPair
from .profile_errors import DIN_PROFILE_TOLERANCES, ToothProfileErrors, draw_profile_errors
from .stiffness import contact_ratio, mesh_stiffness, pair_stiffness

__all__ = [
    "GearPair",
    "Fault",
    "FullToothFaceFault",
    "ToothFault",
    "PartialFaceFault",
    "ToothBreakage",
    "ToothDestruction",
    "FAULT_TYPES",
    "fault_of_type",
    "contact_ratio",
    "mesh_stiffness",
    "pair_stiffness",
    "DIN_PROFILE_TOLERANCES",
    "ToothProfileErrors",
    "draw_profile_errors",
    "DEFAULT_MIN_FS",
    "SimulationResult",
    "simulate",
    "simulate_sa",
    "system_matrices",
    "build_database",
    "load_database",
    "repair_database",
    "pair_attrs",
    "default_database_path",
]
