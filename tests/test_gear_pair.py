"""The gear pair is the source of tooth counts (issue #21, item 1).

A database carries its pair; the estimator takes its mesh order from it, reports it as
``mesh_orders_`` and refuses target SAs declared for another tooth count, through the
Python API and through ``gearshot predict --gear-teeth``.
"""
import numpy as np
import pytest
from estimator_data import N, synthetic_target, tf_pair

from gearshot import GearshotError, paper
from gearshot.estimator import OneFaultShotEstimator
from gearshot.sim import GearPair, build_database, load_database, pair_attrs

PLAIN = dict(feature_selection=False, calibration="nominal", transfer_function="none",
             options={"n_neighbors": range(1, 4)}, random_state=0)


@pytest.fixture(scope="module")
def db40(tmp_path_factory):
    """A small simulated store of a 17/40 pair (one grade, a few seconds)."""
    pair = GearPair.paper(z_gear=40, mass_pinion=None, mass_gear=None)
    store = tmp_path_factory.mktemp("db40") / "db"
    build_database(store, pair, speeds=[15], loads=[10], grades=[7], n_healthy=3,
                   n_faulty=5, seed=1, client=False, progress=False)
    return store


@pytest.fixture(scope="module")
def target():
    tf, _ = tf_pair()
    healthy, long, test, y = synthetic_target(7, tf, n_healthy=10, n_each=2)
    return healthy, long, test[-1], float(y[-1])


def test_the_paper_module_holds_the_papers_set_up():
    assert (paper.PINION_TEETH, paper.GEAR_TEETH) == (17, 38)
    assert paper.TABLE1_SIZES == (0.32, 0.56, 0.66)
    assert paper.PAPER_SPEEDS[0] == 10 and paper.PAPER_SPEEDS[-1] == 35
    assert len(paper.PAPER_SPEEDS) == 26 and paper.PAPER_LOADS == (5.0, 10.0, 15.0, 20.0)
    pair = GearPair.paper()
    assert (pair.z_pinion, pair.z_gear) == (paper.PINION_TEETH, paper.GEAR_TEETH)
    assert OneFaultShotEstimator().mesh_order is None   # from the database, not a literal


def test_a_database_carries_its_gear_pair(db40):
    ds = load_database(db40, speed=15, load=10)
    assert ds.attrs["pinion_teeth"] == 17 and ds.attrs["gear_teeth"] == 40
    assert ds.attrs["module"] == pytest.approx(3e-3)
    assert ds.attrs["pressure_angle"] == pytest.approx(np.radians(20))
    assert ds.attrs["helix_angle"] == 0.0
    assert pair_attrs(GearPair.paper())["gear_teeth"] == 38


def test_the_estimator_takes_its_mesh_orders_from_the_database(db40, target):
    healthy, _, example, size = target
    ds = load_database(db40, speed=15, load=10)
    est = OneFaultShotEstimator(**PLAIN).fit(ds, healthy, example, size)
    assert est.mesh_orders_ == (40,)
    # the orders are used: a tone at the third harmonic of the 40-tooth mesh leaves the
    # features as they were, one at the 38-tooth mesh's does not (and the other way round
    # for an estimator told mesh_order=38)
    paper38 = OneFaultShotEstimator(mesh_order=38, **PLAIN).fit(ds, healthy, example, size)
    assert paper38.mesh_orders_ == (38,)
    theta = np.arange(N) / N
    base = healthy[:3]
    for fitted, hidden, seen in ((est, 120, 114), (paper38, 114, 120)):
        def change(order, fitted=fitted):
            tone = 2 * np.cos(2 * np.pi * order * theta)
            return np.abs(fitted.features_of(base + tone) - fitted.features_of(base)).max()
        assert change(hidden) < 1e-9 and change(seen) > 0.1, fitted.mesh_orders_
    told = OneFaultShotEstimator(mesh_order=[40, 20], **PLAIN).fit(ds, healthy, example, size)
    assert told.mesh_orders_ == (40, 20)


