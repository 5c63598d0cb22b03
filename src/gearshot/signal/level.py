"""Signal level: root mean square."""

from __future__ import annotations

from typing import cast

import numpy as np
from numpy.typing import ArrayLike

from .._typing import FloatArray
from .._validation import as_signal_array, finite_result

__all__ = ["rms", "mean_rms"]


@finite_result
def rms(x: ArrayLike) -> FloatArray:
    """Root mean square along the last axis.

    Parameters
    ----------
    x : array_like, shape (..., n)

    Returns
    -------
    numpy.ndarray, shape (...)
        A 0-d array for a single signal.

    Examples
    --------
    >>> import numpy as np
    >>> from gearshot.signal import rms
    >>> theta = np.arange(1000) / 1000
    >>> print(round(float(rms(np.sin(2 * np.pi * 5 * theta))), 4))    # 1 / sqrt(2)
    0.7071
    >>> print(rms([[3.0, -3.0, 3.0, -3.0], [1.0, 1.0, 1.0, 1.0]]))    # one per signal
    [3. 1.]
    """
    x = as_signal_array(x, "x")
    return cast(FloatArray, np.sqrt(np.mean(x * x, axis=-1)))


@finite_result
def mean_rms(signals: ArrayLike) -> float:
    """Mean over signals of the RMS along the last axis: the RMS-normalization scale.

    Examples
    --------
    >>> from gearshot.signal import mean_rms
    >>> mean_rms([[3.0, -3.0, 3.0, -3.0], [1.0, 1.0, 1.0, 1.0]])
    2.0
    """
    return float(np.mean(rms(signals)))
