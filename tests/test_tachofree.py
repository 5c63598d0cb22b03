"""Machines without a tachometer (issue #24): speed and angle from the vibration, and the
regular / difference / residual / non-synchronous parts of a synchronous average."""

from __future__ import annotations

import dataclasses
import json
import math
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from gearshot import GearshotError, Machine
from gearshot.io import Recording
from gearshot.signal import (
    angle_pulse_times,
    demodulate_angle,
    difference_signal,
    estimate_shaft_angle,
    nonsynchronous_signal,
    regular_signal,
    residual_signal,
    speed_ridge,
)
from gearshot.signal.speed_profile import fit_speed_profile

ROOT = Path(__file__).resolve().parents[1]
PHM09 = ROOT.parent / "shared" / "data" / "phm09"
MACHINES = ROOT / "examples" / "machines"
needs_phm09 = pytest.mark.skipif(not (PHM09 / "spur2_30hz_High_1.zip").is_file(),
                                 reason="../shared/data/phm09 is not here")


def _ramp(fs=20_000.0, seconds=4.0, start=20.0, end=24.0):
    t = np.arange(int(seconds * fs)) / fs
    return t, start * t + 0.5 * (end - start) / seconds * t ** 2


# --------------------------------------------------------------------------- analytic
def test_run_up_angle_and_speed_follow_the_analytic_ramp():
    fs = 20_000.0
    t, revs = _ramp(fs)
    rng = np.random.default_rng(3)
    x = (np.sin(2 * np.pi * 32 * revs) + 0.5 * np.sin(2 * np.pi * 16 * revs + 1.0)
         + 0.5 * rng.standard_normal(t.size))
    est = estimate_shaft_angle(x, fs, orders=[32, 16], speed_range=(15, 30))
    true = 20.0 * est.times + 0.5 * est.times ** 2
    err = est.angle - true
    err -= err.mean()  # the origin is arbitrary
    inner = (est.times > 0.25) & (est.times < 3.75)
    assert np.std(err[inner]) * 360 < 0.05          # degrees of shaft angle
    assert abs(est.mean_speed / (20.0 + 0.5 * (est.times[0] + est.times[-1])) - 1) < 1e-4
    speed_true = 20.0 + est.times
    assert np.max(np.abs(est.speed[inner] - speed_true[inner])) < 0.02
    assert est.order == 32 and est.snr_db > 20
    # the stated uncertainty is of the size of the observed speed noise
    observed = np.std(est.speed[inner] - speed_true[inner])
    assert est.speed_std / 5 < observed < est.speed_std * 5
    # virtual pulses sit at equal angle steps of the true angle
    inner_pulses = est.pulse_times[(est.pulse_times > 0.25) & (est.pulse_times < 3.75)]
    marks = 20.0 * inner_pulses + 0.5 * inner_pulses ** 2
    steps = np.diff(marks)
    assert np.allclose(steps, 1 / est.pulses_per_rev, atol=2e-4)


def test_run_down_and_the_comb_picks_the_speed_not_half_of_it():
    fs = 20_000.0
    t, revs = _ramp(fs, start=30.0, end=26.0)
    rng = np.random.default_rng(5)
    # the idler-stage mesh (order 16) stronger than the shaft's own (32), as on PHM09
    x = (0.5 * np.sin(2 * np.pi * 32 * revs) + np.sin(2 * np.pi * 16 * revs)
         + 0.3 * np.sin(2 * np.pi * 48 * revs) + 0.4 * rng.standard_normal(t.size))
    ridge = speed_ridge(x, fs, orders=[32, 16], speed_range=(20, 38))
    true = 30.0 - ridge.times
    assert np.max(np.abs(ridge.speed - true)) < 0.3
    assert ridge.order % 32 == 0  # the shaft's own mesh is demodulated, not order 16
    times, angle, snr = demodulate_angle(x, fs, order=ridge.order, ridge_times=ridge.times,
                                         ridge_speed=ridge.speed)
    err = angle - (30.0 * times - 0.5 * times ** 2)
    inner = (times > 0.25) & (times < 3.75)
    assert np.std(err[inner] - err[inner].mean()) * 360 < 0.1 and snr > 10


