"""Rig-family rows broken down by transfer path kind and true grade band.

Reads the rows that ``benchmarks/rig_family.py`` writes (one JSON object per rig and
draw) and prints, per path kind (the real beam FRFs against every other path) and band of
the rig's true DIN grade: rigs, MAE %, ``detection_limit_``, the mean estimate of each
test size and the fitted grade minus the true one.

    python benchmarks/family_breakdown.py ROWS.jsonl [ROWS.jsonl ...] [--variant full]
    python benchmarks/family_breakdown.py --paths      # the family's paths, how peaky

``--paths`` prints, for every transfer path of the family's bank, its band, the spectral
flatness of ``|H|²`` (geometric over arithmetic mean: 1 flat, near 0 a few sharp modes)
and the share of its band within 30 dB of its peak.
"""

from __future__ import annotations

import argparse
import json

import pandas as pd


def breakdown(rows: pd.DataFrame) -> pd.DataFrame:
    """One line per (path kind, grade band): rigs, MAE %, limit, mean estimates by size."""
    sizes = pd.DataFrame(list(rows["mean_prediction"])).add_prefix("reads ")
    frame = pd.concat([rows.reset_index(drop=True), sizes], axis=1)
    frame["path"] = frame["kind"].where(frame["kind"] == "beam", "other")
    frame["band"] = pd.cut(frame["grade"], [0, 6, 9, 12],
                           labels=["1-6", "7-9", "10-12"]).astype(str)
    frame["grade_off"] = frame["fitted_grade"] - frame["grade"]
    cols = {"seed": "nunique", "mae": "mean", "detection_limit": "mean",
            "grade_off": "mean", **{c: "mean" for c in sizes.columns}}
    out = frame.groupby(["path", "band"]).agg(cols).rename(columns={"seed": "rigs"})
    out["mae"] *= 100
    return out.round(3)


def path_shapes() -> pd.DataFrame:
    """Band, spectral flatness and share within 30 dB of the peak of every family path."""
    from pathlib import Path

    import numpy as np

    from gearshot.experiments.family import family_paths

    frf = Path(__file__).resolve().parents[2] / "shared" / "data" / "frf"
    rows = []
    for tf in family_paths(frf, n_synthetic=4, seed=2023):
        power = np.abs(np.asarray(tf.values).ravel()) ** 2
        power = power[power > 0]
        rows.append({"path": tf.name, "band_hz": f"0-{float(np.max(tf.freqs)):.0f}",
                     "flatness": np.exp(np.mean(np.log(power))) / power.mean(),
                     "within_30_db": np.mean(power > 1e-3 * power.max())})
    return pd.DataFrame(rows).set_index("path").round(4)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("rows", nargs="*")
    ap.add_argument("--variant", default="full")
    ap.add_argument("--paths", action="store_true", help="the family's paths, how peaky")
    args = ap.parse_args()
    if args.paths:
        print(path_shapes().to_string())
        return
    if not args.rows:
        ap.error("give result rows (ROWS.jsonl) or --paths")
    rows = pd.DataFrame([json.loads(line) for path in args.rows
                         for line in open(path, encoding="utf-8") if line.strip()])
    rows = rows[rows["variant"] == args.variant]
    with pd.option_context("display.width", 200, "display.max_columns", 20):
        print(breakdown(rows).to_string())


if __name__ == "__main__":
    main()
