"""Step 8's regressor, by name: the paper's KNN and the learners screened beyond it.

:func:`fit_regressor` fits one grade's (or one setting's) model on its feature rows and
returns an object with :class:`~gearshot.estimator.knn.KnnModel`'s interface (``predict``,
``n_neighbors``, ``validation_mae``, ``validation_residuals``, ``validation_y``,
``validation_indices``), which is what the grade choice, the intervals and the floors read:

================  =====================================================================
``"paper"``       KNN, K chosen on one validation split (:func:`~.steps.fit_knn`; the paper)
``"isotonic"``    a monotone map of one learned score: the least-squares linear score of
                  the standardised features, then isotonic regression of the size on it
``"boosting"``    gradient-boosted trees (``HistGradientBoostingRegressor``, absolute
                  error loss; the default of ``OneFaultShotEstimator``)
================  =====================================================================

The non-KNN learners hold out the same validation split as the KNN (a ``ShuffleSplit``
seeded alike), keep its residuals for the intervals, and refit on every row. Their
``n_neighbors`` is 1 and ``validation_mae`` holds one value: the validation MAE. When
the last ``n_own`` rows are the machine's own healthy segments, the validation probe
trains on none of them and reads them all (``own_prediction``): how a model of the
simulation reads this machine's healthy segments, which the detection limit needs
(:mod:`~gearshot.estimator.detection`).
"""

from __future__ import annotations

import functools
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np
import sklearn
from numpy.typing import ArrayLike, NDArray
from sklearn.ensemble import HistGradientBoostingRegressor
from sklearn.isotonic import IsotonicRegression
from sklearn.model_selection import ShuffleSplit
from sklearn.utils import check_random_state

from .._errors import GearshotError
from .._validation import as_signal_array
from . import steps
from .knn import KnnModel

__all__ = ["ESTIMATORS", "LearnedModel", "ScoreIsotonic", "StepModel", "fit_regressor"]

FloatArray = NDArray[np.float64]
RandomStateLike = int | np.random.RandomState | None

#: The names ``OneFaultShotEstimator(estimator=...)`` accepts.
ESTIMATORS = ("paper", "isotonic", "boosting")


class ScoreIsotonic:
    """Isotonic regression of ``y`` on a linear score of the standardised features.

    The score's direction is the least-squares fit of ``y`` on the features (a tiny ridge
    keeps it defined for constant or collinear columns); the isotonic fit then takes
    whatever monotone shape the size has along it, increasing or decreasing.
    """

    def fit(self, X: FloatArray, y: FloatArray) -> ScoreIsotonic:
        self.mean_ = X.mean(axis=0)
        self.scale_ = X.std(axis=0)
        self.scale_[self.scale_ == 0] = 1.0
        Z = (X - self.mean_) / self.scale_
        gram = Z.T @ Z + 1e-6 * len(Z) * np.eye(Z.shape[1])
        self.coef_ = np.linalg.solve(gram, Z.T @ (y - y.mean()))
        self.isotonic_ = IsotonicRegression(increasing="auto", out_of_bounds="clip").fit(
            Z @ self.coef_, y)
        return self

    def predict(self, X: FloatArray) -> FloatArray:
        Z = (np.asarray(X, float) - self.mean_) / self.scale_
        return np.asarray(self.isotonic_.predict(Z @ self.coef_), dtype=np.float64)


#: Trees and step of ``"boosting"`` (their product, 6, sets how far the fit moves from the
#: median; 30 trees at 0.2 scored 10.93 % on the development rigs against 11.11 % for 60
#: at 0.1, in about two thirds of the CPU time; benchmarks/RESULTS.md).
BOOSTING_TREES = 30
BOOSTING_STEP = 0.2
#: Leaves per tree of ``"boosting"``: the smallest of 4, 6, 8, 10, 15 whose development
#: rigs (100–123 × 2 draws) score within 0.1 point of 15's mean and 0.6 of its p90 with
#: every condition's 90 % coverage ≥ 85 % (15: 8.09 %, p90 15.07, 0.90 s per fit +
#: predict on rig 100; 10: 8.12; 8: 8.09; **6: 8.09 %, p90 15.16, 0.62 s**; 4: 8.14 %,
#: coverage at 30 rps / 10 N m 83.7 %; benchmarks/RESULTS.md "5. Speed").
BOOSTING_LEAVES = 6


@functools.cache
def _controller() -> Any:
    from threadpoolctl import ThreadpoolController

    return ThreadpoolController()


def _one_thread() -> Any:
    """A context in which the trees' OpenMP loops run on one thread: on a few hundred rows
    their threads cost more than they share (the library default's fit + predict on rig
    100 of the family took 1.32 s wall with the box's 2 threads and 0.92 s with one;
    benchmarks/RESULTS.md "5. Speed"). Process-wide while it lasts, as every OpenMP
    setting is."""
    return _controller().limit(limits=1, user_api="openmp")