def test_noise_is_refused_with_the_snr_found():
    x = np.random.default_rng(0).standard_normal(80_000)
    with pytest.raises(GearshotError, match=r"no mesh harmonic stands out.*-?\d+\.\d dB above "
                                            r"the noise.*min_snr_db=3.*whole record the best "
                                            r"speed profile's strongest mesh line is \d+\.\d dB "
                                            r"over the floor \(0 whole orders") as info:
        estimate_shaft_angle(x, 20_000.0, orders=[32, 16], speed_range=(20, 35))
    assert "\n" not in str(info.value)


# ------------------------------------------------------------ whole-record speed profile
def _rig_run_up(engine="surrogate", seed=5, speed=12.0, end=16.0):
    from gearshot.rig import VirtualRig
    from gearshot.signal import pulse_times
    rec = VirtualRig(seed=seed, engine=engine).record(speed=speed, load=10, duration=4.0,
                                                      end_speed=end)
    return rec, pulse_times(rec.tacho, rec.fs)


def test_a_virtual_rig_run_up_is_tracked_over_the_whole_record():
    """The whole-record profile finds the rig's ramp; the angle (whichever path the
    tracker takes) follows the rig's tacho."""
    from scipy.interpolate import CubicSpline
    rec, pulses = _rig_run_up()
    p = fit_speed_profile(rec.acceleration, rec.fs, orders=[17], speed_range=(10, 19))
    c, a, _ = p.coef  # the rig's ramp: 14 rev/s at mid-record, +1 rev/s per s
    assert abs(c - 14.0) < 0.01 and abs(a - 1.0) < 0.02 and p.n_lines >= 2
    est = estimate_shaft_angle(rec.acceleration, rec.fs, orders=[17], speed_range=(10, 19))
    truth = CubicSpline(pulses, np.arange(pulses.size))
    sel = (est.times > pulses[0]) & (est.times < pulses[-1])
    err = est.angle[sel] - truth(est.times[sel])
    assert np.std(err) * 360 < 5.0  # degrees of shaft angle against the tacho's


def test_fit_speed_profile_recovers_a_curved_run_down_and_names_bad_options():
    fs = 4000.0
    t = np.arange(int(4 * fs)) / fs
    u = t - 0.5 * (t.size - 1) / fs
    revs = 15.0 * u - 0.4 * u ** 2 + 0.05 * u ** 3  # 15 rev/s at mid, -0.8 rev/s^2, curved
    rng = np.random.default_rng(11)
    x = np.cos(2 * np.pi * 20 * revs) + 0.5 * np.cos(2 * np.pi * 40 * revs + 1.0)
    x = x + 1.5 * rng.standard_normal(t.size)
    p = fit_speed_profile(x, fs, orders=[20], speed_range=(11, 19))
    assert np.allclose(p.coef, (15.0, -0.8, 0.15), atol=0.01)
    assert p.lines[0][0] == 20 and p.n_lines == 2
    assert np.max(np.abs(p.angle(t) - p.angle(t)[0] - (revs - revs[0]))) * 360 < 2.0
    for kwargs, message in [(dict(speed_range=(5, 5)), "speed_range"),
                            (dict(max_rate=-1.0), "max_rate must be > 0"),
                            (dict(orders=[3000]), r"orders=\[3000\].*above 0.4 fs")]:
        with pytest.raises(GearshotError, match=message):
            fit_speed_profile(x, fs, **{"orders": [20], "speed_range": (11, 19), **kwargs})


@pytest.mark.parametrize("kwargs, message", [
    (dict(orders=[32], speed_range=(30, 20)), r"speed_range must be \(low, high\) with 0 < low"),
    (dict(orders=[32], speed_range="fast"), r"speed_range must be \(low, high\)"),
    (dict(orders=[], speed_range=(20, 30)), r"orders must be a positive integer or a non-empty"),
    (dict(orders=[0], speed_range=(20, 30)), r"orders\[0\] must be >= 1; got 0"),
    (dict(orders=[32], speed_range=(20, 30), track=400), r"track=400 at 30 rev/s is above"),
    (dict(orders=[32], speed_range=(20, 30), bandwidth=0.0), r"bandwidth must"),
    (dict(orders=[500], speed_range=(20, 30)), r"orders=\[500\] .* above the Nyquist"),
])
def test_bad_options_name_the_parameter(kwargs, message):
    x = np.random.default_rng(1).standard_normal(20_000)
    with pytest.raises(GearshotError, match=message):
        estimate_shaft_angle(x, 20_000.0, **kwargs)


