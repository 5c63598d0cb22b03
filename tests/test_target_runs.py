"""Healthy recordings of several runs: step 6's target-side differences of the fit are
formed with references of *other* runs (``gearshot.estimator._target.cross_run``), as a
new recording's are. Analytic SAs: one gear, each run off by its own synchronous change
(what a remount, another day's temperature or a slightly other load leaves)."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from estimator_data import N, paired_synthetic_database, synthetic_sa, tf_pair

from gearshot._errors import GearshotError, NotFittedError
from gearshot.estimator import OneFaultShotEstimator
from gearshot.estimator._target import cross_run
from gearshot.signal.alignment import subtract_healthy
from gearshot.transfer import propagate


def _run_change(rng: np.random.Generator, size: float) -> np.ndarray:
    """A run's own synchronous change: random content at orders 1–300, RMS ``size``."""
    spec = np.zeros(N // 2 + 1, complex)
    orders = np.arange(1, 301)
    spec[orders] = rng.normal(size=orders.size) + 1j * rng.normal(size=orders.size)
    x = np.fft.irfft(spec, n=N)
    return np.asarray(size * x / x.std())


def _runs(n_runs: int, per_run: int, *, seed: int, fault: float = 0.0,
          run_size: float = 6.0, noise: float = 0.5) -> np.ndarray:
    """``n_runs`` runs of ``per_run`` SAs of one grade-6 gear (size ``fault``)."""
    rng = np.random.default_rng(seed)
    gear = synthetic_sa([fault], 6, np.random.default_rng(7), same_gear=True)[0]
    return np.array([[gear + change + noise * rng.normal(size=N) for _ in range(per_run)]
                     for change in (_run_change(rng, run_size) for _ in range(n_runs))])


def _scenario(make_runs):
    """Through a resonant path: 4 fit runs of 6 healthy SAs (labelled), a long healthy
    signal, an example of size 0.5, 6 new healthy runs of 2 SAs and 6 new faulty SAs; the
    held-out path for step 1 and a paired database."""
    path, held_out = tf_pair()
    db = paired_synthetic_database(n_healthy=20, n_faulty=60)

    def through(runs):
        return propagate(runs.reshape(-1, N), path)

    return (held_out, db, through(make_runs(4, 6, seed=2)), np.repeat(np.arange(4), 6),
            through(make_runs(1, 40, seed=3)).ravel(),
            through(make_runs(1, 1, seed=4, fault=0.5))[0],
            through(make_runs(6, 2, seed=5)), through(make_runs(6, 1, seed=6, fault=0.5)))


def test_cross_run_subtracts_references_of_other_recordings_only():
    runs = _runs(3, 3, seed=1)
    train, refs = runs[:, :2].reshape(-1, N), runs[:, 2]
    labels = np.r_[np.repeat([0, 1, 2], 2), [0, 1, 2]]
    out = cross_run(train, refs, labels, upsample=4)
    for run in range(3):
        rows = np.nonzero(labels[:6] == run)[0]
        others = refs[np.arange(3) != run]
        np.testing.assert_allclose(out[rows], subtract_healthy(train[rows], others,
                                                               upsample=4))
    # with its own run's reference allowed, step 6 picks it and hides the run change
    same_run = subtract_healthy(train, refs, upsample=4)
    assert (out ** 2).mean() > 10 * (same_run ** 2).mean()
    # a recording that holds every reference keeps them all
    solo = cross_run(train[:2], refs[:1], np.r_[0, 0, 0], upsample=4)
    np.testing.assert_allclose(solo, subtract_healthy(train[:2], refs[:1], upsample=4))


def test_new_runs_read_healthy_when_the_fit_differences_cross_runs(monkeypatch):
    """Fitted on 4 labelled runs, healthy SAs of 6 new runs read near 0 and new runs of
    the faulty gear near the example's size; with each training SA's own run among its
    references (the differences then hold the within-run noise only, what
    :func:`cross_run` replaces) the same new healthy runs read as a half-size fault."""
    import gearshot.estimator._target as target

    (held_out, db, fit_runs, labels, long, example, new_healthy,
     new_faulty) = _scenario(_runs)

    def fit(whitening="auto"):
        est = OneFaultShotEstimator(nominal_grade=6, grades=[3, 6, 9], random_state=0,
                                    options={"residue_whitening": whitening})
        return est.fit(db, fit_runs, example, 0.5, long, selection_tf=held_out,
                       healthy_recordings=labels)

    for whitening in ("auto", "off"):   # 4 runs: the default whitens
        by_run = fit(whitening)
        assert (by_run.residue_weights_ is None) == (whitening == "off")
        assert by_run.predict(new_healthy).mean() <= 0.15
        assert abs(np.median(by_run.predict(new_faulty)) - 0.5) <= 0.2
    # the residue's power, compared unweighted
    monkeypatch.setattr(target, "cross_run", lambda train, refs, rec, up, unscaled=None,
                        blend=1: target.suppressed_target(train, refs, up, unscaled, blend))
    within_run = fit("off")
    assert by_run.target_residue_power_.sum() > 50 * within_run.target_residue_power_.sum()
    assert within_run.predict(new_healthy).mean() >= 0.3


def _band_runs(n_runs: int, per_run: int, *, seed: int, fault: float = 0.0) -> np.ndarray:
    """Runs whose change sits in one band of orders (what a drifting speed leaves near a
    resonance), far louder there than the fault."""
    rng = np.random.default_rng(seed)
    gear = synthetic_sa([fault], 6, np.random.default_rng(7), same_gear=True)[0]
    out = []
    for _ in range(n_runs):
        spec = np.zeros(N // 2 + 1, complex)
        band = np.arange(150, 200)
        spec[band] = rng.normal(size=band.size) + 1j * rng.normal(size=band.size)
        change = np.fft.irfft(spec, n=N)
        change *= 20 / change.std()
        out.append([gear + change + 0.3 * rng.normal(size=N) for _ in range(per_run)])
    return np.array(out)


def _band_fit(scenario, options, runs=None):
    """The estimator fitted on a :func:`_scenario`'s runs (labelled by run unless ``runs``
    relabels them) with ``options``."""
    held_out, db, fit_runs, labels, long, example = scenario[:6]
    est = OneFaultShotEstimator(nominal_grade=6, grades=[3, 6, 9], random_state=0,
                                options=options)
    return est.fit(db, fit_runs, example, 0.5, long, selection_tf=held_out,
                   healthy_recordings=labels if runs is None else runs)


def test_residue_whitening_reads_new_runs_of_a_band_limited_change_closer_to_truth():
    """The fit's 4 runs show where a new run's residue lies; weighting those orders down
    reads new healthy runs nearer 0 and new faulty ones nearer their size than the
    unweighted differences do. One run gives no weights (``MIN_RUNS``)."""
    scenario = _scenario(_band_runs)
    held_out, db, fit_runs, labels, long, example, new_healthy, new_faulty = scenario

    def error(whitening, runs=None):
        est = _band_fit(scenario, {"residue_whitening": whitening}, runs)
        return est, (np.abs(est.predict(new_healthy)).mean()
                     + np.abs(est.predict(new_faulty) - 0.5).mean())

    whitened, err_on = error("auto")
    plain, err_off = error("off")
    assert whitened.residue_weights_ is not None and plain.residue_weights_ is None
    assert err_on < 0.7 * err_off
    one_run, _ = error("on", np.zeros(24, int))
    assert one_run.residue_weights_ is None
    paper = OneFaultShotEstimator(nominal_grade=6, grades=[3, 6, 9], random_state=0,
                                  estimator="paper").fit(
        db, fit_runs, example, 0.5, long, selection_tf=held_out, healthy_recordings=labels)
    assert paper.residue_weights_ is None


def test_recorded_residue_draws_are_turned_signed_copies_of_the_healthy_differences():
    from gearshot.estimator._simulated import recorded_residue_spectrum

    rng = np.random.default_rng(0)
    levels = np.array([0.2, 1.0, 5.0])[:, None]     # three runs, their residue levels apart
    rows = levels * rng.normal(size=(3, 64))
    spec = recorded_residue_spectrum(rows, 300, np.random.default_rng(1))
    draws = np.fft.irfft(spec, n=64, axis=-1)
    for d in draws:   # each draw is ± one row turned by a whole number of points
        assert any(np.allclose(d, s * np.roll(r, t)) for r in rows for s in (1, -1)
                   for t in range(64))
    # every run's own level is drawn, and only those (Gaussian draws of the mean power
    # would all lie near one level)
    power, row_power = (draws ** 2).mean(axis=1), (rows ** 2).mean(axis=1)
    nearest = np.abs(power[:, None] - row_power[None, :]).argmin(axis=1)
    np.testing.assert_allclose(power, row_power[nearest])
    assert set(nearest.tolist()) == {0, 1, 2}
    np.testing.assert_allclose(spec, recorded_residue_spectrum(rows, 300,
                                                               np.random.default_rng(1)))


def test_recorded_residue_draws_follow_the_whitening():
    """``residue_draws="auto"`` draws the matched residue from the fit's healthy
    differences when the fit whitens (several runs), and stays Gaussian when it does not
    (one run: the same estimates as ``"gaussian"``)."""
    scenario = _scenario(_band_runs)
    new = np.vstack(scenario[6:])

    def predict(draws, runs=None):
        return _band_fit(scenario, {"residue_draws": draws}, runs).predict(new)

    assert not np.allclose(predict("auto"), predict("gaussian"))
    one_run = np.zeros(24, int)
    np.testing.assert_array_equal(predict("auto", one_run), predict("gaussian", one_run))


def test_auto_model_discrepancy_follows_the_whitening():
    """``model_discrepancy="auto"`` widens a whitened one-fault-shot fit's intervals by
    ``WHITENED_DISCREPANCY`` and any other fit's by ``MODEL_DISCREPANCY``: the intervals
    are those of the number set by hand, and the smaller one is narrower."""
    from types import SimpleNamespace

    from gearshot.estimator.uncertainty import (
        MODEL_DISCREPANCY,
        WHITENED_DISCREPANCY,
        fit_discrepancy,
    )

    assert WHITENED_DISCREPANCY < MODEL_DISCREPANCY
    scenario = _scenario(_band_runs)
    new = np.vstack(scenario[6:])
    whitened = _band_fit(scenario, None)
    assert whitened.model_discrepancy == "auto"
    assert fit_discrepancy(whitened) == WHITENED_DISCREPANCY == whitened.model_discrepancy_
    auto = whitened.predict_interval(new)
    whitened.model_discrepancy = WHITENED_DISCREPANCY
    np.testing.assert_array_equal(auto, whitened.predict_interval(new))
    whitened.model_discrepancy = MODEL_DISCREPANCY
    low, high = whitened.predict_interval(new)
    assert np.mean(high - low) > np.mean(auto[1] - auto[0]) + 0.01
    one_run = _band_fit(scenario, None, np.zeros(24, int))   # no whitening
    assert fit_discrepancy(one_run) == MODEL_DISCREPANCY == one_run.model_discrepancy_
    with pytest.raises(NotFittedError, match="model_discrepancy_"):
        _ = OneFaultShotEstimator().model_discrepancy_
    zero_shot = SimpleNamespace(model_discrepancy="auto", grade_strategy_="zero_shot",
                                residue_weights_=whitened.residue_weights_)
    assert fit_discrepancy(zero_shot) == MODEL_DISCREPANCY
    assert fit_discrepancy(SimpleNamespace(model_discrepancy=0.3)) == 0.3


def test_the_fit_records_how_many_references_step_6_blends():
    """The default blends 3 references in a fit on healthy runs of 3 recordings or more
    (one that whitens its residue); the paper's estimator and a fit on one recording keep
    one; a fit saved before the blend existed (no ``reference_blend_``) predicts with one
    reference."""
    held_out, db, fit_runs, labels, long, example, new_healthy, _ = _scenario(_runs)

    def fit(recordings=labels, **kwargs):
        est = OneFaultShotEstimator(nominal_grade=6, grades=[3, 6, 9], random_state=0,
                                    **kwargs)
        return est.fit(db, fit_runs, example, 0.5, long, selection_tf=held_out,
                       healthy_recordings=recordings)

    one = fit(options={"reference_blend": 1})
    assert fit().reference_blend_ == 3
    assert fit(estimator="paper").reference_blend_ == 1
    assert fit(recordings=None).reference_blend_ == 1
    assert fit(recordings=np.r_[np.zeros(12), np.ones(12)]).reference_blend_ == 1
    assert one.reference_blend_ == 1
    blended = fit(options={"reference_blend": 3})
    old = copy.deepcopy(one)     # the same fit, as saved before the blend existed
    del old.__dict__["reference_blend_"]
    np.testing.assert_array_equal(old.predict(new_healthy), one.predict(new_healthy))
    assert not np.array_equal(blended.predict(new_healthy), one.predict(new_healthy))
    with pytest.raises(GearshotError, match="reference_blend"):
        OneFaultShotEstimator(options={"reference_blend": 0}).fit(
            db, fit_runs, example, 0.5, long, selection_tf=held_out)
