"""Benchmark: one virtual-rig condition (paper Table 1: 6 healthy + 3 sizes x 6 = 24
recordings x 60 s at 50 kHz) written as a campaign, then SA segments of one recording.

Prints numbers; asserts nothing. Target: one condition <= 5 min.

    PYTHONPATH=src python benchmarks/bench_rig.py [--duration 60] [--speed 15] [--load 10]
                                                  [--engine sim|surrogate] [--keep DIR]
"""

from __future__ import annotations

import argparse
import os
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from gearshot.io import Recording
from gearshot.paper import GEAR_TEETH, PINION_TEETH
from gearshot.rig import VirtualRig


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=60.0)
    ap.add_argument("--speed", type=float, default=15.0)
    ap.add_argument("--load", type=float, default=10.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--engine", default="sim", choices=["sim", "surrogate"])
    ap.add_argument("--keep", default=None, help="write the campaign here and keep it")
    args = ap.parse_args()

    folder = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="bench_rig_"))
    rig = VirtualRig(seed=args.seed, engine=args.engine)
    print(f"engine={args.engine} seed={args.seed} speed={args.speed} rev/s "
          f"load={args.load} N m duration={args.duration} s fs={rig.fs:g} Hz")
    print(f"loadavg before: {os.getloadavg()}")
    rig.record(speed=args.speed, load=args.load, duration=0.2)  # JIT warm-up (numba cache)
    t0 = time.perf_counter()
    rec = rig.record(speed=args.speed, load=args.load, fault_size=0.56,
                     duration=args.duration)
    t_one = time.perf_counter() - t0
    t0 = time.perf_counter()
    sa = rec.to_sa_segments(gear_teeth=GEAR_TEETH, pinion_teeth=PINION_TEETH)
    t_sa = time.perf_counter() - t0
    print(f"one recording: {t_one:.2f} s; to_sa_segments: {t_sa:.2f} s -> {sa.shape}")

    t0 = time.perf_counter()
    df = rig.campaign(folder, speed=args.speed, load=args.load, duration=args.duration,
                      progress=True)
    t_campaign = time.perf_counter() - t0
    size = sum(Path(p).stat().st_size for p in df["path"]) / 1e6
    t0 = time.perf_counter()
    back = Recording.read(df["path"].iloc[-1])
    t_read = time.perf_counter() - t0
    assert np.isfinite(back.acceleration).all()
    print(f"campaign: {len(df)} recordings x {args.duration:g} s in {t_campaign:.1f} s "
          f"({t_campaign / len(df):.2f} s each); {size:.0f} MB on disk; "
          f"read one back: {t_read:.2f} s")
    print(f"target <= 300 s per condition: {'MET' if t_campaign <= 300 else 'NOT MET'}")
    print(f"loadavg after: {os.getloadavg()}")
    if not args.keep:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
