"""OneFaultShotEstimator and its eight steps (mechanics on fast synthetic data)."""

import estimator_data
import numpy as np
import pytest
from estimator_data import N, synthetic_database, synthetic_sa, synthetic_target
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.base import clone
from sklearn.model_selection import GridSearchCV, ShuffleSplit
from sklearn.neighbors import KNeighborsRegressor
from sklearn.pipeline import Pipeline
from sklearn.preprocessing import StandardScaler

from gearshot import GearshotError
from gearshot.estimator import OneFaultShotEstimator, signature_weights, steps, uncertainty
from gearshot.transfer import resample_transfer_function

# The synthetic database holds grades 3, 6 and 9; the default nominal_grade (7) is absent
# and is an error where it is used (feature selection, no tuning).
NOMINAL = 3


@pytest.fixture(scope="module")
def tf_pair():
    """A resonant path for the target and a different one held out for selection."""
    return estimator_data.tf_pair()


@pytest.fixture(scope="module")
def data(tf_pair):
    db = synthetic_database()
    healthy, long, faulty, y = synthetic_target(6, tf_pair[0])
    return db, healthy, long, faulty, y


@pytest.fixture(scope="module")
def fitted(data, tf_pair):
    db, healthy, long, faulty, y = data
    est = OneFaultShotEstimator(random_state=0, nominal_grade=NOMINAL)
    return est.fit(db, healthy, faulty[20], y[20], long, selection_tf=tf_pair[1])


# ------------------------------------------------------------------------- steps
def test_fit_knn_matches_gridsearch_on_the_same_split():
    rng = np.random.default_rng(0)
    X = rng.normal(size=(200, 3)) * [1, 10, 100]
    y = np.clip(0.5 + 0.1 * X[:, 0] + 0.01 * X[:, 1] + 0.05 * rng.normal(size=200), 0, 1)
    model = steps.fit_knn(X, y, n_neighbors=range(1, 31), random_state=3)
    seed = np.random.RandomState(3).randint(np.iinfo(np.int32).max)
    pipe = Pipeline([("scale", StandardScaler(with_mean=False)),
                     ("knn", KNeighborsRegressor())])
    grid = GridSearchCV(pipe, {"knn__n_neighbors": list(range(1, 31))},
                        scoring="neg_mean_absolute_error",
                        cv=ShuffleSplit(n_splits=1, test_size=0.3, random_state=seed))
    grid.fit(X, y)
    assert model.n_neighbors == grid.best_params_["knn__n_neighbors"]
    assert_allclose(-grid.cv_results_["mean_test_score"], model.validation_mae[:30],
                    rtol=1e-12)
    assert_allclose(model.predict(X[:5]), grid.best_estimator_.predict(X[:5]))
    assert model.validation_residuals.shape == (60,)


def test_fit_knn_rejects_bad_input():
    with pytest.raises(GearshotError, match="n_neighbors"):
        steps.fit_knn(np.ones((10, 2)), np.ones(10), n_neighbors=[0, 1])
    with pytest.raises(GearshotError, match="validation_fraction"):
        steps.fit_knn(np.ones((10, 2)), np.ones(10), validation_fraction=1.5)


def test_feature_invariance_errors_are_offsets_over_spread():
    rng = np.random.default_rng(1)
    a = rng.normal(size=(500, 2))
    assert_allclose(steps.feature_invariance_errors(a, a), 0)
    shifted = a + [0.1, 1.0]
    err = steps.feature_invariance_errors(a, shifted)
    assert_allclose(err, [0.1, 1.0] / a.std(axis=0), rtol=1e-12)


def test_a_flat_tuning_curve_warns_nothing():
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        best, curve = steps.tune_grade(lambda g: 0.3, [1, 2, 3, 4], 0.5)
    assert best == 1 and np.allclose(curve["smoothed"], 0.3)


def test_tune_grade_picks_the_nearest_prediction():
    best, curve = steps.tune_grade(lambda g: {1: 0.9, 2: 0.52, 3: 0.3}[g], [1, 2, 3], 0.5,
                                   smoothing="none")
    assert best == 2
    assert_allclose(curve["abs_error"], [0.4, 0.02, 0.2], atol=1e-12)


def test_simulated_suppression_zeroes_the_first_healthy():
    rng = np.random.default_rng(2)
    sa = rng.normal(size=(5, 64))
    out = steps.suppress_harmonics_simulated(sa, np.array([False, True, False, True, False]))
    assert_allclose(out[1], 0)
    assert_allclose(out[0], sa[0] - sa[1])