def test_a_lone_tone_is_not_taken_for_a_gear_mesh():
    fs = 20_000.0
    t = np.arange(int(2 * fs)) / fs
    x = np.sin(2 * np.pi * 777.0 * t) + 0.1 * np.random.default_rng(2).standard_normal(t.size)
    with pytest.raises(GearshotError, match=r"1 of 3 comb lines stand out \(min_lines=2\)"):
        estimate_shaft_angle(x, fs, orders=[32], speed_range=(20, 30))


def test_angle_pulse_times_needs_a_turning_shaft():
    t = np.linspace(0, 1, 11)
    with pytest.raises(GearshotError, match=r"angle must increase .* t=0\.4"):
        angle_pulse_times(t, np.r_[0, 1, 2, 3, 4, 4, 5, 6, 7, 8, 9.0])
    with pytest.raises(GearshotError, match="same length"):
        angle_pulse_times(t, t[:-1])


# --------------------------------------------------------------------------- parts of a SA
def _sa(n=256, seed=0):
    return np.random.default_rng(seed).standard_normal((3, n))


def test_regular_plus_residual_is_the_sa_without_its_mean():
    sa = _sa()
    reg = regular_signal(sa, [32, 16])
    res = residual_signal(sa, [32, 16])
    assert np.allclose(reg + res, sa - sa.mean(axis=-1, keepdims=True), atol=1e-12)
    spec = np.abs(np.fft.rfft(res, axis=-1))
    assert np.all(spec[:, [0, 1, 2, 16, 32, 48, 64, 128]] < 1e-10)  # mesh, shaft, DC gone
    assert np.all(spec[:, [3, 15, 17, 31, 33]] > 1e-3)  # sidebands and the rest kept


def test_the_parts_match_the_features_decomposition():
    from gearshot.features import _Parts

    sa = _sa(seed=4)
    parts = _Parts(sa, (32, 16), 2, None, (1, 2))
    assert np.allclose(residual_signal(sa, [32, 16]), parts.residual, atol=1e-12)
    assert np.allclose(difference_signal(sa, [32, 16], n_sidebands=1, shaft_orders=(1, 2)),
                       parts.zakrajsek_diff, atol=1e-12)
    assert np.allclose(regular_signal(sa, [32, 16], shaft_orders=(), n_sidebands=1),
                       parts.regular_mesh - parts.regular_mesh.mean(axis=-1, keepdims=True),
                       atol=1e-12)
    # without shaft_orders, the paper's difference signal is unchanged
    assert np.allclose(difference_signal(sa, [32, 16]), parts.diff, atol=1e-12)


def test_part_options_are_checked():
    sa = _sa()
    with pytest.raises(GearshotError, match=r"shaft_orders\[0\]=300 is above the Nyquist"):
        residual_signal(sa, 32, shaft_orders=[300])
    with pytest.raises(GearshotError, match=r"shaft_orders\[1\] must be >= 0"):
        regular_signal(sa, 32, shaft_orders=[1, -2])
    with pytest.raises(GearshotError, match="fewer than one cycle"):
        nonsynchronous_signal(np.ones(10), 16)


def test_nonsynchronous_signal_keeps_what_changes_from_cycle_to_cycle():
    spc, n_cycles = 64, 20
    k = np.arange(spc * n_cycles)
    synchronous = np.cos(2 * np.pi * 5 * k / spc)
    other = np.cos(2 * np.pi * 5.5 * k / spc)  # half an order off: changes every cycle
    x = synchronous + other
    non = nonsynchronous_signal(x, spc)
    blocks = non.reshape(n_cycles, spc)
    assert np.allclose(blocks.mean(axis=0), 0.0, atol=1e-12)
    corr = np.corrcoef(non, other)[0, 1]
    assert corr > 0.99
    assert np.std(non) == pytest.approx(np.std(other), rel=0.1)


# --------------------------------------------------------------------------- machines
NO_TACHO = """
name = "two stages, no tacho"
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
{speed}
[[sensor]]
name = "acc"
"""


