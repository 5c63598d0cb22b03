"""Input health (issue #29, deliverable 1): every input case of the issue is refused or
marked, never a plain number that reads as healthy; real records pass.

Cases: an all-zero channel, a constant channel, the same record x1e30, NaN, a clipped
channel, 4 KB of flipped acceleration bytes in a native HDF5 file, the zero-tailed HDF5
file of the issue's recipe (refused, and never after more than the read budget), and
``indicators`` on zeroed accelerometers.
"""

from __future__ import annotations

import io
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from gearshot import GearshotError
from gearshot.io import Recording
from gearshot.io.input_health import (
    CHECKS,
    InputCheck,
    check_input,
    check_numeric,
    check_segments,
    input_check_column,
    mark_rows,
    require_ok,
)

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"
PHM = ROOT.parent / "shared" / "data" / "phm09"
SPUR = ROOT / "examples" / "machines" / "phm09_spur.toml"
sys.path.insert(0, str(Path(__file__).parent))
from estimator_data import synthetic_sa  # noqa: E402


def live(n=50_000, seed=0):
    """A live accelerometer-like signal in g: a mesh tone and noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / 50_000
    return 2.0 * np.sin(2 * np.pi * 570 * t) + 0.5 * rng.standard_normal(n)


# ------------------------------------------------------------------ the checks themselves
def test_a_live_signal_passes():
    res = check_input(live())
    assert res.ok and res.failed is None and res.label == "ok"


def test_all_zero_channel_is_dead():
    res = check_input(np.zeros(10_000))
    assert (res.failed, res.ok, res.label) == ("dead", False, "dead")
    # a disconnected channel's rounding noise, far below any sensor's floor, too
    assert check_input(1e-9 * live()).failed == "dead"


def test_constant_channel_is_constant():
    assert check_input(np.full(10_000, 0.35)).failed == "constant"
    assert check_input(2.5 + 1e-9 * live()).failed == "constant"   # stuck at a DC level


def test_record_times_1e30_is_an_implausible_level():
    res = check_input(live() * 1e30)
    assert res.failed == "implausible_level" and "g" in res.reason
    # the same bound in m/s^2: 9.81e5 m/s^2 is 1e5 g
    assert check_input(live() * 1e30, units="m/s^2").failed == "implausible_level"
    assert check_input(live(), units="m/s^2").ok


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_nan_and_inf_are_non_numeric(bad):
    x = live()
    x[123] = bad
    res = check_input(x)
    assert res.failed == "non_numeric" and "1 of" in res.reason
    assert check_numeric(x).failed == "non_numeric" and check_numeric(live()).ok
    assert check_input(np.array(["a", "b"])).failed == "non_numeric"
    assert check_input(live() + 0j).failed == "non_numeric"


def test_clipped_channel_is_clipped():
    x = live()
    rail = 0.5 * np.abs(x).max()   # a sensor range at half the peak
    res = check_input(np.clip(x, -rail, rail))
    assert res.failed == "clipped" and "flat tops" in res.reason
    # the averaged (SA) variant does not look for flat tops
    assert check_segments(np.clip(x, -rail, rail)[None], kind="sa")[0].ok
    assert not check_segments(np.clip(x, -rail, rail)[None], kind="raw")[0].ok


def test_unknown_units_keep_the_unit_free_checks():
    """Volts or counts: no level bound, but zeros and constants are still refused."""
    assert check_input(live() * 1e30, units="V").ok
    assert check_input(np.zeros(100), units="V").failed == "dead"
    assert check_input(np.full(100, 3.0), units="counts").failed == "constant"


def test_multichannel_names_the_channel():
    res = check_input(np.stack([live(), np.zeros(50_000)]))
    assert res.failed == "dead" and res.reason.startswith("channel 1:")


def test_bad_shape_is_a_gearshot_error():
    for bad in (np.zeros((2, 2, 2)), np.zeros(0)):
        with pytest.raises(GearshotError, match="acceleration must be a non-empty"):
            check_input(bad)
    with pytest.raises(GearshotError, match="kind must be 'sa' or 'raw'; got 'x'"):
        check_segments(np.zeros((2, 4)), kind="x")


def test_segment_checks_and_the_column():
    sas = np.stack([live(2048, 1), np.zeros(2048), live(2048, 2) * 1e30, live(2048, 3)])
    seg = check_segments(sas)
    assert [s.label for s in seg] == ["ok", "dead", "implausible_level", "ok"]
    assert input_check_column(InputCheck(), seg) == ["ok", "dead", "implausible_level", "ok"]
    assert input_check_column(InputCheck(), seg, rows=[3, 1]) == ["ok", "dead"]
    # a recording that fails marks every one of its rows
    assert input_check_column(InputCheck("clipped", "x"), seg) == ["clipped"] * 4
    assert set(CHECKS) >= {s.failed for s in seg if s.failed}


def test_mark_rows_withdraws_the_failed_estimates():
    import pandas as pd

    frame = pd.DataFrame(dict(predicted=[0.3, 0.29, 0.4], low=[0.1, 0.1, 0.2],
                              high=[0.5, 0.5, 0.6]))
    mark_rows(frame, ["ok", "dead", "ok"])
    assert frame["input_check"].tolist() == ["ok", "dead", "ok"]
    assert np.isnan(frame.loc[1, ["predicted", "low", "high"]].astype(float)).all()
    assert frame.loc[[0, 2], "predicted"].tolist() == [0.3, 0.4]


def test_require_ok_is_one_line_naming_file_role_and_check():
    require_ok(InputCheck(), "a.h5", "healthy")
    with pytest.raises(GearshotError) as err:
        require_ok(check_input(np.zeros(10)), "/x/h1.h5", "healthy")
    msg = str(err.value)
    assert "'/x/h1.h5' (healthy) fails the input check 'dead'" in msg and "\n" not in msg


# ------------------------------------------------------------------ real records pass
@pytest.mark.parametrize("name", ["spur3_30hz_High_1.zip", "spur2_40hz_Low_2.zip"])
def test_real_phm09_records_pass(name):
    """A development (run 1) and a held-out (run 2) PHM09 record: both channels, raw and
    every SA segment, pass."""
    from gearshot import Machine
    from gearshot.app.predict_machine import machine_segments

    if not (PHM / name).is_file():
        pytest.skip(f"{PHM / name} is absent; real-data checks need ../shared/data/phm09")
    machine = Machine.from_toml(SPUR)
    rec = Recording.read(PHM / name, machine=machine)
    assert check_input(rec.acceleration, units="g").ok
    for sensor in ("acc_input", "acc_output"):
        info: dict = {}
        sa, _, _ = machine_segments(PHM / name, machine, cycles_per_segment=10,
                                    sensor=sensor, info=info)
        assert info["recording"].ok and len(info["segments"]) == len(sa) > 10
        assert all(c.ok for c in info["segments"])


# ------------------------------------------------------------------ files: damaged bytes
def _write(tmp_path, name="r.h5", n=200_000):
    rec = Recording(live(n), np.zeros(n), 50_000.0, speed=15.0)
    return rec.write(tmp_path / name)


def test_native_hdf5_carries_a_digest_of_the_acceleration(tmp_path):
    import h5py

    from gearshot.io._format_hdf5 import samples_digest

    path = _write(tmp_path)
    with h5py.File(path) as f:
        assert f["acceleration"].attrs["sha256"] == samples_digest(f["acceleration"][()])
    assert np.array_equal(Recording.read(path).acceleration, live(200_000))


def test_flipped_acceleration_bytes_are_refused(tmp_path):
    """4 KB of flipped bits inside /acceleration: refused naming the file and the check."""
    import h5py

    path = _write(tmp_path)
    with h5py.File(path) as f:
        start = f["acceleration"].id.get_offset() + 400_000
    data = bytearray(path.read_bytes())
    data[start:start + 4096] = bytes(b ^ 0xFF for b in data[start:start + 4096])
    path.write_bytes(bytes(data))
    with pytest.raises(GearshotError) as err:
        Recording.read(path)
    msg = str(err.value)
    assert str(path) in msg and "damaged_bytes" in msg and "SHA-256" in msg
    assert "\n" not in msg


def test_nan_in_a_file_is_refused_at_read_naming_the_check(tmp_path):
    import h5py

    x = live(10_000)
    x[5] = np.nan
    path = tmp_path / "generic.h5"
    with h5py.File(path, "w") as f:
        f["acceleration"] = x
        f.attrs["fs"] = 50_000.0
    with pytest.raises(GearshotError, match=r"generic\.h5' fails the input check "
                                            r"'non_numeric': 1 of 10000 samples"):
        Recording.read(path, tacho=False)


@pytest.fixture(scope="module")
def zero_tail(tmp_path_factory):
    """The issue's recipe: a VirtualRig(seed=3) recording, bytes from 2249 on zeroed."""
    from gearshot.rig import VirtualRig

    folder = tmp_path_factory.mktemp("zero_tail")
    VirtualRig(seed=3).campaign(folder, speed=15, load=10, duration=4, healthy=1, sizes=(),
                                repetitions=1, progress=False)
    (good,) = sorted(folder.glob("*.h5"))
    data = good.read_bytes()
    bad = folder / "zero_tail.h5"
    bad.write_bytes(data[:2249] + bytes(len(data) - 2249))
    return good, bad


