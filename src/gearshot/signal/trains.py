"""Order tracking through gear trains.

A tacho on one shaft gives the angle of every other shaft of a gear train through an exact
speed ratio -- a fraction of tooth counts (e.g. one idler revolution = 3 input revolutions
for 32 -> 96 teeth; one output revolution = 5 input revolutions for 32 -> 96, 48 -> 80).
:func:`shaft_cycle_times` turns tacho pulses into the times at which the target shaft
completes whole revolutions, computing the tacho angle of cycle ``m`` as the exact
``m * p / q`` before it becomes a float, so no ratio rounding accumulates over a record.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
from numpy.typing import ArrayLike

from .._errors import GearshotError
from .._typing import FloatArray
from .._validation import (
    MAX_POINTS,
    as_signal_array,
    check_int,
    finite_result,
)
from .angular import angle_to_time

__all__ = ["shaft_cycle_times", "as_ratio"]


#: What :func:`as_ratio` takes.
RatioLike = Fraction | int | str | tuple[int, int] | float | np.integer | np.floating


def as_ratio(value: RatioLike, name: str = "revs_per_cycle") -> Fraction:
    """An exact positive ratio from a Fraction, an int, a ``"p/q"`` string or a (p, q) pair.

    Floats are accepted only when they are exact small fractions (e.g. 2.5); pass tooth
    counts as a fraction to stay exact.

    Examples
    --------
    >>> from gearshot.signal.trains import as_ratio
    >>> print(as_ratio("96/32"), as_ratio((38, 17)), as_ratio(2.5))
    3 38/17 5/2
    """
    try:
        if isinstance(value, bool):
            raise TypeError
        if isinstance(value, tuple) and len(value) == 2:
            frac = Fraction(int(value[0]), int(value[1]))
        elif isinstance(value, (Fraction, int, np.integer, str)):
            frac = Fraction(value) if not isinstance(value, np.integer) else Fraction(int(value))
        elif isinstance(value, (float, np.floating)):
            if not np.isfinite(value):
                raise TypeError
            frac = Fraction(float(value)).limit_denominator(10_000)
            if abs(float(frac) - float(value)) > 1e-12 * abs(float(value)):
                raise TypeError
        else:
            raise TypeError
    except (TypeError, ValueError, ZeroDivisionError, OverflowError):
        raise GearshotError(f"{name} must be an exact ratio (Fraction, int, 'p/q' or (p, q)); "
                            f"got {value!r}") from None
    if frac <= 0:
        raise GearshotError(f"{name} must be > 0; got {value!r}")
    return frac


@finite_result
def shaft_cycle_times(pulse_times: ArrayLike, *, revs_per_cycle: RatioLike,
                      pulses_per_rev: int = 1) -> FloatArray:
    """Times (s) at which a shaft completes whole revolutions, from a tacho on another shaft.

    Parameters
    ----------
    pulse_times : array_like, shape (n_pulses,)
        Tacho pulse times in s, increasing, ``pulses_per_rev`` per tacho-shaft revolution.
    revs_per_cycle : Fraction, int, str or (int, int)
        Tacho-shaft revolutions per revolution of the target shaft, exact (e.g.
        ``Fraction(96, 32)`` for an idler driven 32 -> 96 from a tacho on the input).
    pulses_per_rev : int, default 1
        Tacho pulses per tacho-shaft revolution.

    Returns
    -------
    ndarray, shape (n_cycles + 1,)
        Start of target revolution 0 (at the first pulse), 1, ..., up to the last
        revolution that ends by the last pulse.

    Examples
    --------
    An idler turning once per three revolutions of a tacho shaft pulsing every 0.1 s:

    >>> import numpy as np
    >>> from gearshot.signal import shaft_cycle_times
    >>> print(np.round(shaft_cycle_times(np.arange(10) * 0.1, revs_per_cycle="3"), 6) + 0.0)
    [0.  0.3 0.6 0.9]
    """
    pulses = as_signal_array(pulse_times, "pulse_times", max_ndim=1)
    ratio = as_ratio(revs_per_cycle)
    ppr = check_int(pulses_per_rev, "pulses_per_rev", minimum=1, maximum=MAX_POINTS)
    if pulses.size < 2:
        raise GearshotError(f"pulse_times must hold at least 2 pulses; got {pulses.size}")
    if np.any(np.diff(pulses) <= 0):
        raise GearshotError("pulse_times must be strictly increasing")
    # cycle m ends at tacho pulse index m * p * ppr / q: count whole cycles exactly
    p, q = ratio.numerator, ratio.denominator
    n_cycles = ((pulses.size - 1) * q) // (p * ppr)
    if n_cycles > MAX_POINTS:
        raise GearshotError(f"revs_per_cycle={ratio} gives {n_cycles} cycles from "
                            f"{pulses.size} pulses, more than {MAX_POINTS}")
    m = np.arange(n_cycles + 1, dtype=np.int64)
    targets = (m * p) / q  # exact integers times p, one rounding in the division
    return angle_to_time(pulses, targets, pulses_per_rev=ppr)
