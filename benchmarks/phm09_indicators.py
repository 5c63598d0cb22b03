"""Indicators of every PHM09 record of ../shared/data/phm09, every shaft and sensor.

Writes benchmarks/results/phm09_indicators.csv (one row per record x shaft x sensor) and
prints which indicators separate the cases, cell by cell (speed x load):

* spur, input shaft (32T): spur2 (chipped 32T) above spur3 (good 32T, same eccentric 48T);
* helical, idler shaft (24T): helical1 < helical2 < helical5 (good < chipped < broken 24T),
  and both faulty cases above helical1.

"Above" is the only rule: a larger value means a worse gear for every indicator (declared
before looking at the data; nothing is tuned to this subset).

    PYTHONPATH=src python benchmarks/phm09_indicators.py [--data ../shared/data/phm09]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pandas as pd

from gearshot import Machine
from gearshot.app.indicators import baseline_variance, shaft_indicators
from gearshot.io import Recording

ROOT = Path(__file__).resolve().parents[1]


def markdown(frame: pd.DataFrame, fmt: str = "{:.3g}") -> str:
    """A pipe table (no optional dependency)."""
    cells = [[fmt.format(v) if isinstance(v, float) else str(v) for v in row]
             for row in frame.itertuples(index=False)]
    head = "| " + " | ".join(map(str, frame.columns)) + " |"
    rule = "|" + "|".join("---" for _ in frame.columns) + "|"
    return "\n".join([head, rule] + ["| " + " | ".join(c) + " |" for c in cells])


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data" / "phm09")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    args = ap.parse_args()
    machines = {k: Machine.from_toml(ROOT / "examples" / "machines" / f"phm09_{k}.toml")
                for k in ("spur", "helical")}
    rows, recs = [], {}
    t_read, t_ind = [], []
    for path in sorted(args.data.glob("*.zip")):
        case, speed, load, run = path.stem.split("_")
        kind = "spur" if case.startswith("spur") else "helical"
        m = machines[kind]
        t0 = time.perf_counter()
        rec = Recording.read(path, machine=m)
        t1 = time.perf_counter()
        res = {sh: shaft_indicators(rec, m, shaft=sh) for sh in m.shafts}
        t2 = time.perf_counter()
        t_read.append(t1 - t0)
        t_ind.append(t2 - t1)
        recs[path.name] = rec
        speed_hz = rec.shaft_speed()
        for sh, per_sensor in res.items():
            for sensor, r in per_sensor.items():
                rows.append({"file": path.name, "kind": kind, "case": case, "nominal": speed,
                             "load": load, "speed_hz": speed_hz, "shaft": sh, "sensor": sensor,
                             "n_cycles": r["n_cycles"], **r["indicators"]})
    table = pd.DataFrame(rows)
    # NA4 against the healthy record of the same cell (spur3 / helical1)
    healthy = {"spur": "spur3", "helical": "helical1"}
    na4b = []
    for row in table.itertuples():
        key = f"{healthy[row.kind]}_{row.nominal}_{row.load}_1.zip"
        base = baseline_variance([recs[key]], machines[row.kind], shaft=row.shaft,
                                 sensor=row.sensor)
        rec = recs[row.file]
        na4b.append(shaft_indicators(rec, machines[row.kind], shaft=row.shaft,
                                     sensors=[row.sensor], baseline=base)[row.sensor]
                    ["indicators"]["na4"])
    table["na4_baseline"] = na4b
    args.out.mkdir(parents=True, exist_ok=True)
    table.to_csv(args.out / "phm09_indicators.csv", index=False, float_format="%.6g")
    print(f"read: median {np.median(t_read):.3f} s per record; indicators (2 sensors x 3 "
          f"shafts): median {np.median(t_ind):.3f} s, min {np.min(t_ind):.3f} s")
    names = [c for c in table.columns if c not in ("file", "kind", "case", "nominal", "load",
                                                   "speed_hz", "shaft", "sensor", "n_cycles")]
    cells = sorted({(r.nominal, r.load) for r in table.itertuples()})
    out = []
    for sensor in ("acc_input", "acc_output"):
        for name in names:
            spur_ok = helical_order = helical_above = 0
            for nom, load in cells:
                sel = table[(table.nominal == nom) & (table.load == load)
                            & (table.sensor == sensor)]
                v = {r.case: getattr(r, name) for r in sel[
                    ((sel.kind == "spur") & (sel.shaft == "input"))
                    | ((sel.kind == "helical") & (sel.shaft == "idler"))].itertuples()}
                spur_ok += v["spur2"] > v["spur3"]
                helical_order += v["helical1"] < v["helical2"] < v["helical5"]
                helical_above += min(v["helical2"], v["helical5"]) > v["helical1"]
            out.append({"sensor": sensor, "indicator": name, "spur2>spur3": spur_ok,
                        "h1<h2<h5": helical_order, "h2,h5>h1": helical_above})
    summary = pd.DataFrame(out)
    summary.to_csv(args.out / "phm09_separation.csv", index=False)
    print(f"cells: {len(cells)} (speed x load)")
    print(markdown(summary))
    # compact table: paper's four + classical, input sensor, monitored shafts
    show = table[(table.sensor == "acc_input") & (
        ((table.kind == "spur") & (table.shaft == "input"))
        | ((table.kind == "helical") & (table.shaft == "idler")))]
    print(markdown(show[["file", "shaft", "speed_hz", "n_cycles", *names]]))


if __name__ == "__main__":
    main()
