"""Signal level: root mean square."""

from __future__ import annotations

import numpy as np

from .._validation import as_signal_array, finite_result

__all__ = ["rms", "mean_rms"]


@finite_result
def rms(x) -> np.ndarray:
    """Root mean square along the last axis.

    Parameters
    ----------
    x : array_like, shape (..., n)

    Returns
    -------
    numpy.ndarray, shape (...)
        A 0-d array for a single signal.
    """
    x = as_signal_array(x, "x")
    return np.sqrt(np.mean(x * x, axis=-1))


@finite_result
def mean_rms(signals) -> float:
    """Mean over signals of the RMS along the last axis: the RMS-normalization scale."""
    return float(np.mean(rms(signals)))