def test_split_target_healthy_keeps_the_last_fifth_as_references():
    x = np.arange(10)[:, None] * np.ones((10, 4))
    train, refs = steps.split_target_healthy(x)
    assert_array_equal(refs[:, 0], [8, 9])
    assert train.shape == (8, 4)
    with pytest.raises(GearshotError, match="target_healthy"):
        steps.split_target_healthy(x[:1])


def test_selection_keeps_every_feature_when_paths_are_flat():
    rng = np.random.default_rng(3)
    y = np.r_[np.zeros(20), rng.uniform(0, 1, 80)]
    sa = synthetic_sa(y, 3, rng)
    names = ("rms_diff", "kurtosis_diff", "rms_env_diff", "skewness_env_diff")
    selected, errors = steps.select_features(sa, y, np.ones(N), mesh_order=38, names=names,
                                             noise_fraction=0.01, random_state=0)
    assert selected == names, errors
    assert max(errors.values()) < 0.1


def test_selection_rejects_features_a_sharp_path_distorts(tf_pair):
    rng = np.random.default_rng(4)
    y = np.r_[np.zeros(20), rng.uniform(0, 1, 80)]
    sa = synthetic_sa(y, 3, rng)
    names = ("rms_diff", "kurtosis_diff", "rms_env_diff", "skewness_env_diff")
    f = np.linspace(0, 1, 513)
    sharp = resample_transfer_function(1 / (1 - (f / 0.29) ** 2 + 0.002j) + 0.01, N)
    _, errors = steps.select_features(sa, y, sharp, mesh_order=38, names=names,
                                      random_state=0)
    assert max(errors.values()) > 0.1
    # with a threshold nothing passes, the fallback keeps the least-bad one or all of them
    tiny = min(errors.values()) / 2
    kw = dict(mesh_order=38, names=names, random_state=0, threshold=tiny)
    best, errs = steps.select_features(sa, y, sharp, **kw)
    assert best == (min(errs, key=errs.__getitem__),) and errs == errors
    every, _ = steps.select_features(sa, y, sharp, fallback="all", **kw)
    assert every == names
    with pytest.raises(GearshotError, match="fallback"):
        steps.select_features(sa, y, sharp, fallback="some", **kw)


def test_a_second_mesh_order_removes_its_bands_from_the_features():
    # an SA with a strong tone at order 16 beside the order-38 mesh: with [38, 16] the
    # difference signal and its RMS ignore the tone, with 38 alone it dominates
    t = np.arange(N) / N
    base = synthetic_sa(np.zeros(4), 3, np.random.default_rng(5))
    tone = 5 * np.cos(2 * np.pi * 16 * t)
    one = steps.centred_features(base + tone, mesh_order=38, names=("rms_diff",),
                                 healthy_mask=np.ones(4, bool))
    two = steps.centred_features(base + tone, mesh_order=[38, 16], names=("rms_diff",),
                                 healthy_mask=np.ones(4, bool))
    plain = steps.centred_features(base, mesh_order=[38, 16], names=("rms_diff",),
                                   healthy_mask=np.ones(4, bool))
    assert one[1][0] > 3          # the tone's RMS, 5 / sqrt(2), sits in the mean feature
    assert two[1][0] == pytest.approx(plain[1][0], rel=1e-9)


# ------------------------------------------------------------------------- estimator
def test_fit_sets_the_documented_attributes(fitted, data):
    est = fitted
    assert set(est.selected_features_) <= set(est.feature_errors_)
    assert len(est.feature_errors_) == 4
    assert est.grade_ in (3, 6, 9)
    assert_array_equal(est.tuning_curve_["grade"], [3, 6, 9])
    assert est.transfer_function_.shape == (N,)
    assert 1 <= est.n_neighbors_ <= 100
    pred = est.predict(data[3])
    assert pred.shape == (data[3].shape[0],)
    assert np.all((pred >= 0) & (pred <= 1))


def test_estimator_separates_sizes(fitted, data):
    _, healthy, _, faulty, y = data
    pred = fitted.predict(faulty)
    means = [pred[y == s].mean() for s in np.unique(y)]
    assert np.all(np.diff(means) > 0), means
    assert np.mean(np.abs(pred - y)) < 0.2