def _machine(tmp_path, speed=""):
    p = tmp_path / "m.toml"
    p.write_text(NO_TACHO.format(speed=speed))
    return Machine.from_toml(p)


def test_a_machine_without_tacho_tracks_a_named_shaft(tmp_path):
    m = _machine(tmp_path, '[speed]\nshaft = "mid"\nrange_hz = [5, 9]\ntrack = 50')
    assert m.tacho is None and m.reference_shaft == "mid"
    assert m.vibration_speed.speed_range == (5.0, 9.0) and m.vibration_speed.track == 50
    assert m.speed_ratio("in") == Fraction(5, 2)
    assert m.tacho_revs_per_cycle("out") == Fraction(7, 5)
    default = _machine(tmp_path)
    assert default.reference_shaft == "in" and default.vibration_speed.speed_range is None


@pytest.mark.parametrize("speed, message", [
    ('[speed]\nshaft = "brake"', r"speed.shaft='brake' is not one of the shafts"),
    ('[speed]\nrange_hz = [9, 5]', r"speed.range_hz must be \[low, high\] with low < high"),
    ('[speed]\nrange_hz = 7', r"speed.range_hz must be \[low, high\]"),
    ('[speed]\nsensor = "mic"', r"speed.sensor='mic' is not a sensor"),
    ('[speed]\nwindow = 1', r"unknown key\(s\) \['window'\] in \[speed\]"),
])
def test_bad_speed_tables_are_named(tmp_path, speed, message):
    with pytest.raises(GearshotError, match=message):
        _machine(tmp_path, speed)


def test_a_recording_without_tacho_needs_orders_or_a_range():
    rng = np.random.default_rng(2)
    rec = Recording(rng.standard_normal(40_000), None, 20_000.0)
    assert rec.speed_source == "vibration"
    with pytest.raises(GearshotError, match="needs the mesh orders"):
        rec.vibration_angle()
    with pytest.raises(GearshotError, match=r"no tacho and no nominal speed.*range_hz"):
        rec.vibration_angle(orders=[17])


def test_a_machine_less_run_up_gives_gear_cycles_from_the_vibration():
    fs = 20_000.0
    t, revs = _ramp(fs, start=15.0, end=17.0)
    rng = np.random.default_rng(8)
    x = (np.sin(2 * np.pi * 17 * revs) + 0.5 * np.sin(2 * np.pi * 34 * revs)
         + 0.3 * rng.standard_normal(t.size))
    rec = Recording(x, None, fs, speed=16.0)
    sa = rec.to_sa_segments(gear_teeth=38, pinion_teeth=17, cycles_per_segment=None,
                            samples_per_cycle=256)
    # one gear revolution holds 38 mesh cycles: the SA is a clean order-38 sinusoid
    spec = np.abs(np.fft.rfft(sa[0]))
    assert np.argmax(spec) == 38 and spec[38] > 10 * np.delete(spec, [38, 76]).max()
    assert rec.speed_uncertainty is not None and rec.speed_uncertainty < 0.01
    assert rec.shaft_speed() == pytest.approx(16.0, rel=1e-3)


# --------------------------------------------------------------------------- PHM09
@needs_phm09
@pytest.mark.parametrize("name", ["spur2_30hz_High_1", "spur3_40hz_Low_1",
                                  "helical2_40hz_High_1", "spur2_40hz_High_1"])
def test_phm09_speed_from_the_vibration_within_0p2_percent_of_the_tacho(name):
    kind = "spur" if name.startswith("spur") else "helical"
    path = PHM09 / f"{name}.zip"
    rt = Recording.read(path, machine=MACHINES / f"phm09_{kind}.toml")
    rv = Recording.read(path, machine=MACHINES / f"phm09_{kind}_notacho.toml")
    assert rv.tacho is None and rv.speed_source == "vibration" and rt.speed_source == "tacho"
    assert rv.shaft_speed() == pytest.approx(rt.shaft_speed(), rel=0.002)
    assert rv.shaft_speed("output") == pytest.approx(rt.shaft_speed("output"), rel=0.002)
    assert 0 < rv.speed_uncertainty < 0.1 and rt.speed_uncertainty is None
    # the same number of whole idler revolutions, and SAs of the same level
    a = rt.to_sa_segments(shaft="idler", sensor="acc_input", cycles_per_segment=None)
    b = rv.to_sa_segments(shaft="idler", sensor="acc_input", cycles_per_segment=None)
    assert a.shape == b.shape
    assert np.std(b) == pytest.approx(np.std(a), rel=0.15)


