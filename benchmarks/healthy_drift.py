"""Does the healthy baseline drift while it is recorded? (issue #29, fit check)

Runs :func:`gearshot.estimator.drift.healthy_drift` on every shared PHM09 record of the
given speeds, per sensor, on all its SA segments and on the segments a fit keeps (the
first three quarters: ``gearshot predict`` holds out the last quarter), and prints the
p-value, the far/near energy ratio and the verdict. The 30 Hz records are the
development records the thresholds were chosen on; the 40 Hz records are held out.

    PYTHONPATH=src python benchmarks/healthy_drift.py --speeds 30 [40]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data" / "phm09"


def main(argv=None) -> None:
    from gearshot import Machine
    from gearshot.app.predict_machine import machine_segments
    from gearshot.estimator.drift import healthy_drift
    from gearshot.estimator.fit_check import holdout_count

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--speeds", nargs="+", type=int, default=[30])
    parser.add_argument("--cycles-per-segment", type=int, default=10)
    args = parser.parse_args(argv)
    machines = {kind: Machine.from_toml(ROOT / "examples" / "machines" / f"phm09_{kind}.toml")
                for kind in ("spur", "helical")}
    print(f"{'record':27s} {'sensor':10s} {'n':>3s}  all segments            "
          f"fit's segments")
    for speed in args.speeds:
        for path in sorted(DATA.glob(f"*_{speed}hz_*.zip")):
            machine = machines["helical" if path.name.startswith("helical") else "spur"]
            for sensor in [s.name for s in machine.sensors]:
                sa, _, _ = machine_segments(path, machine, sensor=sensor,
                                            cycles_per_segment=args.cycles_per_segment)
                t0 = time.perf_counter()
                whole = healthy_drift(sa)
                fit = healthy_drift(sa[: len(sa) - holdout_count(len(sa), 0.25)])
                cost = time.perf_counter() - t0
                print(f"{path.name:27s} {sensor:10s} {len(sa):3d}  {_text(whole):22s}  "
                      f"{_text(fit):22s}  ({cost:.2f} s)")


def _text(drift) -> str:
    if drift.p_value is None:
        return "not tested"
    return (f"p {drift.p_value:.3f} x{drift.ratio:.2f} "
            + ("DRIFT" if drift.drifting else "-"))


if __name__ == "__main__":
    main()
