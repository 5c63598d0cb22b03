"""Figures (matplotlib): the paper's figures, diagnostics and transfer-function plots.

Every function takes ``ax=None`` / ``axes=None`` (a new figure is made when omitted) and
returns what it drew. Nothing here selects a matplotlib backend: that is the
application's choice (the ``gearshot`` command line uses the non-interactive Agg).
"""

from __future__ import annotations

from .fault_types import plot_fault_signatures
from .paper import (
    VARIANT_LABELS,
    plot_ablation,
    plot_calibration,
    plot_error_vs,
    plot_feature_invariance,
    plot_predicted_vs_true,
    plot_sa_and_difference,
    plot_spectrum_background,
    plot_tf_estimate,
    plot_tuning_curve,
    save_figure,
)
from .transfer import plot_transfer_function, plot_transfer_functions

__all__ = [
    "VARIANT_LABELS",
    "save_figure",
    "plot_sa_and_difference",
    "plot_spectrum_background",
    "plot_tf_estimate",
    "plot_tuning_curve",
    "plot_calibration",
    "plot_feature_invariance",
    "plot_predicted_vs_true",
    "plot_ablation",
    "plot_error_vs",
    "plot_transfer_function",
    "plot_transfer_functions",
    "plot_fault_signatures",
]
