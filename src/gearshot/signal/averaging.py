"""Synchronous (time-synchronous) averaging."""

from __future__ import annotations

import numpy as np

from .._errors import GearshotError
from .._validation import MAX_POINTS, as_signal_array, check_int, finite_result

__all__ = ["synchronous_average", "nonsynchronous_signal"]


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


@finite_result
def nonsynchronous_signal(x, samples_per_cycle) -> np.ndarray:
    """The non-synchronous part of an angle-domain signal: each cycle minus the SA.

    Everything that does not repeat identically every cycle -- noise, other shafts,
    bearings, slip -- is left; every synchronous order is gone. Its RMS is the
    ``rms_residual`` indicator of ``gearshot indicators`` (what ranked the PHM09 helical
    cases). Not to be confused with :func:`gearshot.signal.residual_signal`, the
    *synchronous* residual of the SA (the reference toolchain's ``tsaresidual``).

    Parameters
    ----------
    x : array_like, shape (..., n_samples)
        Angle-domain signal(s) at ``samples_per_cycle`` points per cycle, the first sample
        at the start of a cycle.
    samples_per_cycle : int

    Returns
    -------
    ndarray, shape (..., n_cycles * samples_per_cycle)
        Whole cycles only (the incomplete tail is dropped).

    Examples
    --------
    >>> import numpy as np
    >>> from gearshot.signal import nonsynchronous_signal
    >>> x = np.tile([1.0, 2.0, 3.0, 4.0], 3) + np.repeat([0.0, 1.0, -1.0], 4)
    >>> nonsynchronous_signal(x, 4).reshape(3, 4)[:, 0]
    array([ 0.,  1., -1.])
    """
    spc = check_int(samples_per_cycle, "samples_per_cycle", minimum=1, maximum=MAX_POINTS)
    x = as_signal_array(x, "x")
    n_cycles = x.shape[-1] // spc
    if n_cycles < 1:
        raise GearshotError(f"x has {x.shape[-1]} samples, fewer than one cycle of "
                            f"samples_per_cycle={spc}")
    blocks = x[..., : n_cycles * spc].reshape(*x.shape[:-1], n_cycles, spc)
    return (blocks - blocks.mean(axis=-2, keepdims=True)).reshape(*x.shape[:-1],
                                                                   n_cycles * spc)
