"""The estimator's scikit-learn contract, parameter table, seeds and failure behaviour.

``sklearn.utils.estimator_checks.check_estimator`` cannot run as a whole (``fit`` takes a
simulated database, target SAs and one example, not ``X, y``); the checks that apply are
run one by one, and the rest of the contract is tested here directly.
"""

import numpy as np
import pytest
import sklearn.exceptions
from estimator_data import N, synthetic_database, synthetic_target, tf_pair
from numpy.testing import assert_array_equal
from sklearn.base import clone
from sklearn.utils import estimator_checks
from sklearn.utils.validation import check_is_fitted

from gearshot import GearshotError
from gearshot.estimator import (
    STEP_SEEDS,
    EstimatorOptions,
    NotFittedError,
    OneFaultShotEstimator,
    regressors,
    steps,
)
from gearshot.estimator._params import validate_params

# The synthetic database holds grades 3, 6, 9: quick settings that still run every step.
FAST = dict(nominal_grade=3, grades=[3, 6], calibration="tuned", random_state=0)


@pytest.fixture(scope="module")
def tfs():
    return tf_pair()


@pytest.fixture(scope="module")
def data(tfs):
    db = synthetic_database(n_healthy=10, n_faulty=40)
    healthy, long, faulty, y = synthetic_target(6, tfs[0], n_healthy=10, n_each=5)
    return db, healthy, long, faulty, y


def _fit(est, data, tfs):
    db, healthy, long, faulty, y = data
    return est.fit(db, healthy, faulty[7], y[7], long, selection_tf=tfs[1])


@pytest.fixture(scope="module")
def fitted(data, tfs):
    return _fit(OneFaultShotEstimator(**FAST), data, tfs)


# ------------------------------------------------------------------ sklearn checks that apply
@pytest.mark.parametrize("check", [
    estimator_checks.check_no_attributes_set_in_init,
    estimator_checks.check_get_params_invariance,
    estimator_checks.check_set_params,
    estimator_checks.check_estimator_repr,
    estimator_checks.check_estimator_cloneable,
])
def test_sklearn_checks_that_need_no_fit(check):
    check("OneFaultShotEstimator", OneFaultShotEstimator())


def test_defaults_are_immutable():
    # sklearn's check_parameters_default_constructible would also refuse ``range``
    # defaults (grades), which are as immutable as the tuples it accepts.
    import inspect

    for p in inspect.signature(OneFaultShotEstimator).parameters.values():
        assert isinstance(p.default, (type(None), bool, int, float, str, tuple, range)), p
        assert OneFaultShotEstimator().get_params()[p.name] is p.default


def test_init_stores_arguments_untouched_and_clone_round_trips():
    grades, tf = range(3, 8), np.ones(N, complex)
    options = EstimatorOptions(n_neighbors=[1, 5, 9])
    rng = np.random.RandomState(3)
    est = OneFaultShotEstimator(grades=grades, options=options, transfer_function=tf,
                                random_state=rng, model_discrepancy=0.3)
    params = est.get_params()
    assert params["grades"] is grades and params["options"] is options
    assert params["transfer_function"] is tf and params["random_state"] is rng
    again = clone(est)
    assert again is not est
    assert set(again.get_params()) == set(params)
    assert again.get_params()["model_discrepancy"] == 0.3
    assert again.options == options and again.options.n_neighbors == [1, 5, 9]
    assert again.set_params(options={"upsample": 10}) is again
    assert again.options == {"upsample": 10} and est.options is options


def test_not_fitted_error_is_both_gearshot_and_sklearn(tmp_path):
    est = OneFaultShotEstimator()
    sa = np.zeros((2, N))
    calls = [lambda: est.predict(sa), lambda: est.predict_interval(sa),
             lambda: est.features_of(sa), lambda: est.score(sa, [0, 0]),
             lambda: est.save(tmp_path / "m.joblib")]
    for call in calls:
        with pytest.raises(NotFittedError) as info:
            call()
        assert isinstance(info.value, GearshotError)
        assert isinstance(info.value, sklearn.exceptions.NotFittedError)
    with pytest.raises(sklearn.exceptions.NotFittedError):
        check_is_fitted(est)