def test_predict_interval_brackets_the_prediction(fitted, data):
    faulty = data[3]
    low, high = fitted.predict_interval(faulty, coverage=0.9)
    pred = fitted.predict(faulty)
    assert np.all(low <= pred) and np.all(pred <= high)
    low50, high50 = fitted.predict_interval(faulty, coverage=0.5)
    assert np.all(high50 - low50 <= high - low + 1e-12)
    with pytest.raises(GearshotError, match="coverage"):
        fitted.predict_interval(faulty, coverage=1.5)


def test_same_random_state_same_predictions_and_clone(data, tf_pair):
    db, healthy, long, faulty, y = data
    a = OneFaultShotEstimator(random_state=7, grades=[3, 6], nominal_grade=NOMINAL)
    b = clone(a)
    assert b.get_params() == a.get_params()
    for est in (a, b):
        est.fit(db, healthy, faulty[3], y[3], long, selection_tf=tf_pair[1])
    assert_array_equal(a.predict(faulty), b.predict(faulty))


def test_ablation_switches_change_the_pipeline(data, tf_pair):
    db, healthy, long, faulty, y = data
    args = (db, healthy, faulty[20], y[20], long)
    raw = OneFaultShotEstimator(transfer_function="none", rms_normalization=False,
                                feature_selection=False, random_state=0).fit(*args)
    assert raw.transfer_function_ is None
    assert raw.selected_features_ == ("rms_diff", "kurtosis_diff", "rms_env_diff",
                                      "skewness_env_diff")
    fixed = OneFaultShotEstimator(calibration="nominal", nominal_grade=9,
                                  random_state=0).fit(*args, selection_tf=tf_pair[1])
    assert fixed.grade_ == 9 and fixed.tuning_curve_ is None
    given = OneFaultShotEstimator(transfer_function=tf_pair[0], feature_selection=False,
                                  random_state=0).fit(*args)
    assert_allclose(given.transfer_function_, tf_pair[0])


def test_zero_shot_needs_no_example(data):
    db, healthy, long, faulty, y = data
    est = OneFaultShotEstimator(calibration="zero_shot", feature_selection=False,
                                random_state=0)
    est.fit(db, healthy, healthy_long=long)
    assert est.grade_ in (3, 6, 9)
    assert len(est.tuning_curve_["grade"]) == 3
    assert est.predict(faulty).shape == y.shape


def test_signature_weights_trust_a_matching_grade_and_fall_back_to_uniform():
    rng = np.random.default_rng(0)
    sims = {g: g * 0.5 + 0.1 * rng.standard_normal(200) for g in (1, 2, 3, 4)}
    w, consistent = signature_weights(2.0 + 0.01 * rng.standard_normal(50), sims)
    assert consistent and max(w, key=w.get) == 4 and w[4] > 0.99
    # between grades 2 and 3 (0.15 and 0.35 away, spread 0.1): both kept, the nearer heavier
    w, consistent = signature_weights(1.15 + 0.01 * rng.standard_normal(50), sims)
    assert consistent and set(w) == {2, 3} and w[2] > w[3] > 0.001
    # far outside every grade's range: the signature is not trusted
    w, consistent = signature_weights(np.full(50, 9.0), sims)
    assert not consistent
    assert_allclose([w[g] for g in (1, 2, 3, 4)], 0.25)


def test_zero_shot_soft_weights_are_a_distribution_over_grades(data):
    db, healthy, long, faulty, y = data
    est = OneFaultShotEstimator(calibration="zero_shot", feature_selection=False,
                                random_state=0)
    est.fit(db, healthy, healthy_long=long)
    assert_allclose(sum(est.grade_weights_.values()), 1.0)
    assert set(est.grade_weights_) <= {3, 6, 9}
    assert isinstance(est.tuning_curve_["consistent"], bool)
    X = est.features_of(faulty)
    mix = sum(w * est.grade_models_[g].predict(X) for g, w in est.grade_weights_.items())
    assert_allclose(est.predict(faulty), mix)


def test_save_and_load_round_trip(fitted, data, tmp_path):
    path = tmp_path / "model.skops"
    fitted.save(path)
    again = OneFaultShotEstimator.load(path)
    assert_array_equal(again.predict(data[3]), fitted.predict(data[3]))
    assert not list(tmp_path.glob(".*tmp"))
    (tmp_path / "junk.joblib").write_bytes(b"not a model")
    with pytest.raises(GearshotError, match="junk.joblib"):
        OneFaultShotEstimator.load(tmp_path / "junk.joblib")


