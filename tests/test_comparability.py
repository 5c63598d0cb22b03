"""Comparability (issue #19 item 5): does a segment look like the fitted machine?

Real PHM09 records (../shared/data/phm09, spur train, 30 Hz High, 10-revolution SAs of the
input shaft) and analytic SAs; the estimator's method on the fast synthetic database."""

from __future__ import annotations

from pathlib import Path

import estimator_data
import numpy as np
import pytest
from estimator_data import N, synthetic_database, synthetic_sa, synthetic_target
from numpy.testing import assert_allclose

from gearshot import GearshotError, Machine
from gearshot.estimator import NotFittedError, OneFaultShotEstimator
from gearshot.estimator.comparability import (
    DEFAULT_THRESHOLD,
    fit_comparability,
    harmonic_orders,
    harmonic_profile,
)
from gearshot.transfer import propagate

ROOT = Path(__file__).resolve().parents[1]
PHM = ROOT.parent / "shared" / "data" / "phm09"
MESHES = [32, 16]  # Machine.mesh_orders("input") of the PHM09 spur train


@pytest.fixture(scope="module")
def phm():
    """SA segments (10 input revolutions) of spur1/2/3 at 30 Hz High, both sensors."""
    from gearshot.app.predict_machine import machine_segments

    machine = Machine.from_toml(ROOT / "examples" / "machines" / "phm09_spur.toml")
    assert list(machine.mesh_orders("input")) == MESHES
    out = {}
    for case in ("spur1", "spur2", "spur3"):
        path = PHM / f"{case}_30hz_High_1.zip"
        if not path.is_file():
            pytest.skip(f"{path} is absent; real-data checks need ../shared/data/phm09")
        for sensor in ("acc_input", "acc_output"):
            out[case, sensor] = machine_segments(path, machine, cycles_per_segment=10,
                                                 sensor=sensor)[0]
    return out


def _reference(phm, sensor="acc_input"):
    healthy = phm["spur3", sensor]
    return fit_comparability(healthy[:-2], MESHES, faulty_example=phm["spur2", sensor][0],
                             faulty_size=0.5)


@pytest.mark.parametrize("sensor", ["acc_input", "acc_output"])
def test_spur1_another_build_is_flagged_and_the_same_build_is_not(phm, sensor):
    ref = _reference(phm, sensor)
    held_out = ref.evaluate(phm["spur3", sensor][-2:])
    rest = ref.evaluate(phm["spur2", sensor][1:])
    other_build = ref.evaluate(phm["spur1", sensor])
    assert held_out.comparable.all() and rest.comparable.all()
    assert not other_build.comparable.any()
    # a healthy segment of the fitted machine is about one healthy spread away
    assert held_out.score.max() < 2.0
    assert other_build.score.min() > 1.5 * DEFAULT_THRESHOLD


def test_another_sensor_is_flagged(phm):
    ref = _reference(phm, "acc_input")
    assert not ref.evaluate(phm["spur3", "acc_output"]).comparable.any()


def test_estimator_carries_the_reference_from_fit(phm):
    """The estimator's method scores what fit_comparability scores (same inputs)."""
    db = synthetic_database(grades=(3,), n_healthy=6, n_faulty=20)
    # a synthetic database of 2048-point SAs serves the mechanics; the comparability
    # reference depends only on the target's healthy SAs and the example
    healthy, example = phm["spur3", "acc_input"][:-2], phm["spur2", "acc_input"][0]
    est = OneFaultShotEstimator(mesh_order=MESHES, feature_selection=False,
                                calibration="nominal", nominal_grade=3,
                                transfer_function="none", options={"n_neighbors": range(1, 6)},
                                random_state=0)
    est.fit(db, healthy, example, 0.5)
    got = est.comparability(phm["spur1", "acc_input"])
    want = _reference(phm).evaluate(phm["spur1", "acc_input"])
    assert_allclose(got.score, want.score)
    assert not got.comparable.any()
    assert est.comparability(phm["spur3", "acc_input"][-2:]).comparable.all()
    # a stricter threshold flags more: the score does not move, the verdict does
    strict = est.comparability(phm["spur3", "acc_input"][-2:], threshold=1e-3)
    assert not strict.comparable.any() and strict.threshold == 1e-3


