"""OneFaultShotEstimator: the paper's estimator as a scikit-learn regressor.

``fit`` follows the block diagram of the paper (Fig. 12):

* the target side (steps 3 and 5–7 on the target's healthy SAs),
* feature selection (step 1, on the nominal grade),
* the grade choice, one strategy per mode: ``tuned`` (step 2: the one grade the paper keeps),
  ``soft`` (step 2, every grade weighted by how well it predicts the example),
  ``nominal`` (no tuning) and ``zero_shot`` (healthy statistics, no example),
* the grade models (steps 4–8 on each chosen grade's simulated SAs).

Every part is a short function or method that returns what it learned; ``fit`` sets the
learned attributes only once every part has succeeded, so a failed fit leaves the
estimator as it was. The parts live beside this module, named after what they do:

=====================  ==============================================================
``_inputs``            ``fit``'s arguments checked, per-step seeds, step 1's default TF
``_database``          the database split by fault type and grade, with its twins
``_target``            the target side (steps 3, 5–7 on the target's SAs)
``_grade_choice``      step 1 on the nominal grade, the grade models, the strategies
``_simulated``         steps 4–6 of the simulated side as spectra, block by block
``_joint``             the joint calibration (``calibration="joint"``)
``_prediction``        predict, intervals, comparability, score, save/load
=====================  ==============================================================
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any, ClassVar, Self

import numpy as np
from numpy.typing import ArrayLike, NDArray
from sklearn.base import BaseEstimator, RegressorMixin

from ..fault_registry import FAULT_TYPE_NAMES
from ..features import PAPER_FEATURES, available_features
from ._database import _database_by_grade, _database_twins, _has_twins, _select_fault_type
from ._grade_choice import _GradeChoosing
from ._inputs import (
    STEP_SEEDS,
    _step_seeds,
    check_fit_inputs,
    default_selection_tf,
    spread_references,
)
from ._joint import _JointCalibration
from ._pair import as_orders, resolve_mesh_orders
from ._params import (
    ArrayOrObject,
    Boolean,
    Constraint,
    IntegerSequence,
    Interval,
    NameSequence,
    NoneValue,
    Options,
    RandomStateValue,
    Resolvable,
    validate_params,
)
from ._prediction import _Prediction
from ._target import fit_target_side
from .calibration import CALIBRATION_STRATEGIES, CalibrationOptions, resolve_calibration
from .comparability import fit_comparability
from .detection import detection_limit, holdout_detection
from .drift import fit_drift
from .example import example_contrast
from .fit_check import check_holdouts, split_holdouts
from .options import EstimatorOptions, resolve_options
from .regressors import ESTIMATORS

__all__ = ["OneFaultShotEstimator", "STEP_SEEDS", "default_selection_tf"]

FloatArray = NDArray[np.float64]


# scikit-learn ships no type information: its classes are Any to mypy
class OneFaultShotEstimator(_Prediction, _JointCalibration, _GradeChoosing,
                            RegressorMixin, BaseEstimator):  # type: ignore[misc,unused-ignore]
    """Estimate FTFF size from SAs with one faulty example (Matania et al. 2023).

    Parameters
    ----------
    features : sequence of str, optional
        Candidate features (default the paper's four).
    feature_selection : bool, default True
        Run step 1 (keep the candidates invariant to what the TF estimate leaves); False
        keeps every candidate.
    grades : iterable of int in [1, 12], default range(1, 13)
        DIN grades the grade choice tries (step 2); those absent from the database are
        skipped.
    nominal_grade : int in [1, 12], default 7
        Grade of feature selection and of ``calibration="nominal"``. It must be in the
        database whenever it is used.
    calibration : str, CalibrationOptions or mapping, default "grade"
        The grade-choice strategy: what the one example (or, without one, the healthy
        data) calibrates.

        * ``"grade"``: every grade's model, weighted by how well it predicts the example's
          size (a Gaussian likelihood whose width is half the 90 % validation-residual
          quantile of the best grade; :func:`~gearshot.estimator.grade_weights`): one
          example cannot pin the grade down, and averaging over the grades it leaves
          plausible is steadier.
        * ``"tuned"``: the paper's step 2, the one grade whose model predicts the example
          best.
        * ``"joint"`` (paired databases; otherwise ``"grade"``): every setting of a grid of
          grade × fault gain × fault width × TF mode (× noise scale) on the twin
          differences, weighted by how well it explains the example's whole feature
          vector (:mod:`gearshot.estimator.calibration`); a :class:`CalibrationOptions`
          (or a mapping of its fields) is ``"joint"`` with that grid (rig family, dev:
          12.0 % against 11.3 % for "grade", within the draw-to-draw noise of ± 0.8).
        * ``"nominal"``: no tuning, ``nominal_grade``.
        * ``"zero_shot"``: no faulty example: the grades are weighted by how well their
          simulated healthy SAs match the target's healthy statistics
          (:func:`~gearshot.estimator.match_grade`,
          :func:`~gearshot.estimator.signature_weights`), or uniformly when no grade's
          simulation resembles the target's healthy data.

        With one grade tried, every strategy but ``"zero_shot"`` uses that grade.
    transfer_function : {"estimate", "none"} or array_like of complex, default "estimate"
        Estimate the TF from ``healthy_long`` (step 3), use none, or use a given TF
        (on the SA grid, one-sided to be resampled, or an object with
        ``to_signal_grid(n)``).
    rms_normalization : bool, default True
        Step 5.
    mesh_order : None, int >= 1 or sequence of int >= 1, default None
        Gear-mesh order(s) in the SA cycle whose harmonics and sidebands the difference
        signal removes (step 7). ``None``: from the database's gear pair (its
        ``gear_teeth`` attribute, set by :func:`gearshot.sim.load_database`: the SA cycle
        is one revolution of that gear); a database without pair attributes (one built
        by hand) falls back to ``fit``'s ``gear_teeth`` and then to the paper's 38.
        Several for a shaft whose SA holds several synchronous meshes, e.g. ``[32, 16]``
        for the PHM09 spur input shaft, where the second stage's mesh falls at order 16
        (:meth:`gearshot.Machine.mesh_orders`); the simulated and target signals are
        treated alike. The orders used are ``mesh_orders_``.
    fault_type : str, optional
        Fault type whose database slice trains the model (``fault_type`` coordinate of
        :func:`gearshot.sim.load_database`); ``None``: the database's only type.
    model_discrepancy : "auto" or float >= 0, default "auto"
        Standard deviation (fault-size units) of the simulation-to-reality error that
        :meth:`predict_interval` adds to the simulated validation residuals of a fit
        without hold-outs (they cannot show the bias one example leaves after tuning).
        "auto": :data:`~gearshot.estimator.uncertainty.WHITENED_DISCREPANCY` (0.09) for
        a one-fault-shot fit that whitens its residue (``model_discrepancy_``), else
        :data:`~gearshot.estimator.uncertainty.MODEL_DISCREPANCY` (0.12); both chosen on
        the rig family's development range (the smallest whose 90 % intervals cover 85–95 %
        pooled, ≥ 85 % in every condition; 0.12: 80 %; benchmarks/RESULTS.md). 0 gives
        pure split-conformal intervals; no upper bound (intervals are clipped to [0, 1]).
    estimator : {"boosting", "paper", "isotonic"}, default "boosting"
        Step 8's regressor (:func:`~gearshot.estimator.regressors.fit_regressor`): boosted
        trees (10.96 % against the paper's KNN's 11.31 % on the development rigs), the paper's
        KNN (its sweep and the demo's ablations pass ``"paper"``), or an isotonic map of a
        linear score (benchmarks/RESULTS.md "Estimator").
    random_state : int >= 0, numpy RandomState or Generator, or None
        Root of the random numbers. Each random step (:data:`STEP_SEEDS`: the noise of
        step 1, the validation split of step 8 and the matched noise) gets its own child
        seed, so switching one step off leaves the others' random numbers unchanged.
    options : EstimatorOptions, mapping of its fields or None, default None
        The research settings (:class:`~gearshot.estimator.EstimatorOptions`: step 1's
        threshold and fallback, step 2's smoothing, the zero-shot signature and weighting,
        step 6's references and delay resolution, step 8's K candidates and split, the
        residue whitening); None: their defaults, which are the product.

    Attributes
    ----------
    candidate_features_ : tuple of str
    selected_features_ : tuple of str
    selected_columns_ : list of int
        Columns of the selected features among the candidates.
    feature_errors_ : dict
    selection_features_ : (train, test) tuple of ndarray or None
        Step 1's paired candidate features through the estimated and the held-out TF
        (the paper's Fig. 11; see :func:`gearshot.plotting.plot_feature_invariance`).
    grade_strategy_ : {"tuned", "soft", "joint", "nominal", "zero_shot"}
        The grade-choice strategy that ran ("soft": ``calibration="grade"``, or "joint"
        on an unpaired database; "nominal" also when one grade was tried).
    grade_ : int
        The best grade (the paper's choice).
    grade_weights_ : dict grade → weight
        Weights of the grade models that predict (``{grade_: 1.0}`` unless soft).
    grade_models_ : dict grade → KnnModel
    model_ : KnnModel
        The best grade's model.
    tuning_curve_ : dict of arrays (grade, prediction, abs_error) or None
    transfer_function_ : ndarray of complex or None
    target_scale_ : float
    references_ : ndarray
    target_healthy_mean_, target_healthy_features_ : ndarray
    target_residue_power_ : ndarray (n_points // 2 + 1,)
        Power spectrum of the target's healthy difference signals (step 6 output): what
        the twin reference adds to the simulated differences as noise.
    n_neighbors_, n_points_ : int; faulty_size_ : float or None
    step_seeds_ : dict step → int
    simulated_reference_, reference_blend_ : str, int (step 6: the simulated reference,
        "first_healthy" or "twin"; how many healthy references it blends on the target)
    calibration_ : dict
        What the example calibrated: ``strategy`` ("grade" or "joint"), ``settings`` (list
        of dicts ``grade, gain, width, tf, noise, weight`` — and ``log_likelihood`` with
        "joint" — largest weight first; the models that predict, their weights summing
        to 1), ``grid`` (with "joint": every setting tried, its log-likelihood and
        weight; else None) and ``options`` (the joint grid's options or None).
    setting_models_ : list of KnnModel
        One model per entry of ``calibration_["settings"]``.
    comparability_reference_ : ComparabilityReference
        What :meth:`comparability` tests segments against
        (:mod:`gearshot.estimator.comparability`).
    mesh_orders_ : tuple of int
        The gear-mesh orders step 7 removed (``mesh_order`` resolved).
    fit_check_ : FitCheck
        The fit's hold-outs read back against 0 and ``faulty_size`` and a ``verdict``
        (:mod:`~gearshot.estimator.fit_check`); they calibrate :meth:`predict_interval`.
        A drifting healthy baseline fails it (``healthy_drift_``, :mod:`.drift`).
    detection_limit_, detection_threshold_ : float
        The smallest size told apart from healthy at 95 % confidence and the estimate it
        starts from: from the simulated validation rows, or from the real hold-outs when
        the fit check passed (:mod:`~gearshot.estimator.detection`).
    """

    _parameter_constraints: ClassVar[dict[str, list[Constraint]]] = {
        "features": [NoneValue(), NameSequence(available_features)],
        "feature_selection": [Boolean()],
        "grades": [IntegerSequence(1, 12)],
        "nominal_grade": [Interval(int, 1, 12)],
        "calibration": [Resolvable(
            resolve_calibration, "one of " + ", ".join(repr(v) for v in
                                                      CALIBRATION_STRATEGIES)
            + ", a CalibrationOptions or a mapping of its fields")],
        "transfer_function": [Options(("estimate", "none")), ArrayOrObject("to_signal_grid")],
        "rms_normalization": [Boolean()],
        "mesh_order": [NoneValue(), Interval(int, 1, None), IntegerSequence(1, None)],
        "fault_type": [NoneValue(), Options(tuple(FAULT_TYPE_NAMES))],
        "model_discrepancy": [Options(("auto",)), Interval(float, 0, None)],
        "estimator": [Options(ESTIMATORS)],
        "random_state": [RandomStateValue()],
        "options": [NoneValue(), Resolvable(
            resolve_options, "an EstimatorOptions or a mapping of its fields")],
    }

    def __init__(self, *, features: Sequence[str] | None = None,
                 feature_selection: bool = True, grades: Iterable[int] = range(1, 13),
                 nominal_grade: int = 7,
                 calibration: str | CalibrationOptions | Mapping[str, Any] = "grade",
                 transfer_function: str | ArrayLike | Any = "estimate",
                 rms_normalization: bool = True,
                 mesh_order: int | Sequence[int] | None = None,
                 fault_type: str | None = None, model_discrepancy: float | str = "auto",
                 estimator: str = "boosting", random_state: Any = None,
                 options: EstimatorOptions | Mapping[str, Any] | None = None) -> None:
        self.features = features
        self.feature_selection = feature_selection
        self.grades = grades
        self.nominal_grade = nominal_grade
        self.calibration = calibration
        self.transfer_function = transfer_function
        self.rms_normalization = rms_normalization
        self.mesh_order = mesh_order
        self.fault_type = fault_type
        self.model_discrepancy = model_discrepancy
        self.estimator = estimator
        self.random_state = random_state
        self.options = options

    def _options(self) -> EstimatorOptions:
        """The research settings in effect (``options`` resolved)."""
        return resolve_options(self.options)

    def _mesh_orders(self) -> int | list[int]:
        """The mesh orders as the signal functions take them (an int or a list): the fit's
        under way, else ``mesh_orders_`` (else, saved before it existed, ``mesh_order``)."""
        orders = (self.__dict__.get("_fitting_orders") or self.__dict__.get("mesh_orders_")
                  or as_orders(self.mesh_order))
        return orders[0] if len(orders) == 1 else list(orders)

    def fit(self, database: Any, target_healthy: ArrayLike,
            faulty_example: ArrayLike | None = None, faulty_size: float | None = None,
            healthy_long: ArrayLike | None = None, *, selection_tf: Any = None,
            gear_teeth: int | None = None, pinion_teeth: int | None = None,
            holdout: float = 0.0, healthy_holdout: ArrayLike | None = None,
            example_record: ArrayLike | None = None,
            healthy_recordings: ArrayLike | None = None) -> Self:
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
            The one faulty SA of known size (omit with ``calibration="zero_shot"``).
        faulty_size : float in (0, 1]
            Its size.
        healthy_long : array_like (n_samples,)
            Long healthy angle-domain target signal (≥ 2**15 samples) for the TF estimate.
        selection_tf : array_like of complex or TransferFunction, optional
            The held-out TF for feature selection (on the SA grid, one-sided, or an object
            with ``to_signal_grid(n)``). Default: :func:`default_selection_tf` of
            ``random_state`` (one TF of the synthetic bank, as the command line uses): on a
            real machine no second measured path is at hand, and step 1 only needs a
            plausible path other than the estimated one.
        gear_teeth, pinion_teeth : int, optional
            The pair the target SAs were segmented for (the gear whose revolution is the
            SA cycle, and its mate); SAs of another pair than the database's are refused.
        holdout : float in [0, 1), default 0.0
            Fraction of ``target_healthy`` (its last ``floor(holdout · n)`` SAs) kept out
            of the fit and read back by the fit check; with ``healthy_holdout``, the
            fraction those were cut with (named in an "unchecked" verdict). ``gearshot
            predict`` holds out 0.25 of each healthy recording.
        healthy_holdout : array_like (n, n_points), optional
            Healthy SAs kept out of the fit (e.g. the last segments of each healthy
            recording): their estimates must read near 0 (:attr:`fit_check_`).
        example_record : array_like (n, n_points), optional
            The example record's other segments (not the example itself): their
            estimates must read near ``faulty_size``.
        healthy_recordings : array_like (n_healthy,), optional
            Each ``target_healthy`` SA's recording: from 3 recordings on, step 6's
            references come from every recording, each training SA's difference is
            taken against the references of the other recordings (as a new recording's
            is) and comparability leaves whole recordings out (run-to-run).

        Without hold-outs the fit is "unchecked" or fails if it misreads its own example.

        Returns
        -------
        self

        Raises
        ------
        GearshotError
            On a bad parameter or argument (the message names it and quotes the value),
            or target SAs declared for another tooth count than the database's pair.
            The estimator is left as it was before the call.
        """
        validate_params(self.get_params(deep=False), self._parameter_constraints)
        target_healthy, holdouts = split_holdouts(target_healthy, holdout, healthy_holdout,
                                                  example_record)
        orders = resolve_mesh_orders(self.mesh_order, database, gear_teeth, pinion_teeth)
        self._fitting_orders = orders   # what _mesh_orders() gives until fit returns
        try:
            self._fit(database, *spread_references(target_healthy, healthy_recordings),
                      faulty_example, faulty_size, healthy_long, selection_tf, orders)
        finally:
            del self._fitting_orders
        self.healthy_drift_ = fit_drift(target_healthy, holdouts.healthy, healthy_recordings)
        self.fit_check_ = check_holdouts(self.predict, holdouts, len(self.references_) + len(
            self.target_healthy_features_), self.faulty_size_, faulty_example,  # + the example
            drift=self.healthy_drift_, detection_limit=self.__dict__["detection_limit_"],
            example_contrast=example_contrast(self, faulty_example))
        if (limit := holdout_detection(self.fit_check_)) is not None:   # a passed check
            self.detection_limit_ = self.detection_threshold_ = limit  # from the hold-outs
        return self

    def _fit(self, database: Any, target_healthy: ArrayLike, recordings: Any,
             faulty_example: ArrayLike | None, faulty_size: float | None,
             healthy_long: ArrayLike | None, selection_tf: Any,
             orders: tuple[int, ...]) -> Self:
        """``fit`` with checked parameters and resolved mesh orders."""
        inputs = check_fit_inputs(self, target_healthy, faulty_example, faulty_size,
                                  healthy_long, selection_tf)
        database = _select_fault_type(database, self.fault_type)
        by_grade = _database_by_grade(database, inputs.n_points)
        if (reference := self._options().simulated_reference) == "auto":
            reference = "twin" if _has_twins(database) else "first_healthy"
        twins = _database_twins(database, by_grade) if reference == "twin" else None
        grades = self._grades_in(by_grade)
        nominal = self._nominal_grade_in(by_grade)
        seeds = _step_seeds(self.random_state)
        names = PAPER_FEATURES if self.features is None else tuple(self.features)

        # the block diagram: target side, feature selection, grade choice, grade models
        target = fit_target_side(self, inputs, names, recordings, twins is not None)
        selection = self._select_features(by_grade, nominal, inputs, names,
                                          seeds["select_features"], twins)
        cols = [names.index(n) for n in selection.selected]
        ctx = self._fit_context(by_grade, grades, nominal, target, inputs, names, cols,
                                seeds["fit_knn"], twins, seeds["match_noise"])
        grade_choice = self._choose_grades(ctx, grades, twins is not None)
        detection = detection_limit(grade_choice["setting_models_"], [
            st["weight"] for st in grade_choice["calibration_"]["settings"]])
        comparability = fit_comparability(
            inputs.target_healthy, self._mesh_orders(), faulty_example=inputs.faulty_example,
            faulty_size=inputs.faulty_size, recordings=recordings)

        learned = dict(
            n_points_=inputs.n_points, transfer_function_=target.transfer_function,
            target_scale_=target.scale, references_=target.references,
            candidate_features_=names, target_healthy_mean_=target.healthy_mean,
            target_healthy_features_=target.healthy_features,
            target_residue_power_=target.residue_power, residue_weights_=target.weights,
            reference_blend_=target.blend, selected_features_=selection.selected,
            feature_errors_=selection.errors, selection_features_=selection.features,
            selected_columns_=cols, faulty_size_=inputs.faulty_size, step_seeds_=seeds,
            simulated_reference_=reference, comparability_reference_=comparability,
            mesh_orders_=orders, detection_limit_=detection.limit,
            detection_threshold_=detection.threshold, **grade_choice)
        self.__dict__.update(learned)
        return self