@pytest.mark.parametrize(
    "change, words",
    [
        (lambda a: a.update(healthy=a["healthy"][:, :1024]), ["faulty_example", "1024"]),
        (lambda a: a.update(size=0.0), ["faulty_size", "0.0"]),
        (lambda a: a.update(size=1.5), ["faulty_size", "1.5"]),
        (lambda a: a.update(healthy=np.where(np.arange(N) == 5, np.nan, a["healthy"])),
         ["target_healthy", "nan"]),
        (lambda a: a.update(healthy=a["healthy"][:1]), ["target_healthy", "1 sa"]),
        (lambda a: a.update(db=a["db"].where(a["db"].fault_size > 0, drop=True)),
         ["healthy", "database"]),
        (lambda a: a.update(example=None), ["faulty_example", "zero_shot"]),
        (lambda a: a.update(long=None), ["healthy_long"]),
    ],
)
def test_bad_input_names_the_argument(data, tf_pair, change, words):
    db, healthy, long, faulty, y = data
    args = dict(db=db, healthy=healthy, example=faulty[20], size=y[20], long=long,
                sel=tf_pair[1])
    change(args)
    with pytest.raises(GearshotError) as info:
        OneFaultShotEstimator(random_state=0, grades=[3], nominal_grade=NOMINAL).fit(
            args["db"], args["healthy"], args["example"], args["size"], args["long"],
            selection_tf=args["sel"])
    message = str(info.value).lower()
    for word in words:
        assert word in message, message


def test_selection_tf_defaults_to_the_cli_synthetic_tf(data):
    """Issue #20: fit without selection_tf uses default_selection_tf(random_state), the
    TF the command line passes; the same fit as passing it explicitly."""
    from gearshot.estimator import default_selection_tf

    db, healthy, long, faulty, y = data
    kw = dict(random_state=3, grades=[3], nominal_grade=NOMINAL)
    implicit = OneFaultShotEstimator(**kw).fit(db, healthy, faulty[20], y[20], long)
    explicit = OneFaultShotEstimator(**kw).fit(db, healthy, faulty[20], y[20], long,
                                               selection_tf=default_selection_tf(3))
    assert implicit.selected_features_ == explicit.selected_features_
    assert_array_equal(implicit.predict(faulty), explicit.predict(faulty))
    assert not np.allclose(default_selection_tf(3).to_signal_grid(64),
                           default_selection_tf(4).to_signal_grid(64))


def test_bad_parameters_are_reported_at_fit(data):
    db, healthy, long, faulty, y = data
    for params, word in [(dict(features=["nope"]), "features"),
                         (dict(transfer_function="magic"), "transfer_function"),
                         (dict(grades=[0]), "grades"),
                         (dict(options={"validation_fraction": 0.0}), "validation_fraction")]:
        with pytest.raises(GearshotError, match=word):
            OneFaultShotEstimator(**params).fit(db, healthy, faulty[0], y[0], long,
                                                selection_tf=np.ones(N))


def test_isotonic_tuning_ignores_a_lucky_outlier():
    # rising trend with scatter; grade 9 hits the size by chance, the trend crosses at 3–4
    preds = {1: 0.15, 2: 0.2, 3: 0.3, 4: 0.36, 5: 0.45, 6: 0.5, 7: 0.55, 8: 0.6, 9: 0.33,
             10: 0.7, 11: 0.75, 12: 0.8}
    literal, _ = steps.tune_grade(preds.get, list(preds), 0.32, smoothing="none")
    robust, curve = steps.tune_grade(preds.get, list(preds), 0.32)
    assert literal == 9
    assert robust in (3, 4)
    assert np.all(np.diff(curve["smoothed"]) >= 0)
    with pytest.raises(GearshotError, match="smoothing"):
        steps.tune_grade(preds.get, [1, 2], 0.3, smoothing="spline")


# ------------------------------------------------------------------- soft grade weighting
def test_grade_weights_follow_a_gaussian_likelihood_of_the_example():
    residuals = np.full(99, 0.1)  # 90 % quantile 0.1 → sigma 0.05
    w = uncertainty.grade_weights([0.30, 0.35, 0.40, 0.90], [1, 2, 3, 4], 0.35, residuals)
    assert list(w) == [2, 1, 3]  # largest first; grade 4 (10 sigma away) is dropped
    assert_allclose(sum(w.values()), 1.0)
    assert_allclose(w[1], w[3])
    assert_allclose(w[1] / w[2], np.exp(-0.5))


