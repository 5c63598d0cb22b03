"""The size intervals of monitored lives re-formed from their stored estimates.

For each life of ``benchmarks/monitor_lives.py`` (a folder ``rigN`` holding the
one-fault-shot model ``one_fault_shot.skops``, its history ``one_fault_shot.parquet`` and
the life's ``life/index.csv`` with the true sizes), every trusted recording outside the
load change and the remount gets its 90 % interval again from its stored estimate and the
model's own hold-out residuals (:func:`gearshot.estimator.uncertainty.holdout_interval`),
for every candidate ``--scale-spreads`` value (``--run-spread`` fixed). A recording's
interval is that of its combined estimate (the median of its segments', as the monitor
combines them; the bounds are monotone in the estimate). Printed per true-size band:
recordings, share whose interval holds the true size, share above the interval (the true
size read too low) and mean width.

    PYTHONPATH=src python benchmarks/interval_lives.py --lives /work/lives5 \\
        --scale-spreads 0.06 0.08 0.10
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

from gearshot.estimator.uncertainty import RUN_SPREAD, holdout_interval
from gearshot.monitor.model import load_model

BANDS = [-0.01, 0.0, 0.3, 0.5, 1.0]
LABELS = ["0", "0-0.3", "0.3-0.5", ">=0.5"]


def life_rows(rig: Path, run_spread: float, scale_spreads: list[float]) -> list[dict]:
    """Every candidate's interval of each trusted ordinary recording of one life."""
    model_path = rig / "one_fault_shot.skops"
    if not model_path.exists():
        return []
    check = load_model(model_path).estimator.fit_check_
    if check is None or not check.checked:
        return []
    healthy, example = check.residuals()
    hist = pd.read_parquet(rig / "one_fault_shot.parquet")
    index = pd.read_csv(rig / "life" / "index.csv")
    size = dict(zip(index["file"], index["size"]))
    event = dict(zip(index["file"], index["event"].fillna("")))
    names = [Path(r).name for r in hist["recording"]]
    hist = hist.assign(size=[size[n] for n in names], event=[event[n] for n in names])
    hist = hist[hist["trusted"] & (hist["event"] == "")]
    rows = []
    for c in scale_spreads:
        low, high = holdout_interval(hist["predicted"].to_numpy(), healthy, example, 0.9,
                                     run_spread=run_spread, scale_spread=c,
                                     example_size=check.declared_size)
        low, high = np.clip(low, 0, 1), np.clip(high, 0, 1)
        for y, lo, hi in zip(hist["size"], low, high):
            rows.append(dict(life=rig.name, scale_spread=c, size=float(y),
                             inside=bool(lo <= y <= hi), under=bool(y > hi),
                             width=float(hi - lo)))
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lives", type=Path, nargs="+", required=True,
                    help="folders of rigN lives (benchmarks/monitor_lives.py --work)")
    ap.add_argument("--seeds", type=int, nargs="*", default=None)
    ap.add_argument("--run-spread", type=float, default=RUN_SPREAD)
    ap.add_argument("--scale-spreads", type=float, nargs="+", default=[0.04, 0.06, 0.08, 0.10])
    args = ap.parse_args()
    rows = []
    for folder in args.lives:
        for rig in sorted(folder.glob("rig*")):
            if args.seeds and int(rig.name[3:]) not in args.seeds:
                continue
            rows.extend(life_rows(rig, args.run_spread, args.scale_spreads))
    table = pd.DataFrame(rows)
    table["band"] = pd.cut(table["size"], BANDS, labels=LABELS)
    print(f"{table['life'].nunique()} lives, run spread {args.run_spread}")
    print(table.groupby(["scale_spread", "band"], observed=True).agg(
        n=("inside", "size"), inside=("inside", "mean"), above=("under", "mean"),
        width=("width", "mean")).round(3).to_string())


if __name__ == "__main__":
    main()
