"""Envelope by the analytic signal."""

from __future__ import annotations

import numpy as np

from .._validation import as_signal_array, finite_result

__all__ = ["envelope"]


@finite_result
def envelope(x) -> np.ndarray:
    """Envelope ``|hilbert(x)|`` along the last axis.

    Parameters
    ----------
    x : array_like, shape (..., n)
        Real signal(s).

    Returns
    -------
    ndarray, shape (..., n)
        Magnitude of the analytic signal (mean not removed).
    """
    import scipy.signal  # a slow import (0.5-1 s): only when an envelope is asked for

    x = as_signal_array(x, "x", min_length=2)
    return np.abs(scipy.signal.hilbert(x, axis=-1))
