"""Zarr database: contract, resumability after kill -9, bad input writes nothing."""
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from gearshot import GearshotError
from gearshot.sim import build_database, load_database

KW = dict(speeds=[15, 20], loads=[10], grades=[5, 7, 9], n_healthy=2, n_faulty=3, seed=4)


def test_contract(tmp_path):
    build_database(tmp_path / "db", client=False, progress=False, **KW)
    ds = load_database(tmp_path / "db", speed=15, load=10)
    assert ds.sa.dims == ("signal", "angle") and ds.sa.dtype == np.float64
    assert ds.sa.shape == (15, 2048)
    assert list(np.unique(ds.grade.values)) == [5, 7, 9]
    assert np.all(ds.fault_size.values[:2] == 0) and ds.seed.dtype.kind == "i"
    assert float(ds["speed"]) == 15 and float(ds["load"]) == 10  # ds.load is a method
    one = load_database(tmp_path / "db", speed=20, load=10, grade=7)
    assert one.sa.shape == (5, 2048) and np.all(one.grade.values == 7)


KILL_KW = dict(speeds=[15, 20, 25], loads=[10], grades=[5, 7, 9], n_healthy=2, n_faulty=12,
               seed=4)


def test_kill9_resume_identical(tmp_path):
    ref = tmp_path / "ref"
    build_database(ref, client=False, progress=False, **KILL_KW)
    store = tmp_path / "killed"
    code = (f"from gearshot.sim import build_database; "
            f"build_database({str(store)!r}, client=False, progress=False, **{KILL_KW!r})")
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1] / "src"))
    proc = subprocess.Popen([sys.executable, "-c", code], env=env)
    deadline = time.time() + 120
    while time.time() < deadline:
        done = list((store / "blocks").glob("*.zarr")) if (store / "blocks").exists() else []
        if len(done) >= 2:
            break
        time.sleep(0.05)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    assert len(list((store / "blocks").glob("*.zarr"))) < 9, "build finished before the kill"
    build_database(store, client=False, progress=False, **KILL_KW)
    assert len(list((store / "blocks").glob("*.zarr"))) == 9
    for speed in (15, 20, 25):
        a = load_database(ref, speed=speed, load=10)
        b = load_database(store, speed=speed, load=10)
        assert a.sa.shape == b.sa.shape == (42, 2048)
        np.testing.assert_array_equal(a.sa.values, b.sa.values)
        np.testing.assert_array_equal(a.seed.values, b.seed.values)
    assert not list((store / "blocks").glob(".*tmp"))


@pytest.mark.parametrize("change, name", [
    (dict(speeds=[15, -1]), "speeds"), (dict(loads=[0]), "loads"),
    (dict(grades=[0]), "grades"), (dict(grades=[13]), "grades"),
    (dict(speeds=[np.nan]), "speeds"), (dict(loads=[np.inf]), "loads")])
def test_bad_input_writes_nothing(tmp_path, change, name):
    kw = dict(KW)
    kw.update(change)
    with pytest.raises(GearshotError, match=name):
        build_database(tmp_path / "db", client=False, progress=False, **kw)
    assert not (tmp_path / "db").exists()


def test_unwritable_store(tmp_path):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        if os.access(locked, os.W_OK):
            pytest.skip("running as a user who can write anywhere")
        with pytest.raises(GearshotError, match="store"):
            build_database(locked / "db", client=False, progress=False, **KW)
        assert not (locked / "db").exists()
    finally:
        locked.chmod(0o700)


def test_store_below_a_file_is_refused(tmp_path):
    blocker = tmp_path / "file.txt"
    blocker.write_text("x")
    with pytest.raises(GearshotError, match="store"):
        build_database(blocker / "db", client=False, progress=False, **KW)
    assert blocker.read_text() == "x"
    with pytest.raises(GearshotError, match="store"):
        build_database(blocker, client=False, progress=False, **KW)


