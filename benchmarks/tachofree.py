"""Machines without a tachometer (issue #24): speed and angle from the vibration.

Four parts, numbers printed (nothing asserted):

A. Every PHM09 record of ../shared/data/phm09 read twice: with its tacho
   (``phm09_<kind>.toml``) and with the tacho ignored (``phm09_<kind>_notacho.toml``, no
   ``[tacho]``: the input shaft is tracked in the vibration). Mean speed against the
   tacho's; SA of the monitored shaft (spur: input, helical: idler; all cycles) against
   the tacho-based SA, after the best circular shift (the vibration cannot know the
   absolute orientation); the same against the tacho angle low-passed to the tracker's
   band (what the vibration can possibly follow).
B. Indicator ordering spur2 vs spur3 (input shaft, both sensors, 4 cells) and the helical
   ladder (idler), tacho against vibration.
C. Run-ups / run-downs with a known profile: (1) the virtual rig (surrogate and simulator
   engines) with ``record(end_speed=)``; (2) a gear-mesh signal on the rig's own ramp
   motion and tacho (``gearshot.rig.motion.ramp_angle``, ``gearshot.rig.tacho``) with
   noise, where the true angle is known. Angle error against the tacho (and the truth),
   SA error against the tacho-based SA.
D. Time of the tacho-free angle of one 4 s, 66.7 kHz record (spur2 30 Hz High).

    PYTHONPATH=src python benchmarks/tachofree.py [--data ../shared/data/phm09] [--quick]
    PYTHONPATH=src python benchmarks/tachofree.py --nominal-orderings   # B with A2's range
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import time
from fractions import Fraction
from pathlib import Path

import numpy as np
import pandas as pd
import scipy.signal
from scipy.interpolate import CubicSpline

from gearshot import GearshotError, Machine
from gearshot.app.indicators import shaft_indicators
from gearshot.io import Recording
from gearshot.signal import (
    angle_pulse_times,
    angular_resample,
    estimate_shaft_angle,
    fractional_shift,
    pulse_times,
    shaft_cycle_times,
    synchronous_average,
)

ROOT = Path(__file__).resolve().parents[1]
MACHINES = ROOT / "examples" / "machines"


def aligned_rms_diff(ref: np.ndarray, other: np.ndarray) -> float:
    """RMS of (other, best circular shift) - ref, relative to RMS(ref)."""
    n = ref.size
    c = np.fft.irfft(np.fft.rfft(ref) * np.conj(np.fft.rfft(other)), n=16 * n)
    lag = np.argmax(c) / 16.0
    e = fractional_shift(other, lag) - ref
    return float(np.sqrt(np.mean(e ** 2) / np.mean(ref ** 2)))


def sa_from_pulses(x, fs, pulses, *, ppr, revs_per_cycle, spc=2048):
    cycles = shaft_cycle_times(pulses, revs_per_cycle=revs_per_cycle, pulses_per_rev=ppr)
    y = angular_resample(x, fs, cycles, samples_per_rev=spc)
    return synchronous_average(y, spc)


def part_a(data: Path, files: list[Path], *, nominal_prior: bool = False
           ) -> tuple[pd.DataFrame, dict]:
    """``nominal_prior``: the machine file without ``range_hz``; the search range is the
    nominal (set) speed of the test plan ±10 % instead (the operator knows it; the tacho
    speed is never read from the file name)."""
    from gearshot.machine import VibrationSpeed

    rows, recs = [], {}
    for path in files:
        case, nominal, load, _ = path.stem.split("_")
        kind = "spur" if case.startswith("spur") else "helical"
        mt = Machine.from_toml(MACHINES / f"phm09_{kind}.toml")
        mv = Machine.from_toml(MACHINES / f"phm09_{kind}_notacho.toml")
        meta = None
        if nominal_prior:
            mv = dataclasses.replace(mv, vibration_speed=VibrationSpeed("input"))
            meta = {"speed": float(nominal.rstrip("hz"))}
        rt = Recording.read(path, machine=mt)
        rv = Recording.read(path, machine=mv, metadata=meta)
        recs[path.name] = (rt, rv, mt, mv)
        shaft = "input" if kind == "spur" else "idler"
        c0 = time.process_time()
        try:
            est = rv.vibration_angle()
        except GearshotError as exc:
            msg = str(exc)
            rows.append({"file": path.name, "path": "refused",
                         "cpu_s": time.process_time() - c0,
                         "refused": msg[msg.find("order "):msg.find("; the speed")]})
            continue
        cpu = time.process_time() - c0
        sp_t, sp_v = rt.shaft_speed(), rv.shaft_speed()
        row = {"file": path.name, "path": "ridge" if est.profile is None else "profile",
               "cpu_s": cpu, "order": est.order, "snr_db": est.snr_db,
               "speed_tacho": sp_t, "speed_vib": sp_v,
               "speed_err_pct": 100 * (sp_v / sp_t - 1),
               "speed_std_hz": est.speed_std, "refused": ""}
        for sensor in mt.sensors:
            a = rt.to_sa_segments(shaft=shaft, sensor=sensor.name, cycles_per_segment=None)[0]
            b = rv.to_sa_segments(shaft=shaft, sensor=sensor.name, cycles_per_segment=None)[0]
            row[f"sa_diff_{sensor.name}"] = aligned_rms_diff(a, b)
        # the tacho angle low-passed to the tracker's band: what the vibration can follow
        p = rt.pulse_times()
        ppr = mt.tacho.pulses_per_rev
        angle = CubicSpline(p, np.arange(p.size) / ppr)
        tt = np.arange(p[0], p[-1], 1 / 400.0)
        th = angle(tt)
        band = min(0.25, 0.5 * min(float(mt.speed_ratio(s)) for s in mt.shafts)) * float(
            est.ridge.speed.min())
        trend = np.polyval(np.polyfit(tt, th, 1), tt)
        sos = scipy.signal.butter(4, band, fs=400.0, output="sos")
        smooth = trend + scipy.signal.sosfiltfilt(sos, th - trend)
        pulses_lp = angle_pulse_times(tt, smooth - smooth[0] + 1e-9, pulses_per_rev=8)
        x = rt.acceleration[0]
        ratio = mt.tacho_revs_per_cycle(shaft)
        a = rt.to_sa_segments(shaft=shaft, sensor=mt.sensors[0].name, cycles_per_segment=None)[0]
        b = rv.to_sa_segments(shaft=shaft, sensor=mt.sensors[0].name, cycles_per_segment=None)[0]
        lp = sa_from_pulses(x, rt.fs, pulses_lp, ppr=8, revs_per_cycle=ratio)
        row["sa_diff_lowpassed_tacho_vs_tacho"] = aligned_rms_diff(a, lp)
        row["sa_diff_vib_vs_lowpassed_tacho"] = aligned_rms_diff(lp, b)
        # the vibration angle against the tacho angle (offset removed)
        sel = (est.times > p[0]) & (est.times < p[-1])
        d = est.angle[sel] - angle(est.times[sel])
        row["angle_diff_rms_deg"] = float(np.std(d) * 360)
        rows.append(row)
    return pd.DataFrame(rows), recs


def part_b(recs: dict) -> pd.DataFrame:
    out = []
    for name, (rt, rv, mt, mv) in recs.items():
        case, nominal, load, _ = Path(name).stem.split("_")
        shaft = "input" if case.startswith("spur") else "idler"
        for source, rec, m in (("tacho", rt, mt), ("vibration", rv, mv)):
            try:
                res = shaft_indicators(rec, m, shaft=shaft)
            except GearshotError:
                continue
            for sensor, r in res.items():
                out.append({"case": case, "cell": f"{nominal} {load}", "source": source,
                            "sensor": sensor, **r["indicators"]})
    return pd.DataFrame(out)


def orderings(table: pd.DataFrame) -> pd.DataFrame:
    names = [c for c in table.columns if c not in ("case", "cell", "source", "sensor")]
    rows = []
    for sensor in sorted(table.sensor.unique()):
        for name in names:
            r = {"sensor": sensor, "indicator": name}
            for source in ("tacho", "vibration"):
                spur, ladder = [], []
                for cell in sorted(table.cell.unique()):
                    sel = table[(table.cell == cell) & (table.sensor == sensor)
                                & (table.source == source)]
                    v = dict(zip(sel.case, sel[name]))
                    if {"spur2", "spur3"} <= set(v):
                        spur.append("y" if v["spur2"] > v["spur3"] else "n")
                    else:
                        spur.append("-")
                    if {"helical1", "helical2", "helical5"} <= set(v):
                        ladder.append("y" if v["helical1"] < v["helical2"] < v["helical5"]
                                      else "n")
                    else:
                        ladder.append("-")
                r[f"spur2>spur3 {source}"] = "".join(spur)
                r[f"h1<h2<h5 {source}"] = "".join(ladder)
            # cells where the vibration refused ("-") are not counted as changes
            r["spur same"] = all(b in (a, "-") for a, b in zip(r["spur2>spur3 tacho"],
                                                               r["spur2>spur3 vibration"]))
            r["ladder same"] = all(b in (a, "-") for a, b in zip(r["h1<h2<h5 tacho"],
                                                                 r["h1<h2<h5 vibration"]))
            rows.append(r)
    return pd.DataFrame(rows)


def mesh_signal(revs, rng, *, teeth=17, gear=38, noise=0.5):
    """Mesh harmonics of a ``teeth``-tooth pinion plus a once-per-gear-revolution
    modulation (a gear feature) and white noise, on the shaft angle ``revs``."""
    g = revs * teeth / gear
    x = sum(a * np.cos(2 * np.pi * h * teeth * revs + ph) * (1 + 0.3 * np.cos(2 * np.pi * g))
            for h, a, ph in ((1, 1.0, 0.2), (2, 0.6, 1.1), (3, 0.3, 2.0)))
    return x + noise * rng.standard_normal(revs.size)


def runup_row(label, acc, tacho, fs, *, orders, speed_range, revs_per_cycle, truth=None,
              bandwidth=0.22):
    pulses = pulse_times(tacho, fs)
    angle_t = CubicSpline(pulses, np.arange(pulses.size))
    row = {"case": label}
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        est = estimate_shaft_angle(acc, fs, orders=orders, speed_range=speed_range,
                                   bandwidth=bandwidth)
    except GearshotError as exc:
        row["result"] = f"refused: {str(exc)[:90]}…"
        row["profile"] = str(exc).split("over the whole record")[-1][:90]
        return row
    row["time_s"] = time.perf_counter() - t0
    row["cpu_s"] = time.process_time() - c0
    sel = (est.times > pulses[0]) & (est.times < pulses[-1])
    d = est.angle[sel] - angle_t(est.times[sel])
    d -= d.mean()
    row.update(result="tracked" if est.profile is None else "tracked (whole-record profile)",
               order=est.order, snr_db=est.snr_db,
               angle_err_vs_tacho_rms_deg=float(np.std(d) * 360),
               angle_err_vs_tacho_max_deg=float(np.max(np.abs(d)) * 360))
    if truth is not None:
        e = est.angle - truth(est.times)
        e -= e.mean()
        row["angle_err_vs_truth_rms_deg"] = float(np.std(e) * 360)
    a = sa_from_pulses(acc, fs, pulses, ppr=1, revs_per_cycle=revs_per_cycle)
    b = sa_from_pulses(acc, fs, est.pulse_times, ppr=est.pulses_per_rev,
                       revs_per_cycle=revs_per_cycle)
    row["sa_err_vs_tacho"] = aligned_rms_diff(a, b)
    return row


RIG_SEEDS = {"development": [0], "held-out": [1, 2]}  # seed 0 looked at while developing, 1-2 not


def part_c(quick: bool) -> pd.DataFrame:
    from gearshot.rig import VirtualRig
    from gearshot.rig.motion import ramp_angle
    from gearshot.rig.tacho import tacho_signal

    rows = []
    ramps = [(15.0, None), (12.0, 16.0), (16.0, 12.0)]
    engines = ["surrogate"] if quick else ["surrogate", "sim"]
    for role, seeds in RIG_SEEDS.items():
        for seed in seeds:
            for engine in engines:
                rig = VirtualRig(seed=seed, engine=engine)
                for speed, end in ramps:
                    rec = rig.record(speed=speed, load=10, duration=4.0, end_speed=end)
                    label = (f"VirtualRig(seed={seed}, engine={engine!r}) "
                             f"{speed:g}->{end or speed:g} rev/s [{role}]")
                    rows.append(runup_row(label, rec.acceleration, rec.tacho, rec.fs,
                                          orders=[17], speed_range=(10, 19),
                                          revs_per_cycle=Fraction(38, 17)))
    # a mesh signal on the rig's own ramp motion and tacho: the true angle is known
    fs = 50_000.0
    t = np.arange(int(4 * fs)) / fs
    for seed, (speed, end) in enumerate([(12.0, 16.0), (16.0, 12.0), (10.0, 18.0)]):
        rng = np.random.default_rng([24, seed])
        revs = ramp_angle(t, speed=speed, end_speed=end, t_start=0.0, t_end=4.0, ripple=0.0,
                          rng=rng)
        x = mesh_signal(revs, rng)
        tach = tacho_signal(revs, jitter=1e-4, rng=rng)
        truth = CubicSpline(t, revs)
        rows.append(runup_row(f"mesh signal on ramp_angle {speed:g}->{end:g} rev/s (seed "
                              f"{seed})", x, tach, fs, orders=[17], speed_range=(9, 19),
                              revs_per_cycle=Fraction(38, 17), truth=truth))
    return pd.DataFrame(rows)


def part_d(data: Path, repeats: int) -> dict:
    mv = Machine.from_toml(MACHINES / "phm09_spur_notacho.toml")
    rec = Recording.read(data / "spur2_30hz_High_1.zip", machine=mv)
    walls, cpus = [], []
    for _ in range(repeats):
        fresh = dataclasses.replace(rec)  # no cached angle
        w0, c0 = time.perf_counter(), time.process_time()
        fresh.vibration_angle()
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
    return {"best_wall_s": min(walls), "median_wall_s": float(np.median(walls)),
            "best_cpu_s": min(cpus), "load_average": os.getloadavg()[0]}


def markdown(frame: pd.DataFrame) -> str:
    def cell(v):
        if isinstance(v, float):
            return "" if math.isnan(v) else f"{v:.4g}"
        return str(v)

    head = "| " + " | ".join(map(str, frame.columns)) + " |"
    rule = "|" + "|".join("---" for _ in frame.columns) + "|"
    return "\n".join([head, rule] + ["| " + " | ".join(cell(v) for v in row) + " |"
                                     for row in frame.itertuples(index=False)])


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data" / "phm09")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    ap.add_argument("--quick", action="store_true", help="surrogate rig only, 3 timings")
    ap.add_argument("--runups", action="store_true", help="only part C")
    ap.add_argument("--nominal-orderings", action="store_true",
                    help="only part B on the records read with the nominal-speed range")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    if args.runups:
        c = part_c(args.quick)
        c.to_csv(args.out / "tachofree_runups.csv", index=False, float_format="%.6g")
        print(f"C. run-ups / run-downs (load average {os.getloadavg()[0]:.1f})\n"
              + markdown(c))
        return
    if args.nominal_orderings:
        _, recs = part_a(args.data, sorted(args.data.glob("*.zip")), nominal_prior=True)
        b = orderings(part_b(recs))
        b.to_csv(args.out / "tachofree_orderings_nominal.csv", index=False)
        print(markdown(b))
        print(f"spur2>spur3 unchanged for {int(b['spur same'].sum())}/{len(b)}; ladder "
              f"unchanged for {int(b['ladder same'].sum())}/{len(b)}")
        return
    d = part_d(args.data, 3 if args.quick else 7)
    print(f"D. tacho-free angle, spur2 30 Hz High (266,656 samples): best wall "
          f"{d['best_wall_s']:.3f} s, median {d['median_wall_s']:.3f} s, best CPU "
          f"{d['best_cpu_s']:.3f} s (load average {d['load_average']:.1f})\n")
    files = sorted(args.data.glob("*.zip"))
    a, recs = part_a(args.data, files)
    a.to_csv(args.out / "tachofree_phm09.csv", index=False, float_format="%.6g")
    print("A. PHM09, tacho ignored\n" + markdown(a) + "\n")
    ok = a.dropna(subset=["speed_err_pct"])
    print(f"   speed error: max |{ok.speed_err_pct.abs().max():.4f}| %, "
          f"{int((ok.speed_err_pct.abs() <= 0.2).sum())}/{len(a)} records within 0.2 %; "
          f"SA diff (acc_input) median {ok.sa_diff_acc_input.median():.3f}, "
          f"{int((ok.sa_diff_acc_input <= 0.02).sum())}/{len(a)} within 2 %\n")
    b = orderings(part_b(recs))
    b.to_csv(args.out / "tachofree_orderings.csv", index=False)
    print("B. indicator ordering, tacho vs vibration (y/n per cell: 30 High, 30 Low, "
          "40 High, 40 Low; - = refused)\n" + markdown(b) + "\n")
    print(f"   spur2>spur3 unchanged for {int(b['spur same'].sum())}/{len(b)} indicator x "
          f"sensor pairs; helical ladder unchanged for {int(b['ladder same'].sum())}/{len(b)}\n")
    a2, _ = part_a(args.data, files, nominal_prior=True)
    a2.to_csv(args.out / "tachofree_phm09_nominal.csv", index=False, float_format="%.6g")
    ok2 = a2.dropna(subset=["speed_err_pct"])
    print("A2. the same with the nominal speed ±10 % as the search range (no range_hz)\n"
          + markdown(a2[[c for c in a2.columns if c in ("file", "path", "cpu_s", "order", "snr_db",
                                                          "speed_err_pct", "refused",
                                                          "sa_diff_acc_input",
                                                          "angle_diff_rms_deg")]]) + "\n")
    print(f"   speed error: max |{ok2.speed_err_pct.abs().max():.4f}| %, "
          f"{int((ok2.speed_err_pct.abs() <= 0.2).sum())}/{len(a2)} records within 0.2 %\n")
    c = part_c(args.quick)
    c.to_csv(args.out / "tachofree_runups.csv", index=False, float_format="%.6g")
    print("C. run-ups / run-downs\n" + markdown(c))


if __name__ == "__main__":
    main()
