"""Issue #22: one writer per store, a manifest that cannot lie, cleanup, hostile files.

Concurrency runs real processes (``subprocess``); their simulator is replaced by a fast
deterministic stand-in (with a pause, so that the builds overlap) inside each process.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import fake_store
import numpy as np
import pytest

from gearshot import GearshotError

KW = fake_store.KW
# the stand-in simulator (autouse) and the tiny store, as this module's fixtures
fast_simulator, store = fake_store.fast_simulator, fake_store.store

SRC = Path(__file__).resolve().parents[1] / "src"

BUILDER = r"""
import json, sys, time
import numpy as np
import gearshot.sim.database as d

pause = float(sys.argv[4])
release = sys.argv[5]

def fake(pair, *, speed, load, grade, fault_sizes, n_points, rng, fault_type="ftff"):
    time.sleep(pause)
    while release != "-" and not __import__("os").path.exists(release):
        time.sleep(0.01)
    return np.stack([np.random.default_rng(s).standard_normal(n_points) for s in rng])

d.simulate_sa = fake
go = sys.argv[3]
if go != "-":
    print("ready", flush=True)
while go != "-" and not __import__("os").path.exists(go):
    time.sleep(0.01)
try:
    d.build_database(sys.argv[1], speeds=[15], loads=[10], grades=[5, 6, 7], n_healthy=1,
                     n_faulty=2, seed=int(sys.argv[2]), n_points=64, client=False,
                     progress=True)
    print("OK")
except Exception as exc:
    print(type(exc).__name__, exc)
"""


def _builder(store, seed, go="-", pause=0.3, release="-"):
    """A build in another process: with ``go``, it says "ready" and waits for that file;
    with ``release``, each block waits for that file (the build holds its lock until
    then)."""
    env = dict(os.environ, PYTHONPATH=str(SRC))
    return subprocess.Popen([sys.executable, "-c", BUILDER, str(store), str(seed), str(go),
                             str(pause), str(release)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env)


def _all_ready(procs):
    """Wait until every builder waits for its signal (no sleep a busy machine can outrun)."""
    for p in procs:
        assert p.stdout.readline().strip() == "ready"


def _seeds_of(store):
    """The manifest seed each block's signal seeds come from (None: none of 0..9)."""
    import xarray as xr

    from gearshot.sim._integrity import block_draws

    out = {}
    for k in range(3):
        ds = xr.open_zarr(store / "blocks" / f"s0_l0_g{k}.zarr", consolidated=False)
        got = np.asarray(ds["seed"].values)
        out[k] = next((s for s in range(10)
                       if np.array_equal(block_draws(s, 0, 0, k, 0, 1, 2)[1], got)), None)
    return out


def _leftovers(folder):
    return sorted(str(p) for p in Path(folder).rglob(".*tmp*"))


# ---------------------------------------------------------------------------- concurrency
def test_concurrent_builds_with_other_seeds_never_mix(tmp_path):
    """Two processes start at the same instant with seeds 0 and 5 (5 trials): one builds,
    the other is refused with one clear error; the store holds one seed throughout."""
    for trial in range(5):
        store, go = tmp_path / f"db{trial}", tmp_path / f"go{trial}"
        procs = [_builder(store, seed, go) for seed in (0, 5)]
        _all_ready(procs)   # both started, waiting for the signal
        go.write_text("go")
        outs = [p.communicate(timeout=300) for p in procs]
        results = [o[0].strip().splitlines()[-1] for o in outs]
        ok = [r for r in results if r == "OK"]
        refused = [r for r in results if r != "OK"]
        assert len(ok) == 1 and len(refused) == 1, results
        assert refused[0].startswith("GearshotError") and str(store) in refused[0]
        assert "being built" in refused[0] or "different build" in refused[0]
        winner = 0 if results[0] == "OK" else 5
        assert set(_seeds_of(store).values()) == {winner}
        man = json.loads((store / "manifest.json").read_text())
        assert man["seed"] == winner
        assert not _leftovers(store)


