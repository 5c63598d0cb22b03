"""VirtualRig: hidden reality, signal chain, fault visibility, campaigns."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from scipy.signal import hilbert

from gearshot import GearshotError
from gearshot.io import INDEX_COLUMNS, Recording, read_campaign
from gearshot.rig import SimulatorEngine, SurrogateEngine, VirtualRig, tacho_signal
from gearshot.rig.interference import add_noise, bearing_impacts, extra_shaft, motor_harmonics
from gearshot.rig.path import apply_path, path_fir
from gearshot.signal import difference_signal, harmonic_signal, rms
from gearshot.transfer import TransferFunction

ZG, ZP, N_SA = 38, 17, 2048
SHARED = Path(__file__).resolve().parents[1].parent / "shared"


ENGINES = {"sim": SimulatorEngine, "surrogate": SurrogateEngine}


@pytest.fixture(scope="module")
def rig():
    return VirtualRig(seed=0)  # default engine: the simulator


@pytest.fixture(scope="module", params=sorted(ENGINES))
def any_rig(request):
    return VirtualRig(seed=0, engine=request.param)


def sa_of(rec, **kw):
    return rec.to_sa_segments(gear_teeth=ZG, pinion_teeth=ZP, **kw)


def diff_rms(sa):
    return float(np.sqrt(np.mean(difference_signal(sa, ZG) ** 2)))


def test_reality_is_seeded_and_within_the_issue_ranges(rig):
    r = rig.reveal()
    assert r == VirtualRig(seed=0).reveal()
    assert r != VirtualRig(seed=1).reveal()
    for f in (*r.mass_factor, *r.inertia_factor, r.bearing_stiffness_factor,
              r.shaft_stiffness_factor, r.mesh_stiffness_factor, r.damping_factor):
        assert 0.1 - 1e-12 <= abs(f - 1) <= 0.3 + 1e-12
    assert 20 <= r.snr_db <= 30 and 10 <= r.attenuation_db <= 30
    assert 0 < r.speed_drift <= 0.01 and 0 < r.tacho_jitter < 1e-3
    assert abs(r.extra_order - round(r.extra_order)) > 0.05
    assert r.fault_roughness != (0.0, 0.0, 0.0)


def test_record_is_deterministic_and_hides_the_reality(rig):
    a = rig.record(speed=30.0, load=5.0, fault_size=0.56, duration=0.5, repetition=1)
    b = rig.record(speed=30.0, load=5.0, fault_size=0.56, duration=0.5, repetition=1)
    c = rig.record(speed=30.0, load=5.0, fault_size=0.56, duration=0.5, repetition=2)
    np.testing.assert_array_equal(a.acceleration, b.acceleration)
    assert not np.allclose(a.acceleration, c.acceleration)
    assert a.fs == 50_000.0 and a.acceleration.size == 25_000 and a.tacho.size == 25_000
    assert (a.speed, a.load, a.fault_size, a.units) == (30.0, 5.0, 0.56, "g")
    assert a.extras["repetition"] == 1
    hidden = set(rig.reveal().as_dict())
    assert not hidden & set(a.extras) and "grade" not in a.source


def test_speed_drifts_and_ripples_but_stays_within_one_percent(rig):
    rec = rig.record(speed=15.0, load=10.0, duration=20.0)
    p = rec.pulse_times()
    inst = 1.0 / np.diff(p)  # rev/s per revolution
    dev = inst / 15.0 - 1
    assert np.max(np.abs(dev)) < 0.012
    assert np.ptp(dev) > 0.002  # it does vary
    assert p.size == pytest.approx(20 * 15, abs=3)


def test_interference_components():
    fs, n = 50_000.0, 100_000
    t = np.arange(n) / fs
    revs = 20.0 * t
    rng = np.random.default_rng(0)
    m = motor_harmonics(t, speed=20.0, pole_pairs=2, slip=0.04, rng=rng)
    spec = np.abs(np.fft.rfft(m))
    f_peak = np.fft.rfftfreq(n, 1 / fs)[np.argmax(spec)]
    assert f_peak == pytest.approx(2 * 2 * 20.0 / 0.96, abs=0.5)  # 2 x electrical
    assert rms(m) == pytest.approx(1.0)
    e = extra_shaft(revs, order=1.37, rng=rng)
    spec = np.abs(np.fft.rfft(e))
    assert np.fft.rfftfreq(n, 1 / fs)[np.argmax(spec)] == pytest.approx(1.37 * 20, abs=0.5)
    b = bearing_impacts(revs, fs, order=4.3, frequency=5000.0, rng=rng)
    assert rms(b) == pytest.approx(1.0)
    # about 4.3 impacts per revolution: the envelope spectrum peaks at 4.3 x 20 Hz
    env = np.abs(hilbert(b))
    es = np.abs(np.fft.rfft(env - env.mean()))
    ef = np.fft.rfftfreq(n, 1 / fs)
    band = (ef > 30) & (ef < 300)
    assert ef[band][np.argmax(es[band])] == pytest.approx(4.3 * 20, abs=2.0)
    # ringing at the resonance
    assert np.fft.rfftfreq(n, 1 / fs)[np.argmax(np.abs(np.fft.rfft(b)))] == pytest.approx(
        5000.0, rel=0.05)
    x = np.sin(2 * np.pi * 100 * t)
    noisy = add_noise(x, snr_db=20.0, rng=rng)
    assert 20 * np.log10(rms(x) / rms(noisy - x)) == pytest.approx(20.0, abs=0.2)


def test_transfer_path_stretch_and_attenuation():
    f = np.linspace(0.0, 1000.0, 1001)
    h = np.where(f < 500, 1.0, 0.1).astype(complex)  # step: 0-500 Hz -> 0-12.5 kHz
    fir = path_fir(TransferFunction(f, h), 50_000.0, attenuation_db=10.0)
    t = np.arange(50_000) / 50_000.0
    gain = 10 ** (-10 / 20) / np.sqrt(np.mean(np.abs(h) ** 2))
    lo = apply_path(np.sin(2 * np.pi * 5000 * t), fir)[5000:]
    hi = apply_path(np.sin(2 * np.pi * 20000 * t), fir)[5000:]
    assert rms(lo) / np.sqrt(0.5) == pytest.approx(gain, rel=0.02)
    assert rms(hi) / np.sqrt(0.5) == pytest.approx(0.1 * gain, rel=0.05)
    noise = np.random.default_rng(1).standard_normal(400_000)
    out = apply_path(noise, fir)[20_000:]
    assert 20 * np.log10(rms(noise) / rms(out)) == pytest.approx(10.0, abs=0.5)


def test_fault_shows_in_sa_at_all_four_paper_conditions(any_rig):
    for speed in (15.0, 30.0):
        for load in (5.0, 10.0):
            levels = [diff_rms(sa_of(any_rig.record(speed=speed, load=load, fault_size=y,
                                                duration=8.0)))
                      for y in (0.32, 0.56, 0.66)]
            if any_rig.engine == "surrogate":
                # the crude stand-in separates small from large faults, not 0.56 from 0.66
                assert levels[0] < min(levels[1:]), (speed, load, levels)
            else:
                assert levels[0] < levels[1] < levels[2], (speed, load, levels)


def test_skipping_angular_resampling_degrades_rig_sa(rig):
    rec = rig.record(speed=15.0, load=10.0, fault_size=0.66, duration=30.0)
    good = sa_of(rec)
    bad = sa_of(rec, resample=False)
    mesh = lambda sa: float(np.sqrt(np.mean(harmonic_signal(sa, ZG) ** 2)))  # noqa: E731
    assert mesh(bad) < 0.7 * mesh(good)
    # segment-to-segment consistency also drops
    spread = lambda sa: float(np.std(sa, axis=0).mean() / np.std(sa))  # noqa: E731
    assert spread(bad) > 1.5 * spread(good)


def nominal_sa(engine, speed, load, seed):
    """SA of the nominal model: the engine with reality=None, constant speed and load,
    no interference, transfer path or noise."""
    fs = 50_000.0
    t = np.arange(int(8.0 * fs)) / fs
    revs = speed * t
    vib = ENGINES[engine]()(motor_revs=revs, load_torque=np.full(t.size, load), fs=fs,
                            fault_size=0.0, reality=None, rng=np.random.default_rng(seed))
    skip = int(fs) // 4  # drop the start-up transient
    rec = Recording(vib[skip:], tacho_signal(revs[skip:]), fs, tacho_pulses_per_rev=1)
    return sa_of(rec)[0]


def order_spectrum(sa):
    """RMS-normalized order amplitude spectrum (insensitive to circular shifts)."""
    s = np.abs(np.fft.rfft(sa, axis=-1))[..., 1:400]
    return s / np.sqrt(np.mean(s ** 2, axis=-1, keepdims=True))


def test_reality_gap_exceeds_recording_spread(any_rig):
    speed, load = 15.0, 10.0
    rig_sas = np.stack([sa_of(any_rig.record(speed=speed, load=load, duration=8.0,
                                             repetition=r))[0] for r in range(3)])
    nominal = nominal_sa(any_rig.engine, speed, load, seed=5)
    # level: the rig's transfer path and true parameters change the level by far more
    # than the repetitions differ
    lvl_rig = np.sqrt(np.mean(rig_sas ** 2, axis=-1))
    lvl_nom = np.sqrt(np.mean(nominal ** 2))
    assert abs(np.log(lvl_rig.mean() / lvl_nom)) > 5 * np.std(np.log(lvl_rig))
    # shape: RMS-normalized order spectra
    spec_rig, spec_nom = order_spectrum(rig_sas), order_spectrum(nominal)
    spread = np.mean([np.linalg.norm(a - b) for i, a in enumerate(spec_rig)
                      for b in spec_rig[i + 1:]])
    gap = np.mean([np.linalg.norm(a - spec_nom) for a in spec_rig])
    assert gap > 3 * spread, (gap, spread)


# ----------------------------------------------------------------------------- campaigns
def test_campaign_writes_recordings_and_index(tmp_path, rig):
    df = rig.campaign(tmp_path, speed=30.0, load=5.0, duration=0.3, healthy=2,
                      sizes=(0.32, 0.66), repetitions=1, progress=False)
    assert list(df.columns) == INDEX_COLUMNS and len(df) == 4
    assert df["fault_size"].tolist() == [0.0, 0.0, 0.32, 0.66]
    assert df["repetition"].tolist() == [0, 1, 0, 0]
    for row in df.itertuples():
        rec = Recording.read(row.path)
        assert (rec.speed, rec.load, rec.fault_size) == (30.0, 5.0, row.fault_size)
        assert rec.extras["repetition"] == row.repetition
        ref = rig.record(speed=30.0, load=5.0, fault_size=row.fault_size, duration=0.3,
                         repetition=row.repetition)
        np.testing.assert_allclose(rec.acceleration, ref.acceleration, rtol=1e-6,
                                   atol=1e-6 * np.abs(ref.acceleration).max())
    pd.testing.assert_frame_equal(read_campaign(tmp_path), df)
    # a second condition is added to the index; re-running one replaces its rows
    rig.campaign(tmp_path, speed=15.0, load=5.0, duration=0.3, healthy=1, sizes=(),
                 repetitions=0, progress=False)
    rig.campaign(tmp_path, speed=30.0, load=5.0, duration=0.3, healthy=1, sizes=(0.5,),
                 repetitions=1, progress=False)
    idx = read_campaign(tmp_path)
    assert sorted(zip(idx["speed"], idx["fault_size"])) == [(15.0, 0.0), (30.0, 0.0),
                                                            (30.0, 0.5)]
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


class _FailingEngine:
    def __init__(self, fail_at):
        self.calls, self.fail_at = 0, fail_at

    def __call__(self, **kw):
        self.calls += 1
        if self.calls == self.fail_at:
            raise RuntimeError("engine blew up")
        return SurrogateEngine()(**kw)


def test_failed_campaign_leaves_no_partial_file(tmp_path):
    ok = VirtualRig(seed=0)
    ok.campaign(tmp_path, speed=30.0, load=5.0, duration=0.2, healthy=1, sizes=(),
                repetitions=0, progress=False)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    bad = VirtualRig(seed=0, engine=_FailingEngine(fail_at=3))
    with pytest.raises(RuntimeError, match="blew up"):
        bad.campaign(tmp_path, speed=15.0, load=10.0, duration=0.2, healthy=2,
                     sizes=(0.5,), repetitions=2, progress=False)
    after = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    assert after == before  # nothing new, index untouched, no staging folder


def test_campaign_files_go_into_place_through_the_atomic_writer(tmp_path, monkeypatch):
    """The recordings, then the index last, are moved by ``_atomic.commit_staged``."""
    from gearshot import _atomic

    calls = []

    def spy(staging, folder, names):
        calls.append((Path(folder), list(names), sorted(p.name for p in Path(staging).iterdir())))
        _atomic.commit_staged(staging, folder, names)

    monkeypatch.setattr("gearshot.rig.virtual.commit_staged", spy)
    df = VirtualRig(seed=0, engine="surrogate").campaign(
        tmp_path, speed=15.0, load=5.0, duration=0.2, healthy=1, sizes=(0.5,),
        repetitions=1, progress=False)
    names = [Path(p).name for p in df["path"]]
    assert calls == [(tmp_path, [*names, "index.csv"], sorted([*names, "index.csv"]))]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([*names, "index.csv"])


def test_commit_staged_moves_in_order_and_names_a_failed_destination(tmp_path):
    from gearshot._atomic import commit_staged, staging_dir

    folder = tmp_path / "camp"
    with staging_dir(folder) as stage:
        for name in ("a.h5", "index.csv"):
            (stage / name).write_text(name)
        commit_staged(stage, folder, ["a.h5", "index.csv"])
        assert not list(stage.iterdir())
    assert {p.name: p.read_text() for p in folder.iterdir()} == {"a.h5": "a.h5",
                                                                 "index.csv": "index.csv"}
    (folder / "b.h5").mkdir()                      # a folder where a file must go
    with pytest.raises(GearshotError, match=r"cannot write .*b\.h5"):
        with staging_dir(folder) as stage:
            (stage / "b.h5").write_text("b")
            (stage / "index.csv").write_text("new")
            commit_staged(stage, folder, ["b.h5", "index.csv"])
    assert (folder / "index.csv").read_text() == "index.csv"   # the index is not replaced
    assert sorted(p.name for p in folder.iterdir()) == ["a.h5", "b.h5", "index.csv"]


def test_bad_engine_and_bad_arguments(tmp_path):
    rig = VirtualRig(seed=0, engine=lambda **kw: np.zeros(10))
    with pytest.raises(GearshotError, match="engine returned shape"):
        rig.record(speed=15.0, load=5.0, duration=0.1)
    rig = VirtualRig(seed=0)
    with pytest.raises(GearshotError, match="fault_size"):
        rig.record(speed=15.0, load=5.0, fault_size=1.5, duration=0.1)
    with pytest.raises(GearshotError, match="speed"):
        rig.record(speed=-1.0, load=5.0, duration=0.1)
    with pytest.raises(GearshotError, match="no recording"):
        rig.campaign(tmp_path, speed=15.0, load=5.0, healthy=0, sizes=(), progress=False)
    with pytest.raises(GearshotError, match="seed"):
        VirtualRig(seed=-3).reveal()
    with pytest.raises(GearshotError, match="no campaign index"):
        read_campaign(tmp_path)


def test_tf_bank_from_measured_frf_folder():
    folder = SHARED / "data" / "frf"
    if not folder.is_dir():
        pytest.skip(f"shared FRF folder not found at {folder}")
    rig = VirtualRig(seed=2, tf_bank=folder)
    rec = rig.record(speed=15.0, load=5.0, duration=0.5)
    assert rig.reveal_path()[0] in {p.stem for p in folder.glob("*.uff")}
    assert "transfer_path" not in rec.extras
    assert np.all(np.isfinite(rec.acceleration))


def test_forced_grade_and_with_reality():
    base = VirtualRig(seed=0)
    assert VirtualRig(seed=0, grade=11).reveal().grade == 11
    loud = base.with_reality(attenuation_db=0.0, snr_db=60.0)
    r = loud.reveal()
    assert (r.attenuation_db, r.snr_db) == (0.0, 60.0)
    assert r.grade == base.reveal().grade and r.mass_factor == base.reveal().mass_factor
    a = base.record(speed=30.0, load=5.0, duration=0.5)
    b = loud.record(speed=30.0, load=5.0, duration=0.5)
    gain = 10 ** ((base.reveal().attenuation_db - 0.0) / 20)
    assert rms(b.acceleration) / rms(a.acceleration) == pytest.approx(gain, rel=0.1)
    with pytest.raises(GearshotError, match="no field 'colour'"):
        base.with_reality(colour=3)
    with pytest.raises(GearshotError, match="grade must be <= 12"):
        VirtualRig(seed=0, grade=13).reveal()
    with pytest.raises(GearshotError, match="snr_db must lie in"):
        base.with_reality(snr_db=-5.0)


def test_irregular_face_fault_hooks():
    from gearshot.rig import IrregularFaceFault
    from gearshot.sim import FullToothFaceFault, GearPair

    pair = GearPair.paper()
    arc = FullToothFaceFault(size=0.5, center=0.5, depth=0.5)
    rough = IrregularFaceFault(size=0.5, center=0.5, depth=0.5, roughness=(0.3, -0.2))
    s = np.linspace(0.0, 1.0, 401)
    d_arc, d_rough = arc.displacement(pair, s), rough.displacement(pair, s)
    outside = (s < 0.25) | (s > 0.75)
    assert np.all(d_rough[outside] == 0) and np.all(d_arc[outside] == 0)
    inside = ~outside & (d_arc != 0)
    ratio = d_rough[inside] / d_arc[inside]
    np.testing.assert_allclose(ratio, rough.depth_profile(s[inside]))
    assert ratio.min() < 0.8 and ratio.max() > 1.05  # not a scaled arc
    x = np.linspace(0.05, 0.12, 300)
    loss_arc, loss_rough = arc.section_loss(pair, x), rough.section_loss(pair, x)
    assert np.all((loss_rough > 0) == (loss_arc > 0)) and np.any(loss_arc > 0)
    assert not np.allclose(loss_rough, loss_arc)
    with pytest.raises(GearshotError, match="roughness"):
        IrregularFaceFault(size=0.5, roughness=(0.7, 0.5))
