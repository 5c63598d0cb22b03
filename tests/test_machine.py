"""gearshot.Machine: TOML machine descriptions, gear-train ratios, built-ins."""

from __future__ import annotations

import math
from fractions import Fraction
from pathlib import Path

import pytest

import gearshot
from gearshot import GearshotError, Machine
from gearshot.machine import parse_sensitivity
from gearshot.sim import GearPair

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "machines"

MINIMAL = """
name = "two-stage"
shafts = ["in", "mid", "out"]
[[stage]]
driver = "in"
driver_teeth = 20
driven = "mid"
driven_teeth = 50
[[stage]]
driver = "mid"
driver_teeth = 25
driven = "out"
driven_teeth = 35
module_mm = 2.5
face_width_mm = 12
helix_angle_deg = 15
[tacho]
channel = "tach"
shaft = "out"
pulses_per_rev = 4
[[sensor]]
name = "acc"
channel = "a"
sensitivity = "100 mV/g"
[file]
columns = ["a", "tach"]
delimiter = ","
header = true
fs = 25600
[monitored]
shaft = "out"
teeth = 35
[analysis]
cycles_per_segment = 10
shaft_orders = [1, 2, 3]
"""


def write(tmp_path, text, name="m.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_machine_is_exported_and_frozen():
    assert gearshot.Machine is Machine
    m = Machine.paper()
    with pytest.raises(AttributeError):
        m.name = "x"


def test_minimal_toml_ratios_orders_and_units(tmp_path):
    m = Machine.from_toml(write(tmp_path, MINIMAL))
    assert m.shafts == ("in", "mid", "out")
    # tacho on "out": mid turns 35/25 as fast, in turns 35/25 * 50/20
    assert m.speed_ratio("mid") == Fraction(35, 25)
    assert m.speed_ratio("in") == Fraction(35, 25) * Fraction(50, 20)
    assert m.tacho_revs_per_cycle("in") == Fraction(2, 7)
    assert m.mesh_orders("mid") == (50, 25) and m.gear_teeth("mid") == (50, 25)
    # other stages' meshes in a shaft's orders when whole: 25 * 20/50 = 10, 20 * 50/20 * 35/25 = 70
    assert m.gear_teeth("in") == (20,) and m.mesh_orders("in") == (20, 10)
    assert m.gear_teeth("out") == (35,) and m.mesh_orders("out") == (35, 70)
    assert m.sensors[0].sensitivity == pytest.approx(0.1) and m.sensors[0].unit == "g"
    assert m.layout.delimiter == "," and m.layout.header is True and m.layout.fs == 25600
    assert m.cycles_per_segment == 10 and m.shaft_orders == (1, 2, 3)
    st = m.monitored_stage()
    assert st.module == pytest.approx(2.5e-3) and st.helix_angle == pytest.approx(math.radians(15))
    assert m.mate() == ("mid", 25)


def test_examples_follow_the_data_readme():
    spur = Machine.from_toml(EXAMPLES / "phm09_spur.toml")
    helical = Machine.from_toml(EXAMPLES / "phm09_helical.toml")
    assert [(s.driver_teeth, s.driven_teeth) for s in spur.stages] == [(32, 96), (48, 80)]
    assert [(s.driver_teeth, s.driven_teeth) for s in helical.stages] == [(16, 48), (24, 40)]
    for m in (spur, helical):
        assert m.tacho.pulses_per_rev == 10 and m.tacho.shaft == "input"
        assert m.layout.columns == ("acc_input", "acc_output", "tacho")
        assert m.layout.fs == pytest.approx(200_000 / 3, rel=1e-15)
        assert m.layout.delimiter is None and m.layout.header is False
        assert [s.sensitivity for s in m.sensors] == [pytest.approx(0.01)] * 2
        assert m.tacho_revs_per_cycle("output") == 5
        assert m.tacho_revs_per_cycle("idler") == 3
    assert spur.monitored.teeth == 32 and helical.monitored == type(helical.monitored)("idler", 24)
    assert spur.mesh_orders("idler") == (96, 48) and helical.mesh_orders("idler") == (48, 24)
    # the second stage's mesh is synchronous with the input shaft: 48 / 3 = 16, 24 / 3 = 8
    assert spur.mesh_orders("input") == (32, 16) and helical.mesh_orders("input") == (16, 8)
    assert spur.mesh_orders("output") == (80, 160) and helical.mesh_orders("output") == (40, 80)


def test_paper_machine_gives_the_paper_pair():
    m = Machine.paper()
    assert m.gear_pair() == GearPair.paper()
    assert m.tacho_revs_per_cycle("output") == Fraction(38, 17)
    assert m.mesh_orders("output") == (38,) and m.cycles_per_segment == 50


def test_gear_pair_of_a_driving_monitored_gear_puts_it_on_the_gear_side():
    pair = Machine.from_toml(EXAMPLES / "phm09_spur.toml").gear_pair()
    assert (pair.z_pinion, pair.z_gear) == (96, 32)
    assert Machine.from_toml(EXAMPLES / "phm09_spur.toml").sim_speed(30.0) == pytest.approx(10.0)


@pytest.mark.parametrize("edit, match", [
    (("pulses_per_rev = 4\n", ""), r"\[tacho\] needs 'pulses_per_rev'"),
    (("pulses_per_rev = 4", "pulses_per_rev = 0"), r"tacho.pulses_per_rev must be >= 1; got 0"),
    (("pulses_per_rev = 4", "pulses_per_rev = 2.5"), r"tacho.pulses_per_rev must be an integer"),
    (('shaft = "out"\npulses', 'shaft = "brake"\npulses'), r"tacho.shaft='brake'"),
    (('driven_teeth = 50', 'driven_teeth = "fifty"'), r"stage\[0\].driven_teeth must be an int"),
    (('sensitivity = "100 mV/g"', 'sensitivity = "100 mV per g"'), r"sensor\[0\].sensitivity"),
    (('channel = "a"', 'channel = "b"'), r"channel='b' is not one of file.columns"),
    (('delimiter = ","', 'delimiter = "|"'), r"file.delimiter must be one of"),
    (("fs = 25600", "fs = -1"), r"file.fs must be > 0; got -1"),
    (("shaft = \"out\"\nteeth = 35", "shaft = \"out\"\nteeth = 36"), r"monitored.teeth=36"),
    (("cycles_per_segment = 10", 'cycles_per_segment = "many"'), r"cycles_per_segment"),
    (("[analysis]", "[analysis]\nwindow = 3"), r"unknown key\(s\) \['window'\] in \[analysis\]"),
    (('driver = "mid"', 'driver = "nowhere"'), r"stage\[1\].driver='nowhere'"),
])
def test_errors_name_the_key_and_the_value(tmp_path, edit, match):
    text = MINIMAL.replace(*edit)
    assert text != MINIMAL
    with pytest.raises(GearshotError, match=match):
        Machine.from_toml(write(tmp_path, text))


def test_disconnected_and_inconsistent_trains(tmp_path):
    text = MINIMAL.replace('shafts = ["in", "mid", "out"]', 'shafts = ["in", "mid", "out", "x"]')
    with pytest.raises(GearshotError, match=r"\['x'\] are not connected"):
        Machine.from_toml(write(tmp_path, text))
    loop = MINIMAL + '\n[[stage]]\ndriver = "in"\ndriver_teeth = 10\ndriven = "out"\n' \
        'driven_teeth = 10\n'
    loop = loop.replace("[monitored]", "[monitored_]").replace("[monitored_]", "[monitored]")
    with pytest.raises(GearshotError, match="inconsistent gear train"):
        Machine.from_toml(write(tmp_path, loop.replace("[analysis]\ncycles_per_segment = 10\n"
                                                        "shaft_orders = [1, 2, 3]\n", "")))


def test_bad_files():
    with pytest.raises(GearshotError, match="does not exist"):
        Machine.from_toml("no/such/machine.toml")


def test_bad_toml(tmp_path):
    with pytest.raises(GearshotError, match="not valid TOML"):
        Machine.from_toml(write(tmp_path, "name = [unclosed"))


def test_parse_sensitivity():
    assert parse_sensitivity("10 mV/g") == (pytest.approx(0.01), "g")
    assert parse_sensitivity("1.02V/m/s^2")[1] == "m/s^2"
    with pytest.raises(GearshotError, match="sensitivity"):
        parse_sensitivity(10)


def test_helix_angle_reaches_gear_pair_only_if_it_accepts_one(tmp_path):
    import dataclasses

    m = Machine.from_toml(write(tmp_path, MINIMAL))
    if "helix_angle" in {f.name for f in dataclasses.fields(GearPair)}:
        assert m.gear_pair().helix_angle == pytest.approx(math.radians(15))
    else:
        with pytest.warns(UserWarning, match="helix"):
            pair = m.gear_pair()
        assert (pair.z_pinion, pair.z_gear, pair.module) == (25, 35, pytest.approx(2.5e-3))


def test_indicators_help():
    import subprocess
    import sys

    res = subprocess.run([sys.executable, "-m", "gearshot.app.cli", "indicators", "--help"],
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 0 and "--machine" in res.stdout and "--shaft" in res.stdout
