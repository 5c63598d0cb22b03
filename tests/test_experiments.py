"""Dataset builders of Sec. 4.1 / 4.2, the variant table, the runner and the figures."""

import numpy as np
import pandas as pd
import pytest
from estimator_data import N, synthetic_sa
from numpy.testing import assert_allclose

from gearshot import GearshotError
from gearshot.experiments import (
    RIG_VARIANTS,
    SIMULATED_VARIANTS,
    evaluate_variants,
    rig_dataset,
    rig_experiment,
    simulated_dataset,
    summarize,
    variant_params,
)


@pytest.fixture(scope="module")
def sim_data():
    rng = np.random.default_rng(0)
    y = np.r_[np.zeros(40), rng.uniform(0, 1, 160)]
    return synthetic_sa(y, 4, rng), y


def test_simulated_dataset_splits_like_the_paper(sim_data):
    sa, y = sim_data
    ds = simulated_dataset(sa, y, np.ones(N), attenuation_db=20, noise_fraction=0.0,
                           random_state=0)
    n_h_train = int((ds.database.fault_size == 0).sum())
    assert n_h_train == 20  # healthy half/half
    assert int((ds.database.fault_size > 0).sum()) == 112  # faulty 70 %
    assert ds.target_healthy.shape == (5, N)  # 25 % of the 20 test healthy
    # 15 healthy + 48 faulty - the example
    assert ds.test_sa.shape == (62, N) and ds.test_size.shape == (62,)
    assert 0 < ds.faulty_size <= 1
    # no noise, flat path: test signals are the simulated ones × 10^(-20/20)
    idx = [int(np.flatnonzero(np.all(np.isclose(sa, t / 0.1), axis=1))[0])
           for t in ds.test_sa[:3]]
    assert_allclose(ds.test_size[:3], y[idx])
    train_rows = {tuple(r[:4]) for r in ds.database["sa"].values}
    assert not any(tuple(t[:4] / 0.1) in train_rows for t in ds.test_sa)  # disjoint
    assert ds.healthy_long.size == 128 * N
    again = simulated_dataset(sa, y, np.ones(N), attenuation_db=20, noise_fraction=0.0,
                              random_state=0)
    assert_allclose(again.test_sa, ds.test_sa)


def test_simulated_dataset_bad_input(sim_data):
    sa, y = sim_data
    with pytest.raises(GearshotError, match="attenuation_db"):
        simulated_dataset(sa, y, np.ones(N), attenuation_db=-3)
    with pytest.raises(GearshotError, match="healthy"):
        simulated_dataset(sa[40:], y[40:], np.ones(N))


def test_variants_table():
    assert set(SIMULATED_VARIANTS) <= set(RIG_VARIANTS)
    assert variant_params("full") == {}
    assert variant_params("before_da")["rms_normalization"] is False
    with pytest.raises(GearshotError, match="valid variants"):
        variant_params("best")


def test_evaluate_variants_and_summary(sim_data):
    sa, y = sim_data
    ds = simulated_dataset(sa, y, np.ones(N), random_state=1)
    rows = evaluate_variants(ds.fit_args(), ds.test_sa, ds.test_size,
                             variants=SIMULATED_VARIANTS, selection_tf=np.ones(N),
                             random_state=0)
    frame = pd.DataFrame(rows)
    assert list(frame["variant"]) == list(SIMULATED_VARIANTS)
    mae = frame.set_index("variant")["mae"]
    constant = np.mean(np.abs(ds.test_size - 0.5))  # the always-0.5 predictor
    # every variant learns something; with an identity path, the variants that do not
    # estimate a TF are far better than chance (measured 0.13-0.15 against 0.33)
    assert (mae < constant).all(), (mae, constant)
    assert mae["before_da"] < 0.6 * constant and mae["rms_only"] < 0.6 * constant
    table = summarize(frame)
    assert_allclose(table.set_index("variant").loc["full", "mae_percent"],
                    100 * frame.set_index("variant").loc["full", "mae"])


@pytest.fixture(scope="module")
def small_campaign(tmp_path_factory):
    from gearshot.rig import VirtualRig

    folder = tmp_path_factory.mktemp("campaign")
    VirtualRig(seed=3).campaign(folder, speed=30.0, load=10.0, duration=4.0, healthy=3,
                                sizes=(0.6,), repetitions=3)
    return folder


def test_rig_dataset_keeps_the_example_recording_out_of_the_test_set(small_campaign):
    ds = rig_dataset(small_campaign, n_train_healthy=2, cycles_per_segment=10,
                     random_state=0)
    assert ds.target_healthy.shape[1] == 2048
    assert ds.faulty_size == pytest.approx(0.6)
    assert ds.example_recording not in set(ds.test_recording)
    assert set(np.unique(ds.test_size)) == {0.0, 0.6}
    assert ds.healthy_long.size % 2048 == 0 and ds.healthy_long.size >= 2 ** 15
    with pytest.raises(GearshotError, match="n_train_healthy"):
        rig_dataset(small_campaign, n_train_healthy=3, cycles_per_segment=10)
    with pytest.raises(GearshotError, match="speed"):
        rig_dataset(small_campaign, speed=15.0, cycles_per_segment=10)