@needs_phm09
def test_phm09_cli_indicators_without_tacho(tmp_path):
    from gearshot.app.cli import app

    out = tmp_path / "ind.json"
    res = CliRunner().invoke(app, ["indicators", "--machine",
                                   str(MACHINES / "phm09_spur_notacho.toml"), "--shaft",
                                   "input", str(PHM09 / "spur2_30hz_High_1.zip"), "--json",
                                   str(out)])
    assert res.exit_code == 0, res.output
    rec = json.loads(out.read_text())["records"][0]
    assert rec["speed_source"] == "vibration"
    assert rec["tacho_speed_hz"] == pytest.approx(29.89, rel=0.002)
    assert 0 < rec["speed_uncertainty_hz"] < 0.1


def test_cli_refuses_a_noise_record_in_one_line(tmp_path):
    machine = tmp_path / "m.toml"
    machine.write_text(NO_TACHO.format(speed='[speed]\nrange_hz = [20, 35]') +
                       '[file]\ncolumns = ["acc"]\nfs = 20000\n')
    rec = tmp_path / "noise.txt"
    np.savetxt(rec, np.random.default_rng(0).standard_normal(20_000), fmt="%.5f")
    res = subprocess.run([sys.executable, "-m", "gearshot.app.cli", "indicators", "--machine",
                          str(machine), "--shaft", "in", str(rec), "--json",
                          str(tmp_path / "o.json")], capture_output=True, text=True,
                         timeout=300)
    assert res.returncode != 0 and "Traceback" not in res.stderr
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("gearshot: error: no mesh harmonic stands "
                                                   "out"), res.stderr
    assert " dB above the noise" in lines[0]


def test_dataclass_replace_drops_the_angle_cache():
    fs = 20_000.0
    t, revs = _ramp(fs, seconds=2.0)
    x = (np.sin(2 * np.pi * 32 * revs) + 0.5 * np.sin(2 * np.pi * 64 * revs)
         + 0.1 * np.random.default_rng(1).standard_normal(t.size))
    rec = Recording(x, None, fs, speed=22.0)
    a = rec.vibration_angle(orders=[32])
    assert rec.vibration_angle(orders=[32]) is a
    assert dataclasses.replace(rec).vibration_angle(orders=[32]) is not a


@needs_phm09
def test_phm09_predict_segments_say_where_the_speed_came_from():
    from gearshot.app.predict_machine import machine_segments

    for machine, source in (("phm09_spur.toml", "tacho"),
                            ("phm09_spur_notacho.toml", "vibration")):
        info: dict = {}
        sa, x, speed = machine_segments(PHM09 / "spur3_30hz_High_1.zip",
                                        Machine.from_toml(MACHINES / machine),
                                        cycles_per_segment=10, info=info)
        assert info["speed_source"] == source and sa.shape == (11, 2048)
        assert (info["speed_uncertainty_hz"] is None) == (source == "tacho")
        assert speed == pytest.approx(29.92, rel=0.002)


# ------------------------------------------------- ratio locks, cheap search
def test_the_comb_search_finds_the_same_maximum_as_scoring_every_speed():
    """Branch and bound over cells of candidate speeds: the same best score and the same
    (first) speed as the exact comb of every candidate."""
    from gearshot.signal import speed_profile as sp
    rng = np.random.default_rng(24)
    for trial in range(6):
        level = 20.0 * rng.random(40_000) ** 6 + rng.normal(0, 2, 40_000)
        level[rng.integers(0, 40_000, 300)] += 25.0  # lines
        lines = np.array([17.0, 34.0, 51.0]) if trial % 2 else np.array([16.0, 32.0, 48.0])
        df = 0.05
        speeds = np.arange(10.0, 19.0, df / lines.max())
        best, k = sp._comb(level, df, lines, speeds, float(lines.max()) * 10.0)
        gain = np.clip(level - sp._FLOOR_DB, 0.0, sp._CAP_DB).astype(np.float32)
        gain = np.maximum(gain[:-1], gain[1:])
        orders = np.arange(1.0, max(lines.max(), lines.max() * 10.0 / speeds.min()) + 1.0)
        n_kept = np.minimum(np.floor(lines.max() * 10.0 / speeds).astype(np.int64),
                            orders.size)
        every = sp._comb_rows(gain, speeds.astype(np.float32), (orders / df).astype(np.float32),
                              np.isin(orders, lines), n_kept)
        assert best == every.max() and k == int(np.argmax(every))


