"""From a shaft tacho to gear-revolution cycles: angle domain and SA segments.

The SA cycle is one revolution of the driven gear (``gear_teeth`` teeth). The tacho usually
sits on the input (pinion) shaft, and one gear revolution is ``gear_teeth / pinion_teeth``
pinion revolutions (38/17 for the paper's pair) -- not an integer. Re-sampling on the pinion
angle with an integer number of samples per *gear* cycle is therefore impossible in general
(2048 * 17 / 38 samples per pinion revolution is not an integer). Instead the signal is
re-sampled directly on the gear angle:

1. ``pulse_times`` gives the tacho pulse times t_k; pulse k sits at tacho-shaft angle
   k / pulses_per_rev revolutions.
2. The gear angle is the tacho-shaft angle times ``pinion_teeth / gear_teeth`` (input-shaft
   tacho) or 1 (output-shaft tacho). Gear revolution m therefore starts at tacho-shaft angle
   m * gear_teeth / pinion_teeth revolutions.
3. The time of that angle comes from :func:`gearshot.signal.shaft_cycle_times` (the exact
   ratio as a fraction) through :func:`gearshot.signal.angle_to_time` (cubic spline of
   the pulse times against angle) -- the same curve the angular re-sampler uses. These
   "virtual gear pulses" (one per gear revolution) go to ``angular_resample`` with
   ``pulses_per_rev=1`` and ``samples_per_rev = samples_per_cycle``.
4. The angle-domain signal is cut into whole gear cycles; consecutive blocks of
   ``cycles_per_segment`` cycles are synchronously averaged (the incomplete tail is dropped).

Gear cycle 0 starts at the first tacho pulse. The absolute gear orientation at that pulse
is not known from an input-shaft tacho, so SAs of *different* recordings may be circularly
shifted against each other (by whole teeth and fractions); SAs of one recording are aligned.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .._errors import GearshotError
from .._typing import FloatArray
from .._validation import MAX_POINTS, check_int

__all__ = [
    "check_pulse_train",
    "uniform_cycle_times",
    "TACHO_SHAFTS",
]

TACHO_SHAFTS = ("input", "output")

#: A pulse interval longer than this many median intervals counts as a dropout.
DROPOUT_FACTOR = 1.5


def check_pulse_train(pulses: np.ndarray, *, pulses_per_rev: int, label: str) -> np.ndarray:
    """Validate tacho pulse times (s): enough pulses, increasing, no glitch, no long dropout.

    A gap longer than ``DROPOUT_FACTOR`` median pulse intervals is a dropout (missing
    pulses). A dropout that spans more than one revolution (more than ``pulses_per_rev``
    intervals; with one pulse per revolution, *any* missing pulse) cannot be bridged
    reliably and raises. Shorter dropouts (possible with several pulses per revolution)
    are bridged by inserting the missing pulses evenly. An interval shorter than half the
    median (an extra pulse: electrical glitch, double trigger) raises.

    Returns
    -------
    ndarray
        The pulse times, with bridged dropouts filled in.

    Examples
    --------
    Two pulses per revolution, one missing at 0.15 s (bridged), and a glitch (refused):

    >>> import numpy as np
    >>> from gearshot.signal import check_pulse_train
    >>> print(check_pulse_train(np.array([0.0, 0.05, 0.1, 0.2, 0.25, 0.3]),
    ...                         pulses_per_rev=2, label="demo"))
    [0.   0.05 0.1  0.15 0.2  0.25 0.3 ]
    >>> check_pulse_train(np.array([0.0, 0.1, 0.11, 0.2, 0.3]), pulses_per_rev=1,
    ...                   label="demo")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    gearshot._errors.GearshotError: demo: extra tacho pulse at t=0.11 s ...
    """
    pulses_per_rev = check_int(pulses_per_rev, "pulses_per_rev", minimum=1, maximum=MAX_POINTS)
    try:
        pulses = np.asarray(pulses, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        raise GearshotError(f"{label}: tacho pulse times must be numbers") from None
    if not np.all(np.isfinite(pulses)):
        raise GearshotError(f"{label}: tacho pulse times must be finite")
    if pulses.size < 2 * pulses_per_rev + 1:
        raise GearshotError(f"{label}: the tacho shows {pulses.size} pulse(s); at least "
                            f"{2 * pulses_per_rev + 1} are needed (empty or flat tacho?)")
    gaps = np.diff(pulses)
    if np.any(gaps <= 0):
        raise GearshotError(f"{label}: tacho pulse times are not increasing")
    med = float(np.median(gaps))
    short = np.flatnonzero(gaps < 0.5 * med)
    if short.size:
        i = int(short[0])
        raise GearshotError(
            f"{label}: extra tacho pulse at t={pulses[i + 1]:.4g} s ({gaps[i] / med:.2f} "
            f"median intervals after the previous one); {short.size} such glitch(es)")
    return _bridge_dropouts(pulses, gaps, med, pulses_per_rev=pulses_per_rev, label=label)


def _bridge_dropouts(pulses: FloatArray, gaps: FloatArray, med: float, *, pulses_per_rev: int,
                     label: str) -> FloatArray:
    """``pulses`` with each dropout (a gap over ``DROPOUT_FACTOR`` median intervals) of at
    most one revolution filled with evenly spaced pulses; a longer dropout raises."""
    long = np.flatnonzero(gaps > DROPOUT_FACTOR * med)
    if not long.size:
        return pulses
    spans = np.rint(gaps[long] / med).astype(np.int64)  # intervals the gap covers
    bad = np.flatnonzero(spans > pulses_per_rev)
    if bad.size:
        i = int(long[bad[0]])
        raise GearshotError(
            f"{label}: tacho dropout of {gaps[i]:.4g} s ({gaps[i] / med:.2f} pulse "
            f"intervals, more than one revolution at tacho_pulses_per_rev="
            f"{pulses_per_rev}) after the pulse at t={pulses[i]:.4g} s; {bad.size} such "
            f"gap(s)")
    pieces = [pulses[: long[0] + 1]]
    for j, (at, k) in enumerate(zip(long, spans)):
        a, b = pulses[at], pulses[at + 1]
        pieces.append(a + (b - a) * np.arange(1, k) / k)
        stop = long[j + 1] + 1 if j + 1 < long.size else pulses.size
        pieces.append(pulses[at + 1: stop])
    return np.concatenate(pieces)

def uniform_cycle_times(cycle_times: ArrayLike) -> FloatArray:
    """Equally spaced cycle times with the same first and last value (constant speed).

    Used to show what skipping angular re-sampling costs: the signal is then cut at the
    *mean* cycle period, as a plain time-domain synchronous average would do.

    Examples
    --------
    >>> from gearshot.signal.angle import uniform_cycle_times
    >>> print(uniform_cycle_times([0.0, 1.1, 1.9, 3.0]))
    [0. 1. 2. 3.]
    """
    c = np.asarray(cycle_times, dtype=np.float64)
    return np.linspace(c[0], c[-1], c.size)