def test_zero_tail_recipe_is_refused_within_its_budget(zero_tail):
    """In a child process bounded by the README's budget (20 s + 1 s/MB): the read must
    end there with a GearshotError naming the file and the check (it hung > 2 min)."""
    from gearshot.io.recording import READ_BUDGET_S

    good, bad = zero_tail
    budget = READ_BUDGET_S + bad.stat().st_size / 1e6
    code = ("import sys\nfrom gearshot import GearshotError\nfrom gearshot.io import "
            "Recording\ntry:\n    Recording.read(sys.argv[1])\nexcept GearshotError as e:\n"
            "    print('refused:', e)\n")
    res = subprocess.run([sys.executable, "-c", code, str(bad)], capture_output=True,
                         text=True, timeout=budget, env={"PYTHONPATH": str(SRC)})
    assert res.returncode == 0, res.stderr
    line = res.stdout.strip()
    assert line.startswith("refused:") and str(bad) in line and "damaged_bytes" in line
    assert check_input(Recording.read(good).acceleration).ok   # the recording itself is fine


def test_zero_tail_heap_walk_names_the_bytes(zero_tail):
    from gearshot.io._format_hdf5 import check_heaps

    good, bad = zero_tail
    check_heaps(good)
    with pytest.raises(GearshotError, match=r"global heap at byte \d+ holds an empty object"):
        check_heaps(bad)


