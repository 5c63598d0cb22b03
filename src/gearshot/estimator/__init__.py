"""The one-fault-shot estimator and its eight steps.

=============================  ======================================================
``steps``                      the paper's steps 1–8, in order, one function each
``uncertainty``                grade weights and prediction intervals (not paper steps)
``zero_shot``                  grade choice from healthy data alone
``comparability``              is a segment in the fitted machine's distribution (#19, #29)
``regular_part``               the regular part's description that comparability tests
``fit_check``                  the fit's own hold-outs read back: its verdict (issue #29)
``OneFaultShotEstimator``      the steps as a scikit-learn regressor
``EstimatorOptions``            its research settings (one constructor parameter)
``save_estimator`` / ``load``  persistence with version metadata
=============================  ======================================================
"""

from .._errors import NotFittedError
from . import comparability, fit_check, steps, uncertainty
from ._model import STEP_SEEDS, OneFaultShotEstimator, default_selection_tf
from ._params import check_estimator_params
from .calibration import CalibrationOptions
from .comparability import Comparability, ComparabilityReference, harmonic_profile
from .detection import DETECTION_CONFIDENCE, below_detection_limit
from .fit_check import FitCheck, check_fit, trusted_column
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
from .uncertainty import (
    conformal_quantile,
    grade_weights,
    holdout_interval,
    mixture_interval,
    prune_weights,
)
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
    "fit_check",
    "FitCheck",
    "check_fit",
    "trusted_column",
    "holdout_interval",
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
