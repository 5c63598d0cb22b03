"""Synchronous (time-synchronous) averaging."""

from __future__ import annotations

import numpy as np

from .._errors import GearshotError
from .._validation import MAX_POINTS, as_signal_array, check_int, finite_result

__all__ = ["synchronous_average"]


@finite_result
def synchronous_average(x, samples_per_cycle, *, n_cycles=None) -> np.ndarray:
    """Synchronous average of an angle-domain signal.

    Parameters
    ----------
    x : array_like, shape (..., n_samples)
        Angle-domain signal(s) sampled at ``samples_per_cycle`` points per cycle, the first
        sample at the start of a cycle.
    samples_per_cycle : int
        Points per cycle (2048 for the paper's gear revolution).
    n_cycles : int, optional
        Number of consecutive cycles to average, from the start. Default: every whole cycle.

    Returns
    -------
    sa : ndarray, shape (..., samples_per_cycle)
        Mean over cycles.

    Raises
    ------
    GearshotError
        If ``x`` holds fewer samples than one cycle or than the cycles requested.
    """
    spc = check_int(samples_per_cycle, "samples_per_cycle", minimum=1, maximum=MAX_POINTS)
    x = as_signal_array(x, "x")
    available = x.shape[-1] // spc
    if available < 1:
        raise GearshotError(
            f"x has {x.shape[-1]} samples, fewer than one cycle of "
            f"samples_per_cycle={spc}")
    if n_cycles is None:
        n_cycles = available
    n_cycles = check_int(n_cycles, "n_cycles", minimum=1)
    if n_cycles > available:
        raise GearshotError(
            f"n_cycles={n_cycles} requested but x holds only {available} whole cycles "
            f"of {spc} samples ({x.shape[-1]} samples)")
    blocks = x[..., : n_cycles * spc].reshape(*x.shape[:-1], n_cycles, spc)
    return blocks.mean(axis=-2)
