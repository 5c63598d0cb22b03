"""Synthetic tacho signals from a shaft angle history."""

from __future__ import annotations

import numpy as np

from .._errors import GearshotError
from .._validation import as_signal_array, check_int, check_positive

__all__ = ["tacho_signal"]


def tacho_signal(shaft_revs: np.ndarray, *, pulses_per_rev: int = 1, duty: float = 0.1,
                 edge: float = 0.002, amplitude: float = 5.0, jitter: float = 0.0,
                 rng: np.random.Generator | None = None) -> np.ndarray:
    """A once-(or n-)per-revolution pulse train, sampled with the shaft angle.

    Pulse k rises at shaft angle ``k / pulses_per_rev + delta_k`` revolutions, with
    ``delta_k ~ N(0, jitter)`` (jitter in revolutions, e.g. 2e-4 rev = 0.07 deg), ramps up
    and down linearly over ``edge`` revolutions (so pulse times can be found to a fraction
    of a sample) and stays high for ``duty`` of the pulse pitch.

    Parameters
    ----------
    shaft_revs : ndarray, shape (n,)
        Cumulative shaft angle at each sample, in revolutions (non-decreasing).
    pulses_per_rev : int
        Pulses per shaft revolution.
    duty, edge : float
        High time and ramp width as fractions of the pulse pitch / revolutions.
    amplitude : float
        Pulse height (e.g. volts).
    jitter : float
        Standard deviation of the pulse angle error, in revolutions.
    rng : numpy.random.Generator, optional
        Needed when ``jitter > 0``.

    Returns
    -------
    ndarray, shape (n,)
    """
    revs = as_signal_array(shaft_revs, "shaft_revs", max_ndim=1)
    ppr = check_int(pulses_per_rev, "pulses_per_rev", minimum=1)
    duty = check_positive(duty, "duty")
    edge = check_positive(edge, "edge")
    amplitude = check_positive(amplitude, "amplitude")
    jitter = check_positive(jitter, "jitter", allow_zero=True)
    if not duty + 2 * edge * ppr < 1.0:
        raise GearshotError(f"duty + 2*edge*pulses_per_rev must be < 1; got duty={duty}, "
                            f"edge={edge}")
    a = revs * ppr
    if jitter > 0:
        if rng is None:
            raise GearshotError("rng (a numpy.random.Generator) is needed when jitter > 0")
        # pulse k rises at a = k + delta_k; each sample belongs to the last pulse that has
        # risen before it (indexing delta by floor(a) instead would cut an early pulse's
        # edge in two at the integer angle, a double pulse)
        k0, k1 = int(np.floor(a.min())) - 1, int(np.floor(a.max())) + 2
        starts = np.arange(k0, k1) + rng.normal(0.0, jitter * ppr, size=k1 - k0)
        starts = np.maximum.accumulate(starts)
        j = np.clip(np.searchsorted(starts, a, side="right") - 1, 0, starts.size - 1)
        p = a - starts[j]
    else:
        p = np.mod(a, 1.0)
    rise = np.clip(p / (edge * ppr), 0.0, 1.0)
    fall = np.clip((duty - p) / (edge * ppr), 0.0, 1.0)
    return amplitude * np.minimum(rise, fall)