# ----------------------------------------------------------------------- analytic
def _mesh_sa(amplitudes, *, mesh=38, shift=0.0, noise=0.0, rng=None):
    theta = np.arange(N) / N + shift
    sa = sum(a * np.cos(2 * np.pi * (k + 1) * mesh * theta + k)
             for k, a in enumerate(amplitudes))
    if noise:
        sa = sa + noise * rng.standard_normal(N)
    return sa


def test_profile_is_the_unit_amplitude_vector_at_the_mesh_harmonics():
    assert list(harmonic_orders(64, [8, 4])) == [4, 8, 12, 16, 20, 24, 28]
    sa = _mesh_sa([3.0, 4.0]) + 5 * np.cos(2 * np.pi * 7 * np.arange(N) / N)  # order 7: off
    prof = harmonic_profile(sa, 38)
    orders = harmonic_orders(N, 38)
    assert prof.shape == (1, orders.size)
    assert_allclose(prof[0, :2], [0.6, 0.8], atol=1e-12)
    assert_allclose(prof[0, 2:], 0, atol=1e-12)
    assert_allclose(harmonic_profile(np.zeros(N), 38), 0)


def test_gain_and_start_angle_do_not_move_the_score():
    rng = np.random.default_rng(0)
    healthy = np.array([_mesh_sa([1.0, 0.5, 0.25], noise=0.05, rng=rng) for _ in range(8)])
    ref = fit_comparability(healthy, 38)
    x = _mesh_sa([1.0, 0.5, 0.25], noise=0.05, rng=rng)
    base = ref.evaluate(x).score
    assert_allclose(ref.evaluate(7.5 * x).score, base, rtol=1e-9)  # sensor gain
    assert_allclose(ref.evaluate(np.roll(x, 333)).score, base, rtol=1e-9)  # start angle
    assert ref.evaluate(x).comparable.all()


def test_a_local_fault_stays_comparable_another_build_does_not():
    """A tooth fault (an impulse once per revolution) adds to the difference signal; a
    machine whose mesh harmonics stand in other proportions is another machine."""
    rng = np.random.default_rng(1)
    amps = [1.0, 0.6, 0.3, 0.15]
    healthy = np.array([_mesh_sa(amps, noise=0.05, rng=rng) for _ in range(10)])
    n = np.arange(N)
    pulse = 1.5 * np.exp(-0.5 * ((n - 900) / 6.0) ** 2) * np.cos(2 * np.pi * 300 * n / N)
    example = _mesh_sa(amps, noise=0.05, rng=rng) + pulse
    ref = fit_comparability(healthy, 38, faulty_example=example, faulty_size=0.5)
    faulty = np.array([_mesh_sa(amps, noise=0.05, rng=rng) + s * pulse for s in (0.5, 2)])
    other = np.array([_mesh_sa([0.6, 1.0, 0.1, 0.3], noise=0.05, rng=rng) for _ in range(4)])
    assert ref.evaluate(faulty).comparable.all()
    res = ref.evaluate(other)
    assert not res.comparable.any() and res.score.min() > 10 * DEFAULT_THRESHOLD


def test_estimator_flags_another_gear_on_another_path():
    """The synthetic target of the estimator tests: its own gear through its own path is
    comparable, another gear (another profile draw) through another path is not."""
    tf, other_tf = estimator_data.tf_pair()
    healthy, long, faulty, y = synthetic_target(6, tf)
    est = OneFaultShotEstimator(random_state=0, nominal_grade=3)
    est.fit(synthetic_database(), healthy, faulty[20], y[20], long, selection_tf=other_tf)
    assert est.comparability(faulty).comparable.mean() >= 0.9
    stranger = propagate(synthetic_sa(np.zeros(10), 6, np.random.default_rng(77),
                                      same_gear=True), other_tf)
    assert not est.comparability(stranger).comparable.any()