@needs_phm09
def test_phm09_the_ridges_3_2_lock_on_the_helical_train_is_detected():
    """helical1 30 Hz Low with the machine range [26, 52]: the mesh comb locks at 1.5 times
    the speed (order 16 of 44.15 rev/s = order 24 of 29.43, a second-stage harmonic). The
    whole orders of 2/3 of that speed stand out twice as much: the tracker follows that
    speed (within 0.2 % of the tacho); without the switch it refuses naming both."""
    from gearshot.signal import tracking
    from gearshot.signal.ratio_check import whole_order_scores

    path = PHM09 / "helical1_30hz_Low_1.zip"
    rt = Recording.read(path, machine=MACHINES / "phm09_helical.toml")
    rv = Recording.read(path, machine=MACHINES / "phm09_helical_notacho.toml")
    x = rv.acceleration[0]
    assert rv.shaft_speed() == pytest.approx(rt.shaft_speed(), rel=0.002)
    wrong = estimate_shaft_angle(x, rv.fs, orders=[16, 8], speed_range=(40, 48),
                                 bandwidth=0.1)
    assert wrong.mean_speed == pytest.approx(1.5 * rt.shaft_speed(), rel=0.002)
    s = whole_order_scores(x, rv.fs, wrong.times, wrong.angle, ratios=(1.0, 2 / 3),
                           top_order=32)
    assert s[2 / 3] > 1.5 * s[1.0]
    right = estimate_shaft_angle(x, rv.fs, orders=[16, 8], speed_range=(26, 33),
                                 bandwidth=0.1)
    s = whole_order_scores(x, rv.fs, right.times, right.angle, ratios=(1.0, 1.5),
                           top_order=32)
    assert s[1.5] < 0.7 * s[1.0]
    old = tracking._RATIO_SWITCH
    tracking._RATIO_SWITCH = math.inf
    try:
        with pytest.raises(GearshotError, match=r"speed is ambiguous.*locks at 44\.1\d rev/s"
                                                r".*0\.667 times that, 29\.4\d rev/s") as info:
            estimate_shaft_angle(x, rv.fs, orders=[16, 8], speed_range=(26, 52),
                                 bandwidth=0.1)
    finally:
        tracking._RATIO_SWITCH = old
    assert "\n" not in str(info.value)


@needs_phm09
def test_phm09_a_ridge_refusal_is_tracked_by_the_profile_with_the_nominal_speed():
    """spur2 40 Hz Low: the ridge path is refused; with the nominal speed (±10 %) the
    whole-record profile tracks it within 0.2 % of the tacho; with the machine range
    [26, 52] the profile locks at 2/3 of the speed (the idler's harmonics are whole
    orders of it), 1.5 times that is in the range too, and it is refused."""
    path = PHM09 / "spur2_40hz_Low_1.zip"
    rt = Recording.read(path, machine=MACHINES / "phm09_spur.toml")
    rv = Recording.read(path, machine=MACHINES / "phm09_spur_notacho.toml")
    nominal = Recording.read(path, machine=dataclasses.replace(
        rv.machine, vibration_speed=dataclasses.replace(rv.machine.vibration_speed,
                                                        speed_range=None)),
        metadata={"speed": 40})
    est = nominal.vibration_angle()
    assert est.profile is not None
    assert nominal.shaft_speed() == pytest.approx(rt.shaft_speed(), rel=0.002)
    with pytest.raises(GearshotError, match=r"at 26\.\d+ rev/s mid-record, but 1\.5 times "
                                              r"that is in the speed range too"):
        rv.vibration_angle()