def test_learned_attributes_end_with_underscore(fitted):
    check_is_fitted(fitted)
    params = set(fitted.get_params())
    learned = set(vars(fitted)) - params
    assert learned and all(a.endswith("_") and not a.startswith("_") for a in learned), learned
    assert "database_" not in learned
    assert set(fitted.step_seeds_) == set(STEP_SEEDS)
    assert fitted.grade_strategy_ == "tuned"


def test_fixed_random_state_is_deterministic(data, tfs, fitted):
    faulty = data[3]
    again = _fit(OneFaultShotEstimator(**FAST), data, tfs)
    assert_array_equal(again.predict(faulty), fitted.predict(faulty))
    assert again.step_seeds_ == fitted.step_seeds_
    assert_array_equal(again.model_.validation_indices, fitted.model_.validation_indices)
    # a RandomState or a Generator seeded alike also repeats itself
    for make in (np.random.RandomState, np.random.default_rng):
        a = _fit(OneFaultShotEstimator(**{**FAST, "random_state": make(5)}), data, tfs)
        b = _fit(OneFaultShotEstimator(**{**FAST, "random_state": make(5)}), data, tfs)
        assert a.step_seeds_ == b.step_seeds_
        assert_array_equal(a.predict(faulty), b.predict(faulty))


# ------------------------------------------------------------------ one seed per step
def test_feature_selection_does_not_move_the_knn_split(data, tfs):
    """The no_feature_selection ablation differs from the full method only in step 1."""
    kw = dict(FAST, calibration="nominal")
    with_sel = _fit(OneFaultShotEstimator(**kw, feature_selection=True), data, tfs)
    without = _fit(OneFaultShotEstimator(**kw, feature_selection=False), data, tfs)
    assert with_sel.feature_errors_ and not without.feature_errors_
    assert with_sel.step_seeds_ == without.step_seeds_
    assert_array_equal(with_sel.model_.validation_indices, without.model_.validation_indices)
    assert_array_equal(with_sel.model_.validation_y, without.model_.validation_y)
    other = _fit(OneFaultShotEstimator(**{**kw, "random_state": 1}), data, tfs)
    assert not np.array_equal(other.model_.validation_indices,
                              with_sel.model_.validation_indices)


def test_step_seeds_are_independent_children_of_random_state():
    from gearshot.estimator._model import _step_seeds

    seeds = _step_seeds(0)
    assert list(seeds) == list(STEP_SEEDS)
    assert len(set(seeds.values())) == len(seeds)
    children = np.random.SeedSequence(0).spawn(len(STEP_SEEDS))
    assert seeds["fit_knn"] == int(children[STEP_SEEDS.index("fit_knn")].generate_state(1)[0])
    assert _step_seeds(0) == seeds and _step_seeds(1) != seeds


# ------------------------------------------------------------------ the parameter table
def test_public_constructor_is_short():
    """Issue #21: at most 12 parameters, plus issue #30's ``estimator`` (step 8's
    regressor, a public choice the issue names); research settings live in ``options``."""
    params = OneFaultShotEstimator().get_params()
    assert len(params) <= 13, sorted(params)
    assert "estimator" in params
    assert "select_features" not in params and "feature_selection" in params
    for knob in ("selection_threshold", "upsample", "n_neighbors", "zero_shot",
                 "tune_simulation", "grade_weighting", "simulated_reference"):
        assert knob not in params


@pytest.mark.parametrize("calibration, strategy", [
    ("grade", "soft"), ("tuned", "tuned"), ("nominal", "nominal"),
    ("joint", "soft"),          # an unpaired database: joint falls back to the grades
])
def test_calibration_names_the_grade_strategy(data, tfs, calibration, strategy):
    est = _fit(OneFaultShotEstimator(**{**FAST, "calibration": calibration}), data, tfs)
    assert est.grade_strategy_ == strategy
    assert est.calibration_["strategy"] == "grade"
    if strategy in ("tuned", "nominal"):
        assert est.grade_weights_ == {est.grade_: 1.0}
    if strategy == "nominal":
        assert est.grade_ == FAST["nominal_grade"] and est.tuning_curve_ is None
    if strategy == "soft":
        assert set(est.grade_weights_) <= set(FAST["grades"])
        assert sum(est.grade_weights_.values()) == pytest.approx(1.0)


