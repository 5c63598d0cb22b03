"""The run-to-run spread of a one-recording fit whose healthy baseline holds still.

A fit on one healthy recording (with hold-outs, ``--holdout 0.25``) and one faulty example
estimates recordings of **other runs** of the same machine: how far do they move from
the fit's own hold-outs, and what run-to-run spread must its intervals carry? Each
virtual rig records, at 15 rps / 10 N m, 3 healthy recordings and 2 of size 0.5, 60 s
each, every one on its own run (``VirtualRig.campaign(..., variation=0.01)``: speed and
load off their set-points by 1 % run to run, as in ``VirtualRig.history``). The fit
takes healthy recording 0 and size-0.5 recording 0 (its most typical segment, at the
declared 0.5); estimated: healthy recordings 1 and 2 and size-0.5 recording 1, which
the fit never saw.

Per rig the script stores the fit's verdict, the drift test of its baseline
(``healthy_drift_``: p-value and trend ratio), the hold-out residuals, the estimates of
the other runs, their comparability and every recording's measured speed, and then
re-forms the hold-out intervals (:func:`gearshot.estimator.uncertainty.holdout_interval`)
for every candidate ``--spreads`` value: share of the healthy other-run intervals holding
0, of the faulty other-run intervals holding 0.5, and the mean width. A segment is
trusted when the fit passed, the segment is comparable and its recording's speed passes
the speed check, under two rules: ``range`` (the span of the fit's two recordings'
speeds, widened by 6 relative standard deviations, at least 0.3 %: the rule of commit
``9382b29``) and ``nearest`` (the current
:func:`gearshot.app.conditions.fit_speed_check`: within 0.3 % of one of them). The last
table splits every segment by trust and by the baseline's stillness (a passed fit whose
drift trend ratio is below ``--still-ratio``).

    GEARSHOT_DATA=... PYTHONPATH=src python benchmarks/run_spread.py \\
        --seeds 201 … 212 --database DB --work WORK

``DB``: the monitoring database (``gearshot simulate --speed 15 --load 10 --n-healthy 50
--n-faulty 350``). Recording a rig takes about 10 s on the 2-core box, a fit 3 s.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pandas as pd

from gearshot.app.conditions import fit_speed_check
from gearshot.app.predict_fit import fit_from_files
from gearshot.estimator.uncertainty import holdout_interval
from gearshot.rig import VirtualRig

SIZE = 0.5
COVERAGE = 0.9


def record(seed: int, work: Path, duration: float) -> Path:
    """The rig's campaign (cached in ``work``)."""
    folder = work / f"rig{seed}_{int(duration)}"
    if not (folder / "index.csv").exists():
        VirtualRig(seed=seed).campaign(folder, speed=15, load=10, duration=duration,
                                       healthy=3, sizes=(SIZE,), repetitions=2,
                                       variation=0.01, progress=False)
    return folder


def fit_rig(seed: int, folder: Path, database: str) -> dict:
    """One rig's fit and the numbers the spread sweep needs."""
    def f(size: float, rep: int) -> str:
        return str(folder / f"s15_l10_y{size:.2f}_r{rep}.h5")

    others = [f(0, 1), f(0, 2), f(SIZE, 1)]
    est, fit = fit_from_files(database, [f(0, 0)], f(SIZE, 0), SIZE, speed=15, load=10,
                              recordings=others, holdout=0.25)
    check, drift = est.fit_check_, est.healthy_drift_
    by_path = {Path(p).name: sa for p, sa in fit.targets}

    def speed(path: str) -> float:
        return float(fit.health[Path(path).resolve()].get("speed", np.nan))

    def comparable(path: str) -> list[bool]:
        return [bool(c) for c in est.comparability(by_path[Path(path).name]).comparable]

    healthy_res, example_res = check.residuals()
    return dict(
        seed=seed, verdict=check.verdict, passed=bool(check.passed),
        drift_p=None if drift is None else float(drift.p_value),
        drift_ratio=None if drift is None else float(drift.ratio),
        healthy_residuals=[float(v) for v in healthy_res],
        example_residuals=[float(v) for v in example_res],
        healthy_other=[float(v) for n in (f(0, 1), f(0, 2))
                       for v in est.predict(by_path[Path(n).name])],
        faulty_other=[float(v) for v in est.predict(by_path[Path(f(SIZE, 1)).name])],
        healthy_comparable=comparable(f(0, 1)) + comparable(f(0, 2)),
        faulty_comparable=comparable(f(SIZE, 1)),
        healthy_counts=[len(by_path[Path(n).name]) for n in (f(0, 1), f(0, 2))],
        speeds=[speed(p) for p in (f(0, 0), f(SIZE, 0), *others)],
        grade=int(est.grade_))


