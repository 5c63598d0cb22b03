"""Builders of the paper's datasets and the experiments run on them."""

from .simulated import SimulatedDataset, simulated_dataset
from .variants import RIG_VARIANTS, SIMULATED_VARIANTS, VARIANTS, variant_params

__all__ = ["SimulatedDataset", "simulated_dataset", "VARIANTS", "SIMULATED_VARIANTS",
           "RIG_VARIANTS", "variant_params"]
