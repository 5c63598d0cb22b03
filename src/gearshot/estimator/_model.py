"""OneFaultShotEstimator: the paper's estimator as a scikit-learn regressor."""

from __future__ import annotations

import numbers
import zlib
from typing import Any

import numpy as np
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.utils import check_random_state
from sklearn.utils.validation import check_is_fitted

from .._errors import GearshotError
from .._validation import as_signal_array, check_in_range, check_int
from ..features import PAPER_FEATURES, available_features
from ..transfer import mean_rms, resample_transfer_function
from . import steps
from .matching import add_matched_noise, residual_noise_power, shrink_tf
from .zero_shot import healthy_signature, match_grade, signature_weights

__all__ = ["OneFaultShotEstimator"]


def _database_by_grade(database, n_points=None):
    """Split a simulated database (xarray.Dataset or mapping) into {grade: (sa, y)}."""
    try:
        sa = np.asarray(database["sa"], dtype=float)
        sizes = np.asarray(database["fault_size"], dtype=float)
        grades = np.asarray(database["grade"]).astype(int)
    except (KeyError, TypeError, ValueError) as exc:
        raise GearshotError(
            "database must be a simulated database (xarray.Dataset with 'sa', "
            f"'fault_size' and 'grade', e.g. from gearshot.sim.load_database); {exc}") from None
    sa = as_signal_array(sa, "database['sa']", min_ndim=2, max_ndim=2, min_length=16)
    if grades.ndim == 0:
        grades = np.full(sa.shape[0], int(grades))
    if sizes.shape != (sa.shape[0],) or grades.shape != (sa.shape[0],):
        raise GearshotError(
            f"database coords fault_size {sizes.shape} and grade {grades.shape} must have "
            f"one value per signal ({sa.shape[0]})")
    if n_points is not None and sa.shape[1] != n_points:
        raise GearshotError(f"database SAs have {sa.shape[1]} points but target SAs have "
                            f"{n_points}")
    out = {}
    for g in np.unique(grades):
        m = grades == g
        if not np.any(sizes[m] == 0):
            raise GearshotError(f"database holds no healthy signal (fault_size == 0) for "
                                f"grade {g}; the simulated side needs healthy references")
        out[int(g)] = (sa[m], sizes[m])
    return out


