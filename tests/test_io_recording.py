"""Recording I/O: round trips through every format, channel selection, bad files."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pytest
import scipy.io
import scipy.io.wavfile
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gearshot import GearshotError
from gearshot.io import Recording
from gearshot.rig import tacho_signal

FS = 20_000.0


def make_recording(duration=1.0, *, tacho=True, seed=0, **meta):
    rng = np.random.default_rng(seed)
    n = int(duration * FS)
    revs = 15.0 * np.arange(n) / FS
    acc = rng.normal(0.0, 0.3, n) + np.sin(2 * np.pi * 17 * revs)
    tac = tacho_signal(revs) if tacho else None
    kw = dict(speed=15.0, load=10.0, fault_size=0.56, units="g", source="unit test",
              extras={"rig": "A", "repetition": 3, "tf": [1.5, 2.5], "nested": {"k": None}})
    kw.update(meta)
    return Recording(acc, tac, FS, **kw)


FORMAT_CASES = [  # (file name, write kwargs, absolute tolerance on values)
    ("r.h5", {}, 0.0),
    ("r32.h5", {"dtype": "float32"}, 1e-6),
    ("r5.mat", {}, 0.0),
    ("r73.mat", {"format": "mat73"}, 0.0),
    ("rf.wav", {}, 1e-6),
    ("r16.wav", {"dtype": "int16"}, 1e-4),
    ("r32.wav", {"dtype": "int32"}, 1e-8),
    ("r.csv", {}, 0.0),
]


@pytest.mark.parametrize("name,kwargs,atol", FORMAT_CASES, ids=[c[0] for c in FORMAT_CASES])
def test_round_trip_every_format(tmp_path, name, kwargs, atol):
    rec = make_recording()
    path = rec.write(tmp_path / name, **kwargs)
    back = Recording.read(path)
    scale = np.max(np.abs(rec.acceleration))
    np.testing.assert_allclose(back.acceleration, rec.acceleration, rtol=0, atol=atol * scale)
    np.testing.assert_allclose(back.tacho, rec.tacho, rtol=0, atol=atol * 5.0)
    assert back.fs == rec.fs
    assert back.metadata == rec.metadata
    assert back.origin == str(path)
    # no temporary files left behind
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [name] + ([name + ".json"] if name.endswith(".wav") else []))


@pytest.mark.parametrize("name,kwargs", [("a.h5", {}), ("a.mat", {}),
                                         ("b.mat", {"format": "mat73"}), ("a.wav", {}),
                                         ("a.csv", {})])
def test_round_trip_without_tacho_and_unknown_metadata(tmp_path, name, kwargs):
    rec = Recording(np.arange(100.0), None, 1000.0)
    back = Recording.read(rec.write(tmp_path / name, **kwargs))
    np.testing.assert_allclose(back.acceleration, rec.acceleration, atol=1e-5)
    assert back.tacho is None
    assert back.speed is None and back.load is None and back.fault_size is None
    assert back.metadata == rec.metadata


def test_mat73_is_hdf5_with_matlab_header(tmp_path):
    path = make_recording().write(tmp_path / "x.mat", format="mat73")
    head = path.read_bytes()[:128]
    assert head.startswith(b"MATLAB 7.3 MAT-file")
    assert head[126:128] == b"IM"
    with h5py.File(path, "r") as f:
        assert f["acceleration"].attrs["MATLAB_class"] == b"double"
        assert f["acceleration"].shape == (int(FS), 1)  # MATLAB 1 x n, dims reversed


def test_foreign_mat_v5_matrix_channels_and_names(tmp_path):
    rng = np.random.default_rng(1)
    data = rng.normal(size=(3, 500))
    path = tmp_path / "lab.mat"
    scipy.io.savemat(path, {"Fs": 25600.0, "data": data.T, "RPM": 900.0})
    rec = Recording.read(path, accel="data[2]", tacho="data[0]")
    assert rec.fs == 25600.0
    np.testing.assert_allclose(rec.acceleration, data[2])
    np.testing.assert_allclose(rec.tacho, data[0])
    rec = Recording.read(path, accel=1, tacho=False, metadata={"speed": 15.0, "RPM": 900})
    np.testing.assert_allclose(rec.acceleration, data[1])
    assert rec.speed == 15.0 and rec.extras == {"RPM": 900}


def test_wav_channel_selection_by_index_and_name(tmp_path):
    rng = np.random.default_rng(2)
    data = rng.uniform(-0.9, 0.9, size=(400, 3)).astype(np.float32)
    path = tmp_path / "three.wav"
    scipy.io.wavfile.write(path, 48000, data)
    rec = Recording.read(path, accel=2, tacho=0)
    np.testing.assert_allclose(rec.acceleration, data[:, 2])
    np.testing.assert_allclose(rec.tacho, data[:, 0])
    assert rec.fs == 48000.0
    rec = Recording.read(path, accel="mic", tacho="key", channels=["key", "junk", "mic"])
    np.testing.assert_allclose(rec.acceleration, data[:, 2])
    rec = Recording.read(path, accel="acc", tacho="tacho", channels={"acc": 1, "tacho": 0})
    np.testing.assert_allclose(rec.acceleration, data[:, 1])
    # names from a sidecar
    (tmp_path / "three.wav.json").write_text(json.dumps({"channels": ["tach", "x", "acc"]}))
    rec = Recording.read(path)
    np.testing.assert_allclose(rec.acceleration, data[:, 2])
    np.testing.assert_allclose(rec.tacho, data[:, 0])


def test_csv_by_header_name_with_time_column(tmp_path):
    t = np.arange(300) / 1000.0
    acc = np.cos(t * 50)
    tac = (np.mod(t * 10, 1) < 0.1).astype(float)
    path = tmp_path / "lab.csv"
    with open(path, "w") as fh:
        fh.write("# exported by some DAQ\nTime, Tach , Accel_Y\n")
        for row in zip(t, tac, acc):
            fh.write(",".join(f"{v:.15g}" for v in row) + "\n")
    rec = Recording.read(path, accel="Accel_Y", tacho="Tach")
    assert rec.fs == pytest.approx(1000.0, rel=1e-9)
    np.testing.assert_allclose(rec.acceleration, acc)
    rec = Recording.read(path, accel=2, tacho=1)  # column indices, time column included
    np.testing.assert_allclose(rec.tacho, tac)
    with pytest.raises(GearshotError, match="conflicts"):
        Recording.read(path, accel=2, fs=2000.0)


# ----------------------------------------------------------------------------- bad input
def test_unknown_channel_names_file_and_parameter(tmp_path):
    path = make_recording().write(tmp_path / "r.h5")
    with pytest.raises(GearshotError, match=r"r\.h5.*accel='nope'.*available"):
        Recording.read(path, accel="nope")
    with pytest.raises(GearshotError, match=r"r\.h5.*tacho=7 is out of range"):
        Recording.read(path, tacho=7)
    wav = make_recording().write(tmp_path / "r.wav")
    with pytest.raises(GearshotError, match=r"r\.wav.*channels=.*3 channel"):
        Recording.read(wav, channels=["a", "b", "c"])


def test_missing_fs_and_wrong_fs(tmp_path):
    path = tmp_path / "nofs.csv"
    path.write_text("acc,tacho\n1,0\n2,1\n3,0\n")
    with pytest.raises(GearshotError, match=r"nofs\.csv.*does not state its sampling rate"):
        Recording.read(path)
    assert Recording.read(path, fs=100.0).fs == 100.0
    with pytest.raises(GearshotError, match="fs must be a finite positive"):
        Recording.read(path, fs=-3.0)
    h5 = make_recording().write(tmp_path / "r.h5")
    with pytest.raises(GearshotError, match=r"fs=40000.0 conflicts.*r\.h5"):
        Recording.read(h5, fs=40000.0)
    with pytest.raises(GearshotError, match="fs must be > 0"):
        Recording(np.zeros(10), None, 0.0)


def test_empty_tacho_channel(tmp_path):
    path = tmp_path / "e.mat"
    scipy.io.savemat(path, {"fs": 1000.0, "acceleration": np.ones(50), "tacho": np.zeros(0)})
    with pytest.raises(GearshotError):
        # an empty MATLAB variable is not a channel: naming it explicitly fails loudly
        Recording.read(path, tacho="tacho")
    path = tmp_path / "e.h5"
    with h5py.File(path, "w") as f:
        f.attrs["fs"] = 1000.0
        f["acceleration"] = np.ones(50)
        f["tacho"] = np.zeros(0)
    with pytest.raises(GearshotError, match=r"e\.h5"):
        Recording.read(path, tacho="tacho")


@pytest.mark.parametrize("name,kwargs", [("r.h5", {}), ("r.mat", {}),
                                         ("r73.mat", {"format": "mat73"}), ("r.wav", {}),
                                         ("r.csv", {})])
def test_truncated_file(tmp_path, name, kwargs):
    path = make_recording().write(tmp_path / name, **kwargs)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(GearshotError, match=name.replace(".", r"\.")):
        Recording.read(path)


@pytest.mark.parametrize("name", ["x.h5", "x.mat", "x.wav", "x.csv"])
def test_corrupt_file(tmp_path, name):
    path = tmp_path / name
    path.write_bytes(np.random.default_rng(3).integers(0, 256, 4000, dtype=np.uint8).tobytes())
    with pytest.raises(GearshotError, match=name.replace(".", r"\.")):
        Recording.read(path)


def test_missing_file_and_unknown_suffix(tmp_path):
    with pytest.raises(GearshotError, match="does not exist"):
        Recording.read(tmp_path / "gone.h5")
    (tmp_path / "x.flac").write_bytes(b"")
    with pytest.raises(GearshotError, match="unknown recording format '.flac'"):
        Recording.read(tmp_path / "x.flac")


def test_failed_write_leaves_no_file(tmp_path):
    rec = Recording(np.zeros(10), None, 1000.5)
    with pytest.raises(GearshotError, match="integer sampling rate"):
        rec.write(tmp_path / "x.wav")
    with pytest.raises(GearshotError, match="dtype"):
        rec.write(tmp_path / "x.h5", dtype="int8")
    assert list(tmp_path.iterdir()) == []
    # an existing file is not clobbered by a failed write
    good = Recording(np.ones(10), None, 1000.0).write(tmp_path / "y.h5")
    with pytest.raises(GearshotError):
        rec.write(good, dtype="int8")
    assert Recording.read(good).acceleration.sum() == 10.0
    assert [p.name for p in tmp_path.iterdir()] == ["y.h5"]


def test_constructor_validation():
    with pytest.raises(GearshotError, match="tacho must have as many samples"):
        Recording(np.zeros(10), np.zeros(9), 100.0)
    with pytest.raises(GearshotError, match="fault_size must lie in"):
        Recording(np.zeros(10), None, 100.0, fault_size=1.5)
    with pytest.raises(GearshotError, match="tacho_shaft"):
        Recording(np.zeros(10), None, 100.0, tacho_shaft="left")
    with pytest.raises(GearshotError, match="JSON"):
        Recording(np.zeros(10), None, 100.0, extras={"f": object()})
    with pytest.raises(GearshotError, match="acceleration must be finite"):
        Recording(np.array([0.0, np.nan, 1.0]), None, 100.0)


@settings(max_examples=60, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(values=st.lists(st.floats(allow_nan=False, allow_infinity=False, width=64),
                       min_size=2, max_size=40),
       fs=st.floats(min_value=1e-3, max_value=1e7, allow_nan=False),
       speed=st.one_of(st.none(), st.floats(min_value=1e-6, max_value=1e4)),
       text=st.text(max_size=20),
       extra=st.dictionaries(st.text(min_size=1, max_size=8),
                             st.one_of(st.integers(-10**9, 10**9), st.text(max_size=8),
                                       st.booleans(), st.none()), max_size=4),
       fmt=st.sampled_from(["hdf5", "csv", "mat5", "mat73"]))
def test_round_trip_property(tmp_path, values, fs, speed, text, extra, fmt):
    acc = np.array(values)
    rec = Recording(acc, acc[::-1].copy(), fs, speed=speed, source=text, extras=extra)
    suffix = {"hdf5": ".h5", "csv": ".csv", "mat5": ".mat", "mat73": ".mat"}[fmt]
    back = Recording.read(rec.write(tmp_path / f"p{suffix}", format=fmt))
    np.testing.assert_array_equal(back.acceleration, rec.acceleration)
    np.testing.assert_array_equal(back.tacho, rec.tacho)
    assert back.fs == rec.fs and back.metadata == rec.metadata


def test_jittered_tacho_has_one_clean_pulse_per_revolution():
    """An early pulse must not be split at the integer angle (a double pulse)."""
    from gearshot.rig.tacho import tacho_signal
    from gearshot.signal import pulse_times

    fs = 50_000.0
    revs = 15.0 * np.arange(int(30 * fs)) / fs
    for seed in range(4):
        x = tacho_signal(revs, jitter=5e-3, rng=np.random.default_rng(seed))
        steps = np.diff(pulse_times(x, fs)) * 15.0  # revolutions between pulses
        assert steps.size in (448, 449, 450)
        assert steps.min() > 0.95 and steps.max() < 1.05


def test_a_tacho_recording_with_a_machine_without_tacho_uses_its_own_tacho():
    """A machine without [tacho] (speed from the vibration) and a recording that does
    carry a tacho: the tacho is used with the default trigger level (it once raised
    AttributeError looking up the machine's tacho threshold)."""
    from pathlib import Path

    from gearshot import Machine

    toml = Path(__file__).resolve().parents[1] / "examples/machines/phm09_spur_notacho.toml"
    m = Machine.from_toml(toml)
    assert m.tacho is None
    rec = make_recording(tacho_pulses_per_rev=1)
    plain = rec.pulse_times()
    with_machine = Recording(np.stack([rec.acceleration, rec.acceleration]), rec.tacho,
                             FS, speed=15.0, tacho_pulses_per_rev=1, machine=m,
                             tacho_shaft=m.reference_shaft)
    np.testing.assert_array_equal(with_machine.pulse_times(), plain)
    assert with_machine.speed_source == "tacho"
    assert abs(with_machine.shaft_speed() - 15.0) < 0.01
