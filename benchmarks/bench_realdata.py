"""Speed of the real-data path on one 4 s PHM09 record (3 channels, 266,656 rows).

Times, best of --repeats (the machine is shared; the best run is the least disturbed):
* reading the original zip through the machine file (unzip + parse + scale),
* indicators of every shaft (input, idler, output) for both accelerometers: pulse
  detection, gear-train cycle times, anti-aliased angular resampling, SAs, all 12
  indicators -- everything after the file is in memory.

The CPU time of the indicator step is printed too: with one thread it is what the wall
time would be on an idle core.

    PYTHONPATH=src python benchmarks/bench_realdata.py [--repeats 7]
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from gearshot import Machine
from gearshot.app.indicators import shaft_indicators
from gearshot.io import Recording

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--file", type=Path, default=ROOT.parent / "shared" / "data" / "phm09"
                    / "spur2_30hz_High_1.zip")
    args = ap.parse_args()
    machine = Machine.from_toml(ROOT / "examples" / "machines" / "phm09_spur.toml")
    reads, inds, cpu, per_shaft = [], [], [], {s: [] for s in machine.shafts}
    for _ in range(args.repeats):
        t0 = time.perf_counter()
        rec = Recording.read(args.file, machine=machine)
        t1 = time.perf_counter()
        c1 = time.process_time()
        for shaft in machine.shafts:
            ts = time.perf_counter()
            shaft_indicators(rec, machine, shaft=shaft)
            per_shaft[shaft].append(time.perf_counter() - ts)
        t2 = time.perf_counter()
        cpu.append(time.process_time() - c1)
        reads.append(t1 - t0)
        inds.append(t2 - t1)
    print(f"{args.file.name}: {rec.acceleration.shape[0]} accelerometers + tacho, "
          f"{rec.duration:.1f} s at {rec.fs:.6g} Hz; load average {os.getloadavg()[0]:.1f} "
          f"on {os.cpu_count()} cores")
    print(f"read zip via machine file: best {min(reads):.3f} s, median "
          f"{sorted(reads)[len(reads) // 2]:.3f} s")
    print(f"indicators, 3 shafts x 2 sensors: best {min(inds):.3f} s, median "
          f"{sorted(inds)[len(inds) // 2]:.3f} s (target <= 0.2 s); CPU time best "
          f"{min(cpu):.3f} s")
    for shaft, ts in per_shaft.items():
        print(f"  {shaft:7s} best {min(ts):.3f} s")


if __name__ == "__main__":
    main()