def test_other_build_in_store_is_refused(tmp_path):
    small = dict(KW, speeds=[15], grades=[7])
    build_database(tmp_path / "db", client=False, progress=False, **small)
    with pytest.raises(GearshotError, match="seed"):
        build_database(tmp_path / "db", client=False, progress=False, **dict(small, seed=5))


def test_missing_condition_and_store(tmp_path):
    build_database(tmp_path / "db", client=False, progress=False,
                   **dict(KW, speeds=[15], grades=[7]))
    with pytest.raises(GearshotError, match="speed"):
        load_database(tmp_path / "db", speed=25, load=10)
    with pytest.raises(GearshotError, match="grade"):
        load_database(tmp_path / "db", speed=15, load=10, grade=3)
    with pytest.raises(GearshotError, match="manifest"):
        load_database(tmp_path / "nothing", speed=15, load=10)


def test_dask_client_gives_same_content(tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    small = dict(KW, speeds=[15], grades=[5, 7])
    build_database(tmp_path / "a", client=False, progress=False, **small)
    with distributed.Client(processes=False, n_workers=1, threads_per_worker=2,
                            dashboard_address=":0") as client:
        build_database(tmp_path / "b", client=client, progress=False, **small)
    a = load_database(tmp_path / "a", speed=15, load=10)
    b = load_database(tmp_path / "b", speed=15, load=10)
    np.testing.assert_array_equal(a.sa.values, b.sa.values)


def test_signal_reproducible_from_its_seed(tmp_path):
    from gearshot.sim import GearPair, simulate_sa

    build_database(tmp_path / "db", client=False, progress=False,
                   **dict(KW, speeds=[15], grades=[7]))
    ds = load_database(tmp_path / "db", speed=15, load=10, grade=7)
    i = 3
    sa = simulate_sa(GearPair.paper(), speed=15, load=10, grade=7,
                     fault_sizes=[float(ds.fault_size[i])], rng=[int(ds.seed[i])])
    np.testing.assert_allclose(sa[0], ds.sa.values[i], rtol=0, atol=1e-9)


PAIR_KW = dict(speeds=[15], loads=[10], grades=[9], n_healthy=2, n_faulty=3, seed=4,
               n_points=256)


def test_paired_store_holds_each_signals_healthy_twin(tmp_path):
    from gearshot.sim import GearPair, simulate_sa

    build_database(tmp_path / "plain", client=False, progress=False, paired=False, **PAIR_KW)
    build_database(tmp_path / "paired", client=False, progress=False, **PAIR_KW)  # default
    plain = load_database(tmp_path / "plain", speed=15, load=10)
    paired = load_database(tmp_path / "paired", speed=15, load=10)
    assert "sa_twin" not in plain and paired.sa_twin.shape == paired.sa.shape
    np.testing.assert_array_equal(plain.sa.values, paired.sa.values)   # same signals
    healthy = paired.fault_size.values == 0
    np.testing.assert_array_equal(paired.sa_twin.values[healthy], paired.sa.values[healthy])
    i = int(np.flatnonzero(~healthy)[0])
    twin = simulate_sa(GearPair.paper(), speed=15, load=10, grade=9, fault_sizes=[0.0],
                       n_points=256, rng=[int(paired.seed.values[i])])[0]
    np.testing.assert_allclose(paired.sa_twin.values[i], twin, rtol=0, atol=1e-12)
    # the twin shares the profile errors: faulty - twin is far smaller than faulty minus
    # another gear's healthy SA (what the paper's first-healthy subtraction leaves)
    other = paired.sa.values[np.flatnonzero(healthy)[0]]
    own = np.std(paired.sa.values[~healthy] - paired.sa_twin.values[~healthy], axis=1)
    cross = np.std(paired.sa.values[~healthy] - other, axis=1)
    assert np.all(own < 0.5 * cross), (own, cross)
    # an old unpaired store: the default (paired) build refuses it and says how to finish
    # it; with paired=False it still loads and resumes
    with pytest.raises(GearshotError, match=r"differs in paired.*without healthy twins: "
                       r"finish it with paired=False / --no-paired"):
        build_database(tmp_path / "plain", client=False, progress=False, **PAIR_KW)
    build_database(tmp_path / "plain", client=False, progress=False, paired=False, **PAIR_KW)
    # the repair command of a damaged store rebuilds the same layout
    from gearshot.sim._db_manifest import read_manifest as _read_manifest
    from gearshot.sim._db_manifest import rebuild_hint as _rebuild_hint
    assert "--no-paired" in _rebuild_hint(tmp_path / "plain", _read_manifest(tmp_path / "plain"))
    assert "--no-paired" not in _rebuild_hint(tmp_path / "paired",
                                              _read_manifest(tmp_path / "paired"))
    with pytest.raises(GearshotError, match="paired must be True or False; got 'yes'"):
        build_database(tmp_path / "other", client=False, progress=False, paired="yes",
                       **PAIR_KW)


THREAD_KW = dict(speeds=[15], loads=[10], grades=[4, 9, 11], n_healthy=1, n_faulty=4, seed=2,
                 n_points=256, paired=True, client=False, progress=False)


@pytest.mark.parametrize("helix", [0.0, 20.0])
def test_blocks_side_by_side_equal_blocks_one_by_one(tmp_path, monkeypatch, helix):
    """An in-process build runs its blocks on threads (one per core): the same numbers,
    bit for bit, as one block after another on numba threads; the twins equal
    simulate_sa of the faulty signals' seeds without the fault, bit for bit."""
    import gearshot.sim.database as database
    from gearshot.sim import GearPair, simulate_sa

    pair = GearPair.helical(np.radians(helix)) if helix else GearPair.paper()
    stores = {}
    for n_threads in (1, 3):
        monkeypatch.setattr(database, "block_threads", lambda n, k=n_threads: k)
        stores[n_threads] = load_database(
            build_database(tmp_path / f"t{n_threads}", pair, **THREAD_KW), speed=15, load=10)
    for name in ("sa", "sa_twin", "fault_size", "seed"):
        np.testing.assert_array_equal(stores[1][name].values, stores[3][name].values)
    ds = stores[3]
    faulty = np.flatnonzero((ds.fault_size.values > 0) & (ds.grade.values == 9))
    twins = simulate_sa(pair, speed=15, load=10, grade=9, n_points=256,
                        fault_sizes=np.zeros(faulty.size),
                        rng=[int(s) for s in ds.seed.values[faulty]])
    np.testing.assert_array_equal(ds.sa_twin.values[faulty], twins)
    assert not np.array_equal(ds.sa.values[faulty], twins)


def test_failed_block_on_a_thread_is_raised_and_leaves_no_temporaries(tmp_path, monkeypatch):
    import gearshot.sim.database as database

    real = database.simulate_sa_paired

    def fails_for_grade_9(pair, **kw):
        if kw["grade"] == 9:
            raise OSError(28, "No space left on device")
        return real(pair, **kw)

    monkeypatch.setattr(database, "block_threads", lambda n: 2)
    monkeypatch.setattr(database, "simulate_sa_paired", fails_for_grade_9)
    with pytest.raises(OSError, match="No space left"):
        build_database(tmp_path / "db", **THREAD_KW)
    blocks = tmp_path / "db" / "blocks"
    assert not list(blocks.glob(".*tmp*")) and not list((tmp_path / "db").glob(".*.tmp*"))
    assert not (blocks / "s0_l0_g1.zarr").exists()
    monkeypatch.setattr(database, "simulate_sa_paired", real)     # the next build finishes
    build_database(tmp_path / "db", **THREAD_KW)
    assert load_database(tmp_path / "db", speed=15, load=10).sa.shape == (15, 256)
