"""The transfer path check (issue #29 item 3, issue #31's remount): a recording heard
through another path than the fit's healthy recordings is not comparable.

Real records first: the PHM09 spur gearbox's second run through the same accelerometer
keeps its resonance pattern, the other accelerometer and the helical gearbox do not; then
the virtual rig's remount, which the rig draws as another transfer path of its bank."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from gearshot import GearshotError, Machine
from gearshot.app.conditions import PATH_MIN_CORRELATION, fit_path_check
from gearshot.io import Recording
from gearshot.monitor.trust import OTHER_PATH
from gearshot.signal.path_pattern import PATH_GRID_HZ, path_pattern, pattern_correlation

ROOT = Path(__file__).resolve().parents[1]
PHM = ROOT.parent / "shared" / "data" / "phm09"
SPUR = Machine.from_toml(ROOT / "examples" / "machines" / "phm09_spur.toml")


def _pattern(name: str, sensor: str = "acc_input") -> np.ndarray:
    rec = Recording.read(PHM / f"{name}.zip", machine=SPUR).channel(sensor)
    return path_pattern(rec.acceleration, rec.fs)


def test_the_same_sensor_on_another_run_keeps_its_pattern_another_sensor_does_not():
    for speed in (30, 40):
        ref = [_pattern(f"spur3_{speed}hz_High_1")]
        again = pattern_correlation(_pattern(f"spur3_{speed}hz_High_2"), ref)
        other = pattern_correlation(_pattern(f"spur3_{speed}hz_High_1", "acc_output"), ref)
        assert again > 0.95 and other < 0.8 and other < again - 0.2
        # the chipped gear's build, same sensor: a fault does not fail the check
        assert fit_path_check(_pattern(f"spur2_{speed}hz_High_2"), ref) == "ok"


def test_the_helical_gearbox_under_the_spur_fit_fails_the_path_check():
    ref = [_pattern("spur3_40hz_High_1")]
    check = fit_path_check(_pattern("helical1_40hz_High_1"), ref)
    assert OTHER_PATH in check
    assert float(re.search(r"correlates (-?[0-9.]+)", check).group(1)) < 0.3
    assert fit_path_check(_pattern("spur3_40hz_High_2"), ref) == "ok"


def test_pattern_grid_limits_and_bad_input():
    x = np.random.default_rng(0).normal(size=40_000)
    p = path_pattern(x, 20_000)            # Nyquist 10 kHz: the grid above 9 kHz is NaN
    assert np.all(np.isnan(p[PATH_GRID_HZ >= 9_000])) and np.isfinite(p[:100]).all()
    assert np.isnan(path_pattern(x[:5000], 20_000)).all()          # too short
    assert np.isnan(path_pattern(np.zeros(40_000), 20_000)).all()  # no energy
    with pytest.raises(GearshotError, match="fs"):
        path_pattern(x, 0)
    with pytest.raises(GearshotError, match="references"):
        pattern_correlation(p, [p[:10]])
    # unknown patterns pass; too few shared points give no verdict
    assert fit_path_check(None, [p]) == "ok" and fit_path_check(p, []) == "ok"
    assert fit_path_check(p, [np.full_like(p, np.nan)]) == "ok"
    assert 0 < PATH_MIN_CORRELATION < 1


def test_a_remounted_sensor_on_the_virtual_rig_fails_the_path_check():
    from gearshot.rig import VirtualRig

    rig = VirtualRig(3, engine="surrogate")
    moved = rig.with_reality(tf_index=(rig.reveal().tf_index + 1) % 8)

    def heard(source, rep, size=0.0):
        rec = source.record(speed=15, load=10, fault_size=size, duration=8, repetition=rep)
        return path_pattern(rec.acceleration, rec.fs)

    ref = [heard(rig, 0), heard(rig, 1)]
    assert fit_path_check(heard(rig, 2), ref) == "ok"
    assert fit_path_check(heard(rig, 3, size=0.7), ref) == "ok"   # a large fault: ok
    assert OTHER_PATH in fit_path_check(heard(moved, 4), ref)
    assert OTHER_PATH in fit_path_check(heard(moved, 5, size=0.7), ref)
