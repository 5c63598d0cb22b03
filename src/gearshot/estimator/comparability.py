"""Know when not to answer: does a segment come from the fitted machine's distribution?

A fault changes a gear's *difference* signal; the *regular* part of a synchronous average is
set by the machine itself: its build, its speed and load, the path to the sensor. A segment
whose regular part lies outside what the fitted machine's own healthy segments (and the one
faulty example) show does not come from the machine the estimator was fitted on, and its
estimate must not be trusted.

**Description** (:func:`regular_features`, one row per SA; the groups of
:data:`FEATURE_GROUPS`): the SA's level ``log10 RMS`` (a load, a speed, a sensor or a gain
changes it); and, relative to that level (``log10`` amplitude minus ``log10 RMS``): the
amplitude at every mesh-harmonic order ``k m`` below Nyquist (:func:`harmonic_orders`), at
shaft orders 1-3, the background (the spectrum without the mesh harmonics, their ±1, ±2
sidebands and shaft orders 1-3) in octave bands of order from 4 to Nyquist (the transfer
path's shape, which moves in order with speed), the ±1, ±2 sidebands of the mesh
harmonics in the same octave bands; and the SA's kurtosis.

**Distance.** Each feature is standardised by the healthy SAs' mean and their *local*
spread: the RMS difference of each healthy SA from its nearest healthy neighbour, divided
by ``sqrt(2)`` (at least :data:`MIN_STD`): healthy SAs pooled from several recordings (two
builds, two runs) keep the spread of one recording instead of the spread between them.
The fitted machine's states are the healthy SAs themselves, each moved toward the faulty
example as a fault grows: ``h_i + t_g v_g`` for every feature group ``g`` and
``0 <= t_g <= 1 / faulty_size``, where ``v`` is the example's standardised features minus
the mean of the healthy SAs nearest to it (the nearer half); a fault moves each group by its
own amount (a chip raises the shaft orders and sidebands more in one run than in another),
never against the example's direction nor beyond the example's effect scaled to size 1.
The **score** of a segment is its distance from the nearest of those states: the
root-mean-square over features of the residual, each squared residual divided by its
variance at that state, ``1 + t_g**2 (1 + (k v_j)**2)``: the example is one noisy SA (the
``t_g**2``), and its effect on each feature is known only to a fraction
``k =`` :data:`FAULT_SHAPE_UNCERTAINTY` (a fault of another size does not move every feature
in exact proportion). Zero-shot (no example): the distance from the nearest healthy SA.

**Calibration.** At fit time every healthy SA is scored by the reference fitted without it
(leave-one-out); the logarithms of those scores define a normal model of a healthy segment's
log-score. When the healthy SAs come from at least :data:`MIN_GROUPS` recordings
(``recordings``), each is scored by the reference fitted without its whole recording
(leave-one-recording-out): a new recording differs from the fitted ones by what changes
from run to run (speed and load within their tolerance, temperature, the path), which the
SAs of one recording cannot show; the calibration then states the false-alarm rate of a
*new recording* of the same machine. A segment's **p-value** is the upper tail of that
model at its log-score, and it is **comparable** when its p-value is at least the stated
false-alarm rate, :data:`DEFAULT_FALSE_ALARM` = 0.01 (1 % of the fitted machine's own
healthy segments are expected to be flagged). Fewer than :data:`MIN_HEALTHY` healthy SAs
cannot be calibrated: then no segment is comparable.

The comparable decision of a *recording* takes all its segments together (the median score):
another load, speed or build differs for the whole record.

Development and held-out results (labelled matrix of PHM09 pairs and virtual rigs):
``benchmarks/comparability_matrix.py``, ``benchmarks/RESULTS.md`` "Trust: comparability".
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.special
from numpy.typing import ArrayLike, NDArray

from .._errors import GearshotError
from .._validation import as_signal_array, check_in_range
from ..signal.orders import check_mesh_orders
from .regular_part import (
    FEATURE_GROUPS,
    harmonic_orders,
    harmonic_profile,
    healthy_spread,
    regular_features,
)

__all__ = ["DEFAULT_FALSE_ALARM", "FAULT_SHAPE_UNCERTAINTY", "FEATURE_GROUPS", "MIN_GROUPS",
           "MIN_HEALTHY", "MIN_STD",
           "Comparability", "ComparabilityReference", "fit_comparability",
           "harmonic_orders", "harmonic_profile", "healthy_spread", "regular_features"]

FloatArray = NDArray[np.float64]

#: Stated false-alarm rate: the share of the fitted machine's own healthy segments the
#: calibrated test flags (a segment is comparable when its p-value is at least this).
DEFAULT_FALSE_ALARM = 0.01

#: Fewest healthy SAs that calibrate the test: the leave-one-out scores of fewer are too
#: unsteady (3 healthy SAs of PHM09 spur3 30 Hz High: a threshold of 16 and 78 on the two
#: sensors, against 2.7 with the development fits' 9).
MIN_HEALTHY = 6

#: Fewest healthy recordings whose leave-one-recording-out scores calibrate the test (with
#: fewer, each SA is left out alone): two recordings give one between-run difference each,
#: too few to tell a run-to-run spread from one odd run (chosen on the development lives of
#: ``benchmarks/monitor_lives.py``).
MIN_GROUPS = 3

#: Smallest standard deviation of a feature (log10 units; kurtosis units for kurtosis):
#: identical healthy SAs would otherwise make every other segment infinitely far.
MIN_STD = 1e-3

#: Relative uncertainty of the example's effect on each feature: a fault of another size
#: moves every feature toward the example's value, but not in exact proportion (measured
#: on virtual rigs: a size-0.3 fault moves the level 18 % and the background 43 % of the
#: way to a size-0.6 example). Chosen on the development part of the matrix (0, 0.05,
#: 0.1, 0.25, 0.5, 1 tried: the smallest value that keeps a smaller fault of the
#: development rig comparable).
FAULT_SHAPE_UNCERTAINTY = 0.25

#: Smallest spread of the leave-one-out log-scores (natural-log units).
MIN_LOG_SPREAD = 0.05

_TINY = 1e-30


@dataclass(frozen=True)
class Comparability:
    """Comparability of segments with the fitted machine.

    Attributes
    ----------
    score : ndarray (n_signals,)
        Distance of each segment's regular part from the fitted machine's states, in the
        healthy SAs' local spreads (RMS over features; about 1 for a healthy segment of the
        fitted machine).
    p_value : ndarray (n_signals,)
        Probability that a healthy segment of the fitted machine scores at least as high
        (the calibrated model of the leave-one-out healthy scores); NaN when the
        reference is not calibrated.
    comparable : ndarray of bool (n_signals,)
        ``p_value >= false_alarm_rate`` (equivalently ``score <= threshold``).
    false_alarm_rate : float
    threshold : float
        The score at which the p-value equals the false-alarm rate (0 when the reference
        is not calibrated: no segment is then comparable).
    record_p_value : float
        The p-value of the segments' median score: all segments judged together as one
        recording (another load, speed or build differs for the whole record).
    record_comparable : bool
        ``record_p_value >= false_alarm_rate``.
    """

    score: FloatArray
    p_value: FloatArray
    comparable: NDArray[np.bool_]
    false_alarm_rate: float
    threshold: float
    record_p_value: float
    record_comparable: bool


@dataclass(frozen=True)
class ComparabilityReference:
    """What :meth:`OneFaultShotEstimator.comparability` learned at fit time.

    Attributes
    ----------
    mesh_order : tuple of int
    n_points : int
    groups : tuple of str
        The feature group of each column of :func:`regular_features`.
    mean, std : ndarray (n_features,)
        The healthy SAs' feature mean and local spread (at least :data:`MIN_STD`).
    anchors : ndarray (n_healthy, n_features)
        The healthy SAs' standardised features (the fitted machine's healthy states).
    fault_direction : ndarray (n_features,)
        The faulty example's standardised features minus the mean of its nearer half of
        the anchors (zeros without an example).
    max_step : float
        Largest multiple of ``fault_direction`` a fault can reach (``1 / faulty_size``).
    log_score_mean, log_score_std : float
        Normal model of a healthy segment's ``log(score)``, from the leave-one-out scores
        of the healthy SAs (NaN when fewer than :data:`MIN_HEALTHY` SAs: not calibrated).
    false_alarm_rate : float
    """

    mesh_order: tuple[int, ...]
    n_points: int
    groups: tuple[str, ...]
    mean: FloatArray
    std: FloatArray
    anchors: FloatArray
    fault_direction: FloatArray
    max_step: float
    log_score_mean: float
    log_score_std: float
    false_alarm_rate: float

    @property
    def calibrated(self) -> bool:
        """Whether the healthy scores calibrate the test (at least :data:`MIN_HEALTHY`)."""
        return bool(np.isfinite(self.log_score_mean))

    def distance(self, features: ArrayLike) -> FloatArray:
        """Score of :func:`regular_features` rows (see the module docstring)."""
        z = (np.atleast_2d(np.asarray(features, dtype=float)) - self.mean) / self.std
        return _distance(z, self.anchors, self.fault_direction, self.max_step,
                         _group_masks(self.groups))

    def p_value(self, score: ArrayLike) -> FloatArray:
        """Upper-tail probability of scores under the healthy log-score model."""
        s = np.asarray(score, dtype=float)
        if not self.calibrated:
            return np.full(s.shape, np.nan)
        z = (np.log(np.maximum(s, _TINY)) - self.log_score_mean) / self.log_score_std
        return np.asarray(scipy.special.ndtr(-z), dtype=float)

    def threshold(self, false_alarm_rate: float) -> float:
        """The score whose p-value is ``false_alarm_rate`` (0 when not calibrated)."""
        if not self.calibrated:
            return 0.0
        return float(np.exp(self.log_score_mean
                            + self.log_score_std * scipy.special.ndtri(1 - false_alarm_rate)))

    def evaluate(self, sa: ArrayLike, false_alarm_rate: float | None = None
                 ) -> Comparability:
        """Score SAs (see :class:`Comparability`); ``false_alarm_rate`` overrides the
        fitted one."""
        arr = np.atleast_2d(as_signal_array(sa, "sa", max_ndim=2))
        if arr.shape[-1] != self.n_points:
            raise GearshotError(f"sa has {arr.shape[-1]} points per cycle; the estimator "
                                f"was fitted on {self.n_points}")
        alpha = (self.false_alarm_rate if false_alarm_rate is None else
                 check_in_range(false_alarm_rate, "false_alarm_rate", 0.0, 1.0,
                                low_inclusive=False, high_inclusive=False))
        score = self.distance(regular_features(arr, list(self.mesh_order))[0])
        p = self.p_value(score)
        record_p = float(self.p_value(np.median(score)))
        comparable = np.asarray(p >= alpha, dtype=bool)  # NaN (not calibrated): False
        return Comparability(score, p, comparable, float(alpha), self.threshold(alpha),
                             record_p, bool(record_p >= alpha))


def _group_masks(groups: tuple[str, ...]) -> list[NDArray[np.bool_]]:
    labels = np.asarray(groups)
    return [labels == g for g in dict.fromkeys(groups)]


def _local_spread(features: FloatArray) -> FloatArray:
    """RMS difference of each row from its nearest other row (in pooled standard
    deviations) over ``sqrt(2)``, per column, at least :data:`MIN_STD`."""
    pooled = np.sqrt(features.var(axis=0, ddof=1) + MIN_STD ** 2)
    z = features / pooled
    gap = np.sum((z[:, None, :] - z[None, :, :]) ** 2, axis=-1)
    np.fill_diagonal(gap, np.inf)
    nearest = features[np.argmin(gap, axis=1)]
    return np.asarray(np.sqrt(np.mean((features - nearest) ** 2, axis=0) / 2
                              + MIN_STD ** 2), dtype=float)


def _distance(z: FloatArray, anchors: FloatArray, direction: FloatArray,
              max_step: float, masks: list[NDArray[np.bool_]]) -> FloatArray:
    """Distance of standardised rows ``z`` from the nearest state ``anchor + t_g v_g``."""
    offset = z[:, None, :] - anchors[None, :, :]        # (m, n_anchors, d)
    total = np.zeros(offset.shape[:2])
    for mask in masks:
        v = direction[mask]
        part = offset[..., mask]
        vv = float(v @ v)
        t = np.clip(part @ v / vv, 0.0, max_step) if vv > 0 else np.zeros(total.shape)
        resid = part - t[..., None] * v
        var = 1.0 + t[..., None] ** 2 * (1.0 + (FAULT_SHAPE_UNCERTAINTY * v) ** 2)
        total += np.sum(resid ** 2 / var, axis=-1)
    return np.asarray(np.sqrt(total.min(axis=1) / z.shape[1]), dtype=float)


def _states(features: FloatArray, example: FloatArray | None
            ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Mean, local spread, anchors and fault direction of healthy feature rows."""
    mean = features.mean(axis=0)
    std = _local_spread(features)
    anchors = (features - mean) / std
    direction = np.zeros_like(mean)
    if example is not None:
        ez = (example - mean) / std
        gap = np.sum((anchors - ez) ** 2, axis=1)
        direction = ez - anchors[gap <= np.median(gap)].mean(axis=0)
    return mean, std, anchors, direction


