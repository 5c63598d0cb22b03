"""Builders of the paper's datasets and the experiments run on them."""

from .rig import RigDataset, recording_segments, rig_dataset
from .simulated import SimulatedDataset, simulated_dataset
from .variants import RIG_VARIANTS, SIMULATED_VARIANTS, VARIANTS, variant_params

__all__ = ["RigDataset", "rig_dataset", "recording_segments", "SimulatedDataset", "simulated_dataset", "VARIANTS", "SIMULATED_VARIANTS",
           "RIG_VARIANTS", "variant_params"]
