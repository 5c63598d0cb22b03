"""The spur-gear dynamic simulator and simulated databases."""
from .geometry import GearPair
from .faults import Fault, FullToothFaceFault, ToothFault
from .stiffness import contact_ratio, mesh_stiffness, pair_stiffness

__all__ = ["GearPair", "Fault", "FullToothFaceFault", "ToothFault", "contact_ratio",
           "mesh_stiffness", "pair_stiffness"]
