"""A healthy baseline that drifts while recorded fails the fit (issue #29, fit check).

The test itself on analytic segments (a steady trend, stationary noise, a jump between
two recordings) and on the real PHM09 spur records of the development cells (30 Hz, input
sensor, 10-revolution SAs): the Low-load healthy record drifts, the High-load one does
not (benchmarks/healthy_drift.py, benchmarks/RESULTS.md "Trust: fit check").
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gearshot import GearshotError, Machine
from gearshot.estimator.drift import (
    DRIFT_RATIO,
    MIN_DRIFT_SEGMENTS,
    fit_drift,
    healthy_drift,
)
from gearshot.estimator.fit_check import check_fit

ROOT = Path(__file__).resolve().parents[1]
SPUR = ROOT / "examples" / "machines" / "phm09_spur.toml"
PHM = ROOT.parent / "shared" / "data" / "phm09"
N = 256


def _segments(n: int, trend: float, seed: int = 0) -> np.ndarray:
    """``n`` SAs: a fixed pattern, white noise of RMS 0.1, and a component whose
    amplitude grows by ``trend`` per segment (a steady change in time)."""
    rng = np.random.default_rng(seed)
    theta = np.arange(N) / N
    pattern = np.cos(2 * np.pi * 8 * theta) + 0.5 * np.cos(2 * np.pi * 16 * theta)
    moving = np.cos(2 * np.pi * 5 * theta + 0.3)
    return np.stack([pattern + trend * i * moving + 0.1 * rng.standard_normal(N)
                     for i in range(n)])


def test_a_steady_trend_drifts_and_stationary_segments_do_not():
    drifting = healthy_drift(_segments(11, 0.05))
    assert drifting.drifting and drifting.p_value <= 0.01
    assert drifting.ratio >= DRIFT_RATIO and drifting.n_recordings == 1
    assert "drifts while it is recorded" in drifting.reason()
    steady = [healthy_drift(_segments(11, 0.0, seed)) for seed in range(5)]
    assert not any(d.drifting for d in steady)
    assert all(d.reason() is None for d in steady)


def test_too_few_segments_are_not_tested():
    few = healthy_drift(_segments(MIN_DRIFT_SEGMENTS - 1, 0.05))
    assert few.p_value is None and few.ratio is None and not few.drifting
    assert few.n_recordings == 0


def test_a_jump_between_two_recordings_is_not_a_drift():
    """Two steady recordings of different level: each tested on its own."""
    a, b = _segments(8, 0.0, 1), _segments(8, 0.0, 2) + 0.4
    both = np.vstack([a, b])
    assert not healthy_drift(both, ["a"] * 8 + ["b"] * 8).drifting
    assert healthy_drift(both).drifting    # read as one recording, the jump is a trend


def test_fit_drift_tests_one_or_two_recordings_only():
    segs = _segments(12, 0.05)
    # one recording: its hold-outs are its last segments and are tested with it
    one = fit_drift(segs[:9], segs[9:], None)
    assert one is not None and one.drifting
    assert fit_drift(segs[:9], segs[9:], ["r"] * 9).p_value == one.p_value
    # three recordings: the fit sees run-to-run changes itself, nothing is tested
    assert fit_drift(segs[:9], segs[9:], np.repeat(["a", "b", "c"], 3)) is None
    # no hold-outs: an unchecked fit, not tested
    assert fit_drift(segs, None, None) is None and fit_drift(segs, segs[:0], None) is None


def test_bad_input_is_named():
    with pytest.raises(GearshotError, match="recordings holds 3 labels for 11 SAs"):
        healthy_drift(_segments(11, 0.0), ["a", "b", "c"])
    with pytest.raises(GearshotError, match="n_permutations"):
        healthy_drift(_segments(11, 0.0), n_permutations=10)


def test_the_verdict_names_the_drift_last():
    reason = healthy_drift(_segments(11, 0.05)).reason()
    check = check_fit([0.02, 0.05], [0.5, 0.5], 0.5, drift=reason)
    assert not check.passed and check.verdict == reason and check.drift == reason
    both = check_fit([0.4, 0.4], [0.5, 0.5], 0.5, drift=reason)
    assert both.verdict.startswith("healthy hold-outs read 0.40") and reason in both.verdict
    assert check_fit([0.02, 0.05], [0.5, 0.5], 0.5).as_dict()["drift"] is None


# ------------------------------------------------------------------- real records
def _input_segments(name: str) -> np.ndarray:
    from gearshot.app.predict_machine import machine_segments

    path = PHM / name
    if not path.is_file():
        pytest.skip(f"{path} is absent; real-data checks need ../shared/data/phm09")
    sa, _, _ = machine_segments(path, Machine.from_toml(SPUR), cycles_per_segment=10,
                                sensor="acc_input")
    return sa


def test_the_low_load_healthy_record_drifts_and_the_high_load_one_does_not():
    low = healthy_drift(_input_segments("spur3_30hz_Low_1.zip"))
    high = healthy_drift(_input_segments("spur3_30hz_High_1.zip"))
    assert low.drifting and low.ratio > 1.5
    assert not high.drifting and high.p_value > 0.5 and high.ratio < 1.1


def test_a_drifting_baseline_widens_a_new_runs_spread():
    """A later run moves farther than a drifting baseline's hold-outs show: the interval's
    run spread grows with the drift's amplitude (the square root of its energy ratio),
    and so does the reading up to which a healthy segment's interval holds 0."""
    from gearshot.estimator.uncertainty import RUN_SPREAD, holdout_interval

    drift = healthy_drift(_segments(11, 0.05))
    assert drift.drifting and drift.ratio > DRIFT_RATIO
    check = check_fit([0.02, 0.05], [0.5, 0.48], 0.5, drift=drift.reason(),
                      drift_ratio=drift.ratio)
    assert check.drift_ratio == drift.ratio
    assert check.run_spread == pytest.approx(RUN_SPREAD * np.sqrt(drift.ratio))
    assert check.as_dict()["drift_ratio"] == drift.ratio
    # no drift: the ratio is not kept and the spread is RUN_SPREAD
    steady = check_fit([0.02, 0.05], [0.5, 0.48], 0.5, drift_ratio=3.0)
    assert steady.drift_ratio is None and steady.run_spread == RUN_SPREAD
    healthy, example = check.residuals()
    grid = np.linspace(0.0, 0.6, 61)
    plain, _ = holdout_interval(grid, healthy, example, 0.9, example_size=0.5)
    wide, _ = holdout_interval(grid, healthy, example, 0.9, example_size=0.5,
                               run_spread=check.run_spread)
    assert (wide <= plain + 1e-12).all()
    assert grid[wide <= 0].max() > grid[plain <= 0].max() + 0.05
