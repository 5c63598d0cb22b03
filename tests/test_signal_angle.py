"""Tacho -> gear-revolution cycles -> angle domain -> 50-cycle SA segments."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from gearshot import GearshotError
from gearshot.io import Recording
from gearshot.rig import tacho_signal
from gearshot.signal import shaft_cycle_times

FS = 50_000.0
ZG, ZP = 38, 17
N_SA = 2048


def template(gear_phase):
    """Gear-periodic test waveform: 3 mesh harmonics + a 'fault' bump at 0.3 rev."""
    g = np.asarray(gear_phase)
    x = (1.0 * np.cos(2 * np.pi * ZG * g + 0.3) + 0.5 * np.cos(2 * np.pi * 2 * ZG * g - 1.0)
         + 0.2 * np.cos(2 * np.pi * 3 * ZG * g + 2.0))
    d = np.mod(g - 0.3 + 0.5, 1.0) - 0.5
    return x + 2.0 * np.exp(-0.5 * (d / 0.004) ** 2)


def pinion_revs(t, f0, *, drift=0.01, drift_period=6.0, ripple=0.0):
    """Closed-form pinion angle (rev): speed f0 (1 + drift sin(.) + ripple cos(2 pi f0 t))."""
    return (f0 * t + drift * f0 * drift_period / (2 * np.pi) * np.sin(2 * np.pi * t / drift_period)
            + ripple / (2 * np.pi) * np.sin(2 * np.pi * f0 * t))


def synthetic(duration, f0=30.0, *, noise=0.0, seed=0, **kw):
    t = np.arange(int(duration * FS)) / FS
    revs = pinion_revs(t, f0, **kw)
    rng = np.random.default_rng(seed)
    acc = template(revs * ZP / ZG) + noise * rng.normal(size=t.size)
    return Recording(acc, tacho_signal(revs), FS, speed=f0), revs


def first_pulse_gear_phase(rec, f0, **kw):
    t0 = rec.pulse_times()[0]
    return float(pinion_revs(np.array([t0]), f0, **kw)[0]) * ZP / ZG


def test_gear_cycle_times_constant_speed_and_output_shaft():
    """Gear revolutions from an input-shaft (ratio 38/17) or output-shaft (ratio 1) tacho."""
    pulses = np.arange(40) / 15.0  # 15 rev/s input shaft
    c = shaft_cycle_times(pulses, revs_per_cycle=Fraction(ZG, ZP))
    period = ZG / ZP / 15.0
    np.testing.assert_allclose(c, np.arange(c.size) * period, atol=1e-12)
    assert c.size == int(39 * ZP / ZG) + 1
    # two pulses per output-shaft revolution
    out = np.arange(21) / (2 * 15.0 * ZP / ZG)
    c2 = shaft_cycle_times(out, revs_per_cycle=1, pulses_per_rev=2)
    np.testing.assert_allclose(c2, np.arange(11) * period, atol=1e-12)
    with pytest.raises(GearshotError, match="revs_per_cycle"):
        shaft_cycle_times(pulses, revs_per_cycle=-2)


def test_gear_cycle_times_follow_varying_speed():
    t = np.linspace(0.0, 10.0, 400_001)
    revs = pinion_revs(t, 15.0, drift=0.01, drift_period=4.0)
    pulses = np.interp(np.arange(1, int(revs[-1])), revs, t)
    c = shaft_cycle_times(pulses, revs_per_cycle=Fraction(ZG, ZP))
    # gear revolution m ends at pinion angle 1 + m * 38/17 (cycle 0 starts at pulse 1)
    expect = np.interp(1 + np.arange(c.size) * ZG / ZP, revs, t)
    np.testing.assert_allclose(c, expect, atol=2e-6)  # 2 us << 1 sample at 50 kHz


def test_sa_segments_recover_gear_waveform_under_speed_drift():
    rec, _ = synthetic(8.0, drift=0.01, drift_period=6.0)
    sa = rec.to_sa_segments(gear_teeth=ZG, pinion_teeth=ZP)
    n_cycles = int(np.floor((rec.pulse_times().size - 1) * ZP / ZG))
    assert sa.shape == (n_cycles // 50, N_SA) == (2, N_SA)
    phase0 = first_pulse_gear_phase(rec, 30.0, drift=0.01, drift_period=6.0)
    want = template(phase0 + np.arange(N_SA) / N_SA)
    err = np.sqrt(np.mean((sa - want) ** 2, axis=-1)) / np.sqrt(np.mean(want ** 2))
    assert np.all(err < 0.01), err
    ad = rec.angle_domain(gear_teeth=ZG, pinion_teeth=ZP)
    assert ad.size == n_cycles * N_SA
    np.testing.assert_allclose(ad[:N_SA], want, atol=0.05 * np.abs(want).max())


def test_skipping_angular_resampling_degrades_sa():
    rec, _ = synthetic(8.0, drift=0.01, drift_period=6.0)
    phase0 = first_pulse_gear_phase(rec, 30.0, drift=0.01, drift_period=6.0)
    want = template(phase0 + np.arange(N_SA) / N_SA)
    good = rec.to_sa_segments(gear_teeth=ZG, pinion_teeth=ZP)
    bad = rec.to_sa_segments(gear_teeth=ZG, pinion_teeth=ZP, resample=False)
    err_good = np.sqrt(np.mean((good - want) ** 2))
    err_bad = np.sqrt(np.mean((bad - want) ** 2))
    assert err_bad > 10 * err_good, (err_good, err_bad)
    # the mesh harmonic is smeared out: its SA amplitude drops
    amp = lambda s: np.abs(np.fft.rfft(s, axis=-1)[..., ZG]).mean() * 2 / N_SA  # noqa: E731
    assert amp(good) == pytest.approx(amp(want), rel=0.01)
    assert amp(bad) < 0.8 * amp(want)


# ----------------------------------------------------------------------------- bad input
def test_missing_and_flat_tacho(tmp_path):
    rec, _ = synthetic(1.0)
    path = Recording(rec.acceleration, None, FS).write(tmp_path / "notacho.h5")
    with pytest.raises(GearshotError, match=r"notacho\.h5.*has no tacho"):
        Recording.read(path).to_sa_segments(gear_teeth=ZG, pinion_teeth=ZP)
    flat = Recording(rec.acceleration, np.zeros_like(rec.acceleration), FS)
    with pytest.raises(GearshotError, match="tacho is flat"):
        flat.to_sa_segments(gear_teeth=ZG, pinion_teeth=ZP)
    one = np.zeros_like(rec.acceleration)
    one[1000:30000] = 5.0
    with pytest.raises(GearshotError, match="1 pulse"):
        Recording(rec.acceleration, one, FS).to_sa_segments(gear_teeth=ZG, pinion_teeth=ZP)


def test_tacho_dropout_longer_than_a_revolution(tmp_path):
    rec, revs = synthetic(8.0)
    tach = rec.tacho.copy()
    tach[(revs > 100.5) & (revs < 101.5)] = 0.0  # pulse 101 missing
    path = Recording(rec.acceleration, tach, FS, speed=30.0).write(tmp_path / "drop.h5")
    with pytest.raises(GearshotError,
                       match=r"drop\.h5.*tacho dropout .*more than one revolution.*t=3\.3"):
        Recording.read(path).to_sa_segments(gear_teeth=ZG, pinion_teeth=ZP)


def test_recording_shorter_than_one_segment():
    rec, _ = synthetic(3.0)  # 3 s at 30 rev/s: 89 pulses -> 39 gear revolutions < 50
    with pytest.raises(GearshotError, match=r"holds 39 whole gear.*cycles_per_segment=50"):
        rec.to_sa_segments(gear_teeth=ZG, pinion_teeth=ZP)
    assert rec.to_sa_segments(gear_teeth=ZG, pinion_teeth=ZP, cycles_per_segment=13).shape \
        == (3, N_SA)


def test_wrong_fs_is_detected_from_speed_metadata(tmp_path):
    rec, _ = synthetic(4.0)
    path = tmp_path / "r.csv"
    wrong = Recording(rec.acceleration, rec.tacho, FS / 2, speed=30.0)  # fs mislabelled
    wrong.write(path)
    with pytest.raises(GearshotError,
                       match=r"r\.csv.*input speed of 1[45]\.?[0-9]* rev/s at fs=25000 Hz"):
        Recording.read(path).to_sa_segments(gear_teeth=ZG, pinion_teeth=ZP, cycles_per_segment=5)
    ok = Recording.read(path, metadata={"speed": 15.0})
    assert ok.to_sa_segments(gear_teeth=ZG, pinion_teeth=ZP, cycles_per_segment=5).shape[0] > 0


def test_tacho_signal_jitter_and_pulses_per_rev():
    t = np.arange(int(2 * FS)) / FS
    revs = 10.0 * t
    rng = np.random.default_rng(4)
    tach = tacho_signal(revs, pulses_per_rev=3, jitter=2e-4, rng=rng)
    rec = Recording(np.zeros_like(t), tach, FS, tacho_pulses_per_rev=3)
    p = rec.pulse_times()
    assert p.size == 60  # 20 revolutions x 3
    dev = p - (np.arange(60) / 30.0 + 0.001 / 10)  # rising-edge centre = edge/2 rev late
    assert 1e-6 < np.std(dev) < 4e-5  # ~2e-4 rev / 10 rev/s = 2e-5 s
    with pytest.raises(GearshotError, match="rng"):
        tacho_signal(revs, jitter=1e-4)


def test_short_dropout_bridged_with_several_pulses_per_rev_and_glitch_rejected():
    t = np.arange(int(6.0 * FS)) / FS
    revs = pinion_revs(t, 30.0, drift=0.01, drift_period=6.0)
    acc = template(revs * ZP / ZG)
    tach = tacho_signal(revs, pulses_per_rev=4)
    full = Recording(acc, tach, FS, tacho_pulses_per_rev=4)
    ref = full.to_sa_segments(gear_teeth=ZG, pinion_teeth=ZP)
    holed = tach.copy()
    holed[(revs > 50.1) & (revs < 50.6)] = 0.0  # two of four pulses in one revolution
    rec = Recording(acc, holed, FS, tacho_pulses_per_rev=4)
    assert rec.pulse_times().size == full.pulse_times().size
    sa = rec.to_sa_segments(gear_teeth=ZG, pinion_teeth=ZP)
    assert np.sqrt(np.mean((sa - ref) ** 2)) < 0.01 * np.sqrt(np.mean(ref ** 2))
    long_hole = tach.copy()
    long_hole[(revs > 50.1) & (revs < 51.3)] = 0.0  # more than a revolution
    with pytest.raises(GearshotError, match="more than one revolution"):
        Recording(acc, long_hole, FS, tacho_pulses_per_rev=4).pulse_times()
    glitch = tach.copy()
    k = np.flatnonzero((revs > 20.12) & (revs < 20.13))
    glitch[k] = 5.0  # a spike between two pulses
    with pytest.raises(GearshotError, match="extra tacho pulse"):
        Recording(acc, glitch, FS, tacho_pulses_per_rev=4).pulse_times()


def test_output_shaft_tacho_gives_the_same_sa():
    t = np.arange(int(8.0 * FS)) / FS
    revs = pinion_revs(t, 30.0, drift=0.01, drift_period=6.0)
    gear = revs * ZP / ZG
    acc = template(gear)
    on_input = Recording(acc, tacho_signal(revs), FS, tacho_pulses_per_rev=1)
    on_output = Recording(acc, tacho_signal(gear, pulses_per_rev=2), FS, tacho_shaft="output",
                          tacho_pulses_per_rev=2)
    sa_out = on_output.to_sa_segments(gear_teeth=ZG, pinion_teeth=ZP)
    phase0 = float(np.interp(on_output.pulse_times()[0], t, gear))
    want = template(phase0 + np.arange(N_SA) / N_SA)
    assert np.sqrt(np.mean((sa_out - want) ** 2)) < 0.01 * np.sqrt(np.mean(want ** 2))
    # both tachos see the same number of gear revolutions
    n_in = on_input.angle_domain(gear_teeth=ZG, pinion_teeth=ZP).size // N_SA
    n_out = on_output.angle_domain(gear_teeth=ZG, pinion_teeth=ZP).size // N_SA
    assert abs(n_in - n_out) <= 1