# ------------------------------------------------------------------ predict
def _fake_simulate_sa(pair, *, speed, load, grade, fault_sizes, n_points, rng,
                      fault_type="ftff"):
    """Stands in for the simulator: the estimator tests' synthetic SAs, one per seed."""
    return np.vstack([synthetic_sa([y], grade, np.random.default_rng(s))
                      for y, s in zip(fault_sizes, rng)])


def _fake_simulate_sa_paired(pair, **kw):
    sa = _fake_simulate_sa(pair, **kw)
    twins = _fake_simulate_sa(pair, **{**kw, "fault_sizes": np.zeros(len(sa))})
    return sa, twins


@pytest.fixture(scope="module")
def fit_files(tmp_path_factory, zero_tail):
    """A small database (synthetic SAs) and virtual-rig recordings at 15 rps, 10 N m."""
    from gearshot.rig import VirtualRig
    from gearshot.sim import build_database

    folder = tmp_path_factory.mktemp("fit")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr("gearshot.sim.database.simulate_sa", _fake_simulate_sa)
        mp.setattr("gearshot.sim.database.simulate_sa_paired", _fake_simulate_sa_paired)
        build_database(folder / "db", speeds=[15], loads=[10], grades=[7], n_healthy=12,
                       n_faulty=24, seed=3, client=False, progress=False)
    idx = VirtualRig(seed=1, engine="surrogate").campaign(
        folder / "camp", speed=15, load=10, duration=8.0, healthy=2, sizes=(0.5,),
        repetitions=1, progress=False)
    paths = idx["path"].tolist()   # two healthy, one faulty
    good = Recording.read(paths[1])
    tests = {}
    for case, acc in (("zero", np.zeros_like(good.acceleration)),
                      ("constant", np.full_like(good.acceleration, 0.35)),
                      ("times_1e30", good.acceleration * 1e30)):
        rec = Recording(acc, good.tacho, good.fs, speed=good.speed, load=good.load)
        tests[case] = rec.write(folder / f"{case}.h5")
    return folder / "db", paths, tests