def test_conformal_quantile_is_the_finite_sample_rank():
    res = np.arange(1, 11) / 10  # 0.1 … 1.0
    assert uncertainty.conformal_quantile(res, 0.5) == 0.6  # ceil(11 * 0.5) = 6th
    assert uncertainty.conformal_quantile(res, 0.9) == 1.0
    assert uncertainty.conformal_quantile(-res, 0.5) == 0.6  # signs do not matter


def test_mixture_interval_of_one_model_and_of_two_separated_models():
    res = np.linspace(0, 0.1, 1001)  # uniform |r| on [0, 0.1]
    pred = np.array([0.5])
    lo, hi = uncertainty.mixture_interval({1: pred}, {1: 1.0}, {1: res}, 0.9)
    assert_allclose([lo[0], hi[0]], [0.41, 0.59], atol=2e-3)
    # two equally weighted models 0.4 apart: the 90 % range reaches into both
    lo, hi = uncertainty.mixture_interval({1: pred - 0.2, 2: pred + 0.2}, {1: 0.5, 2: 0.5},
                                    {1: res, 2: res}, 0.9)
    assert lo[0] < 0.3 and hi[0] > 0.7
    # a lopsided mix sits mostly on the heavy model
    lo, hi = uncertainty.mixture_interval({1: pred - 0.2, 2: pred + 0.2}, {1: 0.97, 2: 0.03},
                                    {1: res, 2: res}, 0.9)
    assert hi[0] < 0.4


def test_mixture_interval_discrepancy_is_a_gaussian_widening():
    pred = np.array([0.5, 0.2])
    # zero simulated residuals: the interval is the Gaussian's central 90 % (±1.645 σ)
    lo, hi = uncertainty.mixture_interval({1: pred}, {1: 1.0}, {1: np.zeros(50)}, 0.9,
                                    discrepancy=0.1, n_levels=2000)
    assert_allclose(hi - pred, 0.1645, atol=2e-3)
    assert_allclose(pred - lo, 0.1645, atol=2e-3)
    # Gaussian residuals (σ 0.06) and discrepancy (σ 0.08) add in quadrature: σ 0.1
    res = np.abs(np.random.default_rng(0).normal(0, 0.06, 200_000))
    lo, hi = uncertainty.mixture_interval({1: pred}, {1: 1.0}, {1: res}, 0.9, discrepancy=0.08,
                                    n_levels=2000)
    assert_allclose(hi - pred, 0.1645, atol=3e-3)
    res = np.linspace(0, 0.1, 1001)
    narrow = uncertainty.mixture_interval({1: pred}, {1: 1.0}, {1: res}, 0.9)
    wide = uncertainty.mixture_interval({1: pred}, {1: 1.0}, {1: res}, 0.9, discrepancy=0.05)
    assert np.all(wide[1] - wide[0] > narrow[1] - narrow[0] + 0.02)
    with pytest.raises(GearshotError, match="discrepancy"):
        uncertainty.mixture_interval({1: pred}, {1: 1.0}, {1: res}, 0.9, discrepancy=-0.1)


def test_model_discrepancy_widens_intervals_and_zero_is_split_conformal(fitted, data,
                                                                         tf_pair):
    db, healthy, long, faulty, y = data
    args = (db, healthy, faulty[20], y[20], long)
    pure = clone(fitted).set_params(calibration="tuned", model_discrepancy=0.0).fit(
        *args, selection_tf=tf_pair[1])
    lo0, hi0 = pure.predict_interval(faulty)
    q = uncertainty.conformal_quantile(pure.model_.validation_residuals, 0.9)
    assert_allclose(hi0, np.clip(pure.predict(faulty) + q, 0, 1))
    widened = clone(pure).set_params(model_discrepancy=0.1).fit(
        *args, selection_tf=tf_pair[1])
    lo1, hi1 = widened.predict_interval(faulty)
    assert_allclose(widened.predict(faulty), pure.predict(faulty))
    assert np.all(hi1 - lo1 >= hi0 - lo0 - 1e-12)
    assert np.mean(hi1 - lo1) > np.mean(hi0 - lo0) + 0.05
    with pytest.raises(GearshotError, match="model_discrepancy"):
        clone(pure).set_params(model_discrepancy=-1).fit(*args, selection_tf=tf_pair[1])