def test_every_parameter_has_a_constraint():
    assert set(OneFaultShotEstimator._parameter_constraints) == \
        set(OneFaultShotEstimator().get_params())


@pytest.mark.parametrize("name, value, shown", [
    ("features", ["nope"], "nope"),
    ("features", "rms_diff", "rms_diff"),
    ("features", [], "[]"),
    ("grades", [], "[]"),
    ("grades", [0], "[0]"),
    ("grades", [3, 13], "[3, 13]"),
    ("grades", (g for g in [3, 6]), "generator"),
    ("feature_selection", "yes", "yes"),
    ("feature_selection", 1, "1"),
    ("calibration", None, "None"),
    ("calibration", "soft", "soft"),
    ("calibration", "best", "best"),
    ("options", "fast", "fast"),
    ("options", [("upsample", 10)], "upsample"),
    ("nominal_grade", 0, "0"),
    ("nominal_grade", 13, "13"),
    ("nominal_grade", 7.5, "7.5"),
    ("nominal_grade", True, "True"),
    ("rms_normalization", "false", "false"),
    ("transfer_function", "magic", "magic"),
    ("transfer_function", np.ones((2, 3)), "shape=(2, 3)"),
    ("mesh_order", 0, "0"),
    ("mesh_order", 38.5, "38.5"),
    ("mesh_order", [38, 0], "[38, 0]"),
    ("mesh_order", [], "[]"),
    ("model_discrepancy", -0.1, "-0.1"),
    ("model_discrepancy", np.nan, "nan"),
    ("random_state", -1, "-1"),
    ("random_state", "seed", "seed"),
])
def test_bad_parameter_is_named_with_its_value_at_fit(data, tfs, name, value, shown):
    _assert_refused_at_fit(OneFaultShotEstimator(**{**FAST, name: value}), data, tfs,
                           f"{name} must be ", shown)


def _assert_refused_at_fit(est, data, tfs, start, shown):
    """``fit`` refuses ``est`` with a message that starts with ``start`` and quotes the
    value as ``shown``, and leaves it unfitted."""
    with pytest.raises(GearshotError) as info:
        _fit(est, data, tfs)
    message = str(info.value)
    assert message.startswith(start), message
    assert shown in message, message
    assert not hasattr(est, "model_")


@pytest.mark.parametrize("name, value, shown", [
    ("selection_threshold", 0, "0"),
    ("selection_threshold", np.inf, "inf"),
    ("selection_fallback", "none", "none"),
    ("tuning_smoothing", "spline", "spline"),
    ("zero_shot_signature", "clean", "clean"),
    ("zero_shot_weighting", "mean", "mean"),
    ("simulated_reference", "twins", "twins"),
    ("upsample", 0, "0"),
    ("n_neighbors", [0, 1], "[0, 1]"),
    ("n_neighbors", 5, "5"),
    ("validation_fraction", 0.0, "0.0"),
    ("validation_fraction", 1, "1"),
])
def test_bad_option_is_named_with_its_value(data, tfs, name, value, shown):
    """A bad research setting: refused by EstimatorOptions at once, and as a mapping at
    fit (the CLI's ``--param options=...``), naming the field and quoting the value."""
    with pytest.raises(GearshotError) as info:
        EstimatorOptions(**{name: value})
    assert str(info.value).startswith(f"{name} must be "), str(info.value)
    assert shown in str(info.value)
    _assert_refused_at_fit(OneFaultShotEstimator(**{**FAST, "options": {name: value}}),
                           data, tfs, f"options: {name} must be ", shown)


