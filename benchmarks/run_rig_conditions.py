"""Sec. 4.2 on the virtual rig at the paper's four conditions (prints MAE per variant).

Run:  python benchmarks/run_rig_conditions.py [--data DIR] [--repeats 5] [--variants ...]
          [--fault-type breakage] [--n-faulty 350] [--duration 60] [--sizes 0.32 0.56 0.66]
Builds (once) a 12-grade database (50 healthy + ``--n-faulty`` faulty per grade, of
``--fault-type``) for 15/30 rps × 5/10 Nm and a ``--duration`` s × 24-recording
VirtualRig(seed=0, fault_type=...) campaign per condition (6 healthy + 6 per size), then
runs `rig_experiment` with `--repeats` random example draws per condition. The FTFF keeps
its old file names; another fault type gets its own database and campaign folders.
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
    parser.add_argument("--fault-type", default="ftff",
                        help="fault type of the database and the rig (default ftff)")
    parser.add_argument("--n-faulty", type=int, default=350,
                        help="faulty SAs per grade and condition in the database")
    parser.add_argument("--duration", type=float, default=60.0,
                        help="seconds per campaign recording")
    parser.add_argument("--sizes", type=float, nargs="+", default=[0.32, 0.56, 0.66],
                        help="fault size labels of the campaign (the paper's by default)")
    args = parser.parse_args()
    data = Path(args.data)
    ft = args.fault_type
    # the FTFF at the paper's settings keeps its old folder names
    tag = "" if ft == "ftff" else f"-{ft}"
    db_tag = tag + ("" if args.n_faulty == 350 else f"-n{args.n_faulty}")
    if args.duration != 60.0:
        tag += f"-d{args.duration:g}"
    if args.sizes != [0.32, 0.56, 0.66]:
        tag += f"-y{'_'.join(f'{y:g}' for y in args.sizes)}"
    store = data / f"db-4conditions{db_tag}"
    t0 = time.perf_counter()
    build_database(store, GearPair.paper(), speeds=[15, 30], loads=[5, 10],
                   grades=range(1, 13), n_healthy=50, n_faulty=args.n_faulty, seed=0,
                   fault_types=[ft])
    print(f"database {store} ready ({time.perf_counter() - t0:.0f} s)", flush=True)
    selection = TransferFunctionBank.synthetic(1, rng=[0, 99])[0]
    frames = []
    for speed, load in CONDITIONS:
        campaign = data / f"campaign{tag}-{speed:g}-{load:g}"
        if not (campaign / "index.csv").is_file():
            t0 = time.perf_counter()
            VirtualRig(seed=0, fault_type=ft).campaign(campaign, speed=speed, load=load,
                                                       duration=args.duration,
                                                       sizes=args.sizes, progress=False)
            print(f"campaign {campaign} recorded ({time.perf_counter() - t0:.0f} s)",
                  flush=True)
        t0 = time.perf_counter()
        res, _ = rig_experiment(campaign, load_database(store, speed=speed, load=load,
                                                        fault_type=ft),
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
