"""Failure paths of issue #15: bad command lines, bad API calls, fuzzed calls.

Runs every case and prints the counts that must all be zero: tracebacks, partial (or
temporary) files left behind, command lines that exit 0 or print more than one error line,
and exceptions other than GearshotError (or RuntimeWarnings) from the public API.

    PYTHONPATH=src python benchmarks/failure_paths.py

It ends with the cases of issue #22 (``benchmarks/integrity_paths.py``: concurrent builds,
manifest tampering, zeroed recordings and crafted model files, a full disk, exit 3) and
those of issue #32 (``benchmarks/report_paths.py``: ``gearshot report`` on malformed
outputs, ``gearshot simulate --repair`` after every kind of store damage).

The command-line contract of issue #32 (options never silently ignored, empty paths, stores
into folders of other files, checks before the long work, the same bounds everywhere, a
batch past bad records, all-or-nothing outputs on a full disk, speed hints) runs first;
``--contract`` runs only that part:

    PYTHONPATH=src python benchmarks/failure_paths.py --contract

The API table and the fuzz strategies are those of tests/test_reliability.py (imported from
there, so the benchmark and the tests cannot drift apart); here each fuzzed function gets
120 examples instead of CI's 60.
"""

from __future__ import annotations

import importlib.util
import json
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
sys.path.insert(0, str(ROOT / "tests"))

from phm09_records import crop as _crop  # noqa: E402  (the tests' cropped PHM09 records)

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


