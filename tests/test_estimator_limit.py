"""The information-limit oracle (estimator/oracle.py)."""

from __future__ import annotations

import numpy as np
import pytest

from gearshot import GearshotError
from gearshot.estimator._simulated import residue_noise_spectrum
from gearshot.estimator.oracle import fault_bins, fit_template_oracle

N = 256
MESH = 19


def _components(y: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """One-sided spectra of a fault component whose shape changes with size: a pulse that
    grows in height (∝ y) and in width (∝ 1 + 3 y), at a fixed place in the cycle."""
    theta = np.arange(N) / N
    width = 0.01 * (1 + 3 * y[:, None])
    pulse = y[:, None] * np.exp(-0.5 * ((theta[None, :] - 0.3) / width) ** 2)
    return np.fft.rfft(pulse, axis=1)


def test_fault_bins_leave_out_dc_and_mesh_bands():
    bins = fault_bins(N, MESH)
    assert bins[0] == 1
    assert bins[-1] == N // 2
    assert 0 not in bins
    for k in (MESH, 2 * MESH, 6 * MESH):
        for s in range(-2, 3):
            assert k + s not in bins
    assert MESH + 3 in bins and MESH - 3 in bins


def test_oracle_recovers_size_from_templates_and_known_noise():
    rng = np.random.default_rng(0)
    y_train = np.r_[np.zeros(40), rng.uniform(0, 1, 400)]
    y_test = np.r_[np.zeros(10), rng.uniform(0.02, 1, 60)]
    power = np.full(N // 2 + 1, 0.02)
    oracle = fit_template_oracle(_components(y_train, rng), y_train, power,
                                 mesh_order=MESH, n_points=N, bandwidth=0.01)
    noisy = _components(y_test, rng) + residue_noise_spectrum(power, y_test.size, N, rng)
    pred = oracle.predict(noisy)
    err = np.abs(pred - y_test)
    assert np.mean(err) < 0.02
    assert np.all(pred[:10] <= 0.02)           # healthy read as healthy
    post = oracle.posterior(noisy)
    assert np.allclose(post.sum(axis=1), 1)
    # magnitudes only (the fault's place in the cycle unknown): still close, not better
    blind = fit_template_oracle(_components(y_train, rng), y_train, power, mesh_order=MESH,
                                n_points=N, bandwidth=0.01, phase=False)
    err_blind = np.abs(blind.predict(noisy) - y_test)
    assert np.mean(err_blind) < 0.05
    assert np.mean(err_blind) >= np.mean(err) - 0.005


def test_oracle_error_grows_with_noise():
    rng = np.random.default_rng(1)
    y_train = rng.uniform(0, 1, 400)
    y_test = rng.uniform(0, 1, 200)
    errors = []
    for level in (0.01, 1.0, 300.0):
        power = np.full(N // 2 + 1, level)
        oracle = fit_template_oracle(_components(y_train, rng), y_train, power,
                                     mesh_order=MESH, n_points=N)
        noisy = _components(y_test, rng) + residue_noise_spectrum(
            power, y_test.size, N, np.random.default_rng(2))
        errors.append(np.mean(np.abs(oracle.predict(noisy) - y_test)))
    assert errors[0] < errors[1] < errors[2]
    assert errors[2] > 0.1                     # noise far above the signal: little left


@pytest.mark.parametrize("kwargs, word", [
    (dict(differences=np.zeros((3, N // 2 + 1))), "differences"),
    (dict(fault_size=np.array([0.1, 0.2, 1.5])), "fault_size"),
    (dict(noise_power=np.zeros(N // 2 + 1)), "noise_power"),
    (dict(bandwidth=0.0), "bandwidth"),
])
def test_oracle_bad_inputs_name_the_argument(kwargs, word):
    args = dict(differences=np.zeros((3, N // 2 + 1), complex),
                fault_size=np.array([0.0, 0.2, 0.5]), noise_power=np.ones(N // 2 + 1),
                mesh_order=MESH, n_points=N)
    args.update(kwargs)
    with pytest.raises(GearshotError, match=word):
        fit_template_oracle(**args)


# ------------------------------------------------------------------ detection limit
def _fit_with_noise(noise):
    from estimator_data import paired_synthetic_database, synthetic_target, tf_pair

    from gearshot.estimator import OneFaultShotEstimator

    tfs = tf_pair()
    db = paired_synthetic_database(n_healthy=20, n_faulty=60)
    healthy, long, faulty, y = synthetic_target(6, tfs[0], n_healthy=15, n_each=5,
                                                noise=noise)
    est = OneFaultShotEstimator(nominal_grade=6, grades=[3, 6, 9], random_state=0)
    return est.fit(db, healthy, faulty[7], y[7], long, selection_tf=tfs[1]), faulty, y


def test_detection_limit_exists_and_grows_with_noise():
    from gearshot.estimator import below_detection_limit

    limits = []
    for noise in (0.2, 2.0, 8.0):
        est, faulty, y = _fit_with_noise(noise)
        assert 0 <= est.detection_limit_ <= 1
        assert est.detection_limit_ >= est.detection_threshold_
        limits.append(est.detection_limit_)
        pred = est.predict(faulty)
        flags = below_detection_limit(est, pred)
        assert flags.dtype == bool and flags.shape == pred.shape
        np.testing.assert_array_equal(flags, pred < est.detection_limit_)
    assert limits[0] < limits[1] < limits[2]


def test_an_estimate_below_the_limit_has_0_in_its_interval():
    """A fit without hold-outs (its intervals from the simulation): every estimate below
    ``detection_limit_`` gets a 90 % interval reaching 0 (it is not told apart from
    healthy), every other bound is the simulated one; a 50 % interval keeps its bounds."""
    from gearshot.estimator.detection import reach_zero_below_limit

    est, faulty, y = _fit_with_noise(2.0)
    assert getattr(est, "fit_check_", None) is None or not est.fit_check_.checked
    pred = est.predict(faulty)
    est.detection_limit_ = 0.0          # nothing below: the simulated intervals alone
    sim_low, sim_high = est.predict_interval(faulty, coverage=0.9)
    est.detection_limit_ = limit = 0.6  # a machine that resolves less
    below = pred < limit
    assert np.any(sim_low[below] > 0) and (~below).any()
    low, high = est.predict_interval(faulty, coverage=0.9)
    np.testing.assert_array_equal(low, np.where(below, 0.0, sim_low))
    np.testing.assert_array_equal(high, sim_high)
    plain = np.full(pred.size, 0.05)
    np.testing.assert_array_equal(reach_zero_below_limit(est, pred, plain, 0.9),
                                  np.where(below, 0.0, 0.05))
    np.testing.assert_array_equal(reach_zero_below_limit(est, pred, plain, 0.5), plain)


def test_detection_limit_from_validation_rows():
    from types import SimpleNamespace

    from gearshot.estimator.detection import detection_limit

    rng = np.random.default_rng(0)
    y = np.r_[np.zeros(200), rng.uniform(0, 1, 800)]
    pred = np.where(y == 0, np.abs(rng.normal(0, 0.05, y.size)), y + rng.normal(0, 0.02, y.size))
    model = SimpleNamespace(validation_y=y, validation_prediction=pred)
    found = detection_limit([model], [1.0])
    # healthy estimates |N(0, 0.05)|: 95 % quantile 1.96 * 0.05; unbiased faulty estimates
    assert found.threshold == pytest.approx(0.098, abs=0.015)
    assert found.limit == pytest.approx(found.threshold, abs=0.02)
    with pytest.raises(GearshotError, match="weights"):
        detection_limit([model], [-1.0])
    with pytest.raises(GearshotError, match="confidence"):
        detection_limit([model], [1.0], confidence=1.5)


def test_own_healthy_rows_raise_the_threshold_as_models_that_never_saw_them_read_them():
    """Boosted trees read their simulated healthy rows at 0; the machine's own healthy
    segments, read by the probes that never trained on them, set the threshold when they
    read higher: the 95 % quantile taken at the higher order statistic, weighted over the
    models as predict combines them."""
    from types import SimpleNamespace

    from gearshot.estimator.detection import detection_limit

    y = np.r_[np.zeros(100), np.linspace(0.01, 1, 400)]
    pred = np.where(y == 0, 0.0, y)
    own = np.linspace(0.0, 0.19, 20)   # 20 own rows read 0 … 0.19
    plain = SimpleNamespace(validation_y=y, validation_prediction=pred)
    assert detection_limit([plain], [1.0]).threshold == 0.0
    first = SimpleNamespace(validation_y=y, validation_prediction=pred, own_prediction=own)
    found = detection_limit([first], [1.0])
    assert found.threshold == pytest.approx(0.19)   # higher of 0.95 · 19 = 18.05 → the max
    assert found.limit == pytest.approx(0.19, abs=0.01)
    # a second model reading the same rows at 3× and weighted 1:3 → 0.25·own + 0.75·3·own
    second = SimpleNamespace(validation_y=y, validation_prediction=pred,
                             own_prediction=3 * own)
    assert detection_limit([first, second], [1.0, 3.0]).threshold == pytest.approx(
        0.19 * 2.5)
    # an unweighted model does not count
    assert detection_limit([first, second], [1.0, 0.0]).threshold == pytest.approx(0.19)


def test_boosting_probe_reads_the_own_rows_without_training_on_them():
    """fit_regressor(..., n_own=k): the last k rows are the machine's own healthy rows.
    Placed where the simulated rows say size 1, the probe that never trained on them reads
    them near 1, while the final model, trained on every row, reads them near 0."""
    from gearshot.estimator.regressors import fit_regressor

    rng = np.random.default_rng(0)
    x_sim = rng.uniform(0, 1, (400, 2))
    y_sim = x_sim[:, 0].copy()
    x_own = np.column_stack([rng.uniform(0.95, 1.0, 40), rng.uniform(0, 1, 40)])
    X, y = np.vstack([x_sim, x_own]), np.r_[y_sim, np.zeros(40)]
    model = fit_regressor("boosting", X, y, random_state=0, n_own=40)
    assert model.own_prediction is not None and model.own_prediction.shape == (40,)
    assert model.own_prediction.mean() > 0.8
    assert model.predict(x_own).mean() < 0.2
    assert fit_regressor("boosting", X, y, random_state=0).own_prediction is None
    with pytest.raises(GearshotError, match="n_own"):
        fit_regressor("boosting", X, y, random_state=0, n_own=len(y))