def test_concurrent_identical_builds_share_the_work(tmp_path):
    """Two identical builds: the one holding the lock builds its first block only once the
    other has said that it waits (so the order does not hang on the machine's load)."""
    store = tmp_path / "db"
    go, release = tmp_path / "go", tmp_path / "release"
    procs = [_builder(store, 3, go, release=release) for _ in range(2)]
    _all_ready(procs)
    go.write_text("go")
    waiting = threading.Event()
    errs: list[list[str]] = [[], []]

    def read_err(k):
        for line in procs[k].stderr:
            errs[k].append(line)
            if "waiting for it" in line:
                waiting.set()

    readers = [threading.Thread(target=read_err, args=(k,), daemon=True) for k in (0, 1)]
    for t in readers:
        t.start()
    assert waiting.wait(300), errs          # a guard against a hang only
    release.write_text("go")
    outs = [p.stdout.read() for p in procs]
    for p, t in zip(procs, readers):
        p.wait(timeout=300)
        t.join(timeout=60)
    assert [o.strip().splitlines()[-1] for o in outs] == ["OK", "OK"], (outs, errs)
    assert set(_seeds_of(store).values()) == {3}
    from gearshot.sim import load_database

    assert load_database(store, speed=15, load=10).sa.shape == (9, 64)


@pytest.mark.parametrize("next_seed", [3, 4])
def test_killed_builder_leaves_no_stale_lock(tmp_path, next_seed):
    """kill -9 while holding the lock and writing a block: the next build (same arguments:
    it finishes; other arguments: refused as another build, not as 'being built')."""
    store = tmp_path / "db"
    proc = _builder(store, 3, pause=30.0)
    deadline = time.monotonic() + 120
    while not list((store / "blocks").glob(".*.tmp")) and time.monotonic() < deadline:
        time.sleep(0.05)      # the process is inside its first block (temporary folder)
    assert (store / ".gearshot.writer.json").exists()
    proc.send_signal(signal.SIGKILL)
    proc.communicate(timeout=60)
    assert _leftovers(store)          # what the crash left: a temporary block
    res = _builder(store, next_seed, pause=0.0).communicate(timeout=300)
    last = res[0].strip().splitlines()[-1]
    if next_seed == 3:
        assert last == "OK", res
        assert set(_seeds_of(store).values()) == {3}
    else:
        assert last.startswith("GearshotError") and "different build" in last, res
    assert not _leftovers(store) and not (store / ".gearshot.writer.json").exists()


# ---------------------------------------------------------------------- manifest tampering


@pytest.mark.parametrize("edit, load_kw", [
    ({"speeds": [16.0, 20.0]}, dict(speed=16, load=10)),
    ({"loads": [12.0]}, dict(speed=15, load=12)),
    ({"grades": [9, 8]}, dict(speed=15, load=10, grade=9)),
    ({"n_points": 128}, dict(speed=15, load=10)),
    ({"seed": 4}, dict(speed=15, load=10)),
    ({"n_faulty": 1}, dict(speed=15, load=10)),
])
def test_edited_manifest_is_caught_and_the_named_repair_works(store, edit, load_kw):
    """Valid JSON, other values: loading refuses (never returns other data) and the
    command it names restores manifest.json from the blocks without rebuilding."""
    from gearshot.sim import build_database, load_database

    ref = load_database(store, speed=15, load=10).sa.values
    man = json.loads((store / "manifest.json").read_text())
    stamp = (store / "blocks" / "s0_l0_g0.zarr" / "sa" / "c" / "0" / "0").stat().st_mtime_ns
    (store / "manifest.json").write_text(json.dumps({**man, **edit}))
    with pytest.raises(GearshotError) as info:
        load_database(store, **load_kw)
    msg = str(info.value)
    assert "manifest.json" in msg and "gearshot simulate" in msg and "--seed 3" in msg
    assert "--speed 15 --speed 20" in msg and "restores manifest.json" in msg
    build_database(store, **KW)          # the arguments the message names
    assert json.loads((store / "manifest.json").read_text()) == man
    np.testing.assert_array_equal(load_database(store, speed=15, load=10).sa.values, ref)
    assert (store / "blocks" / "s0_l0_g0.zarr" / "sa" / "c" / "0" / "0").stat() \
        .st_mtime_ns == stamp


def _edit_record(block, **fields):
    meta_path = block / "zarr.json"
    meta = json.loads(meta_path.read_text())
    rec = meta["attributes"]["gearshot_block"]
    for key, value in fields.items():
        if value is None:
            rec.pop(key, None)
        else:
            rec[key] = value
    meta_path.write_text(json.dumps(meta))