def _fusion_signal(drift_cycles=0.0, seed=4):
    """Three harmonics of a 16-tooth mesh at 20 rev/s, each with its own slow phase
    error (transmission error differs per harmonic), white noise; the third harmonic's
    line optionally drifting ``drift_cycles`` over the record (another line, a slip)."""
    fs, s = 20_000.0, 20.0
    t = np.arange(int(4 * fs)) / fs
    rng = np.random.default_rng(seed)
    x = 0.3 * rng.standard_normal(t.size)
    slow = np.arange(1, 9) / 4.0  # 0.25 ... 2 Hz: inside the band (0.25 orders, 5 Hz)
    for h in (1, 2, 3):
        e = np.cos(2 * np.pi * np.outer(t, slow) + rng.uniform(0, 2 * np.pi, slow.size))
        e = e @ rng.standard_normal(slow.size)
        e *= 0.002 / np.std(e)  # 0.7 degrees of shaft angle, RMS
        drift = drift_cycles * t / t[-1] if h == 3 else 0.0
        x += np.cos(2 * np.pi * (h * 16 * (s * t + e) + drift) + h)
    return x, fs, s * t


def _angle_error_deg(est, truth_rate):
    inner = (est.times > 0.4) & (est.times < 3.6)
    err = est.angle[inner] - truth_rate * est.times[inner]
    return float(np.std(err - err.mean()) * 360)


def test_the_angle_fuses_the_meshs_harmonics_and_leaves_out_a_slipping_one():
    """Each harmonic's phase carries its own error: their inverse-variance average is
    closer to the shaft than one harmonic (``track`` keeps one); a harmonic whose line
    drifts away by cycles is left out rather than averaged in."""
    x, fs, _ = _fusion_signal()
    one = estimate_shaft_angle(x, fs, orders=[16], speed_range=(15, 25), track=16)
    fused = estimate_shaft_angle(x, fs, orders=[16], speed_range=(15, 25))
    e1, ef = _angle_error_deg(one, 20.0), _angle_error_deg(fused, 20.0)
    assert 0.3 < e1 < 1.5 and ef < 0.85 * e1
    assert fused.angle_std < one.angle_std  # the stated uncertainty follows
    x, fs, _ = _fusion_signal(drift_cycles=3.0)
    slipping = estimate_shaft_angle(x, fs, orders=[16], speed_range=(15, 25))
    # in: the 3rd harmonic would pull the angle by up to 3/48 rev (22 degrees)
    assert _angle_error_deg(slipping, 20.0) < 1.2 * e1


@needs_phm09
def test_phm09_fused_harmonics_bring_the_helical_sa_near_the_tacho_sa():
    """helical1 40 Hz Low (SNR 22 dB): the idler SA from the vibration angle within 8 % RMS
    of the tacho-based SA (fused harmonics: 5.2 %; one harmonic: 14 %; the tacho's own
    angle low-passed to the tracker's band: 0.7 %)."""
    from gearshot.signal import fractional_shift

    path = PHM09 / "helical1_40hz_Low_1.zip"
    rt = Recording.read(path, machine=MACHINES / "phm09_helical.toml")
    rv = Recording.read(path, machine=MACHINES / "phm09_helical_notacho.toml")
    a = rt.to_sa_segments(shaft="idler", sensor="acc_input", cycles_per_segment=None)[0]
    b = rv.to_sa_segments(shaft="idler", sensor="acc_input", cycles_per_segment=None)[0]
    c = np.fft.irfft(np.fft.rfft(a) * np.conj(np.fft.rfft(b)), n=16 * a.size)
    e = fractional_shift(b, np.argmax(c) / 16.0) - a
    assert np.sqrt(np.mean(e ** 2) / np.mean(a ** 2)) < 0.08


# ------------------------------------------------------------ the tracked speed checked
def _notacho_with_range(tmp_path, kind: str, lo: float, hi: float) -> Path:
    text = (MACHINES / f"phm09_{kind}_notacho.toml").read_text()
    assert "range_hz = [26, 52]" in text
    out = tmp_path / f"{kind}_range.toml"
    out.write_text(text.replace("range_hz = [26, 52]", f"range_hz = [{lo}, {hi}]"))
    return out


