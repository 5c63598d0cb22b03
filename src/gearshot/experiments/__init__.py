"""Builders of the paper's datasets and the experiments run on them."""

from .rig import RigDataset, rig_dataset
from .runner import (
    check_selection_tf,
    evaluate_variants,
    rig_experiment,
    simulated_experiment,
    summarize,
)
from .simulated import SimulatedDataset, simulated_dataset
from .variants import RIG_VARIANTS, SIMULATED_VARIANTS, VARIANTS, variant_params

__all__ = ["evaluate_variants", "rig_experiment", "simulated_experiment", "summarize",
           "RigDataset", "rig_dataset", "SimulatedDataset", "simulated_dataset", "VARIANTS",
           "SIMULATED_VARIANTS", "RIG_VARIANTS", "variant_params", "check_selection_tf"]
