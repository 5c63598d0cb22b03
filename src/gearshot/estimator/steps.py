"""The paper's eight steps (Matania et al. 2023, Fig. 12), one named function each.

1. :func:`select_features`        invariance to what the TF estimate leaves unmitigated
2. :func:`tune_grade`             pick the simulated surface grade from the one example
3. :func:`estimate_tf`            TF from one long healthy target signal
4. :func:`propagate_simulated`    simulated SAs through that TF
5. :func:`normalize_rms`          divide by the mean RMS of the domain's healthy SAs
6. :func:`suppress_harmonics_simulated` / :func:`suppress_harmonics_target`
7. :func:`centred_features`       features minus the healthy mean of their domain
8. :func:`fit_knn`                K-nearest-neighbour regression, K chosen on a 70/30 split
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
from sklearn.model_selection import ShuffleSplit
from sklearn.neighbors import KNeighborsRegressor
from sklearn.pipeline import Pipeline
from sklearn.preprocessing import StandardScaler
from sklearn.utils import check_random_state

from .._errors import GearshotError
from ..features import extract_features
from ..signal import subtract_healthy
from ..transfer import estimate_transfer_function, mean_rms, propagate, rms_normalize

__all__ = [
    "select_features",
    "feature_invariance_errors",
    "tune_grade",
    "grade_weights",
    "prune_weights",
    "conformal_quantile",
    "mixture_interval",
    "estimate_tf",
    "propagate_simulated",
    "normalize_rms",
    "suppress_harmonics_simulated",
    "suppress_harmonics_target",
    "split_target_healthy",
    "centred_features",
    "fit_knn",
    "KnnModel",
]


# ---------------------------------------------------------------- step 3 and 4
def estimate_tf(healthy_long, n_points, *, nfft=2**15, segment_size=200):
    """Step 3: minimum-phase TF estimate from one long healthy angle-domain signal."""
    return estimate_transfer_function(healthy_long, n_points, nfft=nfft,
                                      segment_size=segment_size)


def propagate_simulated(sim_sa, tf):
    """Step 4: simulated SAs through a TF on their DFT grid (``tf=None``: unchanged)."""
    if tf is None:
        return np.asarray(sim_sa, dtype=float)
    return propagate(sim_sa, tf)


# ---------------------------------------------------------------- step 5
def normalize_rms(signals, healthy):
    """Step 5: divide by the mean RMS of the healthy SAs of the same domain."""
    return rms_normalize(signals, healthy)


# ---------------------------------------------------------------- step 6
def suppress_harmonics_simulated(sim_sa, healthy_mask):
    """Step 6, simulated side: subtract the first healthy simulated SA from every SA."""
    sim_sa = np.asarray(sim_sa, dtype=float)
    first = int(np.flatnonzero(healthy_mask)[0])
    return sim_sa - sim_sa[first]


def split_target_healthy(target_healthy, *, ref_fraction=0.2):
    """Split target healthy SAs into (training part, references): the last fifth are references."""
    n = target_healthy.shape[0]
    n_ref = max(1, int(round(n * ref_fraction)))
    if n - n_ref < 1:
        raise GearshotError(
            f"target_healthy holds {n} SAs; at least 2 are needed to keep references apart "
            f"from training (5 or more recommended)")
    return target_healthy[: n - n_ref], target_healthy[n - n_ref:]


def suppress_harmonics_target(signals, references, *, upsample=100):
    """Step 6, target side: subtract the best delay-aligned healthy reference."""
    return subtract_healthy(signals, references, upsample=upsample)


# ---------------------------------------------------------------- step 7
def centred_features(sa, healthy_mean=None, *, mesh_order, names, healthy_mask=None):
    """Step 7: features of (suppressed) SAs minus a healthy mean.

    Either ``healthy_mean`` (a feature vector: centre on another set's healthy mean) or
    ``healthy_mask`` (centre on the mean of these SAs' own healthy rows) is given.

    Returns
    -------
    features : ndarray (n_signals, n_features)
    mean : ndarray (n_features,)
        The healthy mean used.
    """
    feats = extract_features(sa, mesh_order, names=names)
    if healthy_mean is None:
        if healthy_mask is None or not np.any(healthy_mask):
            raise GearshotError("centred_features needs healthy_mean or a non-empty "
                                "healthy_mask")
        healthy_mean = feats[np.asarray(healthy_mask)].mean(axis=0)
    return feats - healthy_mean, np.asarray(healthy_mean)


# ---------------------------------------------------------------- step 8
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
    """

    pipeline: Pipeline
    n_neighbors: int
    validation_mae: np.ndarray
    validation_residuals: np.ndarray
    validation_y: np.ndarray

    def predict(self, X):
        return self.pipeline.predict(X)


def _knn_pipeline(k):
    return Pipeline([("scale", StandardScaler(with_mean=False)),
                     ("knn", KNeighborsRegressor(n_neighbors=k))])


def fit_knn(X, y, *, n_neighbors=range(1, 101), validation_fraction=0.3, random_state=None):
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
    random_state : int, Generator or None

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
    return KnnModel(final, best, mae_all, residuals, y[val])


# ---------------------------------------------------------------- step 1
def feature_invariance_errors(a, b):
    """Per-feature error ``mean_n |a_n - b_n| / min(std a, std b)`` of paired features."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = np.minimum(a.std(axis=0), b.std(axis=0))
    with np.errstate(divide="ignore", invalid="ignore"):
        err = np.mean(np.abs(a - b), axis=0) / scale
    return np.where(scale > 0, err, np.inf)


def _long_healthy_signal(healthy_sa, n_cycles, noise_rms, rng):
    """A long cycle-domain healthy signal of one gear: its SA repeated, fresh noise each cycle.

    What a long healthy recording is in the angle domain: the gear's periodic vibration plus
    non-synchronous vibration, here white noise.
    """
    one = healthy_sa[rng.integers(0, healthy_sa.shape[0])]
    return one + noise_rms * rng.standard_normal((n_cycles, one.size))


def select_features(sim_sa, fault_size, selection_tf, *, mesh_order, names,
                    threshold=0.10, noise_fraction=0.10, n_long_cycles=128,
                    random_state=None, return_features=False):
    """Step 1: keep features that the TF estimate makes invariant to the transfer path.

    A "test" set is the simulated SAs plus white noise (``noise_fraction`` of the healthy
    RMS) through the held-out ``selection_tf``; a "training" set is the same simulated SAs
    through the TF *estimated* (step 3) from a long healthy signal of the test set. Steps
    5–7 are applied to both (both are simulated signals of the same gears, so both subtract
    their first healthy SA) and feature ``i`` is kept when ``mean_n |a_in - b_in| / min(std a_i, std b_i) < threshold``.

    Parameters
    ----------
    sim_sa : ndarray (n_signals, n_points)
        Simulated SAs of one grade.
    fault_size : ndarray (n_signals,)
        Their sizes (0 healthy).
    selection_tf : ndarray of complex (n_points,)
        The held-out TF on the SA grid.
    mesh_order : int
    names : sequence of str
        Candidate features.
    threshold : float
    noise_fraction : float
    n_long_cycles : int
        Cycles in the long healthy test signal used for the TF estimate.
    random_state : int, Generator or None
    return_features : bool, default False
        Also return the paired feature arrays (what the paper's Fig. 11 plots).

    Returns
    -------
    selected : tuple of str
        At least one name: when no feature passes, the one with the smallest error.
    errors : dict name → error
    (train, test) : tuple of ndarray (n_signals - 1, n_features)
        Only with ``return_features``: the features through the estimated and the true TF.
    """
    rng = np.random.default_rng(check_random_state(random_state).randint(2**31 - 1))
    sim_sa = np.asarray(sim_sa, float)
    healthy = np.asarray(fault_size) == 0
    n_points = sim_sa.shape[1]
    noise_rms = noise_fraction * mean_rms(sim_sa[healthy])
    noisy = sim_sa + noise_rms * rng.standard_normal(sim_sa.shape)
    test = propagate(noisy, selection_tf)
    long_cycles = propagate(_long_healthy_signal(sim_sa[healthy], n_long_cycles, noise_rms,
                                                 rng), selection_tf)
    tf_hat = estimate_tf(long_cycles.ravel(), n_points)
    train = propagate(sim_sa, tf_hat)

    train = normalize_rms(train, train[healthy])
    train = suppress_harmonics_simulated(train, healthy)
    f_train, _ = centred_features(train, mesh_order=mesh_order, names=names,
                                  healthy_mask=healthy)

    test = normalize_rms(test, test[healthy])
    test = suppress_harmonics_simulated(test, healthy)
    f_test, _ = centred_features(test, mesh_order=mesh_order, names=names,
                                 healthy_mask=healthy)
    keep = np.ones(len(test), bool)
    keep[np.flatnonzero(healthy)[0]] = False  # the subtracted reference itself
    err = feature_invariance_errors(f_train[keep], f_test[keep])
    errors = dict(zip(names, err.tolist()))
    selected = tuple(n for n, e in errors.items() if e < threshold)
    if not selected:
        selected = (min(errors, key=errors.get),)
    if return_features:
        return selected, errors, (f_train[keep], f_test[keep])
    return selected, errors


# ---------------------------------------------------------------- step 2
def tune_grade(predict_example: Callable[[int], float], grades: Sequence[int],
               faulty_size: float, *, smoothing="isotonic"):
    """Step 2: the grade whose model predicts the one faulty example best.

    The paper keeps the grade whose prediction of the example is nearest its true size.
    With one example that choice is noisy (each grade's KNN prediction scatters), while the
    underlying trend is monotone: a coarser simulated grade puts more tooth-profile energy
    into the training signals, which moves the example's predicted size one way. With
    ``smoothing="isotonic"`` the predictions are first fitted by a monotone (isotonic)
    curve over the grades and the grade nearest on that curve is kept (ties: the one with
    the smaller raw error); ``smoothing="none"`` is the paper's literal rule.

    Parameters
    ----------
    predict_example : callable grade → predicted size of the faulty example
    grades : sequence of int
    faulty_size : float
        The example's true size.
    smoothing : {"isotonic", "none"}

    Returns
    -------
    grade : int
    curve : dict with arrays ``grade``, ``prediction``, ``smoothed``, ``abs_error``
        (``abs_error`` is of the curve used for the choice).
    """
    if smoothing not in ("isotonic", "none"):
        raise GearshotError(f"smoothing must be 'isotonic' or 'none'; got {smoothing!r}")
    grades = [int(g) for g in grades]
    preds = np.array([float(predict_example(g)) for g in grades])
    raw_error = np.abs(preds - faulty_size)
    smoothed = preds
    if smoothing == "isotonic" and len(grades) > 2:
        import warnings

        from sklearn.isotonic import IsotonicRegression

        with warnings.catch_warnings():  # 'auto' direction on a flat curve: either is fine
            warnings.simplefilter("ignore", UserWarning)
            smoothed = IsotonicRegression(increasing="auto").fit_transform(grades, preds)
    errors = np.abs(smoothed - faulty_size)
    candidates = np.flatnonzero(np.isclose(errors, errors.min(), rtol=0, atol=1e-12))
    best = grades[int(candidates[np.argmin(raw_error[candidates])])]
    return best, {"grade": np.array(grades), "prediction": preds, "smoothed": smoothed,
                  "abs_error": errors}


def grade_weights(predictions, grades, faulty_size, validation_residuals, *,
                  coverage=0.9, min_weight=1e-3):
    """Step 2, soft form: weight each grade by how well it predicts the faulty example.

    ``w_g ∝ exp(-½ ((ŷ_g - y) / σ)²)`` with ``σ`` half the ``coverage`` quantile of the
    best grade's validation residuals (the scatter a correct model shows on one signal).
    Grades below ``min_weight`` of the total are dropped and the rest renormalized.

    Parameters
    ----------
    predictions : array_like (n_grades,)
        Each grade model's prediction of the example.
    grades : sequence of int
    faulty_size : float
    validation_residuals : array_like
        ``|y - ŷ|`` of the best grade's model on its validation split.

    Returns
    -------
    dict grade → weight (sums to 1, largest first)
    """
    preds = np.asarray(predictions, float)
    sigma = max(0.5 * conformal_quantile(validation_residuals, coverage), 1e-3)
    logw = -0.5 * ((preds - faulty_size) / sigma) ** 2
    return prune_weights(grades, np.exp(logw - logw.max()), min_weight)


def prune_weights(grades, weights, min_weight=1e-3):
    """Normalize grade weights, drop those below ``min_weight`` and renormalize.

    Returns
    -------
    dict grade → weight (sums to 1, largest first; ties in the given grade order)
    """
    w = np.asarray(weights, float)
    w = w / w.sum()
    keep = w >= min_weight
    w = w[keep] / w[keep].sum()
    kept = np.asarray(grades)[keep]
    order = np.argsort(-w, kind="stable")
    return {int(kept[i]): float(w[i]) for i in order}


def conformal_quantile(residuals, coverage):
    """Split-conformal quantile: the ⌈(n+1)·coverage⌉-th smallest absolute residual.

    ``coverage`` may be an array of levels (then an array of quantiles is returned).
    """
    res = np.sort(np.abs(np.asarray(residuals, float)))
    if res.size == 0:
        raise GearshotError("conformal_quantile needs at least one residual")
    rank = np.ceil((res.size + 1) * np.asarray(coverage, float)).astype(int) - 1
    q = res[np.clip(rank, 0, res.size - 1)]
    return float(q) if q.ndim == 0 else q


def mixture_interval(predictions, weights, residuals, coverage, *, discrepancy=0.0,
                     n_levels=200):
    """Central ``coverage`` interval of a weighted mixture of symmetric residual laws.

    Model ``g`` says ``y = ŷ_g ± e``. The error ``e`` combines the model's absolute
    validation residuals ``r`` with ``δ ~ N(0, discrepancy²)``, an error the simulation
    cannot show (the simulation-to-reality gap left after tuning): at each level ``p`` the
    two quantiles add in quadrature, ``e_p = sqrt(r_p² + (discrepancy · z_p)²)`` with
    ``z_p`` the level-``p`` quantile of ``|N(0, 1)|``. That sum is exact when ``r`` is
    Gaussian too, never narrower than ``r_p`` and pure Gaussian when the residuals are 0.
    ``r_p`` is the split-conformal quantile (the ⌈(n+1)p⌉-th smallest residual), so one
    model without discrepancy gives the split-conformal interval. Each law is summarized
    by ``n_levels`` levels, either sign equally likely; the mixture weights the models by
    ``weights``.

    Parameters
    ----------
    predictions : dict grade → ndarray (n,)
    weights : dict grade → float
    residuals : dict grade → ndarray
    coverage : float in (0, 1)
    discrepancy : float >= 0
        Standard deviation of ``δ`` (fault-size units).

    Returns
    -------
    low, high : ndarray (n,)
    """
    from scipy.stats import halfnorm

    if not discrepancy >= 0:
        raise GearshotError(f"discrepancy must be >= 0; got {discrepancy!r}")
    levels = (np.arange(n_levels) + 0.5) / n_levels
    gauss = discrepancy * halfnorm.ppf(levels)
    values, mass = [], []
    for g, w in weights.items():
        r = np.hypot(conformal_quantile(residuals[g], levels), gauss)
        pred = np.asarray(predictions[g], float)[:, None]
        values += [pred - r, pred + r]
        mass.append(np.full(2 * n_levels, w / (2 * n_levels)))
    values = np.concatenate(values, axis=1)
    mass = np.concatenate(mass)
    order = np.argsort(values, axis=1)
    sorted_values = np.take_along_axis(values, order, axis=1)
    cdf = np.cumsum(mass[order], axis=1) / mass.sum()
    tail = (1 - coverage) / 2
    lo_idx = np.minimum((cdf < tail).sum(axis=1), values.shape[1] - 1)
    hi_idx = np.minimum((cdf < 1 - tail).sum(axis=1), values.shape[1] - 1)
    rows = np.arange(values.shape[0])
    return sorted_values[rows, lo_idx], sorted_values[rows, hi_idx]