@needs_phm09
def test_a_comb_locked_on_a_mesh_sideband_fails_the_speed_check(tmp_path):
    """Issue 29's failure mode on a shared record: a range that leaves the true speed out
    makes the comb lock 2.08 % high (the input mesh's sideband at 2 idler orders, 32 + 2/3);
    the stated uncertainty cannot cover that, the speed check names it."""
    from gearshot.machine.signal_check import speed_check

    path = PHM09 / "spur2_30hz_Low_1.zip"
    true = Recording.read(path, machine=MACHINES / "phm09_spur.toml").shaft_speed()
    rec = Recording.read(path, machine=_notacho_with_range(tmp_path, "spur", 30.2, 33))
    tracked = rec.shaft_speed()
    assert tracked / true - 1 == pytest.approx(2 / 96, abs=0.001)   # the wrong lock
    assert abs(tracked - true) > 10 * rec.speed_uncertainty
    verdict = speed_check(rec.machine, rec)
    assert "looks +2.09 % off" in verdict and f"best at {true:.4g} Hz" in verdict
    with pytest.raises(GearshotError, match=r"tracked in the vibration .* looks \+2\.09 % off"):
        verify_machine_on(rec)
    good = Recording.read(path, machine=MACHINES / "phm09_spur_notacho.toml")
    assert speed_check(good.machine, good) == "ok"


def verify_machine_on(rec):
    from gearshot.machine.signal_check import verify_machine
    return verify_machine(rec.machine, rec)


@needs_phm09
def test_the_stated_speed_uncertainty_covers_the_tacho_and_reaches_predict_rows():
    from gearshot.app.predict_machine import machine_segments
    from gearshot.signal.tracking import SPEED_MODEL_REL

    path = PHM09 / "spur3_30hz_Low_1.zip"
    rt = Recording.read(path, machine=MACHINES / "phm09_spur.toml")
    rv = Recording.read(path, machine=MACHINES / "phm09_spur_notacho.toml")
    angle = rv.vibration_angle()
    u = rv.speed_uncertainty
    assert u == pytest.approx(math.hypot(angle.speed_std, SPEED_MODEL_REL * angle.mean_speed))
    assert u > angle.speed_std   # the phase noise alone was 3.4 x too small here
    assert abs(rv.shaft_speed() - rt.shaft_speed()) < 2 * u
    # the tacho's speed over 0.25 s windows, against the tracked angle's
    pulses = rt.pulse_times()
    edges = np.arange(pulses[0] + 0.1, pulses[-1] - 0.1, 0.25)
    tacho = np.diff(np.interp(edges, pulses, np.arange(pulses.size) / 10)) / 0.25
    tracked = np.diff(np.interp(edges, angle.times, angle.angle)) / 0.25
    assert np.mean(np.abs(tracked - tacho) <= 2 * u) >= 0.9
    assert np.mean(np.abs(tracked - tacho) <= 2 * angle.speed_std) < 0.9
    info: dict = {}
    machine_segments(path, rv.machine, cycles_per_segment=10, info=info)
    assert info["speed_source"] == "vibration" and info["speed_check"] == "ok"
    assert info["speed_uncertainty_hz"] == pytest.approx(u)


def test_a_virtual_rig_run_up_locked_on_another_line_fails_the_speed_check():
    """Rig seed 3's run-up 14 -> 17 rev/s, searched over 12.6-18.7 rev/s, tracks 15 % high
    with a stated uncertainty of 0.04 rev/s; the check names the rig's true mean speed."""
    from gearshot.machine.signal_check import speed_check
    from gearshot.rig import VirtualRig
    from gearshot.signal import pulse_times

    machine = Machine.from_dict({
        "name": "virtual rig", "shafts": ["input", "output"],
        "stage": [{"driver": "input", "driver_teeth": 17, "driven": "output",
                   "driven_teeth": 38}],
        "speed": {"shaft": "input", "range_hz": [12.6, 18.7]},
        "sensor": [{"name": "acceleration", "channel": "acceleration", "sensitivity": 1.0,
                    "unit": "g"}]})
    rec = VirtualRig(seed=3).record(speed=14.0, load=10, duration=4.0, end_speed=17.0)
    pulses = pulse_times(rec.tacho, rec.fs)
    true = (pulses.size - 1) / (pulses[-1] - pulses[0]) / (rec.tacho_pulses_per_rev or 1)
    blind = dataclasses.replace(rec, tacho=None, machine=machine)
    assert blind.shaft_speed() / true > 1.1
    verdict = speed_check(machine, blind)
    assert "looks +15" in verdict and "best at 15.4" in verdict
