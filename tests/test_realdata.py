"""Real gearboxes (issue #11): the eight friction points, order tracking through gear
trains, anti-aliased angular resampling. Real files come from ../shared/data/phm09."""

from __future__ import annotations

import zipfile
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from gearshot import GearshotError, Machine
from gearshot.features import available_features, extract_features
from gearshot.io import Recording
from gearshot.signal import angular_resample, difference_signal, pulse_times, synchronous_average
from gearshot.signal.antialias import antialias_filter
from gearshot.signal.trains import as_ratio, shaft_cycle_times

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples" / "machines"
PHM = ROOT.parent / "shared" / "data" / "phm09"
FS = 200_000 / 3
SPR = 2048


def phm_file(name):
    path = PHM / name
    if not path.is_file():
        pytest.skip(f"{path} is absent; real-data checks need ../shared/data/phm09")
    return path


@pytest.fixture(scope="module")
def spur():
    return Machine.from_toml(EXAMPLES / "phm09_spur.toml")


@pytest.fixture(scope="module")
def helical():
    return Machine.from_toml(EXAMPLES / "phm09_helical.toml")


@pytest.fixture(scope="module")
def spur_rec(spur):
    return Recording.read(phm_file("spur2_30hz_High_1.zip"), machine=spur)


@pytest.fixture(scope="module")
def raw_text():
    """The first 40,000 rows of one original file, as text (0.6 s of recording)."""
    with zipfile.ZipFile(phm_file("spur1_30hz_Low_1.zip")) as zf:
        text = zf.read(zf.namelist()[0]).decode()
    return "".join(text.splitlines(keepends=True)[:40_000])


# ----------------------------------------------------------------------------- 1, 2, 3
def test_1_zipped_whitespace_text_is_read_as_it_comes(spur, spur_rec):
    assert spur_rec.acceleration.shape == (2, 266_656)
    assert spur_rec.channel_names == ("acc_input", "acc_output")
    assert spur_rec.fs == pytest.approx(FS) and spur_rec.tacho_pulses_per_rev == 10
    with zipfile.ZipFile(phm_file("spur2_30hz_High_1.zip")) as zf:
        first = zf.read(zf.namelist()[0])[:200].decode().split()
    # volts / (10 mV/g) = g, column by column, the mean (sensor bias) removed
    raw = Recording.read(phm_file("spur2_30hz_High_1.zip"), fs=FS, accel=0, tacho=2)
    assert raw.acceleration[0] == float(first[0])
    assert_allclose(spur_rec.acceleration[0], (raw.acceleration - raw.acceleration.mean()) / 0.01,
                    atol=1e-9)
    assert abs(spur_rec.acceleration[1].mean()) < 1e-9
    assert spur_rec.tacho[0] == pytest.approx(float(first[2]))
    # without a machine: no silent guess, a clear error naming the parameter
    with pytest.raises(GearshotError, match=r"cannot tell which channel is the acceleration;"
                                            r".*accel=<name or index>"):
        Recording.read(phm_file("spur2_30hz_High_1.zip"), fs=FS)
    with pytest.raises(GearshotError, match="fs="):
        Recording.read(phm_file("spur2_30hz_High_1.zip"), accel=0, tacho=2)


def test_1_renamed_text_files_read_too(tmp_path, spur, raw_text):
    for name in ("rec.txt", "rec.csv", "rec.dat"):
        path = tmp_path / name
        path.write_text(raw_text)
        rec = Recording.read(path, machine=spur)
        assert rec.acceleration.shape == (2, 40_000)
        with pytest.raises(GearshotError, match="cannot tell which channel"):
            Recording.read(path, fs=FS)
    gz = tmp_path / "rec.txt.gz"
    import gzip

    gz.write_bytes(gzip.compress(raw_text.encode()))
    assert Recording.read(gz, machine=spur).acceleration.shape == (2, 40_000)


def test_2_headerless_comma_csv_is_never_read_silently_wrong(tmp_path, raw_text):
    rows = [",".join(line.split()) for line in raw_text.splitlines()]
    path = tmp_path / "rec.csv"
    path.write_text("\n".join(rows) + "\n")
    with pytest.raises(GearshotError, match=r"cannot tell which channel.*\['0', '1', '2'\]"):
        Recording.read(path, fs=FS)
    rec = Recording.read(path, fs=FS, channels=["acc", "acc_out", "tacho"])
    assert rec.acceleration.size == 40_000  # the first row is data, not a header
    assert rec.acceleration[0] == pytest.approx(float(raw_text.split()[0]))
    assert rec.tacho[0] == pytest.approx(float(raw_text.split()[2]))  # tacho = column 3
    # the explicit-index route picks exactly what it is told
    by_index = Recording.read(path, fs=FS, accel=1, tacho=2)
    assert by_index.acceleration[0] == pytest.approx(float(raw_text.split()[1]))
    # a header-less file without a tacho named has no tacho -> SA raises, never guesses
    no_tacho = Recording.read(path, fs=FS, accel=0)
    with pytest.raises(GearshotError, match="has no tacho"):
        no_tacho.to_sa_segments(gear_teeth=96, pinion_teeth=32)


