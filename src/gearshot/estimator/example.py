"""The one faulty example: which segment of its record a fit calibrates on
(:func:`typical_segment`), and how far it stands out from the machine's healthy segments
(:func:`example_contrast`; below 0 the fit check fails,
:mod:`~gearshot.estimator.fit_check`)."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .detection import DETECTION_CONFIDENCE

__all__ = ["MIN_CONTRAST_ROWS", "example_contrast", "typical_segment"]

#: Fewest healthy training rows :func:`example_contrast` compares the example with.
MIN_CONTRAST_ROWS = 5


def typical_segment(sa: ArrayLike) -> int:
    """Index of the segment of one record nearest (Euclidean) to the record's mean SA: the
    example a fit calibrates on. One segment carries its own noise into the calibration,
    and the record's other segments check it; the record's most typical segment is the
    one the others agree with best."""
    arr = np.atleast_2d(np.asarray(sa, dtype=float))
    return int(np.argmin(np.sum((arr - arr.mean(axis=0)) ** 2, axis=1)))


def example_contrast(estimator: Any, example: ArrayLike | None,
                     confidence: float = DETECTION_CONFIDENCE) -> float | None:
    """How far the one faulty example stands out from the machine's own healthy segments.

    In the fit's selected, centred features, the largest over the features of ``(x −
    q) / s``: ``x`` the example's value, ``q`` the ``confidence`` quantile and ``s`` the
    standard deviation of the fit's healthy training rows (differences across runs when
    the fit knows its recordings). Below 0 the example lies inside the healthy segments'
    own scatter in every feature: the grade choice then fits a fault the signal does not
    show, and the scale of every estimate is unanchored (rig family, development rigs
    100–123: the 4 of 48 fits below 0 read 0.07–0.34 MAE against 0.07 for the rest;
    benchmarks/RESULTS.md). None without an example (zero-shot) or with fewer than
    :data:`MIN_CONTRAST_ROWS` healthy rows (no scatter to compare with).
    """
    healthy = np.asarray(estimator.target_healthy_features_,
                         dtype=float)[:, estimator.selected_columns_]
    if example is None or len(healthy) < MIN_CONTRAST_ROWS:
        return None
    x = estimator.features_of(np.asarray(example, dtype=float).reshape(1, -1))[0]
    q = np.quantile(healthy, confidence, axis=0)
    spread = np.maximum(healthy.std(axis=0), 1e-12)
    return float(np.max((x - q) / spread))