def test_unknown_option_is_named():
    est = OneFaultShotEstimator(options={"selection_treshold": 0.2})
    with pytest.raises(GearshotError, match=r"options: options has unknown field\(s\) "
                                            r"\['selection_treshold'\]"):
        validate_params(est.get_params(deep=False), est._parameter_constraints)


def test_options_change_what_they_name(data, tfs, fitted):
    """A research setting reaches its step: fewer K candidates bound the chosen K, a
    coarser delay grid changes the target features, the defaults repeat the default fit."""
    same = _fit(OneFaultShotEstimator(**{**FAST, "options": EstimatorOptions()}), data, tfs)
    assert_array_equal(same.predict(data[3]), fitted.predict(data[3]))
    few = _fit(OneFaultShotEstimator(**{**FAST, "estimator": "paper",  # the KNN's K
                                        "options": {"n_neighbors": [1, 2]}}), data, tfs)
    assert few.n_neighbors_ in (1, 2) and few.model_.validation_mae.size == 2
    coarse = _fit(OneFaultShotEstimator(**{**FAST, "options": {"upsample": 1}}), data, tfs)
    assert not np.array_equal(coarse.features_of(data[3]), fitted.features_of(data[3]))


def test_model_discrepancy_has_no_upper_bound():
    est = OneFaultShotEstimator(model_discrepancy=2.5)
    validate_params(est.get_params(deep=False), est._parameter_constraints)


def test_validate_params_wants_a_constraint_per_parameter():
    with pytest.raises(GearshotError, match="no constraint"):
        validate_params({"a": 1, "b": 2}, {"a": []})


def test_absent_nominal_grade_is_an_error_where_it_is_used(data, tfs):
    with pytest.raises(GearshotError) as info:
        _fit(OneFaultShotEstimator(**{**FAST, "nominal_grade": 7}), data, tfs)
    message = str(info.value)
    assert "nominal_grade=7" in message and "[3, 6, 9]" in message
    assert "feature_selection=True" in message
    with pytest.raises(GearshotError, match="calibration='nominal'"):
        _fit(OneFaultShotEstimator(**{**FAST, "nominal_grade": 7, "feature_selection": False,
                                      "calibration": "nominal"}), data, tfs)
    # unused (no selection, tuned): no error
    est = _fit(OneFaultShotEstimator(**{**FAST, "nominal_grade": 7,
                                        "feature_selection": False}), data, tfs)
    assert est.grade_ in (3, 6)


# ------------------------------------------------------------------ failed fits
def test_failed_fit_leaves_no_state(data, tfs, monkeypatch):
    def broken(*args, **kwargs):
        raise RuntimeError("step 8 failed")

    for name, module, function in (("paper", steps, "fit_knn"),
                                   ("boosting", regressors, "_learner")):
        est = OneFaultShotEstimator(**FAST, estimator=name)
        with monkeypatch.context() as patch:   # one regressor broken at a time
            patch.setattr(module, function, broken)
            with pytest.raises(RuntimeError, match="step 8"):
                _fit(est, data, tfs)
        assert set(vars(est)) == set(est.get_params())


def test_failed_refit_keeps_the_previous_model(data, tfs, fitted):
    est = clone(fitted)
    _fit(est, data, tfs)
    before = est.predict(data[3])
    state = set(vars(est))
    db, healthy, long, faulty, _ = data
    with pytest.raises(GearshotError, match="faulty_size"):
        est.fit(db, healthy, faulty[7], 1.5, long, selection_tf=tfs[1])
    assert set(vars(est)) == state
    assert_array_equal(est.predict(data[3]), before)


def test_fault_type_choices_are_the_registry():
    """The estimator's fault_type choices are the one fault-type record's names."""
    from gearshot.estimator import OneFaultShotEstimator, check_estimator_params
    from gearshot.fault_registry import FAULT_TYPE_NAMES

    for name in FAULT_TYPE_NAMES:
        check_estimator_params(OneFaultShotEstimator(fault_type=name))
    with pytest.raises(GearshotError, match="fault_type"):
        check_estimator_params(OneFaultShotEstimator(fault_type="rust"))