def test_3_one_recording_holds_every_channel(spur_rec):
    sa = spur_rec.to_sa_segments(shaft="idler", cycles_per_segment=None)
    assert sa.shape == (2, 1, SPR)
    one = spur_rec.channel("acc_output")
    assert one.acceleration.ndim == 1 and one.channel_names == ("acc_output",)
    assert_allclose(one.to_sa_segments(shaft="idler", cycles_per_segment=None), sa[1],
                    rtol=1e-10, atol=1e-12)
    assert_allclose(spur_rec.to_sa_segments(shaft="idler", sensor="acc_input",
                                            cycles_per_segment=None), sa[0], atol=1e-12)
    with pytest.raises(GearshotError, match=r"sensor='acc_middle' is not a channel"):
        spur_rec.channel("acc_middle")
    with pytest.raises(GearshotError, match="not supported"):
        spur_rec.write("x.h5")


# ----------------------------------------------------------------------------- 4
def test_4_pulses_per_rev_is_never_assumed(tmp_path, raw_text):
    path = tmp_path / "rec.txt"
    path.write_text(raw_text)
    rec = Recording.read(path, fs=FS, accel=0, tacho=2)
    with pytest.raises(GearshotError, match="tacho_pulses_per_rev is not stated"):
        rec.to_sa_segments(gear_teeth=96, pinion_teeth=32, cycles_per_segment=None)
    # a stated speed lets it be inferred (10 pulses per input revolution)
    with_speed = Recording.read(path, fs=FS, accel=0, tacho=2, metadata={"speed": 30.0})
    assert with_speed.resolved_pulses_per_rev() == 10
    stated = Recording.read(path, fs=FS, accel=0, tacho=2,
                            metadata={"tacho_pulses_per_rev": 10})
    assert_allclose(with_speed.to_sa_segments(gear_teeth=96, pinion_teeth=32,
                                              cycles_per_segment=None),
                    stated.to_sa_segments(gear_teeth=96, pinion_teeth=32,
                                          cycles_per_segment=None))


# ----------------------------------------------------------------------------- 5, 6
def test_5_any_shaft_from_a_tacho_on_another(spur, spur_rec):
    speeds = {s: spur_rec.shaft_speed(s) for s in spur.shafts}
    assert 0.97 * 30 <= speeds["input"] <= 1.0 * 30
    assert speeds["idler"] == pytest.approx(speeds["input"] / 3, rel=1e-12)
    assert speeds["output"] == pytest.approx(speeds["input"] / 5, rel=1e-12)
    # the old pair API agrees with the train when the pair is a stage driven from the tacho
    old = spur_rec.to_sa_segments(gear_teeth=96, pinion_teeth=32, cycles_per_segment=None)
    new = spur_rec.to_sa_segments(shaft="idler", cycles_per_segment=None)
    assert_allclose(old, new, atol=1e-12)
    # the output shaft needs no made-up pair
    assert spur_rec.to_sa_segments(shaft="output", cycles_per_segment=None).shape == (2, 1, SPR)
    with pytest.raises(GearshotError, match=r"shaft='brake' is not a shaft"):
        spur_rec.to_sa_segments(shaft="brake")


def test_5_the_targets_own_pair_is_refused_with_the_right_cycle_named(helical):
    rec = Recording.read(phm_file("helical1_30hz_Low_1.zip"), machine=helical)
    with pytest.raises(GearshotError, match=r"tacho watches shaft 'input', not the 24-tooth "
                                            r"gear's shaft 'idler'.*is 5 tacho revolutions.*"
                                            r"shaft='output'"):
        rec.to_sa_segments(gear_teeth=40, pinion_teeth=24)
    with pytest.raises(GearshotError, match="no stage where a 17-tooth gear drives"):
        rec.to_sa_segments(gear_teeth=38, pinion_teeth=17)
    with pytest.raises(GearshotError, match="needs the gear train"):
        Recording(np.zeros(100), None, 1000.0).to_sa_segments(shaft="idler")