def _leave_one_out_scores(features: FloatArray, example: FloatArray | None,
                          max_step: float, masks: list[NDArray[np.bool_]],
                          recordings: NDArray | None = None) -> FloatArray:
    """Each healthy row scored by the states fitted on the others (on the other
    recordings' rows when ``recordings`` labels the rows)."""
    labels = np.arange(len(features)) if recordings is None else recordings
    scores = np.empty(len(features))
    for label in dict.fromkeys(labels.tolist()):
        out = labels == label
        mean, std, anchors, direction = _states(features[~out], example)
        scores[out] = _distance((features[out] - mean) / std, anchors, direction,
                                max_step, masks)
    return scores


def fit_comparability(healthy_sa: ArrayLike, mesh_order: int | Sequence[int], *,
                      faulty_example: ArrayLike | None = None,
                      faulty_size: float | None = None,
                      false_alarm_rate: float = DEFAULT_FALSE_ALARM,
                      recordings: ArrayLike | None = None) -> ComparabilityReference:
    """Learn the fitted machine's states and calibrate the test on its healthy SAs.

    Parameters
    ----------
    healthy_sa : array_like (n_healthy, n_points)
        At least 2 healthy SAs of the fitted machine, in physical units (at least
        :data:`MIN_HEALTHY` to calibrate the test; with fewer, no segment is comparable).
    mesh_order : int or sequence of int
    faulty_example : array_like (n_points,), optional
        The one faulty SA (none for zero-shot).
    faulty_size : float in (0, 1], optional
        Its size (needed with ``faulty_example``).
    false_alarm_rate : float in (0, 1), default :data:`DEFAULT_FALSE_ALARM`
    recordings : array_like (n_healthy,), optional
        The recording each healthy SA comes from: with at least :data:`MIN_GROUPS`
        recordings the calibration leaves one recording out at a time.

    Returns
    -------
    ComparabilityReference
    """
    healthy = as_signal_array(healthy_sa, "healthy_sa", min_ndim=2, max_ndim=2,
                              min_length=64)
    if healthy.shape[0] < 2:
        raise GearshotError(f"healthy_sa holds {healthy.shape[0]} SA(s); comparability "
                            f"needs at least 2")
    alpha = check_in_range(false_alarm_rate, "false_alarm_rate", 0.0, 1.0,
                           low_inclusive=False, high_inclusive=False)
    n_points = healthy.shape[1]
    meshes = check_mesh_orders(mesh_order, n_points)
    feats, columns = regular_features(healthy, list(meshes))
    example, max_step = None, 0.0
    if faulty_example is not None:
        if faulty_size is None:
            raise GearshotError("faulty_size is required with faulty_example")
        size = check_in_range(faulty_size, "faulty_size", 0.0, 1.0, low_inclusive=False)
        ex = as_signal_array(faulty_example, "faulty_example", max_ndim=2).reshape(-1)
        if ex.size != n_points:
            raise GearshotError(f"faulty_example has {ex.size} points but healthy_sa "
                                f"SAs have {n_points}")
        example = regular_features(ex, list(meshes))[0][0]
        max_step = 1.0 / size
    mean, std, anchors, direction = _states(feats, example)
    log_mean = log_std = float("nan")
    if len(feats) >= MIN_HEALTHY:
        loo = _leave_one_out_scores(feats, example, max_step, _group_masks(columns),
                                    _recording_labels(recordings, len(feats)))
        logs = np.log(np.maximum(loo, _TINY))
        log_mean = float(logs.mean())
        log_std = max(float(logs.std(ddof=1)), MIN_LOG_SPREAD)
    return ComparabilityReference(tuple(meshes), n_points, columns, mean, std, anchors,
                                  direction, max_step, log_mean, log_std, float(alpha))


def _recording_labels(recordings: ArrayLike | None, n: int) -> NDArray | None:
    """The recording labels of ``n`` healthy SAs when they name at least
    :data:`MIN_GROUPS` recordings (else None: leave one SA out)."""
    if recordings is None:
        return None
    labels = np.asarray(recordings).reshape(-1)
    if labels.size != n:
        raise GearshotError(f"recordings has {labels.size} labels for {n} healthy SAs")
    return labels if len(set(labels.tolist())) >= MIN_GROUPS else None
