"""Machine file verified against the signal, and the tracked speed checked: the numbers of
benchmarks/RESULTS.md, "Trust: machine file and tracked speed".

    PYTHONPATH=src python benchmarks/machine_trust.py verify 30     # development records
    PYTHONPATH=src python benchmarks/machine_trust.py verify 40     # held-out records
    PYTHONPATH=src python benchmarks/machine_trust.py locks 30      # wrong locks forced
    PYTHONPATH=src python benchmarks/machine_trust.py speed 30 1,2,3   # uncertainty, dev
    PYTHONPATH=src python benchmarks/machine_trust.py speed 40 4,5,6   # held-out
    PYTHONPATH=src python benchmarks/machine_trust.py time 30

Records: ../shared/data/phm09 (PHM09 spur and helical, runs 1 and 2). Wrong machine files
are made from examples/machines in a temporary folder: pulses_per_rev = 1, fs = 50000,
the other gearbox's file, the tacho on the idler, a tooth count (the idler gear of the
first stage: 90 instead of 96 / 45 instead of 48).
"""

from __future__ import annotations

import dataclasses
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

import numpy as np

from gearshot import GearshotError, Machine
from gearshot.io import Recording
from gearshot.machine.signal_check import speed_check, verify_machine

ROOT = Path(__file__).resolve().parents[1]
PHM = ROOT.parent / "shared" / "data" / "phm09"
EXAMPLES = ROOT / "examples" / "machines"


def _files(speed: str) -> list[Path]:
    return sorted(PHM.glob(f"*_{speed}hz_*.zip"))


def _kind(path: Path) -> str:
    return "helical" if path.name.startswith("helical") else "spur"


def _wrong_files(folder: Path) -> dict[str, dict[str, Path]]:
    """{kind: {case: machine file}} of the correct and the wrong machine files."""
    out: dict[str, dict[str, Path]] = {}
    for kind, other, teeth in (("spur", "helical", ("96", "90")),
                               ("helical", "spur", ("48\n", "45\n"))):
        text = (EXAMPLES / f"phm09_{kind}.toml").read_text()
        cases = {
            "correct": text,
            "correct, no tacho": (EXAMPLES / f"phm09_{kind}_notacho.toml").read_text(),
            "pulses_per_rev = 1": text.replace("pulses_per_rev = 10", "pulses_per_rev = 1"),
            "fs = 50000": text.replace('fs = "200000/3"', "fs = 50000"),
            "other gearbox's file": (EXAMPLES / f"phm09_{other}.toml").read_text(),
            "tacho on the idler": text.replace('[tacho]\nchannel = "tacho"\nshaft = "input"',
                                               '[tacho]\nchannel = "tacho"\nshaft = "idler"'),
            "idler teeth (stage 1 driven)": text.replace(f"driven_teeth = {teeth[0]}",
                                                         f"driven_teeth = {teeth[1]}"),
        }
        out[kind] = {}
        for case, body in cases.items():
            path = folder / f"{kind}_{len(out[kind])}.toml"
            path.write_text(body)
            out[kind][case] = path
    return out


def _verdict(machine_file: Path, record: Path) -> str:
    try:
        verify_machine(machine_file, [record])
    except GearshotError as exc:
        text = str(exc)
        import re
        for key in (r"pulses_per_rev looks like \d+, not \d+", "fs off by factor",
                    r"tacho.shaft looks like '\w+'", "another gear train", "tooth count",
                    "tracked in the vibration", "no mesh harmonic", "do not stand"):
            hit = re.search(key, text)
            if hit:
                return f"refused: {hit.group(0)}"
        return "refused: " + text[:60]
    return "passed"


def verify(speed: str) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        files = _wrong_files(Path(tmp))
        for kind in ("spur", "helical"):
            records = [p for p in _files(speed) if _kind(p) == kind]
            for case, path in files[kind].items():
                # the other gearbox's file is applied to this kind's records
                verdicts = Counter(_verdict(path, r) for r in records)
                line = "; ".join(f"{v} {n}/{len(records)}" for v, n in verdicts.most_common())
                print(f"| {kind} records | {case} | {line} |")
        # several healthy records checked together (the odd-harmonic test pooled)
        for kind, other in (("spur", "helical"), ("helical", "spur")):
            healthy = [p for p in _files(speed) if p.name.startswith(f"{kind}1")
                       or p.name.startswith("spur3")]
            healthy = [p for p in healthy if _kind(p) == kind]
            for name, mf in (("correct", EXAMPLES / f"phm09_{kind}.toml"),
                             ("other gearbox's file", EXAMPLES / f"phm09_{other}.toml")):
                try:
                    verify_machine(mf, healthy)
                    v = "passed"
                except GearshotError as exc:
                    v = "refused: " + ("another gear train" if "another gear train" in str(exc)
                                       else str(exc)[:60])
                print(f"| {kind} healthy records {[p.name for p in healthy]} together | "
                      f"{name} | {v} |")


