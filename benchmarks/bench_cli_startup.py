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
it. ``fft_ref`` (10 real FFTs of a 64 x 8192 array, one thread, best of 3; the reference
of ``bench_speed.py``) is printed first, so that runs on different machines compare
through it. ``parse`` is the text reader alone on the record's bytes, in this process.
The script needs only the ``gearshot`` it imports (set ``PYTHONPATH`` to time another
tree's ``src``).
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

from bench_speed import fft_ref  # the reference FFT workload, beside this script

ROOT = Path(__file__).resolve().parents[1]
MACHINE = ROOT / "examples" / "machines" / "phm09_spur.toml"
FILE = ROOT.parent / "shared" / "data" / "phm09" / "spur2_30hz_High_1.zip"

READ = """
from gearshot import Machine
from gearshot.io import Recording
m = Machine.from_toml({machine!r})
rec = Recording.read({file!r}, machine=m)
"""

#: the first call includes the imports the computation needs (lazy since issue #20); the
#: second is the computation alone
COMPUTE = READ + """
import time
from gearshot.app.indicators import shaft_indicators
t = time.perf_counter()
shaft_indicators(rec, m, shaft="idler", sensors=["acc_input"])
t1 = time.perf_counter()
shaft_indicators(rec, m, shaft="idler", sensors=["acc_input"])
print(t1 - t, time.perf_counter() - t1)
"""


def parse_time(path: Path, repeats: int) -> float:
    """Best time of the text reader alone (unzip + parse) of one record, in this process."""
    from gearshot.io._format_text import read_text

    best = float("inf")
    for _ in range(repeats):
        t = time.perf_counter()
        read_text(path)
        best = min(best, time.perf_counter() - t)
    return best


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
    ap.add_argument("--file", type=Path, default=FILE)
    ap.add_argument("--machine", type=Path, default=MACHINE)
    args = ap.parse_args()
    py = sys.executable
    fmt = {"machine": str(args.machine), "file": str(args.file)}
    with tempfile.TemporaryDirectory() as tmp:
        parts = {
            "start-up (import gearshot.app.cli)": [py, "-c", "import gearshot.app.cli"],
            "start-up + read one record": [py, "-c", READ.format(**fmt)],
            "whole `gearshot indicators` call": [
                py, "-m", "gearshot.app.cli", "indicators", "--machine", str(args.machine),
                "--shaft", "idler", "--sensor", "acc_input", str(args.file), "--json",
                str(Path(tmp) / "i.json")],
        }
        _timed(parts["whole `gearshot indicators` call"])  # warm the OS file cache
        load = os.getloadavg()[0]
        ref_w, ref_c = fft_ref()
        print(f"{args.file.name}, best / median of {args.repeats}; load average {load:.2f} on "
              f"{os.cpu_count()} cores; fft_ref {1e3 * ref_w:.1f} ms wall / "
              f"{1e3 * ref_c:.1f} ms CPU")
        for name, cmd in parts.items():
            runs = [_timed(cmd) for _ in range(args.repeats)]
            ts, cpu = sorted(r[0] for r in runs), sorted(r[2] for r in runs)
            print(f"{name:40s} best {ts[0]:.3f} s  median {ts[len(ts) // 2]:.3f} s  "
                  f"(CPU best {cpu[0]:.3f} s = {cpu[0] / ref_c:.0f} fft_ref)")
        inner = [_timed([py, "-c", COMPUTE.format(**fmt)])[1].split()
                 for _ in range(args.repeats)]
        for k, what in enumerate(("compute, first call (+ its imports)",
                                  "compute, second call")):
            ts = sorted(float(r[k]) for r in inner)
            print(f"{what:40s} best {ts[0]:.3f} s  median {ts[len(ts) // 2]:.3f} s")
        print(f"{'parse (unzip + text reader), in-process':40s} best "
              f"{parse_time(args.file, args.repeats):.3f} s")
        print(f"load average at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