def test_a_checked_fit_holds_out_each_healthy_recordings_last_quarter(small_campaign):
    """``checked``: the fit is given what ``gearshot predict`` gives: the last quarter of
    each healthy recording held out, the example recording's other segments."""
    from gearshot.experiments.rig import CHECKED_HOLDOUT

    ds = rig_dataset(small_campaign, n_train_healthy=2, cycles_per_segment=10,
                     random_state=0)
    labels = ds.healthy_recordings
    args, kw = ds.fit_args("db", checked=True), ds.fit_kwargs(checked=True)
    plain = ds.fit_kwargs()
    assert "healthy_holdout" not in plain and plain["healthy_recordings"] is labels
    kept, held = [], []
    for name in dict.fromkeys(labels.tolist()):
        sa = ds.target_healthy[labels == name]
        n_out = int(np.floor(CHECKED_HOLDOUT * len(sa)))
        assert n_out >= 1
        kept.append(sa[: len(sa) - n_out])
        held.append(sa[len(sa) - n_out:])
    assert_allclose(args[1], np.vstack(kept))
    assert_allclose(kw["healthy_holdout"], np.vstack(held))
    assert len(kw["healthy_recordings"]) == len(args[1]) and kw["holdout"] == CHECKED_HOLDOUT
    rest = kw["example_record"]
    assert rest.shape[0] >= 1 and rest.shape[1] == ds.faulty_example.size
    assert not np.any(np.all(rest == ds.faulty_example, axis=1))
    assert args[0] == "db" and args[2] is ds.faulty_example and args[3] == ds.faulty_size


def test_rig_experiment_rejects_an_unknown_keep_estimators(small_campaign):
    with pytest.raises(GearshotError, match="keep_estimators.*'last'"):
        rig_experiment(small_campaign, None, speed=10, load=5, selection_tf=None,
                       keep_estimators="last")


def test_figures_and_report(tmp_path, sim_data):
    from gearshot.app.figures import report_from_json, simulated_figures

    rows = pd.DataFrame([dict(speed=s, load=10.0, tf=t, attenuation_db=10.0, variant=v,
                              mae=0.1 + 0.01 * s / 10 + (v == "before_da") * 0.1)
                         for s in (10.0, 20.0) for t in ("a", "b")
                         for v in SIMULATED_VARIANTS])
    figs = simulated_figures(rows, tmp_path)
    assert all(p.is_file() and p.stat().st_size > 1000 for p in figs.values())
    assert all(p.with_suffix(".pdf").is_file() for p in figs.values())
    report = (tmp_path / "report.md").read_text()
    assert "before_da" in report and "fig13a_error_vs_speed.png" in report
    import json

    (tmp_path / "res.json").write_text(json.dumps({"experiment": "simulated",
                                                   "rows": rows.to_dict("records")}))
    out = report_from_json(tmp_path / "res.json", tmp_path / "again")
    assert out.is_file()
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(GearshotError, match="bad.json"):
        report_from_json(tmp_path / "bad.json", tmp_path / "x")


def test_rig_figures_include_fig11_and_the_tuning_curve(tmp_path, sim_data):
    from gearshot.app.figures import rig_figures
    from gearshot.estimator import OneFaultShotEstimator

    sa, y = sim_data
    tf = np.ones(N, complex)
    ds = simulated_dataset(sa, y, tf, random_state=1)
    db = ds.database.assign_coords(grade=("signal", np.where(np.arange(ds.database.sizes[
        "signal"]) % 2 == 0, 3, 6)))
    est = OneFaultShotEstimator(random_state=0, grades=[3, 6], nominal_grade=3).fit(
        db, ds.target_healthy, ds.faulty_example, ds.faulty_size, ds.healthy_long,
        selection_tf=tf)
    train, test = est.selection_features_
    assert train.shape == test.shape == (train.shape[0], 4)
    pred = est.predict(ds.test_sa)
    predictions = pd.DataFrame(dict(variant="full", true=ds.test_size, predicted=pred))
    results = pd.DataFrame([dict(variant="full", mae=float(np.mean(np.abs(pred - ds.test_size))))])
    figs = rig_figures(results, predictions, tmp_path, estimator=est)
    names = {p.name for p in figs.values()}
    assert {"fig11_feature_invariance.png", "tuning_curve.png", "fig14a.png"} <= names
    assert all(p.stat().st_size > 1000 for p in figs.values())
    assert "fig11_feature_invariance.png" in (tmp_path / "report.md").read_text()