@pytest.mark.parametrize("case, check", [("zero", "dead"), ("constant", "constant"),
                                         ("times_1e30", "implausible_level")])
def test_predict_marks_every_row_of_a_failed_test_recording(fit_files, case, check):
    from gearshot.app.predict import input_check_summary, predict_from_files

    db, paths, tests = fit_files
    frame = predict_from_files(db, paths[:2], paths[2], 0.5, [paths[1], tests[case]],
                               speed=15, load=10)
    bad = frame[frame["recording"] == str(tests[case])]
    good = frame[frame["recording"] != str(tests[case])]
    assert len(bad) >= 1 and (bad["input_check"] == check).all()
    assert bad[["predicted", "low", "high"]].isna().all().all()   # no number at all
    assert (good["input_check"] == "ok").all() and good["predicted"].notna().all()
    line = input_check_summary(frame)
    assert f"failed for {len(bad)} ({check} {len(bad)})" in line and "no estimate" in line


def test_predict_refuses_a_failed_fit_recording(fit_files, zero_tail):
    from gearshot.app.predict import predict_from_files

    db, paths, tests = fit_files
    with pytest.raises(GearshotError) as err:
        predict_from_files(db, [tests["zero"]], paths[2], 0.5, [paths[1]], speed=15, load=10)
    assert f"'{tests['zero']}' (healthy) fails the input check 'dead'" in str(err.value)
    with pytest.raises(GearshotError, match=r"\(faulty\) fails the input check "
                                            r"'implausible_level'"):
        predict_from_files(db, paths[:1], tests["times_1e30"], 0.5, [paths[1]], speed=15,
                           load=10)
    # the zero-tail recipe among the recordings: refused before any fit
    with pytest.raises(GearshotError, match=r"zero_tail\.h5.*damaged_bytes"):
        predict_from_files(db, paths[:1], paths[2], 0.5, [zero_tail[1]], speed=15, load=10)


def test_cli_predict_zero_tail_is_one_line(fit_files, zero_tail, tmp_path):
    db, paths, _ = fit_files
    res = subprocess.run(
        [sys.executable, "-m", "gearshot.app.cli", "predict", "--database", str(db),
         "--healthy", paths[0], "--faulty", paths[2], "--faulty-size", "0.5",
         "--recordings", str(zero_tail[1]), "--speed", "15", "--load", "10",
         "--out", str(tmp_path / "p.csv")], capture_output=True, text=True, timeout=120,
        env={"PYTHONPATH": str(SRC), "GEARSHOT_DATA": str(tmp_path / "home")})
    err = res.stderr.strip()
    assert res.returncode == 2 and len(err.splitlines()) == 1, err
    assert err.startswith("gearshot: error:") and "zero_tail.h5" in err
    assert "damaged_bytes" in err and not (tmp_path / "p.csv").exists()


