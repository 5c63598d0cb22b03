"""Failure paths (issue #15): nothing half-written, no tracebacks, only GearshotError.

* the one atomic writer (``gearshot._atomic``): temporary file in the target folder, fsync,
  rename; nothing left behind on failure; OS errors named;
* damaged database stores are named (store, block, what to do) and repaired by a rebuild;
* the command line under bad outputs (read-only folder, /dev/full, a parent that is a file,
  a file-size limit): one line ``gearshot: error: …``, exit ≠ 0, no partial file;
* a table of bad API calls, and a Hypothesis fuzz of every public signal/feature function:
  only ``GearshotError`` escapes, and no RuntimeWarning.
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import gearshot.signal as gs
from gearshot import GearshotError
from gearshot._atomic import (
    atomic_dir,
    atomic_path,
    check_writable,
    staging_dir,
    write_json_atomic,
    write_text_atomic,
)
from gearshot.features import available_features, extract_features, na4_baseline_variance

SRC = Path(__file__).resolve().parents[1] / "src"
ROOT = os.geteuid() == 0


def leftovers(folder: Path) -> list[str]:
    """Hidden temporaries (``.name.*.tmp``) anywhere under ``folder``."""
    return sorted(str(p) for p in Path(folder).rglob(".*tmp*"))


# ------------------------------------------------------------------------ atomic writer
def test_atomic_path_replaces_whole_or_not_at_all(tmp_path):
    target = tmp_path / "a.json"
    write_json_atomic({"x": 1}, target)
    assert json.loads(target.read_text()) == {"x": 1}
    with pytest.raises(ZeroDivisionError):
        with atomic_path(target) as tmp:
            tmp.write_text("half")
            raise ZeroDivisionError
    assert json.loads(target.read_text()) == {"x": 1}
    assert not leftovers(tmp_path)
    with pytest.raises(TypeError):  # not serialisable: nothing written
        write_json_atomic({"x": object()}, tmp_path / "b.json")
    assert not (tmp_path / "b.json").exists() and not leftovers(tmp_path)


def test_atomic_path_temp_keeps_suffix_and_os_errors_are_named(tmp_path):
    with atomic_path(tmp_path / "fig.png") as tmp:
        assert tmp.parent == tmp_path and tmp.suffix == ".png" and tmp.name.startswith(".")
        tmp.write_bytes(b"png")
    with pytest.raises(GearshotError, match="out.csv"):
        with atomic_path(tmp_path / "out.csv"):
            raise OSError(28, "No space left on device")
    assert not (tmp_path / "out.csv").exists() and not leftovers(tmp_path)


@pytest.mark.parametrize("case", ["missing-parent", "parent-is-file", "device", "folder"])
def test_atomic_path_refuses_bad_targets(tmp_path, case):
    (tmp_path / "file").write_text("x")
    (tmp_path / "dir").mkdir()
    target = {"missing-parent": tmp_path / "nope" / "a.txt",
              "parent-is-file": tmp_path / "file" / "a.txt",
              "device": Path("/dev/null"), "folder": tmp_path / "dir"}[case]
    with pytest.raises(GearshotError, match="cannot write"):
        write_text_atomic(target, "x")
    if case != "missing-parent":   # a missing folder is created by the commands
        with pytest.raises(GearshotError):
            check_writable(target, "--out")
    assert (tmp_path / "file").read_text() == "x"
    assert not leftovers(tmp_path)


def test_make_parents_and_parent_is_file(tmp_path):
    write_text_atomic(tmp_path / "a" / "b" / "c.txt", "ok", make_parents=True)
    assert (tmp_path / "a" / "b" / "c.txt").read_text() == "ok"
    (tmp_path / "f").write_text("x")
    with pytest.raises(GearshotError, match="is a file"):
        write_text_atomic(tmp_path / "f" / "c.txt", "ok", make_parents=True)
    check_writable(tmp_path / "new" / "deeper", "--out", folder=True)  # creatable: fine
    with pytest.raises(GearshotError, match="folder"):
        check_writable(tmp_path / "f", "--out", folder=True)


def test_atomic_dir_and_staging(tmp_path):
    final = tmp_path / "block.zarr"
    with atomic_dir(final) as tmp:
        (tmp / "data").write_text("1")
    assert (final / "data").read_text() == "1"
    with atomic_dir(final, exist_ok=True) as tmp:   # a second worker: its copy is dropped
        (tmp / "data").write_text("2")
    assert (final / "data").read_text() == "1"
    with pytest.raises(KeyError):
        with atomic_dir(tmp_path / "other.zarr") as tmp:
            (tmp / "data").write_text("x")
            raise KeyError("boom")
    assert not (tmp_path / "other.zarr").exists()
    with staging_dir(tmp_path / "camp") as stage:
        (stage / "r.h5").write_text("x")
    assert (tmp_path / "camp").is_dir() and not list((tmp_path / "camp").iterdir())
    assert not leftovers(tmp_path)


def test_file_size_limit_leaves_nothing(tmp_path):
    code = ("import resource, sys; from gearshot._atomic import write_text_atomic\n"
            "resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))\n"
            "try:\n    write_text_atomic(sys.argv[1], 'x' * 100_000)\n"
            "except Exception as e:\n    print(type(e).__name__, e)\n")
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path / "big.txt")],
                         capture_output=True, text=True, env=_env(), timeout=60)
    assert out.stdout.startswith("GearshotError") and "big.txt" in out.stdout, out
    assert not list(tmp_path.iterdir())


class _FsizeLimit:
    """Lower this process's soft file-size limit (Python ignores SIGXFSZ: writes fail EFBIG)."""

    def __init__(self, limit):
        self.limit = limit

    def __enter__(self):
        self.old = resource.getrlimit(resource.RLIMIT_FSIZE)
        resource.setrlimit(resource.RLIMIT_FSIZE, (self.limit, self.old[1]))

    def __exit__(self, *exc):
        resource.setrlimit(resource.RLIMIT_FSIZE, self.old)