def test_lost_checksum_list_is_an_error_and_rebuilt(store):
    from gearshot.sim import build_database, load_database

    ref = load_database(store, speed=20, load=10).sa.values
    block = store / "blocks" / "s1_l0_g0.zarr"
    meta = json.loads((block / "zarr.json").read_text())
    del meta["attributes"]["gearshot_block"]
    (block / "zarr.json").write_text(json.dumps(meta))
    with pytest.raises(GearshotError, match="checksum list .* is missing") as info:
        load_database(store, speed=20, load=10)
    assert "s1_l0_g0.zarr" in str(info.value) and "(re)builds s1_l0_g0.zarr" in str(info.value)
    build_database(store, **KW)
    np.testing.assert_array_equal(load_database(store, speed=20, load=10).sa.values, ref)


def test_foreign_block_with_a_rewritten_record_is_refused_and_rebuilt(tmp_path, store):
    """A block of another seed copied in, its checksum list recomputed and its manifest copy
    set to this store's (an old-format record without digest): the content check names it,
    and a rebuild replaces it (never approves it)."""
    import shutil

    from gearshot.sim import build_database, load_database
    from gearshot.sim._db_checksums import write_checksums as _write_checksums

    other = build_database(tmp_path / "other", **dict(KW, seed=9))
    ref = load_database(store, speed=15, load=10).sa.values
    target = store / "blocks" / "s0_l0_g1.zarr"
    shutil.rmtree(target)
    shutil.copytree(other / "blocks" / "s0_l0_g1.zarr", target)
    man = json.loads((store / "manifest.json").read_text())
    _write_checksums(target, man)
    _edit_record(target, manifest_sha256=None)     # as a block from before digests
    with pytest.raises(GearshotError, match="seed=3") as info:
        load_database(store, speed=15, load=10)
    assert "s0_l0_g1.zarr" in str(info.value)
    build_database(store, **KW)
    np.testing.assert_array_equal(load_database(store, speed=15, load=10).sa.values, ref)


def test_foreign_block_with_its_own_digest_is_rebuilt(tmp_path, store):
    import shutil

    from gearshot.sim import build_database, load_database

    other = build_database(tmp_path / "other", **dict(KW, seed=9))
    ref = load_database(store, speed=20, load=10).sa.values
    target = store / "blocks" / "s1_l0_g1.zarr"
    shutil.rmtree(target)
    shutil.copytree(other / "blocks" / "s1_l0_g1.zarr", target)
    with pytest.raises(GearshotError, match="another build") as info:
        load_database(store, speed=20, load=10)
    assert "(re)builds s1_l0_g1.zarr" in str(info.value)
    build_database(store, **KW)
    np.testing.assert_array_equal(load_database(store, speed=20, load=10).sa.values, ref)


# ------------------------------------------------------------------------ disk full, cleanup
def test_disk_full_leaves_no_temporary_block_then_resumes(tmp_path, monkeypatch):
    """ENOSPC while writing a block's chunks (simulated): one GearshotError naming the
    block, no temporary folder, and the next build completes."""
    import errno

    import xarray as xr

    from gearshot.sim import build_database, load_database

    real = xr.Dataset.to_zarr

    def full(self, store, *a, **k):
        real(self, store, *a, **k)
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(xr.Dataset, "to_zarr", full)
    with pytest.raises(GearshotError, match="No space left on device") as info:
        build_database(tmp_path / "db", **KW)
    assert "s0_l0_g0.zarr" in str(info.value) and "\n" not in str(info.value)
    assert not _leftovers(tmp_path) and not list((tmp_path / "db" / "blocks").iterdir())
    monkeypatch.setattr(xr.Dataset, "to_zarr", real)
    build_database(tmp_path / "db", **KW)
    assert load_database(tmp_path / "db", speed=15, load=10).sa.shape == (6, 64)


def test_temporaries_of_a_killed_run_are_removed_on_next_start(store):
    from gearshot.sim import build_database

    (store / "blocks" / ".s0_l0_g0.zarr.abc123.tmp").mkdir()
    (store / "blocks" / ".s0_l0_g0.zarr.abc123.tmp" / "junk").write_bytes(b"x" * 1000)
    (store / ".manifest.json.xyz.tmp").write_text("{")
    build_database(store, **KW)
    assert not _leftovers(store)


# ------------------------------------------------------------------------- model files
@pytest.fixture(scope="module")
def fitted_estimator():
    sys.path.insert(0, str(Path(__file__).parent))
    from estimator_data import synthetic_database, synthetic_target, tf_pair

    from gearshot.estimator import OneFaultShotEstimator

    tfs = tf_pair()
    healthy, long, faulty, y = synthetic_target(6, tfs[0])
    est = OneFaultShotEstimator(random_state=0, nominal_grade=3)
    est.fit(synthetic_database(), healthy, faulty[20], y[20], long, selection_tf=tfs[1])
    return est, faulty