def test_soft_weighting_averages_the_plausible_grades(data, tf_pair):
    db, healthy, long, faulty, y = data
    args = (db, healthy, faulty[20], y[20], long)
    soft = OneFaultShotEstimator(random_state=0, nominal_grade=NOMINAL).fit(
        *args, selection_tf=tf_pair[1])
    best = OneFaultShotEstimator(random_state=0, nominal_grade=NOMINAL,
                                 calibration="tuned").fit(
        *args, selection_tf=tf_pair[1])
    assert best.grade_weights_ == {best.grade_: 1.0}
    assert soft.grade_ == best.grade_ and soft.grade_ in soft.grade_weights_
    assert_allclose(sum(soft.grade_weights_.values()), 1.0)
    X = soft.features_of(faulty)
    mix = sum(w * soft.grade_models_[g].predict(X) for g, w in soft.grade_weights_.items())
    assert_allclose(soft.predict(faulty), mix)
    assert_allclose(best.predict(faulty), best.model_.predict(X))
    with pytest.raises(GearshotError, match="calibration must be one of .*'mean'"):
        OneFaultShotEstimator(calibration="mean").fit(*args, selection_tf=tf_pair[1])


# ------------------------------------------------------------------------- paired simulation
def test_simulated_suppression_subtracts_each_twin():
    rng = np.random.default_rng(3)
    sa, twins = rng.normal(size=(2, 4, 64))
    assert_allclose(steps.suppress_harmonics_simulated(sa, np.ones(4, bool), twins),
                    sa - twins)
    with pytest.raises(GearshotError, match=r"twins must have the shape.*\(3, 64\)"):
        steps.suppress_harmonics_simulated(sa, np.ones(4, bool), twins[:3])


def test_twin_path_equals_propagating_signals_and_twins_apart(tf_pair):
    """Steps 4-6 with twins run on SA - twin (one propagation): the same differences as
    propagating SAs and twins apart, each scaled by the propagated healthy SAs' mean RMS;
    step 5's scale is one function for both domains."""
    rng = np.random.default_rng(7)
    sa = rng.normal(size=(6, N))
    twins = sa + 0.1 * rng.normal(size=(6, N))
    healthy = np.array([True, True, False, False, False, False])
    twins[healthy] = sa[healthy]
    noise = 0.01 * rng.normal(size=(6, N))
    tf = tf_pair[0]
    got = steps.simulated_features(sa, healthy, tf, mesh_order=38, names=["rms_diff"],
                                   twins=twins, noise=noise)
    p_sa, p_tw = steps.propagate_simulated(sa, tf), steps.propagate_simulated(twins, tf)
    scale = steps.rms_scale(p_sa[healthy])
    assert scale == pytest.approx(np.mean(np.sqrt(np.mean(p_sa[healthy] ** 2, axis=1))))
    want, _ = steps.centred_features(p_sa / scale - p_tw / scale + noise, mesh_order=38,
                                     names=["rms_diff"], healthy_mask=healthy)
    assert_allclose(got, want, rtol=1e-12, atol=1e-15)
    assert_allclose(steps.normalize_rms(p_sa, p_sa[healthy]), p_sa / scale)
    assert_allclose(steps.normalize_rms(p_sa, scale=scale), p_sa / scale)
    with pytest.raises(GearshotError, match="target_healthy has zero RMS"):
        steps.rms_scale(np.zeros((2, N)), name="target_healthy")


def test_residue_noise_has_the_measured_power_spectrum():
    rng = np.random.default_rng(4)
    shaped = np.fft.irfft(np.fft.rfft(rng.normal(size=(400, 256)), axis=-1)
                          * np.linspace(0.1, 2.0, 129), n=256, axis=-1)
    power = steps.residue_power(shaped)
    noise = steps.residue_noise(power, 400, 256, np.random.default_rng(5))
    got = steps.residue_power(noise)
    # bins averaged in blocks of 8: each block's mean power within 10 %
    assert_allclose(got[1:121].reshape(15, 8).mean(1), power[1:121].reshape(15, 8).mean(1),
                    rtol=0.1)
    with pytest.raises(GearshotError, match="129 bins; got shape"):
        steps.residue_noise(power[:-1], 3, 256, np.random.default_rng(0))