@pytest.mark.parametrize("fmt", ["h5", "csv", "mat", "wav"])
def test_recording_write_under_file_size_limit(tmp_path, fmt):
    from gearshot.io import Recording

    rec = Recording(np.random.default_rng(0).standard_normal(50_000), None, 1000.0)
    with _FsizeLimit(20_000), pytest.raises(GearshotError, match=f"rec.{fmt}"):
        rec.write(tmp_path / f"rec.{fmt}")
    assert not list(tmp_path.iterdir())


def test_database_under_file_size_limit_then_resume(tmp_path):
    from gearshot.sim import build_database, load_database

    kw = dict(DB_KW, n_points=512, n_healthy=2, n_faulty=2)
    with _FsizeLimit(3_000), pytest.raises(GearshotError, match="s0_l0_g0.zarr"):
        build_database(tmp_path / "db", **kw)
    assert not list((tmp_path / "db" / "blocks").iterdir())   # no block, no temporary
    build_database(tmp_path / "db", **kw)
    assert load_database(tmp_path / "db", speed=15, load=10).sa.shape == (8, 512)


# --------------------------------------------------------------------- damaged databases
DB_KW = dict(speeds=[15], loads=[10], grades=[7, 8], n_healthy=1, n_faulty=2, seed=3,
             n_points=64, client=False, progress=False)


def _fake_simulate_sa(pair, *, speed, load, grade, fault_sizes, n_points, rng,
                      fault_type="ftff"):
    """Stands in for the simulator (no numba compile): one deterministic row per seed."""
    return np.stack([np.random.default_rng(s).standard_normal(n_points) for s in rng])


def _fake_simulate_sa_paired(pair, **kw):
    """The stand-in's SAs and twins (a faulty signal's twin: its SA with the sign flipped)."""
    sa = _fake_simulate_sa(pair, **kw)
    return sa, np.where((kw["fault_sizes"] > 0)[:, None], -sa, sa)