class _Evil:
    """Unpickling this creates the marker file: the code a crafted model file runs."""

    def __init__(self, marker):
        self.marker = marker

    def __reduce__(self):
        return (open, (str(self.marker), "w"))


def test_model_file_round_trip_runs_no_pickle(fitted_estimator, tmp_path):
    from gearshot.estimator import OneFaultShotEstimator, load_estimator, save_estimator

    est, faulty = fitted_estimator
    save_estimator(est, tmp_path / "m.skops")
    assert (tmp_path / "m.skops").read_bytes()[:2] == b"PK"        # a zip of JSON + .npy
    again = load_estimator(tmp_path / "m.skops")
    np.testing.assert_array_equal(again.predict(faulty), est.predict(faulty))
    assert isinstance(OneFaultShotEstimator.load(tmp_path / "m.skops"), OneFaultShotEstimator)


def test_crafted_pickle_model_file_runs_no_code(fitted_estimator, tmp_path):
    import joblib

    from gearshot.estimator import load_estimator

    marker = tmp_path / "pwned"
    joblib.dump({"format": "gearshot-estimator/1", "estimator": _Evil(marker)},
                tmp_path / "evil.joblib")
    with pytest.raises(GearshotError, match="trusted=True") as info:
        load_estimator(tmp_path / "evil.joblib")
    assert "evil.joblib" in str(info.value) and "runs any code" in str(info.value)
    assert not marker.exists()
    # an old gearshot pickle loads when the caller vouches for it
    est, faulty = fitted_estimator
    joblib.dump({"format": "gearshot-estimator/1", "gearshot_version": "0.1.0",
                 "sklearn_version": "x", "estimator": est}, tmp_path / "old.joblib")
    with pytest.warns(UserWarning, match="sklearn"):
        old = load_estimator(tmp_path / "old.joblib", trusted=True)
    np.testing.assert_array_equal(old.predict(faulty), est.predict(faulty))


def test_crafted_skops_model_file_is_refused(tmp_path):
    import skops.io as sio

    from gearshot.estimator import load_estimator

    sio.dump({"format": "gearshot-estimator/2", "estimator": os.system,
              "also": eval}, tmp_path / "evil.skops")
    with pytest.raises(GearshotError, match="would construct types") as info:
        load_estimator(tmp_path / "evil.skops")
    assert "system" in str(info.value) and "eval" in str(info.value)
    (tmp_path / "junk.skops").write_bytes(b"PK\x03\x04" + b"\0" * 100)
    with pytest.raises(GearshotError, match="junk.skops"):
        load_estimator(tmp_path / "junk.skops")


def test_killed_save_leaves_a_temporary_that_the_next_save_removes(fitted_estimator,
                                                                    tmp_path):
    """A save killed between write and rename leaves ``.m.skops.<pid>-….tmp.skops``; the
    next write to the same folder removes temporaries whose process is gone."""
    code = ("import os, sys, gearshot._atomic as a\n"
            "with a.atomic_path(sys.argv[1]) as tmp:\n"
            "    tmp.write_bytes(b'half')\n"
            "    os.kill(os.getpid(), 9)\n")
    subprocess.run([sys.executable, "-c", code, str(tmp_path / "m.skops")],
                   env=dict(os.environ, PYTHONPATH=str(SRC)), timeout=120)
    assert _leftovers(tmp_path)
    from gearshot.estimator import save_estimator

    save_estimator(fitted_estimator[0], tmp_path / "m.skops")
    assert not _leftovers(tmp_path) and (tmp_path / "m.skops").is_file()


# ---------------------------------------------------------------------------- bounded reads
@pytest.fixture(scope="module")
def recording():
    from gearshot.io import Recording

    rng = np.random.default_rng(0)
    n = 200_000
    tacho = (np.sin(2 * np.pi * 15 * np.arange(n) / 20_000) > 0.99).astype(float)
    return Recording(rng.standard_normal(n), tacho, 20_000.0, speed=15.0)