@pytest.fixture(scope="module")
def paired_db():
    return estimator_data.paired_synthetic_database()


def test_twin_reference_fits_and_is_seeded(paired_db, data, tf_pair):
    _, healthy, long, faulty, y = data
    kw = dict(options={"simulated_reference": "twin"}, random_state=0, nominal_grade=NOMINAL)
    args = (paired_db, healthy, faulty[20], y[20], long)
    a = OneFaultShotEstimator(**kw).fit(*args, selection_tf=tf_pair[1])
    b = OneFaultShotEstimator(**kw).fit(*args, selection_tf=tf_pair[1])
    assert a.target_residue_power_.shape == (N // 2 + 1,)
    assert set(a.step_seeds_) == {"select_features", "fit_knn", "match_noise"}
    assert_array_equal(a.predict(faulty), b.predict(faulty))
    pred = a.predict(faulty)
    means = [pred[y == s].mean() for s in (0.32, 0.56, 0.66)]
    assert means[0] < means[2]
    assert a.simulated_reference_ == "twin"
    # "auto" (the default) takes the twins of a paired database ...
    auto = OneFaultShotEstimator(random_state=0, nominal_grade=NOMINAL).fit(
        *args, selection_tf=tf_pair[1])
    assert auto.simulated_reference_ == "twin"
    assert_array_equal(auto.predict(faulty), pred)
    # ... and step 1 subtracts them too: its simulated healthy differences are zero
    # through the estimated TF (the training set), so their features sit at the centre
    from gearshot.estimator._model import _database_by_grade

    train_feats = auto.selection_features_[0]
    _, y_nom = _database_by_grade(paired_db, N)[NOMINAL]
    kept = np.delete(np.arange(y_nom.size), np.flatnonzero(y_nom == 0)[0])
    healthy_rows = np.flatnonzero(y_nom[kept] == 0)
    assert healthy_rows.size >= 2
    assert_allclose(np.std(train_feats[healthy_rows], axis=0), 0.0, atol=1e-9)
    # the paper's reference on the same database ignores the twins
    paper = OneFaultShotEstimator(random_state=0, nominal_grade=NOMINAL,
                                  options={"simulated_reference": "first_healthy"}).fit(
        *args, selection_tf=tf_pair[1])
    plain = OneFaultShotEstimator(random_state=0, nominal_grade=NOMINAL).fit(
        paired_db.drop_vars("sa_twin"), *args[1:], selection_tf=tf_pair[1])
    assert plain.simulated_reference_ == paper.simulated_reference_ == "first_healthy"
    assert_array_equal(paper.predict(faulty), plain.predict(faulty))


def test_twin_reference_needs_a_paired_database(data, tf_pair):
    db, healthy, long, faulty, y = data
    est = OneFaultShotEstimator(options={"simulated_reference": "twin"},
                                nominal_grade=NOMINAL)
    with pytest.raises(GearshotError, match="simulated_reference='twin' needs a paired"):
        est.fit(db, healthy, faulty[20], y[20], long, selection_tf=tf_pair[1])
    with pytest.raises(GearshotError,
                       match="options: simulated_reference must be one of .*'twins'"):
        OneFaultShotEstimator(options={"simulated_reference": "twins"}).fit(
            db, healthy, faulty[20], y[20], long, selection_tf=tf_pair[1])


def test_denoised_signature_takes_the_residue_off():
    from gearshot.estimator.zero_shot import healthy_signature, residue_mean_square

    rng = np.random.default_rng(6)
    theta = np.arange(N) / N
    gear = np.cos(2 * np.pi * 38 * theta) + 0.2 * np.cos(2 * np.pi * 7 * theta)
    noisy = gear + 0.3 * rng.normal(size=(40, N))
    # healthy differences hold two residues: half their mean square is one SA's residue
    res = residue_mean_square(noisy[:20] - noisy[20:], 38)
    clean = healthy_signature(gear[None], 38)[0]
    raw = healthy_signature(noisy, 38)
    fixed = healthy_signature(noisy, 38, residue_ms=res)
    assert np.median(raw) > clean + 0.5            # the residue dominates the raw signature
    assert abs(np.median(fixed) - clean) < 0.15    # and is taken off
    # never below 1 % of the measured power (no log of <= 0)
    assert np.all(np.isfinite(healthy_signature(noisy, 38, residue_ms=1e9)))
