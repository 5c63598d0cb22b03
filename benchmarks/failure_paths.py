"""Failure paths of issue #15: bad command lines, bad API calls, fuzzed calls.

Runs every case and prints the counts that must all be zero: tracebacks, partial (or
temporary) files left behind, command lines that exit 0 or print more than one error line,
and exceptions other than GearshotError (or RuntimeWarnings) from the public API.

    PYTHONPATH=src python benchmarks/failure_paths.py

It ends with the cases of issue #22 (``benchmarks/integrity_paths.py``: concurrent builds,
manifest tampering, zeroed recordings and crafted model files, a full disk, exit 3) and
those of issue #32 (``benchmarks/report_paths.py``: ``gearshot report`` on malformed
outputs, ``gearshot simulate --repair`` after every kind of store damage).

The API table and the fuzz strategies are those of tests/test_reliability.py (imported from
there, so the benchmark and the tests cannot drift apart); here each fuzzed function gets
120 examples instead of CI's 60.
"""

from __future__ import annotations

import importlib.util
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"
sys.path.insert(0, str(SRC))

from gearshot import GearshotError  # noqa: E402

spec = importlib.util.spec_from_file_location("reliability", ROOT / "tests" / "test_reliability.py")
rel = importlib.util.module_from_spec(spec)
spec.loader.exec_module(rel)


def fsize(limit):
    def apply():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return apply


def leftovers(folder: Path) -> list[Path]:
    return [p for p in folder.rglob("*") if p.name.startswith(".") and "tmp" in p.name]