@pytest.mark.parametrize("suffix", [".h5", ".wav", ".mat", ".csv"])
@pytest.mark.parametrize("frac", [0.1, 0.5, 0.9, 0.999])
def test_zeroed_tail_fails_fast_never_loads(recording, tmp_path, suffix, frac):
    """A file whose tail is overwritten with zeros: a GearshotError naming it, in seconds
    (the read budget), never a recording of wrong samples."""
    from gearshot.io import Recording

    path = tmp_path / f"rec{suffix}"
    recording.write(path)
    data = path.read_bytes()
    cut = int(len(data) * frac)
    path.write_bytes(data[:cut] + b"\0" * (len(data) - cut))
    with pytest.raises(GearshotError, match="rec"):
        Recording.read(path)


def test_truncated_hdf5_names_the_dataset_before_reading(recording, tmp_path):
    from gearshot.io import Recording

    path = tmp_path / "rec.h5"
    recording.write(path)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(GearshotError, match="rec.h5"):
        Recording.read(path)


def test_a_stuck_reader_gives_up_within_the_budget(recording, tmp_path, monkeypatch):
    import gearshot.io.recording as r

    path = tmp_path / "rec.h5"
    recording.write(path)
    release = threading.Event()
    monkeypatch.setattr(r, "READ_BUDGET_S", 0.5)
    monkeypatch.setattr(r, "read_hdf5", lambda p: release.wait(600))
    with pytest.raises(GearshotError, match="did not finish within"):
        r.Recording.read(path)
    assert not release.is_set()      # given up while the reader was still stuck
    release.set()


def test_ctrl_c_stops_a_stuck_read(recording, tmp_path):
    """Ctrl-C while a read is stuck (a reader that never returns, a read budget of an
    hour): the read stops with KeyboardInterrupt. The signal is sent only once the reader
    is inside its stuck call (it says so), so a busy machine changes nothing; the only
    timeout is a guard against a hang."""
    path = tmp_path / "rec.h5"
    recording.write(path)
    code = ("import sys, threading\nimport gearshot.io.recording as r\n"
            "r.READ_BUDGET_S = 3600.0\n"
            "def stuck(p):\n    print('stuck', flush=True)\n"
            "    threading.Event().wait()\n"
            "r.read_hdf5 = stuck\n"
            "try:\n    r.Recording.read(sys.argv[1])\n"
            "except KeyboardInterrupt:\n    print('interrupted', flush=True)\n")
    proc = subprocess.Popen([sys.executable, "-c", code, str(path)], stdout=subprocess.PIPE,
                            text=True, env=dict(os.environ, PYTHONPATH=str(SRC)))
    assert proc.stdout.readline().strip() == "stuck"    # the reader thread is stuck now
    proc.send_signal(signal.SIGINT)
    out, _ = proc.communicate(timeout=600)
    assert out.strip() == "interrupted"


# ------------------------------------------------------------------- command-line cases
def _cli(args, tmp_path, timeout=300):
    env = dict(os.environ, PYTHONPATH=str(SRC), GEARSHOT_DATA=str(tmp_path / "home"))
    return subprocess.run([sys.executable, "-m", "gearshot.app.cli", *map(str, args)],
                          capture_output=True, text=True, env=env, timeout=timeout,
                          cwd=tmp_path)


def _one_line(res, *words):
    err = res.stderr.strip()
    assert res.returncode == 2, (res.returncode, err)      # a user error, never exit 3
    lines = [ln for ln in err.splitlines() if ln.startswith("gearshot: error:")]
    assert len(lines) == 1 and "Traceback" not in err, err
    for w in words:
        assert w in lines[0], err
    return lines[0]


def _machine_file(tmp_path, **file_overrides):
    import tomllib

    root = Path(__file__).resolve().parents[1]
    text = (root / "examples" / "machines" / "phm09_spur.toml").read_text()
    data = tomllib.loads(text)
    lines = [ln for ln in text.splitlines()]
    for key, value in file_overrides.items():
        lines = [f"{key} = {value}" if ln.split("=")[0].strip() == key
                 and key in data["file"] else ln for ln in lines]
    path = tmp_path / "m.toml"
    path.write_text("\n".join(lines))
    return path


