"""The one-fault-shot estimator and its eight steps.

=============================  ======================================================
``steps``                      the paper's steps 1–8, in order, one function each
``uncertainty``                grade weights and prediction intervals (not paper steps)
``zero_shot``                  grade choice from healthy data alone
``comparability``              does a segment look like the fitted machine (issue #19)
``OneFaultShotEstimator``      the steps as a scikit-learn regressor
``EstimatorOptions``            its research settings (one constructor parameter)
``save_estimator`` / ``load``  persistence with version metadata
=============================  ======================================================
"""

from .._errors import NotFittedError
from . import comparability, steps, uncertainty
from ._model import STEP_SEEDS, OneFaultShotEstimator, default_selection_tf
from ._params import check_estimator_params
from .calibration import CalibrationOptions
from .comparability import Comparability, ComparabilityReference, harmonic_profile
from .detection import DETECTION_CONFIDENCE, below_detection_limit
from .options import EstimatorOptions
from .persistence import load_estimator, save_estimator
from .steps import (
    centred_features,
    estimate_tf,
    fit_knn,
    normalize_rms,
    propagate_simulated,
    select_features,
    simulated_features,
    suppress_harmonics_simulated,
    suppress_harmonics_target,
    tune_grade,
)
from .uncertainty import conformal_quantile, grade_weights, mixture_interval, prune_weights
from .zero_shot import healthy_signature, match_grade, signature_weights

__all__ = [
    "OneFaultShotEstimator",
    "EstimatorOptions",
    "CalibrationOptions",
    "NotFittedError",
    "STEP_SEEDS",
    "default_selection_tf",
    "steps",
    "uncertainty",
    "comparability",
    "Comparability",
    "ComparabilityReference",
    "harmonic_profile",
    "select_features",
    "tune_grade",
    "estimate_tf",
    "propagate_simulated",
    "normalize_rms",
    "suppress_harmonics_simulated",
    "suppress_harmonics_target",
    "centred_features",
    "simulated_features",
    "fit_knn",
    "grade_weights",
    "prune_weights",
    "conformal_quantile",
    "mixture_interval",
    "healthy_signature",
    "match_grade",
    "signature_weights",
    "save_estimator",
    "load_estimator",
    "check_estimator_params",
    "below_detection_limit",
    "DETECTION_CONFIDENCE",
]
