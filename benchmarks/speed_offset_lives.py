"""How a healthy recording's estimate follows its speed's distance from the fit's.

Reads stored monitoring lives (``monitor_lives.py --work LIVES``: per life
``LIVES/rig<seed>/{campaign,life}/`` and the histories ``one_fault_shot.parquet``,
``zero_shot.parquet``). For every trusted healthy recording of a life (true size 0, no
event) it takes the recording's measured mean speed (the life index's ``speed``) and its
relative distance to the nearest measured speed of the fit's healthy campaign recordings
(read from their tachos), and prints the estimate against that distance: the Spearman
correlation and the mean by distance band, per model.

    PYTHONPATH=src python benchmarks/speed_offset_lives.py --work LIVES
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import spearmanr

BANDS = (0.0, 0.002, 0.005, 0.01, 0.02, 0.05)


def fit_speeds(life: Path) -> np.ndarray:
    """Measured mean speeds of a life's healthy campaign recordings."""
    from gearshot.io import Recording

    index = pd.read_csv(life / "campaign" / "index.csv")
    files = index.loc[index["fault_size"] == 0, "path"]
    return np.array([Recording.read(life / "campaign" / f).shaft_speed() for f in files])


def healthy_rows(life: Path) -> pd.DataFrame:
    """The life's trusted healthy recordings with their speed distance, per model."""
    index = pd.read_csv(life / "life" / "index.csv")
    speeds = fit_speeds(life)
    rows = []
    for model in ("one_fault_shot", "zero_shot"):
        path = life / f"{model}.parquet"
        if not path.exists():
            continue
        history = pd.read_parquet(path)
        history["file"] = history["recording"].map(lambda p: Path(p).name)
        merged = history.merge(index, on="file")
        keep = (merged["size"] == 0) & merged["event"].isna() & merged["trusted"]
        for _, r in merged[keep].iterrows():
            rows.append(dict(life=life.name, model=model, predicted=float(r["predicted"]),
                             distance=float(np.min(np.abs(r["speed"] - speeds))
                                            / np.mean(speeds))))
    return pd.DataFrame(rows)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--work", required=True, help="folder of the stored lives")
    args = parser.parse_args(argv)
    lives = sorted(p for p in Path(args.work).glob("rig*") if (p / "life").is_dir())
    frame = pd.concat([healthy_rows(p) for p in lives], ignore_index=True)
    print(f"{len(lives)} lives, {len(frame)} trusted healthy estimates")
    for model, g in frame.groupby("model"):
        rho, p = spearmanr(g["predicted"], g["distance"])
        print(f"\n{model}: Spearman(estimate, speed distance) = {rho:.2f} (p = {p:.1g}), "
              f"n = {len(g)}")
        bands = pd.cut(g["distance"], BANDS)
        table = g.groupby(bands, observed=True)["predicted"].agg(
            ["count", "mean", "median", lambda s: float(np.mean(s > 0.1))])
        table.columns = ["count", "mean", "median", "share > 0.1"]
        table.index = [f"{100 * b.left:.1f}-{100 * b.right:.1f} %" for b in table.index]
        print(table.round(3).to_string())


if __name__ == "__main__":
    main()
