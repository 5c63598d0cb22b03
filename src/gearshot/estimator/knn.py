"""Step 8 of the paper: K-nearest-neighbour regression, K chosen on one validation split.

:func:`fit_knn` (also :func:`gearshot.estimator.steps.fit_knn`, in the order of the steps)
returns a :class:`KnnModel`: the fitted scikit-learn pipeline and what choosing K left
behind (validation errors and residuals, for the prediction intervals).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
import sklearn
from numpy.typing import ArrayLike, NDArray
from sklearn.model_selection import ShuffleSplit
from sklearn.neighbors import KNeighborsRegressor
from sklearn.pipeline import Pipeline
from sklearn.preprocessing import StandardScaler
from sklearn.utils import check_random_state

from .._errors import GearshotError
from .._validation import as_signal_array

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
    validation_prediction : ndarray or None
        ``ŷ`` on the validation split at the chosen K (the detection limit reads the
        healthy rows' estimates from it; None in models saved before it existed).
    """

    pipeline: Pipeline
    n_neighbors: int
    validation_mae: FloatArray
    validation_residuals: FloatArray
    validation_y: FloatArray
    validation_indices: NDArray[np.intp]
    validation_prediction: FloatArray | None = None

    def predict(self, X: ArrayLike) -> FloatArray:
        """Fault sizes of feature rows ``X`` (n_samples, n_features): the pipeline's
        prediction (by :func:`_nearest` where the pipeline searches a k-d tree)."""
        knn, scale = self.pipeline.named_steps["knn"], self.pipeline.named_steps["scale"]
        rows = np.asarray(X)
        fit_X, fit_y = getattr(knn, "_fit_X", None), getattr(knn, "_y", None)
        if (rows.dtype == np.float64 and getattr(knn, "_fit_method", None) == "kd_tree"
                and fit_X is not None
                and fit_y is not None and rows.ndim == 2 and np.all(np.isfinite(rows))
                and rows.shape[1] == fit_X.shape[1] and fit_y.ndim == 1):
            idx = _nearest(fit_X, rows / scale.scale_, int(knn.n_neighbors))
            if idx is not None:   # sklearn's mean over the neighbours, as it takes it
                return np.asarray(np.mean(fit_y.reshape(-1, 1)[idx], axis=1).ravel(),
                                  dtype=float)
        return np.asarray(self.pipeline.predict(X), dtype=float)


def _knn_pipeline(k: int) -> Pipeline:
    return Pipeline([("scale", StandardScaler(with_mean=False)),
                     ("knn", KNeighborsRegressor(n_neighbors=k))])


def _nearest(train: FloatArray, query: FloatArray, k: int) -> NDArray[np.intp] | None:
    """Indices of the ``k`` nearest ``train`` rows of every ``query`` row, nearest first, or
    None where two of the distances that decide them are equal.

    One brute-force matrix of squared distances, summed feature by feature as
    scikit-learn's k-d tree sums them: the same order wherever no two distances tie (a
    tie the tree may break otherwise: the caller asks the tree then).
    """
    d2 = np.zeros((query.shape[0], train.shape[0]))
    for j in range(train.shape[1]):
        step = query[:, j, None] - train[None, :, j]
        d2 += step * step
    nearest = (np.argpartition(d2, k, axis=1)[:, : k + 1] if k < d2.shape[1]
               else np.broadcast_to(np.arange(d2.shape[1]), d2.shape))
    near_d2 = np.take_along_axis(d2, nearest, axis=1)
    order = np.take_along_axis(nearest, np.argsort(near_d2, axis=1), axis=1)
    ranked = np.take_along_axis(d2, order, axis=1)
    if np.any(ranked[:, 1:] == ranked[:, :-1]):
        return None
    return np.asarray(order[:, :k], dtype=np.intp)


def _validation_neighbours(X_train: FloatArray, y_train: FloatArray, X_val: FloatArray,
                           k: int) -> NDArray[np.intp]:
    """Indices of the ``k`` nearest training rows of every validation row, nearest first,
    after scaling by the training std: what the probe pipeline ``_knn_pipeline(k)`` fitted
    on the training rows answers (:func:`_nearest` where that pipeline searches a k-d
    tree: fewer than 16 features and ``k`` below half the rows; else the pipeline itself).
    """
    idx = None
    if X_train.shape[1] <= 15 and k < X_train.shape[0] // 2:
        with sklearn.config_context(assume_finite=True, skip_parameter_validation=True):
            scaler = StandardScaler(with_mean=False).fit(X_train)
        idx = _nearest(X_train / scaler.scale_, X_val / scaler.scale_, k)
    if idx is None:
        probe = _knn_pipeline(k).fit(X_train, y_train)
        _, found = probe.named_steps["knn"].kneighbors(
            probe.named_steps["scale"].transform(X_val), n_neighbors=k)
        idx = np.asarray(found, dtype=np.intp)
    return idx


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
    X = as_signal_array(X, "X", min_ndim=2, max_ndim=2, max_abs=None)
    y = as_signal_array(y, "y", max_ndim=1, max_abs=None)
    if y.shape != X.shape[:1]:
        raise GearshotError(f"y must hold one label per row of X ({X.shape[0]}); got shape "
                            f"{y.shape}")
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
    idx = _validation_neighbours(X[train], y[train], X[val], k_max)
    neighbour_y = y[train][idx]  # (n_val, k_max), nearest first
    running_mean = np.cumsum(neighbour_y, axis=1) / np.arange(1, k_max + 1)
    mae_all = np.mean(np.abs(running_mean - y[val][:, None]), axis=0)
    mae = mae_all[candidates - 1]
    best = int(candidates[int(np.argmin(mae))])
    residuals = np.abs(running_mean[:, best - 1] - y[val])
    with sklearn.config_context(assume_finite=True, skip_parameter_validation=True):
        # what _knn_pipeline(best).fit(X, y) fits, step by step (checked above: the
        # checks are not redone)
        scaler = StandardScaler(with_mean=False).fit(X)
        knn = KNeighborsRegressor(n_neighbors=best).fit(X / scaler.scale_, y)
    final = Pipeline([("scale", scaler), ("knn", knn)])
    return KnnModel(final, best, mae_all, residuals, y[val], val,
                    np.asarray(running_mean[:, best - 1], dtype=np.float64))