def contract() -> dict[str, int]:
    """Issue #32's command-line contract; prints one line per case and returns the counts
    that must be zero."""
    work = Path(tempfile.mkdtemp(prefix="gearshot-contract-"))
    env = dict(os.environ, PYTHONPATH=str(SRC), GEARSHOT_DATA=str(work / "home"))
    W = str(work)
    spur = ROOT / "examples" / "machines" / "phm09_spur.toml"
    notacho = ROOT / "examples" / "machines" / "phm09_spur_notacho.toml"
    camp = work / "camp"
    camp.mkdir()
    (camp / "index.csv").write_text("path,fault_size\n")
    (camp / "s15_l10_y0.00_r0.h5").write_bytes(b"x")
    phm = work / "phm"
    phm.mkdir()
    r30 = _crop("spur2_30hz_High_1.zip", phm, 100_000)
    r40 = _crop("spur3_40hz_High_1.zip", phm, 100_000)
    bad = phm / "broken.zip"
    bad.write_bytes(b"not a zip")
    pred = ["predict", "--database", f"{W}/db", "--healthy", f"{W}/h.h5", "--faulty",
            f"{W}/f.h5", "--faulty-size", "0.5", "--recordings", W, "--speed", "15"]
    big = str(2**40)
    # category -> [(command line, words the one error line must hold)]
    refused = {
        "ignored or overridden option": [
            (["simulate", "--paper", "--speed", "15"], ["--paper", "--speed"]),
            (["simulate", "--paper", "--load", "5"], ["--paper", "--load"]),
            (["simulate", "--paper", "--machine", spur], ["--paper", "--machine"]),
            (["experiment", "simulated", "--full", "--speed", "20"], ["--full", "--speed"]),
            (["experiment", "simulated", "--full", "--load", "5"], ["--full", "--load"]),
            (pred + ["--machine", spur, "--gear-teeth", "38"], ["--machine", "--gear-teeth"]),
            (pred + ["--machine", spur, "--pinion-teeth", "17"],
             ["--machine", "--pinion-teeth"]),
            (pred + ["--cycles-per-segment", "10"], ["--cycles-per-segment", "--machine"]),
            (pred + ["--sensor", "acc_input"], ["--sensor", "--machine"]),
            (pred + ["--speed-tolerance", "0.1"], ["--speed-tolerance", "--machine"]),
            (["experiment", "rig-family", "--range", "heldout", "--seed", "5"],
             ["--range", "--seed"]),
            (["simulate", "--machine", spur, "--store", f"{W}/db"], ["--machine", "--speed"]),
            (["indicators", "--machine", spur, "--shaft", "input", f"{r30}@30"],
             ["speed hint"]),
            (["-v", "-q", "rig", f"{W}/rig"], ["--verbose", "--quiet"]),
        ],
        "empty or foreign path": [
            (["simulate", "--store", ""], ["empty"]),
            (["rig", ""], ["empty"]),
            (["demo", "--out", ""], ["empty"]),
            (["demo", "--out="], ["--out", "empty"]),
            (["simulate", "--store", camp], ["--store", "not a gearshot database"]),
            (["experiment", "simulated", "--store", camp], ["--store", "index.csv"]),
            (["experiment", "rig", "--store", camp], ["--store", "index.csv"]),
        ],
        "bad value, checked before the long work": [
            (["experiment", "rig", "--attenuation-db", "inf"], ["--attenuation-db", "inf"]),
            (["experiment", "rig", "--attenuation-db", "-1"], ["--attenuation-db", "-1"]),
            (["experiment", "simulated", "--attenuation-db", "nan"], ["--attenuation-db"]),
            (["experiment", "simulated", "--attenuation-db", "-inf"], ["--attenuation-db"]),
            (["experiment", "simulated", "--attenuation-db", "1e308"], ["--attenuation-db"]),
            (["experiment", "simulated", "--attenuation-db", "-1000"], ["--attenuation-db"]),
            (["experiment", "simulated", "--selection-tf", "bogus"], ["--selection-tf"]),
            (["experiment", "simulated", "--n-healthy", "2"], ["--n-healthy", "2"]),
            (["experiment", "simulated", "--n-faulty", "3"], ["--n-faulty", "3"]),
            (["demo", "--seed", big], ["--seed", big]),
            (["demo", "--draws", "0"], ["--draws", "0"]),
            (["simulate", "--seed", big], ["--seed", big]),
            (["rig", f"{W}/rig", "--seed", big], ["--seed", big]),
            (["experiment", "simulated", "--seed", big], ["--seed", big]),
            (["experiment", "rig", "--seed", big], ["--seed", big]),
            (["simulate", "--load", "1e-320"], ["--load"]),
            (["rig", f"{W}/rig", "--load", "1e-320"], ["--load"]),
            (["experiment", "rig", "--load", "1e-320"], ["--load"]),
            (["experiment", "simulated", "--load", "1e-320"], ["--load"]),
            (["indicators", "--machine", notacho, "--shaft", "input", f"{r30}@fast"],
             ["'@'"]),
            (["indicators", "--machine", notacho, "--shaft", "input", r30, "--speed-hint",
              "1e9"], ["speed hint"]),
        ],
    }
    counts = dict(cases=0, exit3=0, ignored=0, not_one_line=0, slow=0, left_behind=0,
                  tracebacks=0)
    print(f"{'exit':>4} {'s':>5}  command line -> error line")

    def run(args, preexec=None):
        t0 = time.perf_counter()
        res = subprocess.run([sys.executable, "-m", "gearshot.app.cli", *map(str, args)],
                             capture_output=True, text=True, env=env, timeout=600,
                             preexec_fn=preexec, cwd=work)
        return res, time.perf_counter() - t0

    for category, cases in refused.items():
        print(f"-- {category}")
        for args, words in cases:
            before = sorted(p.name for p in work.iterdir())
            res, secs = run(args)
            err = [ln for ln in res.stderr.splitlines() if ln.strip()]
            counts["cases"] += 1
            counts["exit3"] += res.returncode == 3
            counts["tracebacks"] += "Traceback" in res.stderr
            # refused at once and naming what it refuses; otherwise the option was ignored
            counts["ignored"] += res.returncode != 2 or not err or not all(
                str(w) in err[0] for w in words)
            counts["not_one_line"] += len(err) != 1
            counts["slow"] += secs > 30          # a refusal after a build would take minutes
            counts["left_behind"] += sorted(p.name for p in work.iterdir()) != before
            shown = " ".join(str(a).replace(W, "$W").replace(str(ROOT) + "/", "")
                             for a in args)
            print(f"{res.returncode:>4} {secs:5.1f}  gearshot {shown}\n"
                  f"                -> {(err[0] if err else '').replace(W, '$W')[:160]}")

    print("-- a batch past bad records; all-or-nothing outputs; speed hints")
    ind = ["indicators", "--machine", spur, "--shaft", "input", "--sensor", "acc_input"]
    res, _ = run(ind + [r30, bad, r40, "--json", f"{W}/batch.json"])
    payload = json.loads((work / "batch.json").read_text()) if (
        work / "batch.json").is_file() else {"records": []}
    batch_ok = (res.returncode == 2 and len(payload["records"]) == 2
                and len(res.stderr.strip().splitlines()) == 2)
    counts["exit3"] += res.returncode == 3
    print(f"{res.returncode:>4}  indicators r30 broken.zip r40 -> {len(payload['records'])} "
          f"records written, {len(res.stderr.strip().splitlines())} error lines"
          f"{'' if batch_ok else '  FAILED'}")
    full_ok = True
    for limit in (20_000, 29_000, 33_000):         # a disk full after some of the figures
        out, figs = work / f"full{limit}.json", work / f"figs{limit}"
        res, _ = run(ind + [r30, "--json", out, "--out", figs], preexec=fsize(limit))
        pngs = list(figs.glob("*.png")) if figs.exists() else []
        clean = res.returncode != 0 and not out.exists() and not pngs
        full_ok &= clean and res.returncode != 3
        print(f"{res.returncode:>4}  indicators --json --out, files up to {limit} B -> "
              f"json {'written' if out.exists() else 'none'}, {len(pngs)} PNG(s)"
              f"{'' if clean else '  PARTIAL'}")
    res, _ = run(["indicators", "--machine", notacho, "--shaft", "input", "--sensor",
                  "acc_input", f"{r30}@30", r40, "--speed-hint", "40", "--json",
                  f"{W}/hint.json"])
    hinted = json.loads((work / "hint.json").read_text())["records"] if (
        work / "hint.json").is_file() else []
    hint_ok = res.returncode == 0 and [round(r["tacho_speed_hz"]) for r in hinted] == [30, 40]
    print(f"{res.returncode:>4}  indicators (no tacho) r30@30 r40 --speed-hint 40 -> "
          f"{[round(r['tacho_speed_hz'], 2) for r in hinted]} Hz"
          f"{'' if hint_ok else '  FAILED'}")
    counts.update(batch_failed=int(not batch_ok), partial_outputs=int(not full_ok),
                  hint_failed=int(not hint_ok))
    counts["temporaries_left"] = len(leftovers(work))
    shutil.rmtree(work, ignore_errors=True)
    print()
    print(f"command-line contract: {counts['cases']} refused command lines; exit 3 "
          f"{counts['exit3']}; silently ignored (not refused naming the options) "
          f"{counts['ignored']}; not exactly one error line {counts['not_one_line']}; "
          f"tracebacks {counts['tracebacks']}; refused after > 30 s {counts['slow']}; "
          f"files left behind {counts['left_behind']}; batch past a bad record failed "
          f"{counts['batch_failed']}; partial outputs on a full disk "
          f"{counts['partial_outputs']}; speed hints failed {counts['hint_failed']}; "
          f"temporaries left {counts['temporaries_left']}")
    return counts


def main() -> None:
    contract()
    if "--contract" in sys.argv[1:]:
        return
    print()
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