def test_6_segments_of_all_whole_cycles(spur_rec):
    pulses = spur_rec.pulse_times()
    n_idler = (pulses.size - 1) // 30
    sa = spur_rec.to_sa_segments(shaft="idler", sensor=0, cycles_per_segment=None)
    assert sa.shape == (1, SPR)
    x = spur_rec.angle_domain(shaft="idler", sensor=0)
    assert x.size == n_idler * SPR and n_idler in (38, 39)
    assert_allclose(sa[0], x.reshape(n_idler, SPR).mean(axis=0), atol=1e-12)
    assert spur_rec.to_sa_segments(shaft="idler", sensor=0, cycles_per_segment=10).shape == \
        (n_idler // 10, SPR)
    with pytest.raises(GearshotError, match=r"holds \d+ whole revolution\(s\) of 'output'"):
        spur_rec.to_sa_segments(shaft="output", cycles_per_segment=50)


# ----------------------------------------------------------------------------- 7
def test_7_a_shaft_with_two_meshes():
    n = 2048
    theta = np.arange(n) / n
    meshes = np.cos(2 * np.pi * 96 * theta) + 0.5 * np.cos(2 * np.pi * 48 * theta + 1) \
        + 0.2 * np.cos(2 * np.pi * 49 * theta)  # a sideband of the 48 mesh
    other = 0.3 * np.cos(2 * np.pi * 7 * theta) + 0.1 * np.cos(2 * np.pi * 2 * theta)
    d = difference_signal(meshes + other, [96, 48])
    assert_allclose(d, other, atol=1e-12)
    # with one order, the 48 mesh stays (the old behaviour)
    assert np.ptp(difference_signal(meshes + other, 96) - other) > 1.0
    f_two = extract_features((meshes + other)[None], [96, 48], names=available_features())
    assert f_two.shape == (1, len(available_features()))
    # shaft orders are configurable: removing order 7 leaves only shaft order 2 (removed too)
    fm = extract_features((meshes + other)[None], [96, 48], names=["fm4", "er"],
                          shaft_orders=[1, 2, 7])
    assert_allclose(fm, 0.0, atol=1e-9)
    with pytest.raises(GearshotError, match=r"mesh_order\[1\]=1024 is at or above"):
        difference_signal(meshes, [96, 1024])
    with pytest.raises(GearshotError, match="shaft_orders must be a sequence"):
        extract_features(meshes[None], 96, names=["fm4"], shaft_orders=3)


def test_7_meshes_of_other_stages_that_are_synchronous_leave_the_difference_signal(spur,
                                                                                    spur_rec):
    # The input shaft carries only the 32T gear, but the idler's 48T -> 80T mesh turns
    # 48 / 3 = 16 times per input revolution: in the real input-shaft SA it is the
    # largest order, larger than the 32T mesh itself.
    assert spur.gear_teeth("input") == (32,) and spur.mesh_orders("input") == (32, 16)
    sa = spur_rec.to_sa_segments(shaft="input", sensor="acc_input", cycles_per_segment=None)[0]
    amp = np.abs(np.fft.rfft(sa))
    assert int(np.argmax(amp[1:200])) + 1 == 16 and amp[16] > amp[32]
    d_one = difference_signal(sa, 32)
    d_all = difference_signal(sa, list(spur.mesh_orders("input")))
    amp_all = np.abs(np.fft.rfft(d_all))
    assert_allclose(amp_all[[16, 48, 80, 15, 17, 46, 50]], 0.0, atol=1e-9)
    # the second mesh's bands hold most of what the single-order difference signal keeps
    assert np.sqrt(np.mean(d_all ** 2)) < 0.7 * np.sqrt(np.mean(d_one ** 2))


# ----------------------------------------------------------------------------- 8
def _shaft_signal(orders, *, f0=30.0, duration=4.0, ratio=3):
    """Input speed ~f0 (±1 %), a smooth 10-pulse tacho, a signal with given idler orders."""
    t = np.arange(int(FS * duration)) / FS
    theta = f0 * t + 0.01 * f0 * 3.0 / (2 * np.pi) * np.sin(2 * np.pi * t / 3.0)
    idler = theta / ratio
    x = sum(a * np.cos(2 * np.pi * o * idler + 0.3 * o) for o, a in orders.items())
    return t, idler, np.sin(2 * np.pi * 10 * theta), x


def test_8_antialias_leaves_under_1_percent_error_below_the_angular_nyquist():
    low = {5: 1.0, 96: 0.5, 700: 0.3}
    high = {1500: 3.0, 2600: 3.0}  # 10x stronger, above the Nyquist order 1024
    t, idler, tacho, x = _shaft_signal({**low, **high})
    pulses = pulse_times(tacho, FS, threshold=0.0)
    cycles = shaft_cycle_times(pulses, revs_per_cycle=3, pulses_per_rev=10)
    phase0 = np.interp(cycles[0], t, idler)
    grid = phase0 + np.arange(SPR) / SPR
    ref = sum(a * np.cos(2 * np.pi * o * grid + 0.3 * o) for o, a in low.items())
    err = {}
    for aa in (True, False):
        sa = synchronous_average(angular_resample(x, FS, cycles, samples_per_rev=SPR,
                                                  antialias=aa), SPR)
        err[aa] = np.linalg.norm(sa - ref) / np.linalg.norm(ref)
        amp = 2 * np.abs(np.fft.rfft(sa)[[5, 96, 700]]) / SPR
        if aa:
            assert_allclose(amp, [1.0, 0.5, 0.3], rtol=0.01)
    assert err[True] < 0.01
    assert err[False] > 0.5  # without the low-pass the strong orders fold down


def test_8_paper_rig_sa_unchanged_where_nothing_aliases():
    """Paper pair (17 -> 38), 1-pulse tacho, content far below the angular Nyquist."""
    fs, f0 = 50_000.0, 15.0
    t = np.arange(int(fs * 12.0)) / fs
    revs = f0 * t + 0.005 * f0 * 5 / (2 * np.pi) * np.sin(2 * np.pi * t / 5)
    gear = revs * 17 / 38
    acc = sum(a * np.cos(2 * np.pi * o * gear + o) for o, a in {38: 1.0, 76: 0.4, 19: 0.1,
                                                                 400: 0.05}.items())
    tach = (np.mod(revs, 1.0) < 0.2) * 5.0
    rec = Recording(acc, tach, fs, speed=f0)
    on = rec.to_sa_segments(gear_teeth=38, pinion_teeth=17)
    off = rec.to_sa_segments(gear_teeth=38, pinion_teeth=17, antialias=False)
    keep = slice(0, int(0.9 * SPR / 2))
    a, b = np.fft.rfft(on)[..., keep], np.fft.rfft(off)[..., keep]
    assert np.linalg.norm(a - b) < 1e-3 * np.linalg.norm(b)


def test_antialias_filter_is_flat_in_the_pass_band_and_upsamples():
    fs = 1000.0
    t = np.arange(4000) / fs
    x = np.cos(2 * np.pi * 50 * t) + np.cos(2 * np.pi * 300 * t)
    y = antialias_filter(x, fs, cutoff=200.0)
    mid = slice(500, -500)
    assert_allclose(y[mid], np.cos(2 * np.pi * 50 * t)[mid], atol=1e-4)
    y2 = antialias_filter(x, fs, cutoff=400.0, upsample=2)
    t2 = np.arange(8000) / (2 * fs)
    assert_allclose(y2[1000:-1000], (np.cos(2 * np.pi * 50 * t2)
                                     + np.cos(2 * np.pi * 300 * t2))[1000:-1000], atol=1e-3)
    with pytest.raises(GearshotError, match="passband must lie in"):
        antialias_filter(x, fs, cutoff=200.0, passband=1.0)


def test_exact_ratios():
    assert as_ratio("96/32") == 3 and as_ratio((38, 17)) == Fraction(38, 17)
    with pytest.raises(GearshotError, match="revs_per_cycle must be an exact ratio"):
        as_ratio(38 / 17 + 1e-9)
    pulses = np.arange(0, 1001) / 100.0  # 10 pulses/rev at 10 rev/s, 10 s
    c = shaft_cycle_times(pulses, revs_per_cycle=Fraction(38, 17), pulses_per_rev=10)
    assert c.size == int(100 * 17 / 38) + 1
    assert_allclose(c, np.arange(c.size) * 38 / 17 / 10.0, atol=1e-12)


def test_tdms_recordings_with_a_machine(tmp_path):
    nptdms = pytest.importorskip("nptdms", reason="TDMS reading needs the optional npTDMS")
    fs = 10_000.0
    t = np.arange(int(3 * fs)) / fs
    revs = 20.0 * t
    acc_v = 0.01 * np.cos(2 * np.pi * 32 * revs) + 0.5  # 1 g at order 32, a 0.5 V bias
    tach = (np.mod(revs * 10, 1.0) < 0.5) * 5.0
    path = tmp_path / "run.tdms"
    props = {"wf_increment": 1 / fs}
    with nptdms.TdmsWriter(path) as w:
        w.write_segment([nptdms.ChannelObject("daq", "acc_input", acc_v, properties=props),
                         nptdms.ChannelObject("daq", "acc_output", acc_v, properties=props),
                         nptdms.ChannelObject("daq", "tacho", tach, properties=props)])
    machine = Machine.from_toml(EXAMPLES / "phm09_spur.toml")
    rec = Recording.read(path, machine=machine)
    assert rec.fs == pytest.approx(fs) and rec.acceleration.shape == (2, t.size)
    sa = rec.to_sa_segments(shaft="input", sensor="acc_input", cycles_per_segment=None)
    assert 2 * np.abs(np.fft.rfft(sa[0]))[32] / SPR == pytest.approx(1.0, rel=0.01)
