"""The forecast alone: how often it lands within ±25 % and how often its interval holds.

Two kinds of lives, each forecast from its first 70 % of recordings (28 of 40) to the
time the size reaches 0.6, scored against the true time:

* **synthetic** (``--synthetic N``): the rig's life shape (40 recordings a day apart,
  healthy, then growth to 0.8) under four laws (power 1.5 and 2, linear, exponential 3)
  and three onsets (0.2, 0.3, 0.4 of the life), read as the true size plus normal noise
  of each ``--noise`` (and, with ``--gain``, a per-life gain ``exp(gain · N(0, 1))``: an
  estimator whose scale is off by a different factor on every machine); recordings
  6–8 and 32–34 untrusted, as the rig's load change and remount;
* **stored lives** (``--work DIR --seeds …``): the histories ``monitor_lives.py`` wrote
  (``DIR/rig{seed}/{mode}.parquet`` and the model), re-forecast with the code of
  the checkout, no estimate recomputed; as ``gearshot monitor`` does, with the model's
  reading spread at the limit (:func:`gearshot.monitor.forecast.reading_spread_at` of its
  example's size; synthetic lives have none).

Each prints the forecasts within ±25 % of the true remaining time, the 90 % intervals
holding the true time, and their median width relative to the true remaining time. For
the stored lives it also prints an **oracle**: the true law and onset known (power 1.5,
onset 0.3: ``VirtualRig.history``'s defaults), only the amplitude fitted to the
estimates; what a forecast can reach when its only error is the estimator's scale.

    PYTHONPATH=src python benchmarks/forecast_lives.py --synthetic 96 --noise 0.03 0.06
    PYTHONPATH=src python benchmarks/forecast_lives.py --work LIVES --seeds 1 2 3
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

from gearshot.monitor import forecast_crossing, load_model, read_history
from gearshot.monitor.forecast import reading_spread_at
from gearshot.monitor.payload import current_records
from gearshot.rig.history import first_crossing, growth_size

LIMIT = 0.6
_LAWS = [("power", {"exponent": 1.5}), ("power", {"exponent": 2.0}), ("linear", {}),
         ("exponential", {"rate": 3.0})]


def synthetic(n: int, noise: float, gain: float, seed: int) -> list[dict]:
    rng = np.random.default_rng(seed)
    lives = []
    for i in range(n):
        law, shape = _LAWS[i % 4]
        onset = (0.2, 0.3, 0.4)[(i // 4) % 3]
        days = np.arange(40) + rng.uniform(-0.1, 0.1, 40)
        days -= days[0]
        size = growth_size(days / days[-1], onset=onset, end_size=0.8, law=law, **shape)
        read = size * np.exp(gain * rng.standard_normal()) + noise * rng.standard_normal(40)
        trusted = np.ones(40, bool)
        trusted[[6, 7, 8, 32, 33, 34]] = False
        lives.append({"days": days, "size": size, "pred": read, "trusted": trusted})
    return lives


def stored(work: Path, seeds: list[int], mode: str) -> list[dict]:
    lives = []
    for seed in seeds:
        base = work / f"rig{seed}"
        model = load_model(base / f"{mode}.skops")
        rows = current_records(read_history(base / f"{mode}.parquet"), model.digest)
        truth = pd.read_csv(base / "life" / "index.csv", keep_default_na=False)
        days = ((rows["time"] - rows["time"].iloc[0]) / pd.Timedelta(days=1)).to_numpy(float)
        lives.append({"days": days, "size": truth["size"].to_numpy(float),
                      "pred": rows["predicted"].to_numpy(float),
                      "trusted": rows["trusted"].to_numpy(bool) & rows["predicted"].notna(),
                      "example": (model.faulty or {}).get("size")})
    return lives


def oracle_time(t: np.ndarray, y: np.ndarray, end: float) -> float | None:
    """Power 1.5 from onset 0.3 of a life ending at ``end``: amplitude by least squares."""
    v = np.clip((t / end - 0.3) / 0.7, 0, None) ** 1.5
    if not np.any(v > 0):
        return None
    a = float(v @ y / (v @ v))
    return None if a <= 0 else end * (0.3 + 0.7 * (LIMIT / a) ** (1 / 1.5))


def score(lives: list[dict], oracle: bool = False) -> str:
    hit = held = made = oracle_hit = 0
    widths = []
    for life in lives:
        k = int(np.floor(0.7 * life["days"].size))
        use = life["trusted"][:k]
        t, y = life["days"][:k][use], life["pred"][:k][use]
        now, truth = life["days"][k - 1], first_crossing(life["days"], life["size"], LIMIT)
        remaining = truth - now
        fc = forecast_crossing(t, y, LIMIT, reading_spread=reading_spread_at(
            LIMIT, life.get("example")))   # as gearshot monitor forecasts
        if fc.time is not None:
            made += 1
            hit += abs(fc.time - truth) <= 0.25 * remaining
            held += fc.low <= truth <= fc.high
            widths.append((fc.high - fc.low) / remaining)
        if oracle and t.size:
            when = oracle_time(t, y, life["days"][-1])
            oracle_hit += when is not None and abs(when - truth) <= 0.25 * remaining
    n = len(lives)
    line = (f"within ±25 % {hit}/{n}, interval holds {held}/{n}, forecasts {made}/{n}, "
            f"median width {np.median(widths) if widths else np.nan:.2f} × remaining")
    return line + (f"; oracle (law and onset known) within ±25 % {oracle_hit}/{n}"
                   if oracle else "")


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--synthetic", type=int, default=0, help="synthetic lives per noise")
    parser.add_argument("--noise", type=float, nargs="+", default=[0.03, 0.06])
    parser.add_argument("--gain", type=float, default=0.0)
    parser.add_argument("--seed", type=int, default=10)
    parser.add_argument("--work", type=Path)
    parser.add_argument("--seeds", type=int, nargs="+", default=[])
    args = parser.parse_args()
    for noise in args.noise if args.synthetic else []:
        lives = synthetic(args.synthetic, noise, args.gain, args.seed)
        print(f"synthetic noise {noise:g}, gain {args.gain:g}: {score(lives)}")
    if args.work is not None:
        for mode in ("one_fault_shot", "zero_shot"):
            print(f"{args.work} {mode} seeds {args.seeds[0]}–{args.seeds[-1]}: "
                  f"{score(stored(args.work, args.seeds, mode), oracle=True)}")


if __name__ == "__main__":
    main()
