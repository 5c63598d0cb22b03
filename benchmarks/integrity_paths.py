"""Failure paths of issue #22: concurrency, manifest tampering, hostile files, disk full.

Prints the counts that must all be zero: mixed stores, silently wrong loads, hangs, code
executed by a model file, exit-3 ("unexpected") errors on user input, leftovers.

    PYTHONPATH=src python benchmarks/integrity_paths.py [--trials 10]

The cases are those of tests/test_integrity.py (imported from there, so the benchmark and
the tests cannot drift apart), with more trials. ``failure_paths.py`` runs this too.
"""

from __future__ import annotations

import argparse
import errno
import functools
import importlib.util
import json
import multiprocessing as mp
import os
import shutil
import signal
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT / "tests"))

import numpy as np  # noqa: E402

from gearshot import GearshotError  # noqa: E402

_spec = importlib.util.spec_from_file_location("integ", ROOT / "tests" / "test_integrity.py")
integ = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(integ)

HANG_S = 15.0


def concurrency(work: Path, trials: int) -> dict:
    mixed = both_ok = 0
    for t in range(trials):
        store, go = work / f"race{t}", work / f"go{t}"
        procs = [integ._builder(store, seed, go) for seed in (0, 5)]
        time.sleep(1.5)
        go.write_text("go")
        outs = [p.communicate(timeout=600)[0].strip().splitlines()[-1] for p in procs]
        both_ok += outs.count("OK") == 2
        seeds = set(integ._seeds_of(store).values())
        man = json.loads((store / "manifest.json").read_text())["seed"]
        mixed += len(seeds) != 1 or seeds != {man}
    same_mixed = 0
    for t in range(max(1, trials // 3)):      # identical arguments: wait and share
        store, go = work / f"same{t}", work / f"gs{t}"
        procs = [integ._builder(store, 3, go) for _ in range(2)]
        time.sleep(1.5)
        go.write_text("go")
        outs = [p.communicate(timeout=600)[0].strip().splitlines()[-1] for p in procs]
        same_mixed += outs != ["OK", "OK"] or set(integ._seeds_of(store).values()) != {3}
    stale = 0
    for t in range(max(1, trials // 3)):      # kill -9 inside a block, then build again
        store = work / f"kill{t}"
        proc = integ._builder(store, 3, pause=30.0)
        deadline = time.monotonic() + 120
        while not list((store / "blocks").glob(".*.tmp")) and time.monotonic() < deadline:
            time.sleep(0.05)
        proc.send_signal(signal.SIGKILL)
        proc.communicate(timeout=60)
        res = integ._builder(store, 3, pause=0.0).communicate(timeout=600)[0]
        stale += res.strip().splitlines()[-1] != "OK" or bool(integ._leftovers(store))
    return {"trials (seeds 0 / 5 at the same instant)": trials, "mixed stores": mixed,
            "both reported success": both_ok,
            "identical builds not sharing cleanly": same_mixed,
            "stale lock or leftovers after kill -9": stale}


def tampering(work: Path) -> dict:
    import gearshot.sim.database as d
    from gearshot.sim import build_database, load_database
    from gearshot.sim._db_checksums import write_checksums as _write_checksums

    d.simulate_sa = integ._fake_simulate_sa
    kw = integ.KW
    ref = build_database(work / "ref", **kw)
    other = build_database(work / "other", **{**kw, "seed": 9})
    wrong = failed_repair = cases = 0
    for edit, load_kw in integ.test_edited_manifest_is_caught_and_the_named_repair_works \
            .pytestmark[0].args[1]:
        store = work / f"edit{cases}"
        shutil.copytree(ref, store)
        man = json.loads((store / "manifest.json").read_text())
        (store / "manifest.json").write_text(json.dumps({**man, **edit}))
        cases += 1
        try:
            load_database(store, **load_kw)
            wrong += 1
        except GearshotError:
            pass
        build_database(store, **kw)
        failed_repair += json.loads((store / "manifest.json").read_text()) != man
    for how in ("lost-checksum", "foreign-old-record", "foreign-digest"):
        store = work / f"{how}"
        shutil.copytree(ref, store)
        block = store / "blocks" / "s0_l0_g1.zarr"
        if how == "lost-checksum":
            meta = json.loads((block / "zarr.json").read_text())
            del meta["attributes"]["gearshot_block"]
            (block / "zarr.json").write_text(json.dumps(meta))
        else:
            shutil.rmtree(block)
            shutil.copytree(other / "blocks" / "s0_l0_g1.zarr", block)
            if how == "foreign-old-record":
                _write_checksums(block, json.loads((store / "manifest.json").read_text()))
                integ._edit_record(block, manifest_sha256=None)
        cases += 1
        try:
            load_database(store, speed=15, load=10)
            wrong += 1
        except GearshotError:
            pass
        build_database(store, **kw)
        failed_repair += not np.array_equal(load_database(store, speed=15, load=10).sa.values,
                                            load_database(ref, speed=15, load=10).sa.values)
    return {"tampered stores": cases, "silently wrong loads": wrong,
            "named repair failed": failed_repair}


def _read_child(path, q):
    from gearshot.io import Recording

    try:
        Recording.read(path)
        q.put("OK")
    except GearshotError:
        q.put("error")
    except Exception as exc:  # noqa: BLE001 - counted
        q.put(f"{type(exc).__name__}")


def hostile(work: Path) -> dict:
    from gearshot.io import Recording

    rng = np.random.default_rng(0)
    n = 200_000
    tacho = (np.sin(2 * np.pi * 15 * np.arange(n) / 20_000) > 0.99).astype(float)
    rec = Recording(rng.standard_normal(n), tacho, 20_000.0, speed=15.0)
    files = hangs = silent = other = 0
    slowest = 0.0
    for suffix in (".h5", ".wav", ".mat", ".csv"):
        base = work / f"base{suffix}"
        rec.write(base)
        data = base.read_bytes()
        for k in range(1, 24):
            cut = int(len(data) * k / 24)
            path = work / f"z{k}{suffix}"
            path.write_bytes(data[:cut] + b"\0" * (len(data) - cut))
            if suffix == ".wav":
                shutil.copy(Path(str(base) + ".json"), Path(str(path) + ".json"))
            q = mp.Queue()
            p = mp.Process(target=_read_child, args=(path, q))
            t0 = time.monotonic()
            p.start()
            p.join(HANG_S)
            files += 1
            if p.is_alive():
                p.kill()
                hangs += 1
                continue
            slowest = max(slowest, time.monotonic() - t0)
            res = q.get()
            silent += res == "OK"
            other += res not in ("OK", "error")
    marker = work / "pwned"
    code_run = 0
    import joblib
    import skops.io as sio

    from gearshot.estimator import load_estimator

    joblib.dump({"format": "gearshot-estimator/1", "estimator": integ._Evil(marker)},
                work / "evil.joblib")
    sio.dump({"format": "gearshot-estimator/2", "estimator": os.system}, work / "evil.skops")
    models = 0
    for f in ("evil.joblib", "evil.skops"):
        models += 1
        try:
            load_estimator(work / f)
        except GearshotError:
            pass
        code_run += marker.exists()
    return {"damaged recordings (4 formats x 23 zeroed tails)": files, "hangs > 15 s": hangs,
            "silently wrong loads": silent, "non-GearshotError": other,
            "slowest failure (s)": round(slowest, 2), "crafted model files": models,
            "code executed": code_run}


def disk_full(work: Path) -> dict:
    """ENOSPC simulated two ways: while the data are written (a block's chunks, a PNG: the
    library writes part of the file, then fails) and at ``fsync`` (every writer; as on a
    file system with delayed allocation). Each must give one GearshotError line naming
    ENOSPC and leave no temporary or partial file."""
    import xarray as xr
    from matplotlib.figure import Figure

    import gearshot._atomic as atomic
    import gearshot.sim.database as d
    from gearshot._atomic import write_json_atomic
    from gearshot.app.indicators import indicator_figures
    from gearshot.io import Recording

    def enospc(*a, **k):
        raise OSError(errno.ENOSPC, "No space left on device")

    rec = Recording(np.random.default_rng(0).standard_normal(5000), None, 1000.0)
    real = (xr.Dataset.to_zarr, Figure.savefig, atomic._fsync_file)

    def half_zarr(self, store, *a, **k):
        real[0](self, store, *a, **k)
        enospc()

    def half_png(self, fname, *a, **k):
        Path(fname).write_bytes(b"")
        enospc()

    payload = {"records": [{"file": "a_30hz.zip", "speed_hz": 30.0, "n_cycles": 1,
                            "indicators": {"rms": 1.0}}]}
    jobs = {
        "database block": lambda f: d.build_database(f / "db", **integ.KW),
        "figure": lambda f: indicator_figures(payload, f / "figs"),
        "json": lambda f: write_json_atomic({"a": 1}, f / "x.json"),
    }
    for fmt in ("h5", "csv", "mat", "wav"):
        jobs[f"recording .{fmt}"] = functools.partial(_write_rec, rec, fmt)
    d.simulate_sa = integ._fake_simulate_sa
    cases = bad = 0
    left: list[str] = []
    for mode in ("during write", "at fsync"):
        for name, job in jobs.items():
            if mode == "during write" and name not in ("database block", "figure"):
                continue
            folder = work / f"{mode}-{name}".replace(" ", "_")
            folder.mkdir()
            cases += 1
            if mode == "during write":
                xr.Dataset.to_zarr, Figure.savefig = half_zarr, half_png
            else:
                atomic._fsync_file = enospc
            try:
                job(folder)
                bad += 1
            except GearshotError as exc:
                bad += "\n" in str(exc) or "No space left" not in str(exc)
            except Exception:  # noqa: BLE001 - counted
                bad += 1
            finally:
                xr.Dataset.to_zarr, Figure.savefig, atomic._fsync_file = real
            left += integ._leftovers(folder)
            left += [str(p) for p in folder.rglob("*") if p.is_file()
                     and not p.name.startswith(".gearshot.")
                     and p.name != "manifest.json"]
    return {"writes under a full disk": cases,
            "not one GearshotError line naming ENOSPC": bad, "leftovers": len(left)}


def _write_rec(rec, fmt, folder):
    rec.write(folder / f"r.{fmt}")


def user_errors(work: Path) -> dict:
    exit3 = not_one_line = 0
    for name, (make, _words) in sorted(integ.USER_ERRORS.items()):
        folder = work / f"cli-{len(name)}-{abs(hash(name)) % 10**6}"
        folder.mkdir()
        res = integ._cli(make(folder), folder)
        exit3 += res.returncode == 3
        lines = [ln for ln in res.stderr.splitlines() if ln.startswith("gearshot: error:")]
        not_one_line += len(lines) != 1 or res.returncode == 0
        print(f"  {res.returncode}  {name}: {lines[0][:150] if lines else res.stderr[-150:]}")
    return {"user-input command lines of #22": len(integ.USER_ERRORS), "exit 3": exit3,
            "not exactly one error line / exit 0": not_one_line}


def main(trials: int = 10) -> dict:
    work = Path(tempfile.mkdtemp(prefix="gearshot-integrity-"))
    t0 = time.perf_counter()
    out = {}
    for name, func in (("concurrency", lambda w: concurrency(w, trials)),
                       ("manifest tampering", tampering), ("hostile files", hostile),
                       ("disk full", disk_full), ("exit 3 on user input", user_errors)):
        folder = work / name.replace(" ", "_")
        folder.mkdir()
        t = time.perf_counter()
        out[name] = func(folder)
        print(f"{name} ({time.perf_counter() - t:.0f} s): {out[name]}", flush=True)
    shutil.rmtree(work, ignore_errors=True)
    print(f"({time.perf_counter() - t0:.0f} s)")
    return out


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--trials", type=int, default=10)
    main(ap.parse_args().trials)
