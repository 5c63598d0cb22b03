"""The smallest fault size a fit can tell apart from healthy: ``detection_limit_``.

Every model that predicts (a grade or a calibration setting, with its weight) held out a
validation split of its simulated rows with the target's matched noise and the target's
own healthy rows. Its healthy validation rows show what a healthy gear reads as under this
machine's noise and grade; its faulty rows how the estimate grows with the size:

* **threshold**: the ``confidence`` quantile (default 95 %) of the healthy rows'
  estimates, pooled over the models with their weights: a healthy segment reads below it
  with that probability; and, for learners that read them (``own_prediction``: boosted
  trees), at least the same quantile of the machine's own healthy segments as models
  that never trained on them read them (weighted over the models, as ``predict``
  combines them). The simulated healthy rows carry the target's matched noise but not
  what another recording of the machine adds; boosted trees read them at 0 and, without
  this bound, stated limits of 0.005–0.09 on smooth development rigs whose next healthy
  recording read above them (85 % of the healthy test segments below the limit against
  the 95 % stated; benchmarks/RESULTS.md);
* **size-to-estimate curve**: the weighted isotonic (increasing) fit of the validation
  estimates on the true sizes;
* **limit**: the smallest size whose curve reaches the threshold (where an estimate of a
  fault that size is as likely above as below it), and at least the threshold itself.

An estimate below the limit says "not told apart from healthy at this confidence", not a
small size (:func:`below_detection_limit`, the ``below_detection_limit`` column of
``gearshot predict``).

A fit that **passed its check** on the machine's own hold-outs
(:mod:`~gearshot.estimator.fit_check`) knows better than the simulation what a healthy
segment of this machine reads: :func:`holdout_detection` then sets the limit to the
smallest estimate whose hold-out-calibrated interval
(:func:`~gearshot.estimator.uncertainty.holdout_interval`, two-sided ``2·confidence −
1``: the healthy hold-outs' over-reading and a later run's residue) leaves 0 out, so
that an estimate is below the limit exactly when its interval reaches 0. (On the PHM09
run-2 protocol the simulated limit, 0.46 at 30 Hz High, put 64 % of the chipped gear's
run-2 segments below it while every one of them read above every healthy one.)

The example itself must be told apart from healthy too
(:func:`gearshot.estimator.example.example_contrast`: below 0 the fit check fails).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from sklearn.isotonic import IsotonicRegression

from .._errors import GearshotError, NotFittedError

__all__ = ["DETECTION_CONFIDENCE", "DetectionLimit", "below_detection_limit",
           "detection_limit", "holdout_detection", "reach_zero_below_limit"]

FloatArray = NDArray[np.float64]

#: Share of healthy estimates below the threshold (the limit's stated confidence).
DETECTION_CONFIDENCE = 0.95


@dataclass(frozen=True)
class DetectionLimit:
    """What :func:`detection_limit` found.

    Attributes
    ----------
    limit : float
        Smallest size told apart from healthy (in [0, 1]).
    threshold : float
        The healthy estimates' ``confidence`` quantile.
    confidence : float
    """

    limit: float
    threshold: float
    confidence: float


def _weighted_quantile(values: FloatArray, weights: FloatArray, q: float) -> float:
    order = np.argsort(values, kind="stable")
    cum = np.cumsum(weights[order])
    return float(values[order][min(int(np.searchsorted(cum, q * cum[-1])), len(cum) - 1)])


def _own_quantile(models: Sequence[Any], weights: FloatArray, confidence: float) -> float:
    """The ``confidence`` quantile of the machine's own healthy rows as the weighted
    models that never trained on them read them (0 when no model read them)."""
    own = [(wt, np.asarray(m.own_prediction, dtype=float)) for m, wt in zip(models, weights)
           if wt > 0 and getattr(m, "own_prediction", None) is not None]
    if not own:
        return 0.0
    reading = sum(wt * p for wt, p in own) / sum(wt for wt, _ in own)
    return float(np.quantile(reading, confidence, method="higher"))


def detection_limit(models: Sequence[Any], weights: Sequence[float], *,
                    confidence: float = DETECTION_CONFIDENCE,
                    n_grid: int = 201) -> DetectionLimit:
    """The detection limit of weighted step-8 models from their validation splits.

    Parameters
    ----------
    models : sequence of KnnModel or LearnedModel
        Each with ``validation_y`` and ``validation_prediction``.
    weights : sequence of float >= 0
        One per model (e.g. the calibration settings' weights).
    confidence : float in (0, 1), default 0.95
    n_grid : int, default 201
        Sizes on [0, 1] where the curve is read.

    Returns
    -------
    DetectionLimit

    Raises
    ------
    GearshotError
        When no model holds healthy and faulty validation rows with their estimates, or
        on a bad ``confidence`` or weights.
    """
    if not 0 < confidence < 1:
        raise GearshotError(f"confidence must lie in (0, 1); got {confidence!r}")
    w = np.asarray(weights, dtype=float)
    if w.shape != (len(models),) or not np.all(np.isfinite(w)) or np.any(w < 0) \
            or w.sum() <= 0:
        raise GearshotError(f"weights must hold one finite weight >= 0 per model "
                            f"({len(models)}), not all 0; got {list(w)!r}")
    ys, preds, row_w = [], [], []
    for model, weight in zip(models, w):
        pred = getattr(model, "validation_prediction", None)
        if pred is None or weight == 0:
            continue
        y = np.asarray(model.validation_y, dtype=float)
        ys.append(y)
        preds.append(np.asarray(pred, dtype=float))
        row_w.append(np.full(y.size, weight / y.size))
    if not ys:
        raise GearshotError("detection_limit needs models with validation estimates "
                            "(fitted by this version of gearshot)")
    y, pred, rw = np.concatenate(ys), np.concatenate(preds), np.concatenate(row_w)
    healthy = y == 0
    if not healthy.any() or healthy.all():
        raise GearshotError(f"detection_limit needs healthy and faulty validation rows; got "
                            f"{int(healthy.sum())} healthy of {y.size}")
    threshold = max(_weighted_quantile(pred[healthy], rw[healthy], confidence),
                    _own_quantile(models, w, confidence))
    curve = IsotonicRegression(increasing=True, out_of_bounds="clip").fit(
        y, pred, sample_weight=rw)
    grid = np.linspace(0.0, 1.0, n_grid)
    reached = np.flatnonzero(curve.predict(grid) >= threshold)
    crossing = float(grid[reached[0]]) if reached.size else 1.0
    return DetectionLimit(float(min(1.0, max(crossing, threshold))), threshold,
                          float(confidence))


def holdout_detection(check: Any, confidence: float = DETECTION_CONFIDENCE) -> float | None:
    """The detection limit a fit takes from its hold-outs (module docstring): the smallest
    estimate (on a 0.001 grid) whose hold-out-calibrated interval at ``2 · confidence -
    1`` leaves 0 out, when its
    fit check (``fit_check_``, a :class:`~gearshot.estimator.fit_check.FitCheck`) passed
    with healthy and example hold-outs; otherwise None (the simulated limit stands).
    """
    from .uncertainty import holdout_interval

    if check is None or not check.passed or not check.n_healthy or not check.n_example:
        return None
    healthy, example = check.residuals()
    grid = np.linspace(0.0, 1.0, 1001)
    low, _ = holdout_interval(grid, healthy, example, 2 * confidence - 1,
                              example_size=check.declared_size)
    above = np.flatnonzero(low > 0)
    return float(grid[above[0]]) if above.size else 1.0


def below_detection_limit(estimator: Any, estimates: ArrayLike) -> NDArray[np.bool_]:
    """Whether each estimate lies below the fitted estimator's ``detection_limit_``.

    Parameters
    ----------
    estimator : OneFaultShotEstimator
        Fitted.
    estimates : array_like (n,)
        Its size estimates (``predict``).

    Returns
    -------
    ndarray of bool (n,)
        True where the estimate does not tell the segment apart from healthy (an estimator
        fitted before ``detection_limit_`` existed: all False).
    """
    if not hasattr(estimator, "model_"):
        raise NotFittedError(f"{type(estimator).__name__} is not fitted; fit it before "
                             f"asking for its detection limit")
    limit = getattr(estimator, "detection_limit_", None)
    values = np.asarray(estimates, dtype=float)
    if limit is None:
        return np.zeros(values.shape, dtype=bool)
    return np.asarray(values < float(limit), dtype=bool)


def reach_zero_below_limit(estimator: Any, estimates: ArrayLike, low: ArrayLike,
                           coverage: float,
                           confidence: float = DETECTION_CONFIDENCE) -> FloatArray:
    """Lower interval bounds that reach 0 where the estimate lies below the detection limit.

    An estimate below ``detection_limit_`` is not told apart from healthy at
    ``confidence`` (one-sided): an interval of at least that confidence (``coverage ≥ 2 ·
    confidence − 1``, two-sided) that left 0 out would state a fault the fit cannot
    resolve. Below it the lower bound is 0; elsewhere, and for narrower intervals, ``low``
    is returned as it is. For a fit that passed its check the two already agree (its limit
    is the smallest estimate whose interval leaves 0 out, :func:`holdout_detection`); a
    fit that refused itself or has no hold-outs keeps its simulated limit, and its
    intervals otherwise follow the simulation or hold-outs that the check found wanting.

    Parameters
    ----------
    estimator : OneFaultShotEstimator
        Fitted.
    estimates, low : array_like (n,)
        Its estimates and the interval's lower bounds.
    coverage : float in (0, 1)
    confidence : float in (0, 1), default :data:`DETECTION_CONFIDENCE`

    Returns
    -------
    ndarray (n,)
    """
    bounds = np.asarray(low, dtype=float)
    if coverage < 2 * confidence - 1 - 1e-12:
        return bounds
    below = below_detection_limit(estimator, estimates)
    return np.asarray(np.where(below, 0.0, bounds), dtype=np.float64)
