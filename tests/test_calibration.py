"""Calibration beyond the grade (issue #19): fault gain, width and TF mode on twin differences."""

import estimator_data
import numpy as np
import pytest
from numpy.testing import assert_allclose

from gearshot import GearshotError
from gearshot.estimator import OneFaultShotEstimator
from gearshot.estimator.calibration import (
    CalibrationOptions,
    fault_centre,
    resolve_calibration,
    setting_log_likelihoods,
    stretch_about,
)

NOMINAL = 3   # the synthetic databases hold grades 3, 6 and 9


def _pulse(n=512, centre=200, sigma=6.0):
    offset = (np.arange(n) - centre + n // 2) % n - n // 2   # on the cycle
    return np.exp(-0.5 * (offset / sigma) ** 2)


def test_stretch_about_scales_a_pulse_width_about_its_centre():
    d = _pulse()[None, :]
    assert stretch_about(d, 1.0, 200) is not None
    assert_allclose(stretch_about(d, 1.0, 200), d)
    x = np.arange(512)
    for width in (0.5, 2.0):
        out = stretch_about(d, width, 200)[0]
        mean = np.sum(x * out) / out.sum()
        std = np.sqrt(np.sum((x - mean) ** 2 * out) / out.sum())
        assert mean == pytest.approx(200, abs=0.05)
        assert std == pytest.approx(6.0 * width, rel=0.02)
        assert out.max() == pytest.approx(1.0, abs=0.02)   # a stretch, not a gain


def test_stretch_about_wraps_on_the_cycle_and_zeroes_outside_a_compression():
    d = _pulse(centre=5)[None, :]          # the pulse straddles the cycle's start
    out = stretch_about(d, 2.0, 5)[0]
    # 15 samples before the centre (across sample 0) the stretched pulse is where the
    # original was at 7.5: exp(-0.5 (7.5/6)²)
    assert out[5] == pytest.approx(1.0) and out[-10] == pytest.approx(np.exp(-0.78125),
                                                                      abs=0.01)
    flat = np.ones((1, 512))
    squeezed = stretch_about(flat, 0.5, 100)[0]
    assert np.count_nonzero(squeezed) == pytest.approx(256, abs=2)


def test_fault_centre_finds_the_faulty_tooth_under_noise():
    rng = np.random.default_rng(0)
    delta = 0.2 * rng.standard_normal((30, 512)) + _pulse(centre=333, sigma=4)
    assert abs(fault_centre(delta) - 333) <= 3


def test_setting_log_likelihoods_prefer_the_setting_whose_cloud_holds_the_example():
    rng = np.random.default_rng(1)
    clouds = [rng.normal(mu, 0.1, size=(40, 2)) for mu in (0.0, 1.0, 2.0)]
    ll = setting_log_likelihoods(np.array([1.02, 0.97]), clouds, np.array([0.05, 0.05]))
    assert np.argmax(ll) == 1 and ll[1] - max(ll[0], ll[2]) > 20
    with pytest.raises(GearshotError, match="fewer than 2 simulated signals"):
        setting_log_likelihoods(np.zeros(2), [np.zeros((1, 2))], np.ones(2))


def test_resolve_calibration_names_bad_options():
    assert resolve_calibration("grade") is None
    assert resolve_calibration("joint") == CalibrationOptions()
    opts = resolve_calibration({"gains": [1, 2], "tf_modes": ["none"]})
    assert opts.gains == (1.0, 2.0) and opts.tf_modes == ("none",)
    with pytest.raises(GearshotError, match=r"unknown option\(s\) \['gain'\]"):
        resolve_calibration({"gain": [1]})
    with pytest.raises(GearshotError, match=r"gains must be.*positive.*\[0, 1\]"):
        CalibrationOptions(gains=[0, 1])
    with pytest.raises(GearshotError, match="tf_modes must hold 'tf' and/or 'none'"):
        CalibrationOptions(tf_modes=["blind"])
    with pytest.raises(GearshotError, match="calibration must be one of"):
        resolve_calibration("everything")
    est = OneFaultShotEstimator(calibration="everything")
    with pytest.raises(GearshotError, match="calibration.*'everything'"):
        est.fit(None, np.zeros((5, 64)))


@pytest.fixture(scope="module")
def target():
    tf, sel = estimator_data.tf_pair()
    healthy, long, faulty, y = estimator_data.synthetic_target(6, tf)
    return healthy, long, faulty, y, sel


@pytest.fixture(scope="module")
def paired_db():
    return estimator_data.paired_synthetic_database()


SMALL = dict(gains=[0.7, 1.0, 1.4], widths=[0.8, 1.0], n_near=16, max_settings=4)


@pytest.fixture(scope="module")
def joint(paired_db, target):
    healthy, long, faulty, y, sel = target
    est = OneFaultShotEstimator(random_state=0, nominal_grade=NOMINAL, calibration=SMALL)
    return est.fit(paired_db, healthy, faulty[20], y[20], long, selection_tf=sel)


def test_joint_calibration_weights_settings_and_predicts_their_mixture(joint, target):
    healthy, long, faulty, y, sel = target
    cal = joint.calibration_
    assert joint.grade_strategy_ == "joint" and cal["strategy"] == "joint"
    weights = [s["weight"] for s in cal["settings"]]
    assert 1 <= len(weights) <= 4 and sum(weights) == pytest.approx(1.0)
    assert weights == sorted(weights, reverse=True)
    # the grid: 3 grades × 3 gains × 2 widths × 2 TF modes, each with a log-likelihood
    assert len(cal["grid"]["log_likelihood"]) == 36
    assert set(cal["grid"]["tf"]) == {"tf", "none"}
    assert cal["grid"]["weight"].sum() == pytest.approx(1.0)
    best = int(np.argmax(cal["grid"]["log_likelihood"]))
    top = cal["settings"][0]
    assert (top["grade"], top["gain"], top["width"], top["tf"]) == (
        cal["grid"]["grade"][best], cal["grid"]["gain"][best], cal["grid"]["width"][best],
        cal["grid"]["tf"][best])
    X = joint.features_of(faulty)
    mix = sum(s["weight"] * m.predict(X) for s, m in zip(cal["settings"],
                                                        joint.setting_models_))
    assert_allclose(joint.predict(faulty), mix)
    assert sum(joint.grade_weights_.values()) == pytest.approx(1.0)
    # the product still estimates: far better than a constant guess
    assert np.mean(np.abs(joint.predict(faulty) - y)) < 0.5 * np.mean(np.abs(y - y.mean()))
    low, high = joint.predict_interval(faulty)
    assert np.all(low <= joint.predict(faulty) + 1e-12)
    assert np.all(high >= joint.predict(faulty) - 1e-12)


def test_a_setting_at_gain_1_and_width_1_is_the_twin_grade_model(paired_db, target):
    healthy, long, faulty, y, sel = target
    one = dict(gains=[1.0], widths=[1.0], tf_modes=["tf"], n_near=16, max_settings=3,
               temperature=1e6)   # every grade kept, nearly equal weights
    kw = dict(random_state=0, feature_selection=False)
    joint = OneFaultShotEstimator(calibration=one, **kw).fit(
        paired_db, healthy, faulty[20], y[20], long)
    assert [s["grade"] for s in joint.calibration_["settings"]] != []
    X = joint.features_of(faulty)
    for setting, model in zip(joint.calibration_["settings"], joint.setting_models_):
        ref = OneFaultShotEstimator(calibration="nominal",   # joint does not whiten
                                    nominal_grade=setting["grade"],
                                    options={"residue_whitening": "off"}, **kw)
        ref.fit(paired_db, healthy, faulty[20], y[20], long)
        assert ref.simulated_reference_ == "twin"
        # the same KNN on the same twin differences and matched noise (up to rounding)
        assert model.n_neighbors == ref.model_.n_neighbors
        assert_allclose(model.predict(X), ref.model_.predict(X), atol=1e-9)


def test_joint_needs_twins_and_falls_back_to_the_grade(paired_db, target):
    healthy, long, faulty, y, sel = target
    est = OneFaultShotEstimator(random_state=0, nominal_grade=NOMINAL, calibration="joint")
    est.fit(paired_db.drop_vars("sa_twin"), healthy, faulty[20], y[20], long,
            selection_tf=sel)
    assert est.grade_strategy_ == "soft" and est.calibration_["strategy"] == "grade"
    assert [s["grade"] for s in est.calibration_["settings"]] == list(est.grade_weights_)
    assert all(s["gain"] == 1.0 and s["width"] == 1.0 for s in est.calibration_["settings"])


def test_without_a_tf_the_joint_calibration_uses_rms_normalization_only(paired_db, target):
    healthy, long, faulty, y, sel = target
    est = OneFaultShotEstimator(random_state=0, nominal_grade=NOMINAL, calibration=SMALL,
                                transfer_function="none", feature_selection=False)
    est.fit(paired_db, healthy, faulty[20], y[20])
    assert set(est.calibration_["grid"]["tf"]) == {"none"}
    assert all(s["tf"] == "none" for s in est.calibration_["settings"])


def test_default_is_the_grade_calibration_chosen_on_the_development_range():
    assert OneFaultShotEstimator().calibration == "grade"