# ---------------------------------------------------------------------- bad input
@pytest.mark.parametrize("call, words", [
    (lambda h: fit_comparability(h[:1], 38), ["healthy_sa", "at least 2"]),
    (lambda h: fit_comparability(h, 38, threshold=-1.0), ["threshold", "-1.0"]),
    (lambda h: fit_comparability(h, 38, threshold=float("nan")), ["threshold", "nan"]),
    (lambda h: fit_comparability(h, 1024), ["mesh_order=1024", "Nyquist"]),
    (lambda h: fit_comparability(h, 38, faulty_example=h[0]), ["faulty_size"]),
    (lambda h: fit_comparability(h, 38, faulty_example=h[0], faulty_size=1.5),
     ["faulty_size", "1.5"]),
    (lambda h: fit_comparability(h, 38, faulty_example=h[0, :100], faulty_size=0.5),
     ["faulty_example", "100"]),
    (lambda h: fit_comparability(np.where(np.eye(4, N) > 0, np.nan, h[:4]), 38),
     ["healthy_sa", "finite"]),
    (lambda h: fit_comparability(h, 38).evaluate(h[:, :1024]), ["1024", "2048"]),
    (lambda h: fit_comparability(h, 38).evaluate(h, threshold=0), ["threshold", "0"]),
])
def test_bad_input_names_the_argument(call, words):
    rng = np.random.default_rng(2)
    healthy = np.array([_mesh_sa([1.0, 0.5], noise=0.05, rng=rng) for _ in range(5)])
    with pytest.raises(GearshotError) as info:
        call(healthy)
    for w in words:
        assert w in str(info.value), str(info.value)


def test_comparability_before_fit_is_an_error():
    with pytest.raises(NotFittedError, match="comparability"):
        OneFaultShotEstimator().comparability(np.zeros((2, N)))


def test_predict_without_machine_writes_the_columns(tmp_path):
    """`gearshot predict` (files of the paper's pair) carries comparability + comparable."""
    import json
    import os
    import subprocess
    import sys

    from gearshot.rig import VirtualRig

    env = {**os.environ, "GEARSHOT_DATA": str(tmp_path / "home")}
    idx = VirtualRig(seed=1, engine="surrogate").campaign(
        tmp_path / "camp", speed=15, load=10, duration=8.0, healthy=3, sizes=(0.5,),
        repetitions=1, progress=False)
    paths = idx["path"].tolist()  # three healthy (one SA each), one faulty
    cli = [sys.executable, "-m", "gearshot.app.cli"]
    res = subprocess.run([*cli, "simulate", "--speed", "15", "--load", "10", "--grade", "7",
                          "--n-healthy", "6", "--n-faulty", "12",
                          "--store", str(tmp_path / "db")], capture_output=True, text=True,
                         env=env, timeout=600)
    assert res.returncode == 0, res.stderr
    out = tmp_path / "p.json"
    res = subprocess.run([*cli, "predict", "--database", str(tmp_path / "db"), "--healthy",
                          paths[0], "--healthy", paths[1], "--faulty", paths[3],
                          "--faulty-size", "0.5", "--recordings", paths[2], "--speed", "15",
                          "--load", "10", "--out", str(out)], capture_output=True,
                         text=True, env=env, timeout=600)
    assert res.returncode == 0, res.stderr
    payload = json.loads(out.read_text())
    records = payload["rows"]
    assert len(records) == 1 and payload["summary"]["comparable"] == int(
        records[0]["comparable"])
    assert isinstance(records[0]["comparable"], bool)
    assert records[0]["comparability"] >= 0
    n_yes = int(records[0]["comparable"])
    assert f"comparable: {n_yes} segment(s), not comparable: {1 - n_yes}" in res.stdout
