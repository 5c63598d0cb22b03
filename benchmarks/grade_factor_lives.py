"""Which simulated grade would read a monitored machine's small faults on their true scale?

For every stored life of ``benchmarks/monitor_lives.py`` (``WORK/rig<seed>/``: the fit
campaign, the life and its one-fault-shot history), refit the one-fault-shot model on the
same campaign files as ``gearshot fit`` does (4 healthy recordings in the fit, the last 2
kept out, the 0.42 example) once with the library defaults (soft grade weights) and once
per single grade (``calibration="nominal"``), and re-estimate the life's ordinary
recordings of true size 0.15-0.45 that the stored history trusted. Per fit: the
machine's **scale factor** (mean of ``log(estimate / true size)``), what the fit reads on
the example record's other segments, and the Mahalanobis distance of their selected
features from the grade model's simulated rows of size 0.37-0.47 (a two-feature match of
the example). Prints, per life, the factor of the defaults, of the true grade, of the
grade whose reading of the example is nearest 0.42, of the grade the feature match
picks and of the best grade in hindsight, then how often each lies within ±0.1.

    GEARSHOT_DATA=... PYTHONPATH=src python benchmarks/grade_factor_lives.py \
        --lives WORK --seeds 1 … 10 51 … 60 --database DB [--out CSV]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd


def life_rows(rig: Path, database: str) -> list[dict]:
    from gearshot.app.predict_fit import fit_from_files
    from gearshot.io import recording_segments
    from gearshot.rig import VirtualRig

    seed = int(rig.name[3:])
    camp = pd.read_csv(rig / "campaign" / "index.csv")
    healthy = [str(rig / "campaign" / p) for p, y in zip(camp.path, camp.fault_size) if y == 0]
    faulty = [str(rig / "campaign" / p) for p, y in zip(camp.path, camp.fault_size) if y > 0][0]
    fit, held = healthy[:-2], healthy[-2:]
    life = pd.read_csv(rig / "life" / "index.csv", keep_default_na=False)
    hist = pd.read_parquet(rig / "one_fault_shot.parquet")
    trusted = dict(zip([Path(r).name for r in hist.recording], hist.trusted))
    sel = life[(life["size"] >= 0.15) & (life["size"] <= 0.45) & (life.event == "")
               & life.file.map(lambda f: bool(trusted.get(f, False)))]
    if sel.empty:      # no trusted recording of a small fault (e.g. a fit that refused itself)
        return []
    segments = {f: recording_segments(rig / "life" / f, gear_teeth=38, pinion_teeth=17)
                for f in sel.file}
    true_grade = VirtualRig(seed).reveal().grade
    reads: dict = {}
    rows = []
    for grade in [None, *range(1, 13)]:
        params = {} if grade is None else {"calibration": "nominal", "nominal_grade": grade}
        est, fitted = fit_from_files(database, fit, faulty, 0.42, speed=15, load=10, seed=0,
                                     recordings=held, holdout=0.0, holdout_files=held,
                                     reads=reads, params=params)
        pred = np.array([float(np.mean(est.predict(segments[f]))) for f in sel.file])
        row = dict(seed=seed, grade="soft" if grade is None else grade, true_grade=true_grade,
                   factor=float(np.mean(np.log(np.maximum(pred, 1e-3) / sel["size"]))),
                   example=float(np.mean(est.predict(fitted.rest))), distance=np.nan)
        if grade is not None:
            model = est.model_
            knn, scale = model.pipeline.named_steps["knn"], model.pipeline.named_steps["scale"]
            X, y = knn._fit_X * scale.scale_, knn._y
            near = X[(y >= 0.37) & (y <= 0.47)]
            dx = est.features_of(fitted.rest).mean(axis=0) - near.mean(axis=0)
            cov = np.atleast_2d(np.cov(near.T)) + 1e-12 * np.eye(near.shape[1])
            row["distance"] = float(dx @ np.linalg.solve(cov, dx))
        rows.append(row)
    return rows


def summary(frame: pd.DataFrame) -> pd.DataFrame:
    out = []
    for seed, g in frame.groupby("seed"):
        soft = g[g.grade == "soft"].iloc[0]
        single = g[g.grade != "soft"].assign(grade=lambda d: d.grade.astype(int))
        pick = {"true grade": single[single.grade == soft.true_grade].iloc[0],
                "example nearest 0.42": single.loc[(single.example - 0.42).abs().idxmin()],
                "feature match": single.loc[single.distance.idxmin()],
                "best in hindsight": single.loc[single.factor.abs().idxmin()]}
        out.append(dict(seed=seed, true_grade=int(soft.true_grade), defaults=soft.factor,
                        **{k: v.factor for k, v in pick.items()},
                        **{f"{k} (grade)": int(v.grade) for k, v in pick.items()},
                        **{"best: example read": pick["best in hindsight"].example}))
    return pd.DataFrame(out)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--lives", nargs="+", type=Path, required=True)
    parser.add_argument("--seeds", nargs="+", type=int, required=True)
    parser.add_argument("--database", required=True)
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args()
    rows = []
    for seed in args.seeds:
        rig = next((d / f"rig{seed}" for d in args.lives
                    if (d / f"rig{seed}" / "one_fault_shot.parquet").is_file()), None)
        if rig is None:
            print(f"# seed {seed}: no stored life")
            continue
        rows.extend(life_rows(rig, args.database))
    frame = pd.DataFrame(rows)
    if args.out is not None:
        frame.to_csv(args.out, index=False)
    table = summary(frame)
    print(table.round(2).to_string(index=False))
    for col in ("defaults", "true grade", "example nearest 0.42", "feature match",
                "best in hindsight"):
        v = table[col]
        print(f"# {col}: factor within ±0.1 in {int((v.abs() <= 0.1).sum())}/{len(v)} lives, "
              f"spread (sd) {v.std():.2f}, mean |factor| {v.abs().mean():.2f}")


if __name__ == "__main__":
    main()
