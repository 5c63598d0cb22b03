"""Residue whitening: the target's difference signals weighted, order by order, by the
inverse of what a healthy gear compared with itself leaves there.

What a healthy recording leaves after step 6 (its *residue*) is not white. On the virtual
rigs most of it comes from the speed drifting while the machine runs: the gear's own
vibration meets the structure's resonances at slightly other frequencies from one
revolution, segment or recording to the next, and the subtraction leaves those orders
behind (`benchmarks/physics_budget.py` and RESULTS, "Estimator": the speed drift alone
takes the development rigs from 6.7 % to 10.4 %). A fault's signature spreads over every
order, so the orders where the residue is small carry most of what tells a fault apart;
an unweighted RMS of the difference is dominated by the few orders where it is large.

The weights are ``W_k = P_k^(-1/2)`` with ``P`` the target's healthy differences' mean
power per order (:func:`gearshot.estimator.steps.residue_power`), smoothed over
neighbouring orders in the log domain (``SMOOTH_ORDERS``) and floored at ``FLOOR`` times
its median. They act as one more linear filter on both sides: the target's differences
are multiplied by them (with the RMS scale of step 5 taken after the filter), and the
simulated signals are propagated through the estimated transfer function times them, so
step 5 divides each side by its own filtered healthy RMS. The noise matched on the
simulated side is then drawn from the *weighted* residue, close to white.

Chosen on the rig family's development range (rigs 100–123 × 2 draws); the paper's
estimator (``estimator="paper"``) keeps its literal pipeline and does not use them.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.ndimage import uniform_filter1d

from .steps import residue_power

__all__ = ["SMOOTH_ORDERS", "FLOOR", "MIN_RUNS", "residue_weights", "filter_orders",
           "two_sided"]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

#: Orders averaged (in log power) around each order before the weights are formed.
SMOOTH_ORDERS = 9
#: The smoothed power is floored at this share of its median (no order weighs more than
#: ``FLOOR ** -0.5`` times a typical one).
FLOOR = 1e-3
#: Healthy recordings (runs) a fit needs before it whitens: the weights must learn the
#: residue a *new run* leaves, which one run's segments do not show (PHM09, one healthy
#: recording per fit: whitened, run 2's healthy gear read 0.17 at 40 Hz High, trusted).
MIN_RUNS = 3


def residue_weights(differences: ArrayLike) -> FloatArray:
    """One-sided weights (``n // 2 + 1``; DC weight 0, root mean square 1) of the target's
    healthy difference signals ``differences`` (n_signals, n).

    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> theta = np.arange(256) / 256
    >>> d = rng.standard_normal((40, 256))            # white, but orders 15-25 loud:
    >>> d += 30 * np.cos(2 * np.pi * np.arange(15, 26)[:, None] * theta).sum(axis=0)
    >>> w = residue_weights(d)
    >>> bool(w[20] < 0.1 * np.median(w)), round(float(np.sqrt(np.mean(w ** 2))), 6)
    (True, 1.0)
    """
    power = residue_power(differences)
    tiny = np.finfo(float).tiny
    smooth = np.exp(uniform_filter1d(np.log(power + tiny), SMOOTH_ORDERS, mode="nearest"))
    smooth = np.maximum(smooth, FLOOR * float(np.median(smooth)) + tiny)
    weights = smooth ** -0.5
    weights[0] = 0.0
    return np.asarray(weights / np.sqrt(np.mean(weights ** 2)), dtype=np.float64)


def filter_orders(signals: ArrayLike, weights: ArrayLike | None) -> FloatArray:
    """``signals`` (..., n: SAs or their differences) filtered by one-sided real
    ``weights`` per order (None: unchanged)."""
    d = np.asarray(signals, dtype=float)
    if weights is None:
        return d
    n = d.shape[-1]
    return np.asarray(np.fft.irfft(np.fft.rfft(d, axis=-1) * np.asarray(weights), n=n,
                                   axis=-1), dtype=np.float64)


def two_sided(weights: ArrayLike, n: int) -> FloatArray:
    """One-sided real weights on the ``n``-point two-sided DFT grid (symmetric), to
    multiply a transfer function by."""
    w = np.asarray(weights, dtype=float)
    k = np.arange(n)
    return np.asarray(w[np.minimum(k, n - k)], dtype=np.float64)
