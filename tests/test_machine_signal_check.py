"""The machine file verified against the signal (gearshot.machine.signal_check) on real
PHM09 records, and the machine's helix angle and geometry carried to the simulator's
database (and refused where they are not stated or do not match)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from gearshot import GearshotError, Machine
from gearshot.io import Recording
from gearshot.machine.signal_check import check_recording, verify_machine

ROOT = Path(__file__).resolve().parents[1]
PHM09 = ROOT.parent / "shared" / "data" / "phm09"
MACHINES = ROOT / "examples" / "machines"
needs_phm09 = pytest.mark.skipif(not (PHM09 / "spur1_30hz_Low_1.zip").is_file(),
                                 reason="real-data checks need ../shared/data/phm09")


def _edited(tmp_path: Path, name: str, old: str, new: str) -> Path:
    """A copy of an example machine file with one text replaced (the replaced text must
    be there: a test of a mistake that was never made would prove nothing)."""
    text = (MACHINES / name).read_text()
    assert old in text
    out = tmp_path / f"edited_{name}"
    out.write_text(text.replace(old, new))
    return out


# --------------------------------------------------------------- correct files pass
@needs_phm09
@pytest.mark.parametrize("machine, records", [
    ("phm09_spur.toml", ["spur1_30hz_Low_1", "spur2_30hz_High_1", "spur3_30hz_High_2"]),
    ("phm09_spur_notacho.toml", ["spur2_30hz_Low_1", "spur3_30hz_Low_1"]),
    ("phm09_helical.toml", ["helical1_30hz_High_1", "helical2_30hz_Low_1"]),
    ("phm09_helical_notacho.toml", ["helical1_30hz_Low_1", "helical2_30hz_High_1"]),
])
def test_the_right_machine_file_passes_on_its_records(machine, records):
    checks = verify_machine(MACHINES / machine, [PHM09 / f"{r}.zip" for r in records])
    assert [c.passed for c in checks] == [True] * len(records)
    assert all(c.mistake == "" and c.scale == 1.0 for c in checks)
    assert checks[0].speed_source == ("vibration" if "notacho" in machine else "tacho")
    assert 29.0 < checks[0].speed_hz < 30.0
    assert "machine file verified" in checks[0].describe()


# --------------------------------------------------------------- the mistakes
@needs_phm09
def test_pulses_per_rev_1_instead_of_10_is_refused_and_named(tmp_path):
    wrong = _edited(tmp_path, "phm09_spur.toml", "pulses_per_rev = 10", "pulses_per_rev = 1")
    with pytest.raises(GearshotError, match=r"pulses_per_rev looks like 10, not 1") as info:
        verify_machine(wrong, PHM09 / "spur2_30hz_High_1.zip")
    assert "\n" not in str(info.value) and "spur2_30hz_High_1.zip" in str(info.value)
    assert "0.1 x the declared" in str(info.value)


@needs_phm09
def test_fs_50000_instead_of_200000_over_3_is_refused_and_named(tmp_path):
    wrong = _edited(tmp_path, "phm09_spur.toml", 'fs = "200000/3"', "fs = 50000")
    with pytest.raises(GearshotError, match=r"fs off by factor at most 0\.8") as info:
        verify_machine(wrong, [PHM09 / "spur1_30hz_Low_1.zip"])
    assert "outside the declared speed range 26-52 Hz" in str(info.value)
    # the orders themselves stand where declared: only the speed tells
    rec = Recording.read(PHM09 / "spur1_30hz_Low_1.zip", machine=wrong)
    check = check_recording(rec.machine, rec)
    assert not check.passed and check.scale == 1.0
    assert check.speed_hz == pytest.approx(29.45 * 0.75, rel=0.01)


@needs_phm09
def test_the_helical_machine_file_on_spur_records_is_refused_as_another_gear_train():
    records = [PHM09 / f"{n}.zip" for n in ("spur1_30hz_Low_1", "spur3_30hz_Low_1")]
    with pytest.raises(GearshotError, match=r"mesh orders found \(32, 16\) match another "
                                            r"gear train than the declared \(16, 8\)"):
        verify_machine(MACHINES / "phm09_helical.toml", records)
    checks = verify_machine(MACHINES / "phm09_helical.toml", records, raise_on_failure=False)
    assert not any(c.passed for c in checks)
    assert np.mean([c.odd_db for c in checks]) < 2.0 < min(
        c.odd_db for c in verify_machine(MACHINES / "phm09_spur.toml", records))


@needs_phm09
def test_a_tacho_on_another_shaft_and_a_tooth_count_are_named(tmp_path):
    idler = _edited(tmp_path, "phm09_spur.toml", '[tacho]\nchannel = "tacho"\nshaft = "input"',
                    '[tacho]\nchannel = "tacho"\nshaft = "idler"')
    with pytest.raises(GearshotError, match=r"tacho\.shaft looks like 'input', not 'idler'"):
        verify_machine(idler, PHM09 / "spur1_30hz_Low_1.zip")
    teeth = _edited(tmp_path, "phm09_spur.toml", "driver_teeth = 48", "driver_teeth = 40")
    with pytest.raises(GearshotError, match=r"a tooth count looks wrong: the mesh of idler "
                                            r"40T -> output 80T at order 13\.33"):
        verify_machine(teeth, PHM09 / "spur1_30hz_Low_1.zip")


@needs_phm09
def test_indicators_refuse_a_wrong_machine_file_in_one_line(tmp_path):
    import os
    import subprocess
    import sys

    wrong = _edited(tmp_path, "phm09_spur.toml", "pulses_per_rev = 10", "pulses_per_rev = 1")
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    res = subprocess.run([sys.executable, "-m", "gearshot.app.cli", "indicators", "--machine",
                          str(wrong), "--shaft", "input", str(PHM09 / "spur1_30hz_Low_1.zip")],
                         capture_output=True, text=True, env=env, timeout=300)
    assert res.returncode != 0
    assert "pulses_per_rev looks like 10, not 1" in res.stderr
    assert len(res.stderr.strip().splitlines()) == 1
    assert "rms_diff" not in res.stdout   # no indicator table


@needs_phm09
def test_predict_refuses_the_machine_file_before_the_fit(tmp_path):
    from gearshot.app.predict_machine import predict_from_machine

    wrong = Machine.from_toml(_edited(tmp_path, "phm09_spur.toml", 'fs = "200000/3"',
                                      "fs = 50000"))
    store = tmp_path / "db"
    store.mkdir()
    pair = wrong.gear_pair()
    (store / "manifest.json").write_text(json.dumps(
        {"pair": repr(pair), "speeds": [wrong.sim_speed(29.5)], "loads": [10.0],
         "grades": [7]}))
    with pytest.raises(GearshotError, match=r"fs off by factor"):
        predict_from_machine(wrong, store, [PHM09 / "spur1_30hz_Low_1.zip"],
                             PHM09 / "spur2_30hz_Low_1.zip", 0.5)


# --------------------------------------------------------------- helix angle and geometry
def _helical_file(tmp_path: Path, angle: str = "helix_angle_deg = 20.0") -> Path:
    return _edited(tmp_path, "phm09_helical.toml",
                   "driven_teeth = 40\nhelical = true",
                   f"driven_teeth = 40\n{angle}\nmodule_mm = 2.5\nface_width_mm = 20")


def test_the_helix_angle_and_geometry_reach_the_simulated_pair_and_the_manifest(tmp_path):
    from gearshot.sim._db_manifest import make_manifest, pair_from_manifest

    m = Machine.from_toml(_helical_file(tmp_path))
    pair = m.gear_pair()
    assert pair.is_helical and pair.helix_angle == pytest.approx(math.radians(20.0))
    assert (pair.z_pinion, pair.z_gear) == (40, 24)   # the fault on the monitored 24T gear
    assert pair.module == pytest.approx(2.5e-3) and pair.face_width == pytest.approx(0.02)
    man = make_manifest(pair, [10.0], [10.0], [7], 2, 2, 0, 2048)
    back = pair_from_manifest(json.loads(json.dumps(man)))
    assert back is not None and back.helix_angle == pytest.approx(math.radians(20.0))
    assert back.module == pytest.approx(2.5e-3)


def test_a_helical_stage_without_its_angle_is_refused_for_the_simulator(tmp_path):
    from gearshot.app.simulate import simulate_machine_database

    m = Machine.from_toml(MACHINES / "phm09_helical.toml")
    assert m.monitored_stage().helical and m.monitored_stage().helix_angle == 0.0
    with pytest.raises(GearshotError, match=r"is helical but states no helix_angle_deg") as e:
        m.gear_pair()
    assert "\n" not in str(e.value)
    with pytest.raises(GearshotError, match=r"states no helix_angle_deg"):
        simulate_machine_database(MACHINES / "phm09_helical.toml", tmp_path / "db",
                                  speeds=[30.0], loads=[10.0], grades=[7], n_healthy=2,
                                  n_faulty=2, seed=0)
    with pytest.raises(GearshotError, match=r"stage\[0\]\.helical must be true or false"):
        Machine.from_toml(_edited(tmp_path, "phm09_helical.toml", "helical = true  ",
                                  "helical = 1  "))


def test_predict_refuses_a_database_of_another_pair(tmp_path):
    from gearshot.app.conditions import check_database_pair

    helical = Machine.from_toml(_helical_file(tmp_path))
    spur_pair = helical.gear_pair(helix_angle=0.0)
    store = tmp_path / "db"
    store.mkdir()
    (store / "manifest.json").write_text(json.dumps(
        {"pair": repr(spur_pair), "speeds": [10.0], "loads": [10.0], "grades": [7]}))
    with pytest.raises(GearshotError, match=r"helix_angle 0 deg in the database, 20 deg in "
                                            r"the machine"):
        check_database_pair(store, helical)
    (store / "manifest.json").write_text(json.dumps(
        {"pair": repr(helical.gear_pair()), "speeds": [10.0], "loads": [10.0],
         "grades": [7]}))
    check_database_pair(store, helical)   # the same pair: accepted
