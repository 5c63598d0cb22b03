"""The spur-gear dynamic simulator and simulated databases."""
from .database import build_database, default_database_path, load_database
from .dynamics import SimulationResult, simulate, simulate_sa, system_matrices
from .faults import Fault, FullToothFaceFault, ToothFault
from .geometry import GearPair
from .profile_errors import DIN_PROFILE_TOLERANCES, ToothProfileErrors, draw_profile_errors
from .stiffness import contact_ratio, mesh_stiffness, pair_stiffness

__all__ = ["GearPair", "Fault", "FullToothFaceFault", "ToothFault", "contact_ratio",
           "mesh_stiffness", "pair_stiffness", "DIN_PROFILE_TOLERANCES", "ToothProfileErrors",
           "draw_profile_errors", "SimulationResult", "simulate", "simulate_sa",
           "system_matrices", "build_database", "load_database", "default_database_path"]