def main() -> None:
    work = Path(tempfile.mkdtemp(prefix="gearshot-failures-"))
    home = work / "home"
    env = dict(os.environ, PYTHONPATH=str(SRC), GEARSHOT_DATA=str(home))
    t0 = time.perf_counter()

    # fixtures: a file, a locked folder, a small campaign, a damaged database
    (work / "file").write_text("x")
    locked = work / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    immutable = os.geteuid() == 0 and subprocess.run(
        ["chattr", "+i", str(locked)], capture_output=True).returncode == 0
    from gearshot.rig import VirtualRig
    from gearshot.sim import build_database

    idx = VirtualRig(seed=1, engine="surrogate").campaign(
        work / "camp", speed=15, load=10, duration=8.0, healthy=1, sizes=(0.5,),
        repetitions=1, progress=False)
    healthy = idx.loc[idx.fault_size == 0, "path"].iloc[0]
    faulty = idx.loc[idx.fault_size > 0, "path"].iloc[0]
    db = work / "db"
    build_database(db, speeds=[15], loads=[10], grades=[7], n_healthy=1, n_faulty=1,
                   n_points=64, client=False, progress=False)
    (db / "blocks" / "s0_l0_g0.zarr" / "sa" / "c" / "0" / "0").write_bytes(b"junk")
    db_missing = work / "db-missing"
    shutil.copytree(db, db_missing)
    build_database(db_missing, speeds=[15], loads=[10], grades=[7], n_healthy=1, n_faulty=1,
                   n_points=64, client=False, progress=False)   # repairs it
    (db_missing / "blocks" / "s0_l0_g0.zarr" / "sa" / "c" / "0" / "0").unlink()
    db_manifest = work / "db-manifest"
    shutil.copytree(db_missing, db_manifest)
    (db_manifest / "manifest.json").write_text("{not json")

    def predict(database, out):
        return ["predict", "--database", database, "--healthy", healthy, "--faulty", faulty,
                "--faulty-size", "0.5", "--recordings", faulty, "--speed", "15", "--load",
                "10", "--out", out]

    W = str(work)
    # (command line, outputs that must not exist afterwards, preexec_fn)
    cases = [
        (predict(db, "/dev/full"), [], None),
        (predict(db, f"{W}/file/p.csv"), [], None),
        (predict(db, W), [], None),
        (predict(db, f"{W}/locked/p.csv"), [f"{W}/locked/p.csv"], None),
        (predict(db, f"{W}/p1.csv"), [f"{W}/p1.csv"], None),            # junk chunk
        (predict(db_missing, f"{W}/p2.csv"), [f"{W}/p2.csv"], None),    # missing chunk
        (predict(db_manifest, f"{W}/p3.csv"), [f"{W}/p3.csv"], None),   # bad manifest
        (predict(f"{W}/no-db", f"{W}/p4.csv"), [f"{W}/p4.csv"], None),
        (predict(db, f"{W}/p5.json") [:-2] + ["--faulty-size", "0", "--out", f"{W}/p5.json"],
         [f"{W}/p5.json"], None),
        (predict(db, f"{W}/p6.csv")[:-2] + ["--coverage", "1.5", "--out", f"{W}/p6.csv"],
         [f"{W}/p6.csv"], None),
        (["rig", f"{W}/rig1", "--duration", "0.05"], [f"{W}/rig1"], None),
        (["rig", f"{W}/rig2", "--duration", "1e9"], [f"{W}/rig2"], None),
        (["rig", f"{W}/rig3", "--healthy", "10000000"], [f"{W}/rig3"], None),
        (["rig", f"{W}/rig4", "--speed", "-1"], [f"{W}/rig4"], None),
        (["rig", f"{W}/file/rig"], [], None),
        (["rig", f"{W}/locked/rig"], [f"{W}/locked/rig"], None),
        (["rig", f"{W}/rig5", "--duration", "8", "--healthy", "1", "--repetitions", "0"],
         [f"{W}/rig5/s15_l10_y0.00_r0.h5", f"{W}/rig5/index.csv"], fsize(100_000)),
        (["rig", f"{W}/rig6", "--rig-grade", "13"], [f"{W}/rig6"], None),
        (["simulate", "--store", f"{W}/file"], [], None),
        (["simulate", "--store", f"{W}/file/db"], [], None),
        (["simulate", "--store", f"{W}/locked/db"], [f"{W}/locked/db"], None),
        (["simulate", "--store", f"{W}/db2", "--n-faulty", "100000000"], [f"{W}/db2"], None),
        (["simulate", "--store", f"{W}/db3", "--grade", "13"], [f"{W}/db3"], None),
        (["simulate", "--store", f"{W}/db4", "--grade", "7", "--n-healthy", "1", "--n-faulty",
          "1"], [f"{W}/db4/blocks/s0_l0_g0.zarr"], fsize(20_000)),
        (["simulate", "--store", str(db), "--grade", "7", "--seed", "5", "--n-healthy", "1",
          "--n-faulty", "1"], [], None),                                # other build
        (["report", f"{W}/nothing.json"], [], None),
        (["report", f"{W}/file", "--out", f"{W}/file"], [], None),
        (["report", f"{W}/file", "--out", f"{W}/rep"], [f"{W}/rep/report.md"], None),
        (["experiment", "rig", "--duration", "0.05"], [], None),
        (["experiment", "rig", "--json", "/dev/full"], [], None),
        (["experiment", "rig", "--out", f"{W}/file"], [], None),
        (["experiment", "rig", "--repeats", "0"], [], None),
        (["experiment", "simulated", "--json", f"{W}/file/x.json"], [], None),
        (["experiment", "simulated", "--frf-folder", f"{W}/nothing"], [], None),
        (["demo", "--out", f"{W}/file"], [], None),
        (["demo", "--out", f"{W}/locked/demo"], [f"{W}/locked/demo"], None),
    ]
    n_tb = n_partial = n_zero = n_lines = 0
    print(f"{'exit':>4}  command line -> error line")
    for args, must_not_exist, preexec in cases:
        args = [str(a) for a in args]
        res = subprocess.run([sys.executable, "-m", "gearshot.app.cli", *args],
                             capture_output=True, text=True, env=env, preexec_fn=preexec,
                             timeout=600)
        err = [ln for ln in res.stderr.splitlines() if ln.startswith("gearshot: error:")]
        tb = "Traceback" in res.stderr
        partial = [p for p in must_not_exist if Path(p).exists()]
        n_tb += tb
        n_partial += bool(partial)
        n_zero += res.returncode == 0
        n_lines += len(err) != 1
        shown = " ".join(a.replace(W, "$W") for a in args)
        line = (err[0] if err else res.stderr.strip()[-200:]).replace(W, "$W")
        print(f"{res.returncode:>4}  gearshot {shown}\n      -> {line[:200]}"
              + (f"  PARTIAL {partial}" if partial else "") + ("  TRACEBACK" if tb else ""))
    tmp_left = [p for p in leftovers(work)]
    n_cli = len(cases)

    # API table and fuzz
    n_api_bad = 0
    for name, call in rel.API_CASES.items():
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            try:
                call()
                n_api_bad += 1
                print(f"API {name}: no error")
            except GearshotError:
                pass
            except Exception as exc:  # noqa: BLE001 - counted
                n_api_bad += 1
                print(f"API {name}: {type(exc).__name__}: {exc}")

    from hypothesis import HealthCheck, given, settings

    n_fuzz = n_fuzz_bad = 0
    def fuzz(name, func, args_st, kwargs_st):
        @settings(max_examples=120, deadline=None, derandomize=True, database=None,
                  suppress_health_check=list(HealthCheck))
        @given(args=args_st, kwargs=kwargs_st)
        def run(args, kwargs):
            nonlocal n_fuzz, n_fuzz_bad
            n_fuzz += 1
            try:
                rel.call_only_gearshot_errors(func, args, kwargs)
            except Exception as exc:  # noqa: BLE001 - counted
                n_fuzz_bad += 1
                print(f"fuzz {name}: {type(exc).__name__}: {str(exc)[:120]}")
        run()

    for name, (func, args_st, kwargs_st) in rel.FUZZ.items():
        fuzz(name, func, args_st, kwargs_st)

    if immutable:
        subprocess.run(["chattr", "-i", str(locked)], capture_output=True)
    locked.chmod(0o755)
    shutil.rmtree(work, ignore_errors=True)
    print()
    print(f"bad command lines: {n_cli}; tracebacks {n_tb}; partial files {n_partial}; "
          f"temporaries left {len(tmp_left)}; exit 0 {n_zero}; not exactly one error line "
          f"{n_lines}")
    print(f"bad API calls: {len(rel.API_CASES)}; non-GearshotError or no error {n_api_bad}")
    print(f"fuzzed calls: {n_fuzz} over {len(rel.FUZZ)} functions; non-GearshotError "
          f"exceptions or RuntimeWarnings {n_fuzz_bad}")
    print(f"({time.perf_counter() - t0:.0f} s)")

    # issue #22: concurrency, manifest tampering, hostile files, disk full, exit 3
    print()
    spec22 = importlib.util.spec_from_file_location("integrity_paths",
                                                    ROOT / "benchmarks" / "integrity_paths.py")
    integrity = importlib.util.module_from_spec(spec22)
    spec22.loader.exec_module(integrity)
    integrity.main(trials=10)

    # issue #32: report on malformed outputs, repairs
    print()
    spec32 = importlib.util.spec_from_file_location("report_paths",
                                                    ROOT / "benchmarks" / "report_paths.py")
    report_paths = importlib.util.module_from_spec(spec32)
    spec32.loader.exec_module(report_paths)
    report_paths.main()


if __name__ == "__main__":
    main()
