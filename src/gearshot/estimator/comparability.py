"""Know when not to answer: does a segment look like the fitted machine?

A fault changes a gear's *difference* signal (what is left once the mesh harmonics are
removed); the *regular* part — the amplitudes of the mesh orders and their harmonics —
is set by the machine itself: its build (the gears' profiles, the assembly), its speed and
load, and the path to the sensor. A segment whose regular part matches none of the fitted
machine's states does not come from the machine the estimator was fitted on, and its
estimate must not be trusted.

The regular part is summarised by the **harmonic profile** (:func:`harmonic_profile`): the
amplitude spectrum of an SA at the exact mesh-harmonic orders ``k * m`` of every mesh ``m``
up to the Nyquist order, divided by its Euclidean norm (so the overall level, which a fault
and the sensor gain change, drops out; phases are left out because the SA's start angle is
only known up to one tacho pulse).

The fitted machine's states are a segment of a line in profile space
(:class:`ComparabilityReference`): the healthy recordings' mean profile ``h``, moved toward
the faulty example's profile ``e`` as a fault grows, ``h + t (e - h)`` for ``t`` in
``[0, 1 / faulty_size]`` (the example's effect on the regular part scaled linearly from its
size to the largest, 1). The **comparability score** of a segment is its distance from that
segment of line, in units of the healthy recordings' own spread (the root-mean-square
leave-one-out distance of each healthy profile from the mean of the others). A segment is
**comparable** when its score is at most the threshold, :data:`DEFAULT_THRESHOLD` = 3.0,
chosen on the development cells of the PHM 2009 spur subset (30 Hz; issue #19,
``benchmarks/RESULTS.md``). Without an example (zero-shot) the line shrinks to ``h``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import cast

import numpy as np
import scipy.fft
from numpy.typing import ArrayLike, NDArray

from .._errors import GearshotError
from .._validation import as_signal_array, check_in_range, check_positive
from ..signal.orders import check_mesh_orders

__all__ = ["DEFAULT_THRESHOLD", "Comparability", "ComparabilityReference",
           "harmonic_orders", "harmonic_profile", "healthy_spread", "fit_comparability"]

FloatArray = NDArray[np.float64]

#: Largest comparability score of a comparable segment (healthy spreads from the fitted
#: machine's states). Chosen on the development cells (30 Hz) of the PHM 2009 spur subset,
#: both sensors: the geometric mean of the largest same-build score (2.32) and the
#: smallest other-build score (3.90); reported on the 40 Hz cells (benchmarks/RESULTS.md).
DEFAULT_THRESHOLD = 3.0

#: Smallest healthy spread used as the score's unit (profiles are unit vectors): healthy
#: SAs that are exact copies of each other would otherwise make every other segment
#: infinitely far.
MIN_SPREAD = 1e-6


def harmonic_orders(n_points: int, mesh_order: int | Sequence[int]) -> np.ndarray:
    """The distinct mesh-harmonic orders ``k * m`` (every mesh ``m``, ``k ≥ 1``) below the
    Nyquist order of an ``n_points`` cycle, sorted."""
    meshes = check_mesh_orders(mesh_order, n_points)
    nyquist = n_points // 2
    return np.unique(np.concatenate([np.arange(m, nyquist, m) for m in meshes]))


def harmonic_profile(sa: ArrayLike, mesh_order: int | Sequence[int]) -> FloatArray:
    """Unit-norm amplitudes of SAs at their mesh-harmonic orders (the regular part).

    Parameters
    ----------
    sa : array_like (n_signals, n_points) or (n_points,)
        Synchronous averages, one cycle each.
    mesh_order : int or sequence of int
        Mesh order(s) of the cycle (:meth:`gearshot.Machine.mesh_orders`).

    Returns
    -------
    ndarray (n_signals, n_orders)
        ``|DFT(sa)|`` at :func:`harmonic_orders`, each row divided by its norm (a row
        without any harmonic content stays zero).
    """
    arr = np.atleast_2d(as_signal_array(sa, "sa", max_ndim=2, min_length=4))
    orders = harmonic_orders(arr.shape[-1], mesh_order)
    amp = np.abs(scipy.fft.rfft(arr, axis=-1))[:, orders]
    norm = np.linalg.norm(amp, axis=1, keepdims=True)
    return cast(FloatArray, np.divide(amp, norm, out=np.zeros_like(amp), where=norm > 0))


@dataclass(frozen=True)
class Comparability:
    """Comparability of segments with the fitted machine.

    Attributes
    ----------
    score : ndarray (n_signals,)
        Distance of each segment's harmonic profile from the fitted machine's states, in
        healthy spreads (about 1 for a healthy segment of the fitted machine).
    comparable : ndarray of bool (n_signals,)
        ``score <= threshold``.
    threshold : float
    """

    score: FloatArray
    comparable: NDArray[np.bool_]
    threshold: float


@dataclass(frozen=True)
class ComparabilityReference:
    """What :meth:`OneFaultShotEstimator.comparability` learned at fit time.

    Attributes
    ----------
    mesh_order : tuple of int
    n_points : int
    healthy_mean : ndarray (n_orders,)
        Mean harmonic profile of the healthy SAs.
    fault_direction : ndarray (n_orders,)
        Example profile minus ``healthy_mean`` (zeros without an example).
    max_step : float
        Largest multiple of ``fault_direction`` a fault can reach (``1 / faulty_size``).
    spread : float
        RMS leave-one-out distance of the healthy profiles (the score's unit).
    threshold : float
    """

    mesh_order: tuple[int, ...]
    n_points: int
    healthy_mean: FloatArray
    fault_direction: FloatArray
    max_step: float
    spread: float
    threshold: float

    def distance(self, profiles: ArrayLike) -> FloatArray:
        """Distance of profiles from the segment of line ``healthy_mean + t *
        fault_direction``, ``0 ≤ t ≤ max_step`` (profile units, not spreads)."""
        p = np.atleast_2d(np.asarray(profiles, dtype=float)) - self.healthy_mean
        v = self.fault_direction
        vv = float(v @ v)
        t = np.clip(p @ v / vv, 0.0, self.max_step) if vv > 0 else np.zeros(len(p))
        return np.asarray(np.linalg.norm(p - t[:, None] * v, axis=1), dtype=float)

    def evaluate(self, sa: ArrayLike, threshold: float | None = None) -> Comparability:
        """Score SAs (see :class:`Comparability`); ``threshold`` overrides the fitted one."""
        arr = np.atleast_2d(as_signal_array(sa, "sa", max_ndim=2))
        if arr.shape[-1] != self.n_points:
            raise GearshotError(f"sa has {arr.shape[-1]} points per cycle; the estimator "
                                f"was fitted on {self.n_points}")
        thr = self.threshold if threshold is None else check_positive(threshold,
                                                                      "threshold")
        score = self.distance(harmonic_profile(arr, list(self.mesh_order))) / self.spread
        return Comparability(score, score <= thr, float(thr))


def healthy_spread(profiles: FloatArray) -> float:
    """RMS leave-one-out distance of each healthy profile from the mean of the others (the
    unit of the comparability score), at least :data:`MIN_SPREAD`; needs 2 profiles."""
    n = len(profiles)
    loo = (n * profiles.mean(axis=0) - profiles) / (n - 1)  # the mean of the others
    return max(float(np.sqrt(np.mean(np.sum((profiles - loo) ** 2, axis=1)))), MIN_SPREAD)


def fit_comparability(healthy_sa: ArrayLike, mesh_order: int | Sequence[int], *,
                      faulty_example: ArrayLike | None = None,
                      faulty_size: float | None = None,
                      threshold: float = DEFAULT_THRESHOLD) -> ComparabilityReference:
    """Learn the fitted machine's states from its healthy SAs and the one faulty example.

    Parameters
    ----------
    healthy_sa : array_like (n_healthy, n_points)
        At least 2 healthy SAs of the fitted machine.
    mesh_order : int or sequence of int
    faulty_example : array_like (n_points,), optional
        The one faulty SA (none for zero-shot).
    faulty_size : float in (0, 1], optional
        Its size (needed with ``faulty_example``).
    threshold : float > 0, default :data:`DEFAULT_THRESHOLD`

    Returns
    -------
    ComparabilityReference
    """
    healthy = as_signal_array(healthy_sa, "healthy_sa", min_ndim=2, max_ndim=2, min_length=4)
    if healthy.shape[0] < 2:
        raise GearshotError(f"healthy_sa holds {healthy.shape[0]} SA(s); the healthy "
                            f"spread needs at least 2")
    threshold = check_positive(threshold, "threshold")
    n_points = healthy.shape[1]
    meshes = check_mesh_orders(mesh_order, n_points)
    prof = harmonic_profile(healthy, list(meshes))
    mean = prof.mean(axis=0)
    spread = healthy_spread(prof)
    direction, max_step = np.zeros_like(mean), 0.0
    if faulty_example is not None:
        if faulty_size is None:
            raise GearshotError("faulty_size is required with faulty_example")
        size = check_in_range(faulty_size, "faulty_size", 0.0, 1.0, low_inclusive=False)
        example = as_signal_array(faulty_example, "faulty_example", max_ndim=2).reshape(-1)
        if example.size != n_points:
            raise GearshotError(f"faulty_example has {example.size} points but healthy_sa "
                                f"SAs have {n_points}")
        direction = harmonic_profile(example, list(meshes))[0] - mean
        max_step = 1.0 / size
    return ComparabilityReference(tuple(meshes), n_points, mean, direction, max_step,
                                  spread, float(threshold))