@pytest.fixture(autouse=True)
def fast_simulator(monkeypatch):
    monkeypatch.setattr("gearshot.sim.database.simulate_sa", _fake_simulate_sa)
    monkeypatch.setattr("gearshot.sim.database.simulate_sa_paired", _fake_simulate_sa_paired)


@pytest.fixture(scope="module")
def small_db(tmp_path_factory):
    from gearshot.sim import build_database, load_database

    store = tmp_path_factory.mktemp("db") / "db"
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr("gearshot.sim.database.simulate_sa", _fake_simulate_sa)
        mp.setattr("gearshot.sim.database.simulate_sa_paired", _fake_simulate_sa_paired)
        build_database(store, **DB_KW)
    return store, load_database(store, speed=15, load=10).sa.values


def _copy(store: Path, tmp_path: Path) -> Path:
    import shutil

    dest = tmp_path / "db"
    shutil.copytree(store, dest)
    return dest


@pytest.mark.parametrize("damage", ["missing-chunk", "junk-chunk", "truncated-chunk",
                                    "bad-block-metadata", "bad-manifest", "empty-manifest"])
def test_damaged_store_is_named_then_repaired(small_db, tmp_path, damage):
    from gearshot.sim import build_database, load_database

    ref_store, ref = small_db
    store = _copy(ref_store, tmp_path)
    chunk = store / "blocks" / "s0_l0_g1.zarr" / "sa" / "c" / "0" / "0"
    if damage == "missing-chunk":
        chunk.unlink()
    elif damage == "junk-chunk":
        chunk.write_bytes(b"\x00junk" * (chunk.stat().st_size // 5))
    elif damage == "truncated-chunk":
        chunk.write_bytes(chunk.read_bytes()[:10])
    elif damage == "bad-block-metadata":
        (chunk.parents[2] / "zarr.json").write_text("{not json")
    elif damage == "bad-manifest":
        (store / "manifest.json").write_text("{not json")
    else:
        (store / "manifest.json").write_text("")
    with pytest.raises(GearshotError) as info:
        load_database(store, speed=15, load=10)
    msg = str(info.value)
    assert str(store) in msg and "gearshot simulate" in msg
    if "manifest" not in damage:
        assert "s0_l0_g1.zarr" in msg and "grade=8" in msg
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        build_database(store, **DB_KW)       # repairs only what is damaged
    np.testing.assert_array_equal(load_database(store, speed=15, load=10).sa.values, ref)
    assert not leftovers(store)


def test_repair_rebuilds_only_the_damaged_block(small_db, tmp_path):
    from gearshot.sim import build_database

    store = _copy(small_db[0], tmp_path)
    good = store / "blocks" / "s0_l0_g0.zarr" / "sa" / "c" / "0" / "0"
    stamp = good.stat().st_mtime_ns
    (store / "blocks" / "s0_l0_g1.zarr" / "sa" / "c" / "0" / "0").unlink()
    build_database(store, **DB_KW)
    assert good.stat().st_mtime_ns == stamp


def test_other_build_keeps_manifest_check(small_db, tmp_path):
    from gearshot.sim import build_database

    store = _copy(small_db[0], tmp_path)
    (store / "manifest.json").write_text("garbage")
    with pytest.raises(GearshotError, match="manifest"):   # blocks say: another build
        build_database(store, **dict(DB_KW, seed=4))


# ------------------------------------------------------------------- bad API calls table
def _sa(n=64, rows=3, seed=0):
    return np.random.default_rng(seed).standard_normal((rows, n))


API_CASES = {
    "extract_features names=3": lambda: extract_features(_sa(), 5, names=3),
    "extract_features names=[1]": lambda: extract_features(_sa(), 5, names=[1]),
    "extract_features huge": lambda: extract_features(_sa() * 1e305, 5),
    "extract_features 1e60 (8th moment overflows)":
        lambda: extract_features(_sa() * 1e60, 5, names=["m8a"]),
    "fractional_shift delay='abc'": lambda: gs.fractional_shift(_sa(), "abc"),
    "fractional_shift delay shape": lambda: gs.fractional_shift(_sa(), np.zeros(5)),
    "fractional_shift delay nan": lambda: gs.fractional_shift(_sa(), np.nan),
    "angle_to_time nan": lambda: gs.angle_to_time(np.arange(10.0), [np.nan]),
    "angle_to_time out of range": lambda: gs.angle_to_time(np.arange(10.0), [12.0]),
    "angle_to_time negative": lambda: gs.angle_to_time(np.arange(10.0), [-1.0]),
    "order_mask 2**31": lambda: gs.order_mask(2 ** 31, 38),
    "order_mask n_sidebands=10**9": lambda: gs.order_mask(2048, 38, n_sidebands=10 ** 9),
    "mesh_band_orders mesh_order=0": lambda: gs.mesh_band_orders(64, 0, 1),
    "synchronous_average spc=10**9": lambda: gs.synchronous_average(_sa(), 10 ** 9),
    "angular_resample samples_per_rev=10**9":
        lambda: gs.angular_resample(np.zeros(1000), 100.0, [1.0, 2.0, 3.0],
                                    samples_per_rev=10 ** 9),
    "amplitude_spectrum nfft=2**40": lambda: gs.amplitude_spectrum(np.zeros(100), nfft=2 ** 40),
    "rms 1e305": lambda: gs.rms(np.full(8, 1e305)),
    "envelope inf": lambda: gs.envelope([0.0, np.inf, 1.0]),
    "pulse_times threshold='x'": lambda: gs.pulse_times(np.r_[np.zeros(50), np.ones(50)],
                                                        100.0, threshold="x"),
    "pulse_times constant": lambda: gs.pulse_times(np.zeros(100), 100.0),
    "check_pulse_train strings": lambda: gs.check_pulse_train(["a"], pulses_per_rev=1,
                                                              label="rec"),
    "shaft_cycle_times empty": lambda: gs.shaft_cycle_times([], revs_per_cycle="38/17"),
    "shaft_cycle_times ratio 1/10**9": lambda: gs.shaft_cycle_times(
        np.arange(5.0), revs_per_cycle=(1, 10 ** 9)),
    "subtract_healthy upsample=10**9": lambda: gs.subtract_healthy(_sa(), _sa(), upsample=10**9),
    "subtract_blend n_blend=0": lambda: gs.subtract_blend(_sa(), _sa(), n_blend=0),
    "minimum_phase zeros": lambda: gs.minimum_phase(np.zeros(8)),
    "na4_baseline_variance ragged": lambda: na4_baseline_variance([[1, 2], [3]], 5),
    "acs_background segment_size=str": lambda: gs.acs_background(np.ones(300),
                                                                 segment_size="200"),
}


@pytest.mark.parametrize("name", sorted(API_CASES))
def test_bad_api_call_raises_gearshot_error(name):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(GearshotError):
            API_CASES[name]()


def test_single_tacho_pulse_is_not_called_constant():
    tacho = np.zeros(1000)
    tacho[500:503] = 5.0
    assert gs.pulse_times(tacho, 1000.0).size == 1    # found, not "constant"
    with pytest.raises(GearshotError, match="at least 2 pulses"):
        gs.angular_resample(np.zeros(1000), 1000.0, gs.pulse_times(tacho, 1000.0),
                            samples_per_rev=8)


def test_not_fitted_estimator_is_a_gearshot_error():
    from sklearn.exceptions import NotFittedError

    from gearshot.estimator import OneFaultShotEstimator

    with pytest.raises(NotFittedError) as info:
        OneFaultShotEstimator().predict(_sa(2048))
    assert isinstance(info.value, GearshotError)


def test_csv_without_rate_names_a_real_fix(tmp_path):
    from gearshot.io import Recording

    path = tmp_path / "rec.csv"
    path.write_text("acceleration,tacho\n" + "\n".join(f"{i % 3},{i % 2}" for i in range(20)))
    with pytest.raises(GearshotError) as info:
        Recording.read(path)
    msg = str(info.value)
    assert "rec.csv.json" in msg and '"fs"' in msg and "Recording.read(path, fs=" in msg


# ------------------------------------------------------------------------------- fuzzing
_SPECIAL = [np.nan, np.inf, -np.inf, 0.0, -0.0, 1e305, -1e305, 1e-310, 1e150, 1e60, 7.0]
_floats = st.one_of(st.floats(allow_nan=True, allow_infinity=True, width=64),
                    st.sampled_from(_SPECIAL))
_arrays = st.one_of(
    st.lists(_floats, min_size=0, max_size=40).map(np.array),
    st.lists(st.floats(-1e3, 1e3), min_size=0, max_size=40).map(np.array),
    st.integers(0, 3).flatmap(lambda r: st.lists(st.lists(st.floats(-10, 10), min_size=r * 8,
                                                          max_size=r * 8),
                                                 min_size=1, max_size=3)).map(np.array),
    st.builds(lambda n, k: np.sin(2 * np.pi * 5 * np.arange(n) / n)[None].repeat(k, 0) * 1e3,
              st.sampled_from([16, 32, 64, 65]), st.integers(1, 3)),
    st.just(np.arange(12.0)), st.just(np.ones(64)), st.just(np.zeros((2, 64))),
    st.just(np.array([[1.0, 2.0], [3.0, 4.0]])),
)
_junk = st.one_of(st.none(), st.text(max_size=4), st.booleans(),
                  st.sampled_from([[1, [2]], {"a": 1}, object(), 1j, b"x"]))
_ints = st.one_of(st.sampled_from([-1, 0, 1, 2, 3, 4, 5, 7, 8, 16, 38, 64, 2 ** 31, 10 ** 9,
                                   2 ** 63, -(2 ** 63)]), st.floats(-1e3, 1e3), _junk)
_nums = st.one_of(st.sampled_from([-1.0, 0.0, 0.5, 1.0, 100.0, 1e6, np.nan, np.inf, 1e305]),
                  st.integers(-5, 10 ** 6), _junk)
_arg = st.one_of(_arrays, _junk, _nums)

# every public signal/feature function with a strategy for its arguments
FUZZ = {
    "pulse_times": (gs.pulse_times, st.tuples(_arrays, _nums),
                    st.fixed_dictionaries({}, optional={"threshold": _nums,
                                                        "hysteresis": _nums})),
    "angle_to_time": (gs.angle_to_time, st.tuples(_arrays, _arg),
                      st.fixed_dictionaries({}, optional={"pulses_per_rev": _ints})),
    "angular_resample": (gs.angular_resample, st.tuples(_arrays, _nums, _arrays),
                         st.fixed_dictionaries({"samples_per_rev": _ints},
                                               optional={"pulses_per_rev": _ints,
                                                         "upsample": _ints})),
    "check_pulse_train": (gs.check_pulse_train, st.tuples(_arg),
                          st.fixed_dictionaries({"pulses_per_rev": _ints,
                                                 "label": st.just("fuzz")})),
    "shaft_cycle_times": (gs.shaft_cycle_times, st.tuples(_arg),
                          st.fixed_dictionaries({"revs_per_cycle": _arg},
                                                optional={"pulses_per_rev": _ints})),
    "antialias_filter": (gs.antialias_filter, st.tuples(_arrays, _nums),
                         st.fixed_dictionaries({"cutoff": _nums},
                                               optional={"passband": _nums,
                                                         "upsample": _ints})),
    "synchronous_average": (gs.synchronous_average, st.tuples(_arrays, _ints),
                            st.fixed_dictionaries({}, optional={"n_cycles": _ints})),
    "harmonic_signal": (gs.harmonic_signal, st.tuples(_arrays, _ints),
                        st.fixed_dictionaries({}, optional={"n_sidebands": _ints})),
    "difference_signal": (gs.difference_signal, st.tuples(_arrays, _ints),
                          st.fixed_dictionaries({}, optional={"n_sidebands": _ints})),
    "order_mask": (gs.order_mask, st.tuples(_ints, _ints),
                   st.fixed_dictionaries({}, optional={"n_sidebands": _ints})),
    "mesh_band_orders": (gs.mesh_band_orders, st.tuples(_ints, _ints, _ints),
                         st.just({})),
    "rms": (gs.rms, st.tuples(_arg), st.just({})),
    "mean_rms": (gs.mean_rms, st.tuples(_arg), st.just({})),
    "envelope": (gs.envelope, st.tuples(_arg), st.just({})),
    "amplitude_spectrum": (gs.amplitude_spectrum, st.tuples(_arrays),
                           st.fixed_dictionaries({}, optional={"nfft": _ints})),
    "acs_background": (gs.acs_background, st.tuples(_arrays),
                       st.fixed_dictionaries({}, optional={"segment_size": _ints,
                                                           "overlap": _nums,
                                                           "percentile": _nums,
                                                           "symmetric": st.booleans()})),
    "real_cepstrum": (gs.real_cepstrum, st.tuples(_arg), st.just({})),
    "minimum_phase": (gs.minimum_phase, st.tuples(_arg), st.just({})),
    "fractional_shift": (gs.fractional_shift, st.tuples(_arrays, _arg), st.just({})),
    "subtract_healthy": (gs.subtract_healthy, st.tuples(_arrays, _arrays),
                         st.fixed_dictionaries({}, optional={"upsample": _ints,
                                                             "return_details": st.booleans()})),
    "subtract_blend": (gs.subtract_blend, st.tuples(_arrays, _arrays),
                       st.fixed_dictionaries({}, optional={"n_blend": _ints,
                                                           "upsample": _ints,
                                                           "lags": _arg})),
    "extract_features": (extract_features, st.tuples(_arrays, _ints),
                         st.fixed_dictionaries({}, optional={
                             "names": st.one_of(st.lists(st.sampled_from(
                                 list(available_features())), min_size=1, max_size=3), _arg),
                             "n_sidebands": _ints, "baseline_variance": _nums})),
    "na4_baseline_variance": (na4_baseline_variance, st.tuples(_arrays, _ints), st.just({})),
    "regular_signal": (gs.regular_signal, st.tuples(_arrays, _ints),
                       st.fixed_dictionaries({}, optional={"n_sidebands": _ints,
                                                           "shaft_orders": _arg})),
    "residual_signal": (gs.residual_signal, st.tuples(_arrays, _ints),
                        st.fixed_dictionaries({}, optional={"shaft_orders": _arg})),
    "nonsynchronous_signal": (gs.nonsynchronous_signal, st.tuples(_arrays, _ints),
                              st.just({})),
    "speed_ridge": (gs.speed_ridge, st.tuples(_arrays, _nums),
                    st.fixed_dictionaries({"orders": _arg, "speed_range": _arg},
                                          optional={"n_harmonics": _ints, "window": _nums,
                                                    "max_rate": _nums, "smooth": _nums,
                                                    "track": _ints})),
    "demodulate_angle": (gs.demodulate_angle, st.tuples(_arrays, _nums),
                         st.fixed_dictionaries({"order": _ints, "ridge_times": _arg,
                                                "ridge_speed": _arg},
                                               optional={"bandwidth": _nums})),
    "angle_pulse_times": (gs.angle_pulse_times, st.tuples(_arg, _arg),
                          st.fixed_dictionaries({}, optional={"pulses_per_rev": _ints})),
    "estimate_shaft_angle": (gs.estimate_shaft_angle, st.tuples(_arrays, _nums),
                             st.fixed_dictionaries({"orders": _arg, "speed_range": _arg},
                                                   optional={"bandwidth": _nums,
                                                             "min_snr_db": _nums,
                                                             "max_wander": _nums,
                                                             "min_lines": _ints,
                                                             "pulses_per_rev": _ints})),
}
#: cases per function; 28 functions × 60 = 1,680 fuzzed calls in CI
FUZZ_EXAMPLES = 60


def call_only_gearshot_errors(func, args, kwargs):
    """Call; GearshotError is fine, any other exception or RuntimeWarning fails."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        try:
            func(*args, **kwargs)
        except GearshotError:
            pass


@pytest.mark.parametrize("name", sorted(FUZZ))
def test_fuzz_public_function(name):
    func, args_st, kwargs_st = FUZZ[name]

    @settings(max_examples=FUZZ_EXAMPLES, deadline=None,
              suppress_health_check=list(HealthCheck))
    @given(args=args_st, kwargs=kwargs_st)
    def run(args, kwargs):
        call_only_gearshot_errors(func, args, kwargs)

    run()


def test_fuzz_covers_every_public_function():
    assert set(FUZZ) >= set(gs.__all__)
    assert len(FUZZ) * FUZZ_EXAMPLES >= 1000


# ---------------------------------------------------------------- command line, failures
_HOME = None


def _env(**extra):
    global _HOME
    if _HOME is None:
        import tempfile
        _HOME = tempfile.mkdtemp(prefix="gearshot-reliability-")
    return dict(os.environ, PYTHONPATH=str(SRC), GEARSHOT_DATA=extra.pop("data", _HOME),
                **extra)


def run_cli(args, *, cwd=None, preexec_fn=None, env=None, timeout=120):
    return subprocess.run([sys.executable, "-m", "gearshot.app.cli", *map(str, args)],
                          capture_output=True, text=True, timeout=timeout, cwd=cwd,
                          preexec_fn=preexec_fn, env=env or _env())


def one_line_error(res, *words):
    err = res.stderr.strip()
    assert res.returncode != 0, (res.stdout, err)
    assert "Traceback" not in err, err
    lines = [ln for ln in err.splitlines() if ln.startswith("gearshot: error:")]
    assert len(lines) == 1, err
    for word in words:
        assert str(word) in lines[0], err
    return lines[0]


def _limit_fsize(limit=50_000):
    def apply():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return apply


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    """A tiny virtual-rig campaign and database slice for predict (seconds)."""
    from gearshot.rig import VirtualRig

    folder = tmp_path_factory.mktemp("camp")
    idx = VirtualRig(seed=1, engine="surrogate").campaign(
        folder, speed=15, load=10, duration=8.0, healthy=1, sizes=(0.5,), repetitions=1,
        progress=False)
    return folder, idx


def predict_args(campaign, db, out):
    folder, idx = campaign
    healthy = idx.loc[idx.fault_size == 0, "path"].iloc[0]
    faulty = idx.loc[idx.fault_size > 0, "path"].iloc[0]
    return ["predict", "--database", db, "--healthy", healthy, "--faulty", faulty,
            "--faulty-size", "0.5", "--recordings", faulty, "--speed", "15", "--load", "10",
            "--out", out]


DUMMY = (None, pd.DataFrame({"path": ["/nonexistent/h.h5", "/nonexistent/f.h5"],
                             "fault_size": [0.0, 0.5]}))


@pytest.mark.parametrize("case", ["dev-full", "parent-is-file", "out-is-folder"])
def test_cli_predict_bad_outputs_fail_early(tmp_path, case):
    """Checked before anything is read or fitted (the recordings here do not even exist)."""
    (tmp_path / "file").write_text("x")
    out = {"dev-full": "/dev/full", "parent-is-file": tmp_path / "file" / "p.csv",
           "out-is-folder": tmp_path}[case]
    res = run_cli(predict_args(DUMMY, tmp_path / "no-db", out))
    words = {"dev-full": ["/dev/full"], "parent-is-file": ["file"],
             "out-is-folder": [str(tmp_path)]}[case]
    one_line_error(res, *words)
    assert (tmp_path / "file").read_text() == "x"
    assert not (tmp_path / "p.csv").exists() and not leftovers(tmp_path)


def _lock(folder: Path) -> None:
    """Make ``folder`` unwritable: mode 0o555, and for root (who ignores modes) immutable."""
    folder.chmod(0o555)
    if ROOT:
        res = subprocess.run(["chattr", "+i", str(folder)], capture_output=True)
        if res.returncode != 0:
            folder.chmod(0o755)
            pytest.skip("running as root without chattr: no folder is read-only")


def _unlock(folder: Path) -> None:
    if ROOT:
        subprocess.run(["chattr", "-i", str(folder)], capture_output=True)
    folder.chmod(0o755)


@pytest.mark.parametrize("command", ["rig", "predict", "simulate"])
def test_cli_read_only_folder(tmp_path, command):
    locked = tmp_path / "locked"
    locked.mkdir()
    _lock(locked)
    try:
        args = {"rig": ["rig", locked / "camp", "--duration", "8", "--healthy", "1",
                        "--repetitions", "0"],
                "predict": predict_args(DUMMY, tmp_path / "no-db", locked / "p.csv"),
                "simulate": ["simulate", "--store", locked / "db", "--grade", "7"]}[command]
        one_line_error(run_cli(args), "locked")
        assert not list(locked.iterdir())
    finally:
        _unlock(locked)


@pytest.mark.slow
def test_cli_rig_file_size_limit_leaves_nothing(tmp_path):
    res = run_cli(["rig", tmp_path / "camp", "--duration", "8", "--healthy", "1",
                   "--repetitions", "0"], preexec_fn=_limit_fsize(100_000))
    one_line_error(res, "camp")
    camp = tmp_path / "camp"
    assert not camp.exists() or not any(camp.iterdir())


@pytest.mark.slow
def test_cli_simulate_file_size_limit_then_resume(tmp_path):
    store = tmp_path / "db"
    args = ["simulate", "--store", store, "--speed", "15", "--load", "10", "--grade", "7",
            "--n-healthy", "1", "--n-faulty", "1", "--workers", "1"]
    res = run_cli(args, preexec_fn=_limit_fsize(20_000))
    one_line_error(res, "db")
    assert not list((store / "blocks").glob("*.zarr")) and not leftovers(store)
    ok = run_cli(args)
    assert ok.returncode == 0, ok.stderr


@pytest.mark.parametrize("args, words", [
    (["rig", "{tmp}/c", "--duration", "0.05"], ["--duration", "0.05", "gear revolution"]),
    (["rig", "{tmp}/c", "--duration", "1e9"], ["--duration"]),
    (["rig", "{tmp}/c", "--healthy", "1000000"], ["--healthy"]),
    (["rig", "{tmp}/file/c"], ["file"]),
    (["simulate", "--store", "{tmp}/file"], ["--store", "folder"]),
    (["simulate", "--store", "{tmp}/db", "--n-faulty", "10000000"], ["--n-faulty"]),
    (["report", "{tmp}/nothing.json"], ["nothing.json"]),
    (["report", "{tmp}/file", "--out", "{tmp}/file"], ["--out"]),
    (["experiment", "rig", "--duration", "0.05"], ["--duration"]),
    (["experiment", "rig", "--json", "/dev/full"], ["--json", "/dev/full"]),
    (["experiment", "simulated", "--json", "{tmp}/file/x.json"], ["--json"]),
    (["demo", "--out", "{tmp}/file"], ["--out"]),
])
def test_cli_bad_command_lines(tmp_path, args, words):
    (tmp_path / "file").write_text("x")
    args = [a.replace("{tmp}", str(tmp_path)) for a in args]
    words = [w.replace("{tmp}", str(tmp_path)) for w in words]
    one_line_error(run_cli(args, env=_env(data=str(tmp_path / "home"))), *words)
    assert (tmp_path / "file").read_text() == "x"
    assert not leftovers(tmp_path)


@pytest.mark.slow
def test_cli_damaged_database_is_named(small_db, tmp_path, campaign):
    store = _copy(small_db[0], tmp_path)
    (store / "blocks" / "s0_l0_g0.zarr" / "sa" / "c" / "0" / "0").write_bytes(b"junk")
    res = run_cli(predict_args(campaign, store, tmp_path / "p.csv"))
    one_line_error(res, str(store), "s0_l0_g0.zarr", "gearshot simulate")
    assert not (tmp_path / "p.csv").exists()
