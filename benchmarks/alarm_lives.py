"""Re-judge the alarms of stored monitored lives under other threshold rules.

Reads the lives ``benchmarks/monitor_lives.py`` left (``WORK/rig<seed>/``: the model
files, the histories and the life's ``index.csv``), keeps every estimate and trust flag
as stored, and runs :func:`gearshot.monitor.alarm_states` again with the threshold of
each rule from the model's healthy baseline. Prints, per rule and model kind: lives
whose alarm came within 3 recordings after the true size first passed 0.2, false alarms
per 100 healthy recordings and event recordings in alarm (the criteria of
``monitor_lives.py``).

    PYTHONPATH=src python benchmarks/alarm_lives.py --lives DIR [DIR ...] \
        [--seeds 1 2 ...] --rates 0.01 0.05 --sustains 2 3 --commissioning 0 10 --young 0 1
"""

from __future__ import annotations

import argparse
import itertools
import sys
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))


def judge(rig: Path, mode: str, rate: float, sustain: int,
          commissioning: int = 0, young: int = 0) -> dict | None:
    from monitor_lives import fault_alarm_start

    from gearshot.monitor import alarm_states, alarm_threshold, load_model
    from gearshot.monitor.alarm import history_sustain, history_thresholds

    mpath, hpath = rig / f"{mode}.skops", rig / f"{mode}.parquet"
    if not (mpath.is_file() and hpath.is_file()):
        return None
    model = load_model(mpath)
    hist = pd.read_parquet(hpath)
    hist = hist[hist["model"] == hist["model"].iloc[-1]]
    truth = pd.read_csv(rig / "life" / "index.csv", keep_default_na=False)
    hist = hist.assign(file=[Path(r).name for r in hist["recording"]])
    recs = truth.merge(hist[["file", "predicted", "trusted"]], on="file", how="left")
    thr = alarm_threshold(model.baseline, false_alarm_rate=rate)
    ok = recs["trusted"].fillna(False).to_numpy(bool)
    limits, runs = np.full(len(recs), thr), np.full(len(recs), sustain)
    if commissioning:   # the history's own first trusted recordings set a threshold too
        got = history_thresholds(recs["predicted"].to_numpy(float), ok, thr,
                                 false_alarm_rate=rate, commissioning=commissioning)
        limits, thr = got.per_recording, float(got.per_recording[-1])   # in force at the end
        runs = history_sustain(got, sustain, extra=young)   # more while the history is young
    res = alarm_states(recs["predicted"].to_numpy(float), ok, limits, sustain=runs)
    size = recs["size"].to_numpy(float)
    cross = int(np.nonzero(size > 0.2)[0][0])
    first = fault_alarm_start(res.alarm, ok, cross)
    events = recs["event"].to_numpy(str) != ""
    return dict(seed=int(rig.name[3:]), model=mode, threshold=thr,
                delay=None if first is None else first - cross,
                healthy=int((size == 0).sum()),
                false_alarms=int((res.alarm & (size == 0)).sum()),
                events_alarmed=int((res.alarm & events).sum()))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--lives", nargs="+", type=Path, required=True)
    parser.add_argument("--seeds", nargs="*", type=int, default=None)
    parser.add_argument("--rates", nargs="+", type=float, default=[0.01])
    parser.add_argument("--sustains", nargs="+", type=int, default=[2])
    parser.add_argument("--commissioning", nargs="+", type=int, default=[0],
                        help="trusted recordings at a history's start that also set a "
                             "threshold (0: the fit's threshold alone)")
    parser.add_argument("--young", nargs="+", type=int, default=[0],
                        help="recordings beyond the sustain a history needs before it "
                             "holds its commissioning recordings (with --commissioning)")
    parser.add_argument("--modes", nargs="+", default=["one_fault_shot", "zero_shot"])
    parser.add_argument("--out", type=Path, default=None, help="per-life CSV")
    args = parser.parse_args()
    rigs = sorted({r for d in args.lives for r in d.glob("rig*")
                   if args.seeds is None or int(r.name[3:]) in args.seeds},
                  key=lambda r: int(r.name[3:]))
    seen: set[int] = set()
    unique = []
    for r in rigs:   # a seed stored in two folders counts once
        if int(r.name[3:]) not in seen:
            seen.add(int(r.name[3:]))
            unique.append(r)
    rows = []
    for rate, sustain, k, young, mode in itertools.product(
            args.rates, args.sustains, args.commissioning, args.young, args.modes):
        got = [j for r in unique if (j := judge(r, mode, rate, sustain, k, young))]
        part = pd.DataFrame(got)
        if part.empty:
            continue
        part = part.assign(rate=rate, sustain=sustain, commissioning=k, young=young)
        rows.append(part)
        d = part["delay"]
        ok = int((d.notna() & (d <= 3)).sum())
        fa = part["false_alarms"].sum()
        print(f"rate {rate:g} sustain {sustain} commissioning {k} young {young} {mode}: in time "
              f"{ok}/{len(part)}, "
              f"false alarms {fa} in {part['healthy'].sum()} "
              f"({100 * fa / max(part['healthy'].sum(), 1):.2f} per 100), events "
              f"alarmed {part['events_alarmed'].sum()}, median threshold "
              f"{part['threshold'].median():.3f}", flush=True)
    if args.out is not None and rows:
        pd.concat(rows).to_csv(args.out, index=False)


if __name__ == "__main__":
    main()
