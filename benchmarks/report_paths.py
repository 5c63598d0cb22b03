"""Failure paths of issue #32: ``gearshot report`` on malformed outputs, and the repairs.

Every malformed output of ``tests/test_report_inputs.py`` (imported from there, so the
benchmark and the tests cannot drift apart) goes through ``gearshot report`` as a whole
process; every kind of store damage of ``tests/test_store_repair.py`` is made on a small real
store and repaired with ``gearshot simulate --repair --store S``. Prints the counts that must
all be zero: exit 3, exit 0, not exactly one error line, tracebacks; repairs that leave a
store that does not load, or loads other data.

    PYTHONPATH=src python benchmarks/report_paths.py
"""

from __future__ import annotations

import importlib.util
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"
sys.path.insert(0, str(SRC))


def _tests(name: str):
    spec = importlib.util.spec_from_file_location(name, ROOT / "tests" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


CSV_CASES = {
    "predicted inf": "recording,predicted,low,high\na.zip,inf,0,1\n",
    "predicted -5": "recording,predicted,low,high\na.zip,-5,0,1\n",
    "predicted text": "recording,predicted,low,high\na.zip,abc,0,1\n",
    "no high column": "recording,predicted,low\na.zip,0.3,0\n",
    "empty recording": "recording,predicted,low,high\n,0.3,0.1,0.5\n",
    "other table": "x,y\n1,2\n",
    "binary": "\x00\x01\x02 not a table",
}


def report_cases(work: Path, env: dict) -> tuple[int, dict]:
    """``gearshot report`` on every malformed output; returns (cases, counts)."""
    cases = {f"{k}.json": v[0] for k, v in _tests("test_report_inputs").MALFORMED.items()}
    cases.update({f"{k}.csv": v for k, v in CSV_CASES.items()})
    counts = dict(exit3=0, exit0=0, lines=0, traceback=0)
    for name, content in cases.items():
        path = work / name.replace(" ", "_")
        path.write_text(content)
        res = subprocess.run([sys.executable, "-m", "gearshot.app.cli", "report", str(path),
                              "--out", str(work / "rep")], capture_output=True, text=True,
                             env=env, timeout=300)
        err = [ln for ln in res.stderr.splitlines() if ln.startswith("gearshot: error:")]
        counts["exit3"] += res.returncode == 3
        counts["exit0"] += res.returncode == 0
        counts["lines"] += len(err) != 1
        counts["traceback"] += "Traceback" in res.stderr
        print(f"{res.returncode:>4}  report {name:<32} -> "
              f"{(err[0] if err else res.stderr.strip()[-120:])[:150]}")
    return len(cases), counts


def _damage(store: Path, kind: str) -> None:
    man = store / "manifest.json"
    if kind == "edited CRC":
        meta_path = store / "blocks" / "s0_l0_g0.zarr" / "zarr.json"
        meta = json.loads(meta_path.read_text())
        files = meta["attributes"]["gearshot_block"]["files"]
        rel = sorted(files)[0]
        files[rel] = [files[rel][0], (files[rel][1] + 1) % 2 ** 32]
        meta_path.write_text(json.dumps(meta))
    elif kind == "chunk overwritten, size and time kept":
        chunk = next(p for p in (store / "blocks" / "s0_l0_g1.zarr" / "sa").rglob("*")
                     if p.is_file() and p.name != "zarr.json")
        st = chunk.stat()
        data = bytearray(chunk.read_bytes())
        data[-1] ^= 0xFF
        chunk.write_bytes(bytes(data))
        os.utime(chunk, ns=(st.st_atime_ns, st.st_mtime_ns))
    elif kind == "block deleted":
        shutil.rmtree(store / "blocks" / "s0_l0_g1.zarr")
    elif kind == "manifest deleted":
        man.unlink()
    elif kind == "manifest empty":
        man.write_text("")
    elif kind == "manifest invalid":
        man.write_text("{not json")
    elif kind == "manifest speed edited":
        man.write_text(json.dumps({**json.loads(man.read_text()), "speeds": [16.0]}))


REPAIRS = ("edited CRC", "chunk overwritten, size and time kept", "block deleted",
           "manifest deleted", "manifest empty", "manifest invalid", "manifest speed edited")


def repair_cases(work: Path, env: dict) -> tuple[int, dict]:
    """Each store damage, then ``gearshot simulate --repair``; the store must load and
    hold the data it held before."""
    from gearshot.sim import GearPair, build_database, load_database

    base = build_database(work / "base", GearPair.paper(), speeds=[15], loads=[10],
                          grades=[6, 7], n_healthy=1, n_faulty=1, seed=0, n_points=256,
                          client=False, progress=False)
    ref = load_database(base, speed=15, load=10).sa.values
    counts = dict(failed=0, wrong=0, not_loading=0)
    for kind in REPAIRS:
        store = work / kind.replace(" ", "_").replace(",", "")
        shutil.copytree(base, store)
        _damage(store, kind)
        res = subprocess.run([sys.executable, "-m", "gearshot.app.cli", "simulate", "--repair",
                              "--store", str(store)], capture_output=True, text=True,
                             env=env, timeout=600)
        counts["failed"] += res.returncode != 0
        try:
            got = load_database(store, speed=15, load=10).sa.values
            counts["wrong"] += not np.array_equal(got, ref)
            state = "loads, same data" if np.array_equal(got, ref) else "loads OTHER data"
        except Exception as exc:  # noqa: BLE001 - counted
            counts["not_loading"] += 1
            state = f"does not load: {exc}"[:120]
        print(f"{res.returncode:>4}  simulate --repair after {kind:<38} -> {state}; "
              f"{res.stdout.strip().splitlines()[0][:110] if res.stdout.strip() else ''}")
    return len(REPAIRS), counts


def main() -> None:
    work = Path(tempfile.mkdtemp(prefix="gearshot-report-paths-"))
    env = dict(os.environ, PYTHONPATH=str(SRC), GEARSHOT_DATA=str(work / "home"))
    t0 = time.perf_counter()
    try:
        n_rep, rep = report_cases(work, env)
        n_fix, fix = repair_cases(work, env)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print()
    print(f"malformed outputs given to report: {n_rep}; exit 3 {rep['exit3']}; exit 0 "
          f"{rep['exit0']}; not exactly one error line {rep['lines']}; tracebacks "
          f"{rep['traceback']}")
    print(f"store damages repaired with simulate --repair: {n_fix}; repair failed "
          f"{fix['failed']}; store does not load {fix['not_loading']}; loads other data "
          f"{fix['wrong']}")
    print(f"({time.perf_counter() - t0:.0f} s)")


if __name__ == "__main__":
    main()