def locks(speed: str) -> None:
    """Ranges that make the comb lock wrongly: the nominal speed 2-4 % off, range +-10 %,
    (nominal above and below the true speed), and the shipped range."""
    with tempfile.TemporaryDirectory() as tmp:
        for path in _files(speed):
            kind = _kind(path)
            tacho = Recording.read(path, machine=EXAMPLES / f"phm09_{kind}.toml")
            true = tacho.shaft_speed()
            for label, (lo, hi) in (("shipped [26, 52]", (26.0, 52.0)),
                                    ("true x 1.03 +-10 %", (true * 1.03 * 0.9,
                                                            true * 1.03 * 1.1)),
                                    ("excludes true, above", (true * 1.01, true * 1.1)),
                                    ("excludes true, below", (true * 0.9, true * 0.99))):
                text = (EXAMPLES / f"phm09_{kind}_notacho.toml").read_text().replace(
                    "range_hz = [26, 52]", f"range_hz = [{lo:.3f}, {hi:.3f}]")
                mf = Path(tmp) / "m.toml"
                mf.write_text(text)
                rec = Recording.read(path, machine=mf)
                try:
                    tracked = rec.shaft_speed()
                    u = rec.speed_uncertainty
                    chk = speed_check(rec.machine, rec)
                    off = 100 * (tracked / true - 1)
                    print(f"| {path.name} | {label} | {off:+.2f} % | {abs(tracked - true) / u:.1f} "
                          f"| {'ok' if chk == 'ok' else 'FAILS: ' + chk[:70]} |")
                except GearshotError as exc:
                    print(f"| {path.name} | {label} | - | - | tracker refuses: "
                          f"{str(exc)[:50]} |")


def _windows(times, angle, pulses, ppr, width=0.25):
    tach = np.arange(pulses.size) / ppr
    t0, t1 = max(times[0], pulses[0]) + 0.1, min(times[-1], pulses[-1]) - 0.1
    e = np.arange(t0, t1, width)
    return (np.diff(np.interp(e, times, angle)) - np.diff(np.interp(e, pulses, tach))) / width


def _rig_machine(lo: float, hi: float) -> Machine:
    return Machine.from_dict({
        "name": "virtual rig", "shafts": ["input", "output"],
        "stage": [{"driver": "input", "driver_teeth": 17, "driven": "output",
                   "driven_teeth": 38}],
        "speed": {"shaft": "input", "range_hz": [lo, hi]},
        "sensor": [{"name": "acceleration", "channel": "acceleration", "sensitivity": 1.0,
                    "unit": "g"}]})


def speed(speed_: str, seeds: str) -> None:
    """Tracked vs tacho speed over 0.25 s windows: the fraction within 2 u (u: the phase
    noise alone, and with the model term), and the checks' verdicts."""
    from gearshot.rig import VirtualRig
    from gearshot.signal import pulse_times

    rows = []
    for path in _files(speed_):
        kind = _kind(path)
        rt = Recording.read(path, machine=EXAMPLES / f"phm09_{kind}.toml")
        rn = Recording.read(path, machine=EXAMPLES / f"phm09_{kind}_notacho.toml")
        rows.append((path.name, rt.pulse_times(), 10, rn, rt.shaft_speed()))
    for seed in (int(s) for s in seeds.split(",")):
        for sp, end in ((15.0, None), (14.0, 17.0), (25.0, None)):
            rec = VirtualRig(seed=seed).record(speed=sp, load=10, duration=4.0, end_speed=end)
            pulses = pulse_times(rec.tacho, rec.fs)
            ppr = rec.tacho_pulses_per_rev or 1
            m = _rig_machine(0.9 * sp, 1.1 * (end or sp))
            rows.append((f"rig seed {seed} {sp:g}" + (f"->{end:g}" if end else "") + " rev/s",
                         pulses, ppr, dataclasses.replace(rec, tacho=None, machine=m),
                         (pulses.size - 1) / ppr / (pulses[-1] - pulses[0])))
    n = n_noise = n_full = 0
    for name, pulses, ppr, rec, true in rows:
        try:
            a = rec.vibration_angle()
        except GearshotError as exc:
            print(f"| {name} | tracker refuses ({str(exc)[:40]}) | | | |")
            continue
        chk = speed_check(rec.machine, rec)
        err = np.abs(_windows(a.times, a.angle, pulses, ppr))
        z = abs(a.mean_speed - true) / a.speed_uncertainty
        print(f"| {name} | {a.mean_speed - true:+.4f} | {a.speed_std:.4f} -> "
              f"{a.speed_uncertainty:.4f} | {np.mean(err <= 2 * a.speed_std):.2f} -> "
              f"{np.mean(err <= 2 * a.speed_uncertainty):.2f} | {z:.1f} | "
              f"{'ok' if chk == 'ok' else 'FAILS (' + chk[:60] + ')'} |")
        if chk == "ok":
            n += err.size
            n_noise += int(np.sum(err <= 2 * a.speed_std))
            n_full += int(np.sum(err <= 2 * a.speed_uncertainty))
    print(f"windows of records passing speed_check within 2 u: phase noise only "
          f"{n_noise / n:.3f}, with the model term {n_full / n:.3f} ({n} windows)")


def timing(speed_: str) -> None:
    from gearshot.app.predict_machine import machine_segments

    for kind in ("spur", "helical"):
        mach = Machine.from_toml(EXAMPLES / f"phm09_{kind}.toml")
        paths = [p for p in _files(speed_) if _kind(p) == kind][:4]
        t0 = time.perf_counter()
        for p in paths:
            machine_segments(p, mach, cycles_per_segment=10)
        t1 = time.perf_counter()
        verify_machine(mach, paths)
        t2 = time.perf_counter()
        print(f"| {kind} | {len(paths)} | {(t1 - t0) / len(paths):.2f} s | "
              f"{(t2 - t1) / len(paths):.2f} s |")


if __name__ == "__main__":
    what = sys.argv[1]
    if what == "verify":
        verify(sys.argv[2])
    elif what == "locks":
        locks(sys.argv[2])
    elif what == "speed":
        speed(sys.argv[2], sys.argv[3])
    elif what == "time":
        timing(sys.argv[2])
    else:
        raise SystemExit(__doc__)