def range_speed_check(speed: float, fit_speeds: list[float]) -> bool:
    """The speed check of commit ``9382b29`` for a fit of one healthy recording and an
    example: the span of their speeds, widened by 6 of their relative standard deviations
    and at least 0.3 %."""
    known = np.asarray(fit_speeds, float)
    mean = known.mean()
    tolerance = max(0.003, 6.0 * known.std(ddof=1) / mean)
    return max(known.min() - speed, speed - known.max(), 0.0) / mean <= tolerance


def at_speed(row: dict, rule: str) -> tuple[list[bool], list[bool]]:
    """Per healthy and faulty other-run segment: at a speed the fit has seen."""
    h0, ex, r1, r2, f1 = row["speeds"]
    ok = ((lambda v: fit_speed_check(v, [h0], example_speed=ex) == "ok") if rule == "nearest"
          else (lambda v: range_speed_check(v, [h0, ex])))
    n1, n2 = row["healthy_counts"]
    return [ok(r1)] * n1 + [ok(r2)] * n2, [ok(f1)] * len(row["faulty_other"])


def sweep(rows: list[dict], spreads: list[float], still_ratio: float,
          rule: str) -> pd.DataFrame:
    """Coverage and width of the other runs' intervals per candidate spread; ``trusted``:
    the fit passed, the segment is comparable and its recording at a speed the fit has
    seen by ``rule`` (``predict``'s trust but the input checks, which every rig recording
    passes)."""
    out = []
    for row in rows:
        still = (row["passed"] and row["drift_ratio"] is not None
                 and row["drift_ratio"] < still_ratio)
        healthy_speed, faulty_speed = at_speed(row, rule)
        healthy_ok = [c and v for c, v in zip(row["healthy_comparable"], healthy_speed)]
        faulty_ok = [c and v for c, v in zip(row["faulty_comparable"], faulty_speed)]
        for s in spreads:
            for kind, values, truth, comp in (
                    ("healthy", row["healthy_other"], 0.0, healthy_ok),
                    ("faulty", row["faulty_other"], SIZE, faulty_ok)):
                low, high = holdout_interval(values, row["healthy_residuals"],
                                             row["example_residuals"], COVERAGE,
                                             run_spread=s, example_size=SIZE)
                low, high = np.clip(low, 0, 1), np.clip(high, 0, 1)
                inside = (low <= truth) & (truth <= high)
                out.extend(dict(seed=row["seed"], still=still, spread=s, kind=kind,
                                trusted=bool(row["passed"] and c), inside=bool(i),
                                width=float(w))
                           for i, w, c in zip(inside, high - low, comp))
    return pd.DataFrame(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, nargs="+", required=True)
    ap.add_argument("--database", required=True)
    ap.add_argument("--work", type=Path, required=True)
    ap.add_argument("--duration", type=float, default=60.0)
    ap.add_argument("--spreads", type=float, nargs="+",
                    default=[0.04, 0.06, 0.08, 0.10, 0.12, 0.14])
    ap.add_argument("--still-ratio", type=float, default=1.25)
    args = ap.parse_args()
    args.work.mkdir(parents=True, exist_ok=True)
    rows = []
    for seed in args.seeds:
        cache = args.work / f"fit{seed}_{int(args.duration)}.json"
        if cache.exists():
            row = json.loads(cache.read_text())
        else:
            row = fit_rig(seed, record(seed, args.work, args.duration), args.database)
            cache.write_text(json.dumps(row))
        rows.append(row)
        print(f"rig {seed}: grade {row['grade']}, {row['verdict'][:60]}, drift p "
              f"{row['drift_p']}, ratio {row['drift_ratio']}, hold-outs "
              f"{np.round(row['healthy_residuals'], 3)}, healthy other runs mean "
              f"{np.mean(row['healthy_other']):.3f}, faulty other run mean "
              f"{np.mean(row['faulty_other']):.3f}", flush=True)
    for rule in ("range", "nearest"):
        table = sweep(rows, args.spreads, args.still_ratio, rule)
        print(f"\nspeed check: {rule}" + (" (the current fit_speed_check)"
                                          if rule == "nearest" else " (commit 9382b29)"))
        trusted = table[table.trusted].groupby(["spread", "kind"]).agg(
            n=("inside", "size"), inside=("inside", "mean"), width=("width", "mean"))
        print("trusted segments of the other runs:")
        print(trusted.round(3).to_string())
        if rule == "nearest":
            summary = table.groupby(["still", "trusted", "spread", "kind"]).agg(
                n=("inside", "size"), inside=("inside", "mean"), width=("width", "mean"))
            print("every segment, by the baseline's stillness and trust:")
            print(summary.round(3).to_string())


if __name__ == "__main__":
    main()