# ------------------------------------------------------------------ machine path, indicators
def _zeroed_copy(name: str, folder: Path, columns=(0,), rows: int = 100_000) -> Path:
    """A zipped copy of a PHM09 record (first ``rows`` rows) with ``columns`` set to 0."""
    src = PHM / name
    if not src.is_file():
        pytest.skip(f"{src} is absent; real-data checks need ../shared/data/phm09")
    with zipfile.ZipFile(src) as zf:
        member = zf.namelist()[0]
        table = np.loadtxt(io.BytesIO(zf.read(member)), max_rows=rows)
    table[:, list(columns)] = 0.0
    buf = io.StringIO()
    np.savetxt(buf, table, fmt="%.6g")
    out = folder / name
    with zipfile.ZipFile(out, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        zf.writestr(member, buf.getvalue())
    return out


def test_indicators_on_zeroed_accelerometer_are_null_with_the_check(tmp_path):
    """A zeroed acc_input writes no indicator (they would be 0/0), names the check; the
    live acc_output of the same file keeps its numbers."""
    from gearshot import Machine
    from gearshot.app.indicators import format_indicators, indicator_table, record_indicators

    path = _zeroed_copy("spur3_30hz_High_1.zip", tmp_path)
    payload = record_indicators([path], Machine.from_toml(SPUR), shaft="input")
    rec = {r["sensor"]: r for r in payload["records"]}
    assert rec["acc_input"]["input_check"] == "dead"
    assert all(v is None for v in rec["acc_input"]["indicators"].values())
    assert rec["acc_output"]["input_check"] == "ok"
    assert all(np.isfinite(v) for v in rec["acc_output"]["indicators"].values())
    assert "dead" in format_indicators(payload) and "null" in format_indicators(payload)
    assert indicator_table(payload)["input_check"].tolist() == ["dead", "ok"]


def test_machine_predict_refuses_a_dead_healthy_recording(tmp_path):
    """The machine path's segments carry the sensor's checks; a fit recording that fails
    is refused in one line naming file and check (before any database is read)."""
    from gearshot import Machine
    from gearshot.app.predict_machine import _segment_recordings

    path = _zeroed_copy("spur3_30hz_High_1.zip", tmp_path)
    with pytest.raises(GearshotError) as err:
        _segment_recordings(Machine.from_toml(SPUR), [path], path, [], cps=10,
                            sensor="acc_input", holdout=0.25, example_segment=0)
    assert f"'{path}' (healthy) fails the input check 'dead'" in str(err.value)


def test_a_read_stuck_inside_libhdf5_is_killed_at_the_budget(zero_tail):
    """Without the heap walk, libhdf5 loops on the zero-tail file holding Python's global
    lock (no thread timeout can fire): the read runs in a child process that is killed when
    the budget (here 1 s + 1 s/MB) is spent. Run in its own process, bounded by 60 s."""
    code = ("import functools, sys\nfrom pathlib import Path\n"
            "import gearshot.io.recording as r\nfrom gearshot import GearshotError\n"
            "from gearshot.io._format_hdf5 import read_hdf5\nr.READ_BUDGET_S = 1.0\n"
            "try:\n    r._bounded_read(functools.partial(read_hdf5, walk_heaps=False), "
            "Path(sys.argv[1]), isolate=True)\nexcept GearshotError as e:\n"
            "    print('refused:', e)\n")
    res = subprocess.run([sys.executable, "-c", code, str(zero_tail[1])], capture_output=True,
                         text=True, timeout=60, env={"PYTHONPATH": str(SRC)})
    assert res.returncode == 0, res.stderr
    assert res.stdout.startswith("refused:") and "did not finish within 2 s" in res.stdout