USER_ERRORS = {
    "predict --seed -1": (lambda t: ["predict", "--database", t / "db", "--healthy", t / "h.h5",
                                     "--faulty", t / "f.h5", "--faulty-size", "0.5",
                                     "--recordings", t, "--speed", "15", "--load", "10",
                                     "--seed", "-1"], ["--seed", "-1"]),
    "predict --out p.xlsx": (lambda t: ["predict", "--database", t / "db", "--healthy",
                                        t / "h.h5", "--faulty", t / "f.h5", "--faulty-size",
                                        "0.5", "--recordings", t, "--speed", "15", "--load",
                                        "10", "--out", t / "p.xlsx"], ["p.xlsx", ".csv"]),
    "simulate --speed 1e308": (lambda t: ["simulate", "--store", t / "db", "--speed", "1e308",
                                          "--grade", "7"], ["--speed", "1e+308"]),
    "simulate --speed 1e-6": (lambda t: ["simulate", "--store", t / "db", "--speed", "1e-6",
                                         "--grade", "7"], ["--speed", "rev/s"]),
    "simulate --load 1e12": (lambda t: ["simulate", "--store", t / "db", "--load", "1e12",
                                        "--grade", "7"], ["--load", "N m"]),
    "rig --load 1e9": (lambda t: ["rig", t / "camp", "--load", "1e9"], ["--load"]),
    "machine fs 1e400": (lambda t: ["simulate", "--machine",
                                    _machine_file(t, fs='"1e400"'), "--grade", "7"],
                         ["m.toml", "file.fs"]),
    "machine fs 1e300": (lambda t: ["simulate", "--machine", _machine_file(t, fs="1e300"),
                                    "--grade", "7"], ["m.toml", "file.fs"]),
    "machine delimiter list": (lambda t: ["simulate", "--machine",
                                          _machine_file(t, delimiter='[","]'), "--grade",
                                          "7"], ["m.toml", "delimiter"]),
    "report on a JSON list": (lambda t: ["report", _write(t / "r.json", "[1, 2]")],
                              ["r.json"]),
    "report rows without keys": (lambda t: ["report", _write(t / "r.json",
                                                              '{"rows": [{"x": 1}]}')],
                                 ["r.json"]),
    "report rows not objects": (lambda t: ["report", _write(t / "r.json", '{"rows": [1]}')],
                                ["r.json"]),
    "experiment simulated, empty FRF folder": (
        lambda t: ["experiment", "simulated", "--frf-folder", _mkdir(t / "frf"), "--store",
                   t / "db"], ["--frf-folder", "no FRF files"]),
    "experiment rig --rig-grade 13": (lambda t: ["experiment", "rig", "--rig-grade", "13",
                                                 "--store", t / "db"], ["--rig-grade", "13"]),
}


def _write(path, text):
    path.write_text(text)
    return path


def _mkdir(path):
    path.mkdir(exist_ok=True)
    return path


@pytest.mark.parametrize("case", sorted(USER_ERRORS))
def test_user_errors_are_one_line_exit_2_before_any_work(tmp_path, case):
    make, words = USER_ERRORS[case]
    _one_line(_cli(make(tmp_path), tmp_path), *words)
    assert not (tmp_path / "db").exists() and not (tmp_path / "camp").exists()
    assert not list((tmp_path / "home").rglob("*.zarr")) if (tmp_path / "home").exists() \
        else True


def test_simulate_at_an_absurd_speed_does_not_suggest_duration(tmp_path):
    line = _one_line(_cli(["simulate", "--store", tmp_path / "db", "--speed", "1e-6"],
                          tmp_path), "--speed")
    assert "--duration" not in line


def test_multi_line_library_errors_print_as_one_line(monkeypatch, capsys, tmp_path):
    """The rig's disk-full error (h5py's message spans lines) is one line."""
    import gearshot.app.cli as cli

    def full(*a, **k):
        raise GearshotError(f"cannot write {str(tmp_path / 'camp' / 'x.h5')!r}:\n  No space "
                            f"left on device\n  (errno 28)")

    monkeypatch.setattr("gearshot.rig.virtual.VirtualRig.campaign", full)
    monkeypatch.setattr(sys, "argv", ["gearshot", "rig", str(tmp_path / "camp"), "--duration",
                                      "8", "--healthy", "1", "--repetitions", "0"])
    with pytest.raises(SystemExit) as info:
        cli.main()
    err = capsys.readouterr().err.strip()
    assert info.value.code == 2 and len(err.splitlines()) == 1
    assert "x.h5" in err and "No space left on device" in err


