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
import time
from pathlib import Path

import numpy as np
import pytest

from gearshot import GearshotError

SRC = Path(__file__).resolve().parents[1] / "src"

BUILDER = r"""
import json, sys, time
import numpy as np
import gearshot.sim.database as d

pause = float(sys.argv[4])

def fake(pair, *, speed, load, grade, fault_sizes, n_points, rng, fault_type="ftff"):
    time.sleep(pause)
    return np.stack([np.random.default_rng(s).standard_normal(n_points) for s in rng])

d.simulate_sa = fake
go = sys.argv[3]
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


def _builder(store, seed, go="-", pause=0.3):
    env = dict(os.environ, PYTHONPATH=str(SRC))
    return subprocess.Popen([sys.executable, "-c", BUILDER, str(store), str(seed), str(go),
                             str(pause)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=env)


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
        time.sleep(1.5)   # both started, waiting for the signal
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
    store = tmp_path / "db"
    go = tmp_path / "go"
    procs = [_builder(store, 3, go) for _ in range(2)]
    time.sleep(1.5)
    go.write_text("go")
    outs = [p.communicate(timeout=300) for p in procs]
    assert [o[0].strip().splitlines()[-1] for o in outs] == ["OK", "OK"], outs
    assert any("waiting for it" in o[1] for o in outs), [o[1] for o in outs]
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
def _fake_simulate_sa(pair, *, speed, load, grade, fault_sizes, n_points, rng,
                      fault_type="ftff"):
    return np.stack([np.random.default_rng(s).standard_normal(n_points) for s in rng])


@pytest.fixture(autouse=True)
def fast_simulator(monkeypatch):
    monkeypatch.setattr("gearshot.sim.database.simulate_sa", _fake_simulate_sa)


KW = dict(speeds=[15, 20], loads=[10], grades=[7, 8], n_healthy=1, n_faulty=2, seed=3,
          n_points=64, client=False, progress=False)


@pytest.fixture
def store(tmp_path):
    from gearshot.sim import build_database

    return build_database(tmp_path / "db", **KW)


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
    from gearshot.sim.database import _write_checksums

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
