"""Step 8 of the paper: K-nearest-neighbour regression, K chosen on one validation split.

:func:`fit_knn` (also :func:`gearshot.estimator.steps.fit_knn`, in the order of the steps)
returns a :class:`KnnModel`: the fitted scikit-learn pipeline and what choosing K left
behind (validation errors and residuals, for the prediction intervals).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from sklearn.model_selection import ShuffleSplit
from sklearn.neighbors import KNeighborsRegressor
from sklearn.pipeline import Pipeline
from sklearn.preprocessing import StandardScaler
from sklearn.utils import check_random_state

from .._errors import GearshotError

__all__ = ["KnnModel", "fit_knn"]

FloatArray = NDArray[np.float64]
RandomStateLike = int | np.random.RandomState | None


@dataclass(frozen=True)
class KnnModel:
    """A fitted step-8 regressor with what choosing K left behind.

    Attributes
    ----------
    pipeline : sklearn.pipeline.Pipeline
        Scaling by the training std, then ``KNeighborsRegressor``; fitted on all data.
    n_neighbors : int
        The chosen K.
    validation_mae : ndarray
        Validation MAE for K = 1 … len(validation_mae).
    validation_residuals : ndarray
        ``|y - ŷ|`` on the validation split at the chosen K (for conformal intervals).
    validation_y : ndarray
        Labels of the validation split.
    validation_indices : ndarray of int
        Rows of the training data in the validation split.
    """

    pipeline: Pipeline
    n_neighbors: int
    validation_mae: FloatArray
    validation_residuals: FloatArray
    validation_y: FloatArray
    validation_indices: NDArray[np.intp]

    def predict(self, X: ArrayLike) -> FloatArray:
        """Fault sizes of feature rows ``X`` (n_samples, n_features)."""
        return np.asarray(self.pipeline.predict(X), dtype=float)


def _knn_pipeline(k: int) -> Pipeline:
    return Pipeline([("scale", StandardScaler(with_mean=False)),
                     ("knn", KNeighborsRegressor(n_neighbors=k))])


def fit_knn(X: ArrayLike, y: ArrayLike, *, n_neighbors: Iterable[int] = range(1, 101),
            validation_fraction: float = 0.3,
            random_state: RandomStateLike = None) -> KnnModel:
    """Step 8: KNN regression; K chosen by validation MAE on one random split.

    Features are divided by the training standard deviation (``StandardScaler`` without
    centring). For every candidate K the validation MAE is computed from one neighbour
    query of the largest K (equivalent to refitting per K, much faster); the final model
    is refitted on all of ``X`` with the best K.

    Parameters
    ----------
    X : ndarray (n_samples, n_features)
    y : ndarray (n_samples,)
    n_neighbors : iterable of int
        Candidate K values.
    validation_fraction : float
        Share of samples in the validation split.
    random_state : int, RandomState or None
        Seeds the split (which depends only on it and on ``n_samples``).

    Returns
    -------
    KnnModel
    """
    X = np.asarray(X, dtype=float)
    y = np.asarray(y, dtype=float)
    candidates = np.unique(np.asarray(list(n_neighbors), dtype=int))
    if candidates.size == 0 or candidates[0] < 1:
        raise GearshotError(f"n_neighbors must hold positive integers; got {n_neighbors!r}")
    if not 0 < validation_fraction < 1:
        raise GearshotError(f"validation_fraction must lie in (0, 1); got "
                            f"{validation_fraction!r}")
    if X.shape[0] < 4:
        raise GearshotError(f"fit_knn needs at least 4 training samples; got {X.shape[0]}")
    seed = check_random_state(random_state).randint(np.iinfo(np.int32).max)
    split = ShuffleSplit(n_splits=1, test_size=validation_fraction, random_state=seed)
    train, val = next(split.split(X))
    candidates = candidates[candidates <= train.size]
    if candidates.size == 0:
        candidates = np.array([1])
    k_max = int(candidates[-1])
    probe = _knn_pipeline(k_max).fit(X[train], y[train])
    scaled = probe.named_steps["scale"].transform(X[val])
    _, idx = probe.named_steps["knn"].kneighbors(scaled, n_neighbors=k_max)
    neighbour_y = y[train][idx]  # (n_val, k_max), nearest first
    running_mean = np.cumsum(neighbour_y, axis=1) / np.arange(1, k_max + 1)
    mae_all = np.mean(np.abs(running_mean - y[val][:, None]), axis=0)
    mae = mae_all[candidates - 1]
    best = int(candidates[int(np.argmin(mae))])
    residuals = np.abs(running_mean[:, best - 1] - y[val])
    final = _knn_pipeline(best).fit(X, y)
    return KnnModel(final, best, mae_all, residuals, y[val], val)
