"""The one-fault-shot estimator and its eight steps."""

from . import steps
from ._model import OneFaultShotEstimator
from .persistence import load_estimator, save_estimator
from .steps import (
    centred_features,
    estimate_tf,
    fit_knn,
    normalize_rms,
    propagate_simulated,
    select_features,
    suppress_harmonics_simulated,
    suppress_harmonics_target,
    tune_grade,
)
from .zero_shot import healthy_signature, match_grade, signature_weights

__all__ = [
    "OneFaultShotEstimator",
    "steps",
    "select_features",
    "tune_grade",
    "estimate_tf",
    "propagate_simulated",
    "normalize_rms",
    "suppress_harmonics_simulated",
    "suppress_harmonics_target",
    "centred_features",
    "fit_knn",
    "healthy_signature",
    "match_grade",
    "signature_weights",
    "save_estimator",
    "load_estimator",
]
