"""Sec. 4.2 on the virtual rig at the paper's four conditions (prints MAE per variant).

Run:  python benchmarks/run_rig_conditions.py [--data DIR] [--repeats 5] [--variants ...]
Builds (once) a 12-grade database (50 healthy + 350 faulty per grade) for 15/30 rps ×
5/10 Nm and a 60 s × 24-recording VirtualRig(seed=0) campaign per condition, then runs
`rig_experiment` with `--repeats` random example draws per condition.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import pandas as pd

CONDITIONS = [(15.0, 10.0), (15.0, 5.0), (30.0, 5.0), (30.0, 10.0)]


def main():
    from gearshot.experiments import RIG_VARIANTS, rig_experiment, summarize
    from gearshot.rig import VirtualRig
    from gearshot.sim import GearPair, build_database, load_database
    from gearshot.transfer import TransferFunctionBank

    parser = argparse.ArgumentParser()
    parser.add_argument("--data", default="/tmp/gearshot-bench")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--variants", nargs="+", default=list(RIG_VARIANTS) + ["zero_shot"])
    args = parser.parse_args()
    data = Path(args.data)
    store = data / "db-4conditions"
    build_database(store, GearPair.paper(), speeds=[15, 30], loads=[5, 10],
                   grades=range(1, 13), n_healthy=50, n_faulty=350, seed=0)
    selection = TransferFunctionBank.synthetic(1, rng=[0, 99])[0]
    frames = []
    for speed, load in CONDITIONS:
        campaign = data / f"campaign-{speed:g}-{load:g}"
        if not (campaign / "index.csv").is_file():
            VirtualRig(seed=0).campaign(campaign, speed=speed, load=load, duration=60)
        t0 = time.perf_counter()
        res, _ = rig_experiment(campaign, load_database(store, speed=speed, load=load),
                                speed=speed, load=load, selection_tf=selection,
                                variants=args.variants, n_repeats=args.repeats, seed=0)
        frames.append(res)
        table = summarize(res).set_index("variant")["mae_percent"].round(1).to_dict()
        cover = res.groupby("variant")["coverage"].mean().round(3).to_dict()
        print(f"{speed:g} rps {load:g} Nm ({time.perf_counter() - t0:.0f} s): MAE % {table}; "
              f"90 % interval coverage {cover}", flush=True)
    res = pd.concat(frames, ignore_index=True)
    print("mean over conditions (MAE %):")
    print(summarize(res).to_string(index=False))
    print("coverage of the 90 % intervals:",
          res.groupby("variant")["coverage"].mean().round(3).to_dict())


if __name__ == "__main__":
    main()
