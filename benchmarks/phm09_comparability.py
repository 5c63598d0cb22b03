"""Issue #19 item 5 on the PHM09 spur subset: predictions and comparability, 4 cells x 2
sensors, one `predict --machine` fit per cell and sensor (the protocol of
``phm09_predict.py``: healthy = spur3, its last quarter of segments held out; example =
spur2 segment 0 at the declared size 0.5; spur1, another build, estimated as a further
record).

Development cells (issue #19's comparability threshold was chosen on them): 30 Hz High and
Low, both sensors. Held-out cells: 40 Hz High and Low. The comparability test of issue #29
(a p-value in the ``comparability`` column) is designed and measured on the labelled matrix
of ``comparability_matrix.py``; this script reports it per fit.

    GEARSHOT_DATA=... PYTHONPATH=src python benchmarks/phm09_comparability.py --database DB
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pandas as pd

from gearshot import Machine
from gearshot.app.predict_machine import predict_from_machine
from gearshot.experiments.family import parse_params

ROOT = Path(__file__).resolve().parents[1]
DEV_SPEEDS = (30,)


def _fits(args, params) -> pd.DataFrame:
    machine = Machine.from_toml(ROOT / "examples" / "machines" / "phm09_spur.toml")
    frames = []
    for speed in (30, 40):
        for load in ("High", "Low"):
            cell = f"{speed}hz_{load}_1.zip"
            for sensor in ("acc_input", "acc_output"):
                t0 = time.perf_counter()
                f = predict_from_machine(machine, args.database, [args.data / f"spur3_{cell}"],
                                         args.data / f"spur2_{cell}", args.size,
                                         [args.data / f"spur1_{cell}"], speed=float(speed),
                                         load=args.load, cycles_per_segment=10, seed=0,
                                         sensor=sensor, params=params)
                f.insert(0, "sensor", sensor)
                f.insert(0, "cell", f"{speed}hz_{load}")
                f["set"] = "dev" if speed in DEV_SPEEDS else "held-out"
                f["grade"] = f.attrs.get("grade")
                f["seconds"] = time.perf_counter() - t0
                frames.append(f)
                print(f"{speed}hz_{load} {sensor}: {f['seconds'].iloc[0]:.1f} s", flush=True)
    table = pd.concat(frames, ignore_index=True)
    table["recording"] = table["recording"].map(lambda p: Path(p).name)
    table["case"] = table["recording"].str.split("_").str[0]
    return table


def _per_fit(table: pd.DataFrame) -> pd.DataFrame:
    rows = []
    for (cell, sensor), sub in table.groupby(["cell", "sensor"], sort=False):
        s1, s2, s3 = (sub[sub.case == c] for c in ("spur1", "spur2", "spur3"))
        rows.append(dict(
            set=sub.set.iloc[0], cell=cell, sensor=sensor, grade=sub.grade.iloc[0],
            spur3_mean=s3.predicted.mean(), spur3_max=s3.predicted.max(),
            spur2_mean=s2.predicted.mean(), spur2_min=s2.predicted.min(),
            ordered=bool(s2.predicted.min() > s3.predicted.max()),
            spur1_mean=s1.predicted.mean(),
            same_comparable=pd.concat([s2, s3]).comparable.mean(),
            spur1_flagged=1 - s1.comparable.mean(),
            same_p_min=pd.concat([s2, s3]).comparability.min(),
            spur1_p_max=s1.comparability.max()))
    return pd.DataFrame(rows)


def _pooled(table: pd.DataFrame, which: str) -> str:
    sub = table if which == "all" else table[table.set == which]
    s1, s2, s3 = (sub[sub.case == c] for c in ("spur1", "spur2", "spur3"))
    same = pd.concat([s2, s3])
    fits = sub.groupby(["cell", "sensor"])
    ordered = fits.apply(lambda g: g[g.case == "spur2"].predicted.min()
                         > g[g.case == "spur3"].predicted.max(), include_groups=False)
    return (f"{which:8s}: spur3 held-out mean {s3.predicted.mean():.3f} (n={len(s3)}), "
            f"spur2 rest mean {s2.predicted.mean():.3f}, every spur2 above every spur3 in "
            f"{int(ordered.sum())}/{len(ordered)} fits; same-build comparable "
            f"{same.comparable.mean():.1%} ({int(same.comparable.sum())}/{len(same)}), "
            f"spur1 not comparable {1 - s1.comparable.mean():.1%} "
            f"({int((~s1.comparable.astype(bool)).sum())}/{len(s1)})")


def _cross_conditions(args) -> pd.DataFrame:
    """Every fit's comparability reference (as ``fit`` builds it: the fit segments of
    spur3 and spur2's segment 0) scoring spur3's segments of every *other* cell and
    sensor: another sensor, another load, another speed of the same build."""
    from gearshot.app.predict_machine import machine_segments
    from gearshot.estimator.comparability import fit_comparability

    machine = Machine.from_toml(ROOT / "examples" / "machines" / "phm09_spur.toml")
    meshes = list(machine.mesh_orders(machine.monitored.shaft))
    fits = [(sp, ld, se) for sp in (30, 40) for ld in ("High", "Low")
            for se in ("acc_input", "acc_output")]
    seg = {}
    for sp, ld, se in fits:
        for case in ("spur2", "spur3"):
            seg[case, sp, ld, se] = machine_segments(
                args.data / f"{case}_{sp}hz_{ld}_1.zip", machine, cycles_per_segment=10,
                sensor=se)[0]
    rows = []
    for sp, ld, se in fits:
        healthy = seg["spur3", sp, ld, se]
        n_fit = healthy.shape[0] - int(np.floor(0.25 * healthy.shape[0]))
        ref = fit_comparability(healthy[:n_fit], meshes,
                                faulty_example=seg["spur2", sp, ld, se][0],
                                faulty_size=args.size)
        for sp2, ld2, se2 in fits:
            if (sp2, ld2, se2) == (sp, ld, se):
                continue
            kind = "+".join(k for k, a, b in (("speed", sp, sp2), ("load", ld, ld2),
                                                ("sensor", se, se2)) if a != b)
            res = ref.evaluate(seg["spur3", sp2, ld2, se2])
            rows.extend(dict(set="dev" if sp in DEV_SPEEDS else "held-out", other=kind,
                             score=s, comparable=bool(c))
                        for s, c in zip(res.score, res.comparable))
    return pd.DataFrame(rows)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--database", type=Path, required=True)
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data" / "phm09")
    ap.add_argument("--load", type=float, default=10.0)
    ap.add_argument("--size", type=float, default=0.5)
    ap.add_argument("--param", action="append", default=[],
                    help="estimator parameter NAME=VALUE (JSON value), repeatable")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results"
                    / "phm09_comparability.csv")
    args = ap.parse_args()
    table = _fits(args, parse_params(args.param))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    table.to_csv(args.out, index=False, float_format="%.4g")
    with pd.option_context("display.width", 250):
        print(_per_fit(table).to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    print()
    for which in ("dev", "held-out", "all"):
        print(_pooled(table, which))
    cross = _cross_conditions(args)
    print()
    print("spur3 segments of another cell/sensor scored by each fit's reference "
          "(flagged = not comparable):")
    summary = cross.groupby(["set", "other"]).comparable.agg(n="size", comparable="mean")
    summary["flagged"] = 1 - summary.pop("comparable")
    print(summary.to_string(float_format=lambda v: f"{v:.1%}"))
    for which in ("dev", "held-out"):
        sub = cross[cross.set == which]
        print(f"{which}: another condition or sensor flagged {1 - sub.comparable.mean():.1%} "
              f"({int((~sub.comparable).sum())}/{len(sub)})")
    print(f"per-segment table: {args.out}; fit+predict "
          f"{np.round(table.groupby(['cell', 'sensor']).seconds.first().to_numpy(), 1)} s")


if __name__ == "__main__":
    main()
