"""Whole-process time of a one-record ``gearshot indicators`` call, split into parts.

Each part is timed in a fresh Python process (nothing cached in memory, the OS file cache
warm after the first run), best and median of --repeats:

* ``start-up``: ``python -c "import gearshot.app.cli"`` (what every command pays);
* ``read``: start-up + reading one 4 s PHM09 zip through the machine file;
* ``compute``: the indicators of one shaft for one sensor, in-process, after the read;
* ``whole``: ``python -m gearshot.app.cli indicators --machine ... --shaft idler FILE
  --json OUT`` as a user types it (the target is <= 0.8 s).

    python benchmarks/bench_cli_startup.py [--repeats 7]

The load average is printed beside the numbers (the machine is shared); the CPU time
(user + system) of each process is printed too: on an idle core the wall time is close to
it.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MACHINE = ROOT / "examples" / "machines" / "phm09_spur.toml"
FILE = ROOT.parent / "shared" / "data" / "phm09" / "spur2_30hz_High_1.zip"

READ = f"""
from gearshot import Machine
from gearshot.io import Recording
m = Machine.from_toml({str(MACHINE)!r})
rec = Recording.read({str(FILE)!r}, machine=m)
"""

COMPUTE = READ + """
import time
from gearshot.app.indicators import shaft_indicators
t = time.perf_counter()
shaft_indicators(rec, m, shaft="idler", sensors=["acc_input"])
print(time.perf_counter() - t)
"""


def _cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _timed(cmd: list[str]) -> tuple[float, str, float]:
    """Wall time, stdout and CPU time (user + system) of one child process."""
    c, t = _cpu(), time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True, check=True)
    return time.perf_counter() - t, res.stdout, _cpu() - c


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args()
    py = sys.executable
    with tempfile.TemporaryDirectory() as tmp:
        parts = {
            "start-up (import gearshot.app.cli)": [py, "-c", "import gearshot.app.cli"],
            "start-up + read one record": [py, "-c", READ],
            "whole `gearshot indicators` call": [
                py, "-m", "gearshot.app.cli", "indicators", "--machine", str(MACHINE),
                "--shaft", "idler", "--sensor", "acc_input", str(FILE), "--json",
                str(Path(tmp) / "i.json")],
        }
        _timed(parts["whole `gearshot indicators` call"])  # warm the OS file cache
        load = os.getloadavg()[0]
        print(f"{FILE.name}, best / median of {args.repeats}; load average {load:.2f} on "
              f"{os.cpu_count()} cores")
        for name, cmd in parts.items():
            runs = [_timed(cmd) for _ in range(args.repeats)]
            ts, cpu = sorted(r[0] for r in runs), sorted(r[2] for r in runs)
            print(f"{name:40s} best {ts[0]:.3f} s  median {ts[len(ts) // 2]:.3f} s  "
                  f"(CPU best {cpu[0]:.3f} s)")
        inner = sorted(float(_timed([py, "-c", COMPUTE])[1].split()[-1])
                       for _ in range(args.repeats))
        print(f"{'compute (in-process, idler, 1 sensor)':40s} best {inner[0]:.3f} s  "
              f"median {inner[len(inner) // 2]:.3f} s")
        print(f"load average at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