def test_indicator_figures_go_through_the_atomic_writer(tmp_path, monkeypatch):
    """A full disk while saving a figure leaves no 0-byte PNG and names the path."""
    import errno

    from matplotlib.figure import Figure

    from gearshot.app.indicators import indicator_figures

    def full(self, fname, *a, **k):
        Path(fname).write_bytes(b"")
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(Figure, "savefig", full)
    payload = {"records": [{"file": f"case{i}_30hz.zip", "speed_hz": 30.0 + i,
                            "n_cycles": 10, "indicators": {"rms": 1.0 + i, "fm4": 3.0}}
                           for i in range(2)]}
    with pytest.raises(GearshotError, match="No space left on device") as info:
        indicator_figures(payload, tmp_path / "figs", title="t")
    assert str(tmp_path / "figs") in str(info.value) and ".png" in str(info.value)
    assert not list((tmp_path / "figs").glob("*.png"))
    assert not _leftovers(tmp_path)


# ------------------------------------------------------------------------------ API cases
def test_machine_from_dict_never_raises_type_error():
    import tomllib

    from gearshot import Machine

    root = Path(__file__).resolve().parents[1]
    base = tomllib.loads((root / "examples" / "machines" / "phm09_spur.toml").read_text())
    hostile = [[","], {"a": 1}, [[1]], 1e400, float("nan"), None, True, "x" * 1000]
    n = 0
    for table in ("file", "tacho", "monitored", "analysis"):
        for key in list(base.get(table, {})) + ["unknown"]:
            for value in hostile:
                data = {**base, table: {**base.get(table, {}), key: value}}
                try:
                    Machine.from_dict(data)
                except GearshotError:
                    n += 1
    for top in ("shafts", "stage", "sensor", "name"):
        for value in hostile:
            try:
                Machine.from_dict({**base, top: value})
            except GearshotError:
                n += 1
    assert n > 100
    with pytest.raises(GearshotError):
        Machine.from_dict([1, 2])


def test_order_mask_with_huge_sidebands_is_fast_and_exact():
    import gearshot.signal as gs

    mask = gs.order_mask(2 ** 24, 38, n_sidebands=2 ** 24)
    assert mask.all() and mask.size == 2 ** 23 + 1
    small = gs.order_mask(64, 5, n_sidebands=1)
    want = np.zeros(33, bool)
    for h in range(5, 33, 5):
        want[[h - 1, h, min(h + 1, 32)]] = True
    want[31] = want[31] or False
    np.testing.assert_array_equal(small, want | np.isin(np.arange(33), [64 - 31]))


@pytest.mark.parametrize("kw, words", [
    (dict(speeds=[1e308]), ["speeds", "rev/s"]), (dict(speeds=[1e-6]), ["speeds"]),
    (dict(loads=[1e12]), ["loads", "N m"]), (dict(loads=[1e9]), ["loads"]),
])
def test_database_physical_bounds(tmp_path, kw, words):
    from gearshot.sim import build_database

    with pytest.raises(GearshotError) as info:
        build_database(tmp_path / "db", **{**KW, **kw})
    assert all(w in str(info.value) for w in words)
    assert not (tmp_path / "db").exists()


def test_recording_and_simulator_bounds():
    from gearshot.io import Recording
    from gearshot.sim import GearPair, simulate_sa

    with pytest.raises(GearshotError, match="fs must be <= 1e"):
        Recording(np.zeros(10), None, 1e300)
    with pytest.raises(GearshotError, match="load must lie"):
        simulate_sa(GearPair.paper(), speed=15, load=1e12, grade=7, n_points=64)
    with pytest.raises(GearshotError, match="speed must lie"):
        simulate_sa(GearPair.paper(), speed=1e308, load=10, grade=7, n_points=64)


def test_rig_family_cache_is_keyed_by_frf_contents():
    import dataclasses

    from gearshot.experiments.family import _tf_digest
    from gearshot.transfer import TransferFunctionBank

    tf = TransferFunctionBank.synthetic(1, rng=0)[0]
    same_name = dataclasses.replace(tf, values=tf.values * 1.01)
    assert same_name.name == tf.name and _tf_digest(same_name) != _tf_digest(tf)
    assert _tf_digest(dataclasses.replace(tf)) == _tf_digest(tf)


def test_os_errors_are_one_line(tmp_path):
    from gearshot._atomic import atomic_path

    with pytest.raises(GearshotError) as info:
        with atomic_path(tmp_path / "a.h5"):
            raise OSError(27, "file write failed: time = x\n, errno = 27, 'File too large'")
    assert "\n" not in str(info.value) and "a.h5" in str(info.value)
