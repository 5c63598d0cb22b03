"""`gearshot predict --machine` on the PHM09 spur subset, one fit per speed x load cell.

Per cell: healthy = the spur3 record (good 32T, eccentric 48T); its last quarter of
segments is held out of the fit and estimated; the faulty example = segment 0 of the spur2
record (chipped 32T, same eccentric 48T) at the declared size 0.5; its other segments and
the spur1 record (all good, a different build) are estimated. The subset holds one record
per case and cell, so spur2's test segments come from the example's own record (the paper
keeps the example's record out of the test set; with one record per cell that would leave
no spur2 test segment). Database: ``gearshot simulate --machine`` (see RESULTS.md).

    GEARSHOT_DATA=... PYTHONPATH=src python benchmarks/phm09_predict.py --database DB
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import pandas as pd

from gearshot import Machine
from gearshot.app.predict_machine import predict_from_machine
from gearshot.experiments.family import parse_params

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--database", type=Path, required=True)
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data" / "phm09")
    ap.add_argument("--load", type=float, default=10.0)
    ap.add_argument("--size", type=float, default=0.5)
    ap.add_argument("--param", action="append", default=[],
                    help="estimator parameter NAME=VALUE (JSON value), repeatable")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results"
                    / "phm09_predict.csv")
    args = ap.parse_args()
    params = parse_params(args.param)
    machine = Machine.from_toml(ROOT / "examples" / "machines" / "phm09_spur.toml")
    frames = []
    for speed in (30, 40):
        for load in ("High", "Low"):
            cell = f"{speed}hz_{load}_1.zip"
            t0 = time.perf_counter()
            f = predict_from_machine(machine, args.database, [args.data / f"spur3_{cell}"],
                                     args.data / f"spur2_{cell}", args.size,
                                     [args.data / f"spur1_{cell}"], speed=float(speed),
                                     load=args.load, cycles_per_segment=10, seed=0,
                                     params=params)
            f.insert(0, "cell", f"{speed}hz_{load}")
            f["grade"] = f.attrs.get("grade")
            f["seconds"] = time.perf_counter() - t0
            frames.append(f)
    table = pd.concat(frames, ignore_index=True)
    table["recording"] = table["recording"].map(lambda p: Path(p).name)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    table.to_csv(args.out, index=False, float_format="%.4g")
    table["case"] = table["recording"].str.split("_").str[0]
    summary = table.groupby(["cell", "case", "role"]).agg(
        n=("predicted", "size"), mean=("predicted", "mean"), min=("predicted", "min"),
        max=("predicted", "max")).reset_index()
    print(summary.to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    print()
    for cell, sub in table.groupby("cell"):
        s2 = sub[(sub.case == "spur2")].predicted
        s3 = sub[(sub.case == "spur3")].predicted
        print(f"{cell}: grade {sub.grade.iloc[0]}, spur2 rest mean {s2.mean():.3f} "
              f"(min {s2.min():.3f}) vs spur3 held-out mean {s3.mean():.3f} (max "
              f"{s3.max():.3f}): mean above: {s2.mean() > s3.mean()}, every spur2 above "
              f"every spur3: {s2.min() > s3.max()}; fit+predict {sub.seconds.iloc[0]:.1f} s")


if __name__ == "__main__":
    main()