class OneFaultShotEstimator(RegressorMixin, BaseEstimator):
    """Estimate FTFF size from SAs with one faulty example (Matania et al. 2023).

    Parameters
    ----------
    features : sequence of str, optional
        Candidate features (default the paper's four).
    selection_threshold : float, default 0.10
        Keep features whose invariance error is below this (step 1).
    grades : iterable of int, default range(1, 13)
        DIN grades tried by simulation tuning (step 2); those absent from the database
        are skipped.
    select_features : bool, default True
    tune_simulation : bool, default True
        When False, ``nominal_grade`` is used.
    nominal_grade : int, default 7
        Grade used without tuning and for feature selection.
    rms_normalization : bool, default True
    transfer_function : {"estimate", "none"} or array_like of complex, default "estimate"
        Estimate the TF from ``healthy_long`` (step 3), use none, or use a given TF
        (on the SA grid, or one-sided to be resampled).
    n_neighbors : iterable of int, default range(1, 101)
    validation_fraction : float, default 0.3
    mesh_order : int, default 38
    zero_shot : bool, default False
        No faulty example: choose the grade by matching healthy-signal statistics
        (:func:`~gearshot.estimator.match_grade`). With soft weighting the grades are
        weighted by that match, or uniformly when no grade's simulation resembles the
        target's healthy data (:func:`~gearshot.estimator.signature_weights`).
    upsample : int, default 100
        Delay resolution (1/upsample sample) of target harmonic suppression.
    tuning_smoothing : {"isotonic", "none"}, default "isotonic"
        Fit the example's predicted size over the grades by a monotone curve before
        choosing (robust to KNN scatter); "none" is the paper's literal nearest rule.
    grade_weighting : {"soft", "best"}, default "soft"
        "best" predicts with the one tuned grade (the paper). "soft" averages the models of
        every grade, weighted by how well each predicts the faulty example (a Gaussian
        likelihood whose width is half the 90 % validation-residual quantile of the best
        grade): one example cannot pin the grade down, and averaging over the grades it
        leaves plausible is steadier (see :func:`steps.grade_weights`).
    noise_matching : bool, default False
        Add to the simulated SAs (after RMS normalization) noise with the per-order power
        of the target's non-synchronous residue, measured from its healthy SAs after
        harmonic suppression (:mod:`gearshot.estimator.matching`). Needs
        ``rms_normalization``.
    tf_exponent : float in [0, 1], default 1.0
        Trust in the blind TF estimate (step 3): the simulated SAs go through the minimum-
        phase TF of magnitude ``|TF|**tf_exponent`` (0: flat, i.e. RMS normalization only;
        1: the paper's estimate); see :func:`gearshot.estimator.matching.shrink_tf`.
    model_discrepancy : float >= 0, default 0.08
        Standard deviation (fault-size units) of the simulation-to-reality error that
        :meth:`predict_interval` adds to the simulated validation residuals. Conformal
        residuals come from the simulated domain and cannot show the bias that one
        example leaves after tuning; 0.08 is of the order of the method's typical
        error after domain adaptation (an MAE of about 6 %, as in the paper). 0 gives
        pure split-conformal intervals.
    random_state : int, numpy Generator/RandomState or None

    Attributes
    ----------
    selected_features_ : tuple of str
    feature_errors_ : dict
    selection_features_ : (train, test) tuple of ndarray or None
        Step 1's paired candidate features through the estimated and the held-out TF
        (the paper's Fig. 11; see :func:`gearshot.plotting.plot_feature_invariance`).
    grade_ : int
        The best grade (the paper's choice).
    grade_weights_ : dict grade → weight
        Weights of the grade models that predict (``{grade_: 1.0}`` unless soft).
    tuning_curve_ : dict of arrays (grade, prediction, abs_error) or None
    transfer_function_ : ndarray of complex or None
    n_neighbors_ : int
    """

    def __init__(self, *, features=None, selection_threshold=0.10, grades=range(1, 13),
                 select_features=True, tune_simulation=True, nominal_grade=7,
                 rms_normalization=True, transfer_function="estimate",
                 n_neighbors=range(1, 101), validation_fraction=0.3, mesh_order=38,
                 zero_shot=False, upsample=100, tuning_smoothing="isotonic",
                 grade_weighting="soft", model_discrepancy=0.08, noise_matching=False,
                 tf_exponent=1.0, random_state=None):
        self.features = features
        self.selection_threshold = selection_threshold
        self.grades = grades
        self.select_features = select_features
        self.tune_simulation = tune_simulation
        self.nominal_grade = nominal_grade
        self.rms_normalization = rms_normalization
        self.transfer_function = transfer_function
        self.n_neighbors = n_neighbors
        self.validation_fraction = validation_fraction
        self.mesh_order = mesh_order
        self.zero_shot = zero_shot
        self.upsample = upsample
        self.tuning_smoothing = tuning_smoothing
        self.grade_weighting = grade_weighting
        self.model_discrepancy = model_discrepancy
        self.noise_matching = noise_matching
        self.tf_exponent = tf_exponent
        self.random_state = random_state

    # ------------------------------------------------------------------ validation
    def _check_params(self):
        names = PAPER_FEATURES if self.features is None else tuple(self.features)
        unknown = [n for n in names if n not in available_features()]
        if not names or unknown:
            raise GearshotError(f"features holds unknown name(s) {unknown}; valid names are "
                                f"{list(available_features())}")
        check_in_range(self.selection_threshold, "selection_threshold", 0, np.inf,
                       low_inclusive=False)
        check_in_range(self.validation_fraction, "validation_fraction", 0, 1,
                       low_inclusive=False, high_inclusive=False)
        check_int(self.mesh_order, "mesh_order", minimum=1)
        check_int(self.upsample, "upsample", minimum=1)
        if self.grade_weighting not in ("soft", "best"):
            raise GearshotError(f"grade_weighting must be 'soft' or 'best'; got "
                                f"{self.grade_weighting!r}")
        check_in_range(self.model_discrepancy, "model_discrepancy", 0, 1)
        grades = [check_int(g, "grades", minimum=1, maximum=12) for g in self.grades]
        if not grades:
            raise GearshotError("grades must list at least one DIN grade")
        tf = self.transfer_function
        if isinstance(tf, str) and tf not in ("estimate", "none"):
            raise GearshotError(f"transfer_function must be 'estimate', 'none' or an array; "
                                f"got {tf!r}")
        return names, grades

    def _target_tf(self, healthy_long, n_points):
        tf = self.transfer_function
        if isinstance(tf, str):
            if tf == "none":
                return None
            if healthy_long is None:
                raise GearshotError("healthy_long is required with "
                                    "transfer_function='estimate'")
            return shrink_tf(steps.estimate_tf(healthy_long, n_points), self.tf_exponent)
        return _on_grid(tf, n_points, "transfer_function")

    # ------------------------------------------------------------------ the simulated side
    def _simulated_features(self, sa, y, names):
        """Steps 4–7 on one grade's simulated SAs; returns centred features."""
        healthy = y == 0
        sim = steps.propagate_simulated(sa, self.transfer_function_)
        if self.rms_normalization:
            sim = steps.normalize_rms(sim, sim[healthy])
        if self.noise_power_ is not None:
            sim = add_matched_noise(sim, self.noise_power_, np.random.default_rng(
                [self.noise_seed_, len(y)]))
        sim = steps.suppress_harmonics_simulated(sim, healthy)
        feats, _ = steps.centred_features(sim, mesh_order=self.mesh_order, names=names,
                                          healthy_mask=healthy)
        return feats

    def _target_features(self, sa):
        """Steps 5–7 on target SAs, with the fitted scale, references and healthy mean."""
        sa = np.atleast_2d(sa)
        if self.rms_normalization:
            sa = sa / self.target_scale_
        sub = steps.suppress_harmonics_target(sa, self.references_, upsample=self.upsample)
        feats, _ = steps.centred_features(sub, self.target_healthy_mean_,
                                          mesh_order=self.mesh_order,
                                          names=self.candidate_features_)
        return feats

    def _model_for_grade(self, grade, cols, seed):
        sa, y = self.database_[grade]
        X_sim = self._simulated_features(sa, y, self.candidate_features_)[:, cols]
        X = np.vstack([X_sim, self.target_healthy_features_[:, cols]])
        labels = np.concatenate([y, np.zeros(len(self.target_healthy_features_))])
        return steps.fit_knn(X, labels, n_neighbors=self.n_neighbors,
                             validation_fraction=self.validation_fraction,
                             random_state=seed)

    # ------------------------------------------------------------------ fit / predict
    def fit(self, database, target_healthy, faulty_example=None, faulty_size=None,
            healthy_long=None, *, selection_tf=None):
        """Fit on a simulated database, target healthy SAs and one faulty example.

        Parameters
        ----------
        database : xarray.Dataset
            Simulated database of the operating condition, all grades
            (:func:`gearshot.sim.load_database` with ``grade=None``).
        target_healthy : array_like (n_healthy, n_points)
            Healthy SAs of the target machine (≥ 5 recommended: the last fifth become
            harmonic-suppression references, the rest training data with label 0).
        faulty_example : array_like (n_points,)
            The one faulty SA of known size (omit with ``zero_shot=True``).
        faulty_size : float in (0, 1]
            Its size.
        healthy_long : array_like (n_samples,)
            Long healthy angle-domain target signal (≥ 2**15 samples) for the TF estimate.
        selection_tf : array_like of complex or TransferFunction
            The held-out TF for feature selection (on the SA grid, one-sided, or an object
            with ``to_signal_grid(n)``); needed when ``select_features``.

        Returns
        -------
        self
        """
        names, grades = self._check_params()
        rng = check_random_state(self.random_state)
        target_healthy = as_signal_array(target_healthy, "target_healthy", min_ndim=2,
                                         max_ndim=2, min_length=16)
        n_points = target_healthy.shape[1]
        if target_healthy.shape[0] < 2:
            raise GearshotError(f"target_healthy holds {target_healthy.shape[0]} SA(s); at "
                                f"least 2 are needed (5 or more recommended)")
        if not self.zero_shot:
            if faulty_example is None or faulty_size is None:
                raise GearshotError("faulty_example and faulty_size are required unless "
                                    "zero_shot=True")
            faulty_example = as_signal_array(faulty_example, "faulty_example", max_ndim=2)
            faulty_example = faulty_example.reshape(-1)
            if faulty_example.size != n_points:
                raise GearshotError(f"faulty_example has {faulty_example.size} points but "
                                    f"target_healthy SAs have {n_points}")
            if (isinstance(faulty_size, bool) or not isinstance(faulty_size, numbers.Real)
                    or not 0 < float(faulty_size) <= 1):
                raise GearshotError(f"faulty_size must lie in (0, 1]; got {faulty_size!r}")
            faulty_size = float(faulty_size)
        if healthy_long is not None:
            healthy_long = as_signal_array(healthy_long, "healthy_long", max_ndim=1)
        self.database_ = _database_by_grade(database, n_points)
        grades = [g for g in grades if g in self.database_]
        if not grades:
            raise GearshotError(f"none of grades={list(self.grades)!r} is in the database "
                                f"(it has {sorted(self.database_)})")
        nominal = self.nominal_grade if self.nominal_grade in self.database_ else grades[0]
        self.n_points_ = n_points
        self.transfer_function_ = self._target_tf(healthy_long, n_points)

        # target side (steps 5–7), independent of the grade
        self.target_scale_ = mean_rms(target_healthy)
        if self.rms_normalization and self.target_scale_ <= 0:
            raise GearshotError("target_healthy has zero RMS")
        scaled = target_healthy / self.target_scale_ if self.rms_normalization \
            else target_healthy
        train_h, self.references_ = steps.split_target_healthy(scaled)
        sub_h = steps.suppress_harmonics_target(train_h, self.references_,
                                                upsample=self.upsample)
        self.candidate_features_ = names
        feats_h, self.target_healthy_mean_ = steps.centred_features(
            sub_h, mesh_order=self.mesh_order, names=names,
            healthy_mask=np.ones(len(sub_h), bool))
        self.target_healthy_features_ = feats_h
        # tuning beyond the grade: the target's non-synchronous residue, measured
        self.noise_power_ = (residual_noise_power(sub_h)
                             if self.noise_matching and self.rms_normalization else None)
        # its seed comes from the data, so the other steps' random draws are unchanged
        self.noise_seed_ = zlib.crc32(np.ascontiguousarray(sub_h).tobytes())

        # step 1: feature selection on the nominal grade
        if self.select_features:
            if selection_tf is None:
                raise GearshotError("selection_tf is required with select_features=True "
                                    "(the held-out TF of step 1)")
            sel_tf = _on_grid(selection_tf, n_points, "selection_tf")
            sa_n, y_n = self.database_[nominal]
            selected, errors, self.selection_features_ = steps.select_features(
                sa_n, y_n, sel_tf, mesh_order=self.mesh_order, names=names,
                threshold=self.selection_threshold, random_state=rng, return_features=True)
        else:
            selected, errors, self.selection_features_ = names, {}, None
        self.selected_features_ = tuple(selected)
        self.feature_errors_ = errors
        cols = [names.index(n) for n in self.selected_features_]
        self.selected_columns_ = cols

        # step 2: simulation tuning (or zero-shot grade matching, or the nominal grade)
        seed = int(rng.randint(np.iinfo(np.int32).max))
        self.tuning_curve_ = None
        self.grade_weights_ = None
        if self.zero_shot:
            target_sig = healthy_signature(scaled, self.mesh_order)
            sims = {g: healthy_signature(
                steps.propagate_simulated(sa[y == 0], self.transfer_function_),
                self.mesh_order) for g, (sa, y) in self.database_.items() if g in grades}
            self.grade_, self.tuning_curve_ = match_grade(target_sig, sims)
            self.model_ = self._model_for_grade(self.grade_, cols, seed)
            if self.grade_weighting == "soft":
                weights, consistent = signature_weights(target_sig, sims)
                self.tuning_curve_["consistent"] = consistent
                self.grade_weights_ = weights
                self.grade_models_ = {g: self.model_ if g == self.grade_ else
                                      self._model_for_grade(g, cols, seed) for g in weights}
        elif self.tune_simulation and len(grades) > 1:
            x_example = self._target_features(faulty_example)[:, cols]
            models = {}

            def predict_example(g):
                models[g] = self._model_for_grade(g, cols, seed)
                return models[g].predict(x_example)[0]

            self.grade_, self.tuning_curve_ = steps.tune_grade(
                predict_example, grades, faulty_size, smoothing=self.tuning_smoothing)
            self.model_ = models[self.grade_]
            if self.grade_weighting == "soft":
                self.grade_weights_ = steps.grade_weights(
                    self.tuning_curve_["prediction"], grades, faulty_size,
                    self.model_.validation_residuals)
                self.grade_models_ = {g: models[g] for g in self.grade_weights_}
        else:
            self.grade_ = nominal if not self.tune_simulation else grades[0]
            self.model_ = self._model_for_grade(self.grade_, cols, seed)
        if self.grade_weights_ is None:
            self.grade_weights_ = {int(self.grade_): 1.0}
            self.grade_models_ = {int(self.grade_): self.model_}
        self.n_neighbors_ = self.model_.n_neighbors
        self.faulty_size_ = faulty_size
        del self.database_  # do not keep (or pickle) the whole database
        return self

    def features_of(self, sa):
        """Selected, centred target features of SAs (what the KNN sees, before scaling)."""
        check_is_fitted(self, "model_")
        sa = as_signal_array(sa, "sa", max_ndim=2)
        if sa.shape[-1] != self.n_points_:
            raise GearshotError(f"sa has {sa.shape[-1]} points per cycle; the estimator was "
                                f"fitted on {self.n_points_}")
        return self._target_features(sa)[:, self.selected_columns_]

    def predict(self, sa):
        """Fault sizes of target SAs.

        Parameters
        ----------
        sa : array_like (n_signals, n_points) or (n_points,)

        Returns
        -------
        ndarray (n_signals,)
        """
        X = self.features_of(sa)
        return sum(w * self.grade_models_[g].predict(X) for g, w in self.grade_weights_.items())

    def predict_interval(self, sa, coverage=0.9):
        """Prediction intervals: split-conformal residuals widened by the model discrepancy.

        Each grade model says ``y = ŷ_g ± r + δ``: ``r`` from its validation residuals
        (split conformal), ``δ ~ N(0, model_discrepancy²)`` the simulation-to-reality
        error the validation split cannot show. With soft grade weighting the interval
        is the central ``coverage`` range of the weighted mixture over the grade models
        (:func:`steps.mixture_interval`); with one model and ``model_discrepancy=0`` it
        is the plain split-conformal interval.

        Returns
        -------
        low, high : ndarray (n_signals,)
            Clipped to [0, 1].
        """
        coverage = check_in_range(coverage, "coverage", 0, 1, low_inclusive=False,
                                  high_inclusive=False)
        X = self.features_of(sa)
        discrepancy = float(self.model_discrepancy)
        if len(self.grade_weights_) == 1 and discrepancy == 0:
            pred = self.model_.predict(X)
            q = steps.conformal_quantile(self.model_.validation_residuals, coverage)
            return np.clip(pred - q, 0, 1), np.clip(pred + q, 0, 1)
        preds = {g: self.grade_models_[g].predict(X) for g in self.grade_weights_}
        low, high = steps.mixture_interval(
            preds, self.grade_weights_,
            {g: self.grade_models_[g].validation_residuals for g in self.grade_weights_},
            coverage, discrepancy=discrepancy)
        return np.clip(low, 0, 1), np.clip(high, 0, 1)

    def score(self, X, y, sample_weight=None):
        """Negative mean absolute error (higher is better)."""
        pred = self.predict(X)
        return -float(np.average(np.abs(pred - np.asarray(y, float)), weights=sample_weight))

    # ------------------------------------------------------------------ persistence
    def save(self, path):
        """Save the fitted estimator (joblib) with version metadata, atomically."""
        from .persistence import save_estimator

        save_estimator(self, path)

    @classmethod
    def load(cls, path):
        """Load an estimator saved by :meth:`save`."""
        from .persistence import load_estimator

        return load_estimator(path)


def _on_grid(tf: Any, n_points: int, name: str):
    """A TF on the n-point DFT grid from an array (grid or one-sided) or a TransferFunction."""
    if hasattr(tf, "to_signal_grid"):
        return np.asarray(tf.to_signal_grid(n_points))
    arr = as_signal_array(tf, name, max_ndim=1, allow_complex=True)
    if arr.size == n_points:
        return arr.astype(complex)
    return resample_transfer_function(arr, n_points)