def test_target_sas_of_38_teeth_against_a_17_40_database_are_refused(db40, target):
    healthy, _, example, size = target
    ds = load_database(db40, speed=15, load=10)
    est = OneFaultShotEstimator(**PLAIN)
    with pytest.raises(GearshotError, match=r"gear_teeth=38.*17/40 pair \(gear_teeth=40\)"):
        est.fit(ds, healthy, example, size, gear_teeth=38)
    assert not hasattr(est, "mesh_orders_") and not hasattr(est, "_fitting_orders")
    with pytest.raises(GearshotError, match=r"pinion_teeth=18.*17/40"):
        est.fit(ds, healthy, example, size, gear_teeth=40, pinion_teeth=18)
    # an explicit mesh_order does not make another pair's SAs acceptable
    with pytest.raises(GearshotError, match="gear_teeth=38"):
        OneFaultShotEstimator(mesh_order=38, **PLAIN).fit(ds, healthy, example, size,
                                                          gear_teeth=38)
    with pytest.raises(GearshotError, match=r"gear_teeth must be .* got 38\.5"):
        est.fit(ds, healthy, example, size, gear_teeth=38.5)
    assert est.fit(ds, healthy, example, size, gear_teeth=40,
                   pinion_teeth=17).mesh_orders_ == (40,)


def test_a_database_without_pair_attributes_falls_back(db40, target):
    """A database built by hand (no pair attributes): the declared teeth, else 38."""
    healthy, _, example, size = target
    ds = load_database(db40, speed=15, load=10)
    ds.attrs.clear()
    assert OneFaultShotEstimator(**PLAIN).fit(ds, healthy, example, size).mesh_orders_ \
        == (paper.GEAR_TEETH,)
    assert OneFaultShotEstimator(**PLAIN).fit(ds, healthy, example, size,
                                              gear_teeth=40).mesh_orders_ == (40,)


def test_an_unreadable_manifest_pair_loads_without_pair_attributes():
    from gearshot.sim._db_manifest import pair_from_manifest as _pair_from_manifest

    assert _pair_from_manifest({"pair": "GearPair(z_pinion=17, z_gear=40)"}).z_gear == 40
    numpy2 = "GearPair(z_pinion=17, z_gear=np.int64(40), module=np.float64(0.004))"
    assert (_pair_from_manifest({"pair": numpy2}).z_gear,
            _pair_from_manifest({"pair": numpy2}).module) == (40, 0.004)
    for text in ("not a pair", "os.system('x')", "GearPair(17, 38)", "GearPair(z_gear=3)",
                 "GearPair(**{'z_gear': 40})", "GearPair(z_gear=np.sum(40))"):
        assert _pair_from_manifest({"pair": text}) is None, text
    assert _pair_from_manifest({}) is None


def test_cli_predict_refuses_recordings_of_another_tooth_count(db40, tmp_path):
    """`gearshot predict --gear-teeth 38` against a 17/40 database: one-line error
    naming both tooth counts (the option used to be ignored by the estimator); without
    the option the recordings are segmented for the database's pair and predicted."""
    import pandas as pd
    from test_reliability import one_line_error, run_cli

    from gearshot.rig import VirtualRig

    idx = VirtualRig(seed=1, engine="surrogate").campaign(
        tmp_path / "camp", speed=15, load=10, duration=8.0, healthy=2, sizes=(0.5,),
        repetitions=1, progress=False)
    healthy = list(idx.loc[idx.fault_size == 0, "path"])
    faulty = idx.loc[idx.fault_size > 0, "path"].iloc[0]
    args = ["predict", "--database", db40, "--faulty", faulty, "--faulty-size", "0.5",
            "--recordings", faulty, "--speed", "15", "--load", "10"]
    for h in healthy:
        args += ["--healthy", h]
    res = run_cli([*args, "--out", tmp_path / "p38.csv", "--gear-teeth", "38"])
    one_line_error(res, "gear_teeth=38", "38-tooth", "17/40", "gear_teeth=40")
    assert not (tmp_path / "p38.csv").exists()
    ok = run_cli([*args, "--out", tmp_path / "p.csv"])   # the database's pair
    assert ok.returncode == 0, ok.stderr
    frame = pd.read_csv(tmp_path / "p.csv")
    assert len(frame) >= 1 and frame["predicted"].between(0, 1).all()
    assert frame["below_detection_limit"].dtype == bool    # issue #30: every row says
