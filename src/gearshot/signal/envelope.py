"""Envelope by the analytic signal."""

from __future__ import annotations

from typing import cast

import numpy as np
from numpy.typing import ArrayLike

from .._typing import FloatArray
from .._validation import as_signal_array, finite_result

__all__ = ["envelope"]


@finite_result
def envelope(x: ArrayLike) -> FloatArray:
    """Envelope ``|hilbert(x)|`` along the last axis.

    Parameters
    ----------
    x : array_like, shape (..., n)
        Real signal(s).

    Returns
    -------
    ndarray, shape (..., n)
        Magnitude of the analytic signal (mean not removed).

    Examples
    --------
    A carrier at order 100 amplitude-modulated at order 3 (depth 0.5): the envelope is
    the modulation, 1.5 at its peak and 0.5 at its trough.

    >>> import numpy as np
    >>> from gearshot.signal import envelope
    >>> theta = np.arange(1000) / 1000
    >>> x = (1 + 0.5 * np.cos(2 * np.pi * 3 * theta)) * np.cos(2 * np.pi * 100 * theta)
    >>> env = envelope(x)
    >>> print(round(float(env.max()), 3), round(float(env.min()), 3))
    1.5 0.5
    """
    import scipy.signal  # a slow import (0.5-1 s): only when an envelope is asked for

    x = as_signal_array(x, "x", min_length=2)
    return cast(FloatArray, np.abs(scipy.signal.hilbert(x, axis=-1)))