def _learner(name: str, seed: int) -> Any:
    if name == "isotonic":
        return ScoreIsotonic()
    return HistGradientBoostingRegressor(
        loss="absolute_error", max_iter=BOOSTING_TREES, learning_rate=BOOSTING_STEP,
        max_leaf_nodes=BOOSTING_LEAVES, min_samples_leaf=10, random_state=seed)


@dataclass(frozen=True)
class LearnedModel:
    """A fitted non-KNN step-8 regressor with its validation split's residuals.

    Attributes
    ----------
    learner : object with ``predict``
        Fitted on every training row.
    n_neighbors : int
        Always 1 (the KNN's K has no meaning here).
    validation_mae : ndarray (1,)
        MAE on the validation split (of a learner fitted on the other rows).
    validation_residuals, validation_y : ndarray
        ``|y - ŷ|`` and ``y`` on the validation split.
    validation_indices : ndarray of int
    validation_prediction : ndarray
        ``ŷ`` on the validation split.
    own_prediction : ndarray or None
        ``ŷ`` of the validation probe, which trained on none of them, on the machine's own
        healthy rows (None when the fit named none).
    """

    learner: Any
    n_neighbors: int
    validation_mae: FloatArray
    validation_residuals: FloatArray
    validation_y: FloatArray
    validation_indices: NDArray[np.intp]
    validation_prediction: FloatArray | None = None
    own_prediction: FloatArray | None = None

    def predict(self, X: ArrayLike) -> FloatArray:
        """Fault sizes of feature rows ``X`` (n_samples, n_features), clipped to [0, 1]."""
        with _one_thread():
            raw = np.asarray(self.learner.predict(np.asarray(X, float)), dtype=np.float64)
        return np.asarray(np.clip(raw, 0.0, 1.0), dtype=np.float64)


#: What step 8 fits: the paper's KNN or another learner, with the same interface.
StepModel = KnnModel | LearnedModel


def fit_regressor(name: str, X: ArrayLike, y: ArrayLike, *,
                  n_neighbors: Iterable[int] = range(1, 101),
                  validation_fraction: float = 0.3,
                  random_state: RandomStateLike = None, n_own: int = 0) -> StepModel:
    """Step 8 with the regressor ``name`` (one of :data:`ESTIMATORS`).

    Parameters
    ----------
    name : {"paper", "isotonic", "boosting"}
    X : ndarray (n_samples, n_features)
    y : ndarray (n_samples,)
    n_neighbors : iterable of int
        The KNN's candidate K ("paper" only).
    validation_fraction : float in (0, 1)
        Share of rows in the validation split.
    random_state : int, RandomState or None
        Seeds the split (and the learner): the same split as :func:`fit_knn`'s.
    n_own : int >= 0, default 0
        The last ``n_own`` rows are the machine's own healthy segments (not "paper"):
        the validation probe leaves them out of its training and reads them.

    Returns
    -------
    KnnModel or LearnedModel
    """
    if name == "paper":   # step 8 as the paper's steps module has it
        return steps.fit_knn(X, y, n_neighbors=n_neighbors, validation_fraction=validation_fraction,
                       random_state=random_state)
    if name not in ESTIMATORS:
        raise GearshotError(f"estimator must be one of {ESTIMATORS}; got {name!r}")
    X = as_signal_array(X, "X", min_ndim=2, max_ndim=2, max_abs=None)
    y = as_signal_array(y, "y", max_ndim=1, max_abs=None)
    if y.shape != X.shape[:1]:
        raise GearshotError(f"y must hold one label per row of X ({X.shape[0]}); got shape "
                            f"{y.shape}")
    if not 0 < validation_fraction < 1:
        raise GearshotError(f"validation_fraction must lie in (0, 1); got "
                            f"{validation_fraction!r}")
    if X.shape[0] < 4:
        raise GearshotError(f"fit_regressor needs at least 4 training samples; got "
                            f"{X.shape[0]}")
    seed = check_random_state(random_state).randint(np.iinfo(np.int32).max)
    split = ShuffleSplit(n_splits=1, test_size=validation_fraction, random_state=seed)
    if not 0 <= n_own < X.shape[0]:
        raise GearshotError(f"n_own must lie in [0, {X.shape[0]}); got {n_own!r}")
    train, val = next(split.split(X))
    first_own = X.shape[0] - n_own
    simulated = train[train < first_own]   # the probe trains on no row of the machine's own
    with sklearn.config_context(assume_finite=True), _one_thread():
        probe = _learner(name, seed).fit(X[simulated], y[simulated])
        estimate = np.clip(probe.predict(X[val]), 0, 1)
        own = np.clip(probe.predict(X[first_own:]), 0, 1) if n_own else None
        residuals = np.abs(estimate - y[val])
        final = _learner(name, seed).fit(X, y)
    return LearnedModel(final, 1, np.array([residuals.mean()]), residuals, y[val],
                        np.asarray(val, dtype=np.intp), np.asarray(estimate, np.float64),
                        None if own is None else np.asarray(own, np.float64))
