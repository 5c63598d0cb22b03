"""Fit + predict time of one rig dataset with 12-grade tuning (target ≤ 10 s).

Run:  python benchmarks/bench_estimator.py [--data DIR]
Builds (once, cached in DIR) the 15 rps / 10 Nm database (12 grades × 50 + 350 signals)
and a virtual-rig campaign, then times OneFaultShotEstimator.fit + predict. Prints numbers.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--data", default="/tmp/gearshot-bench")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    from gearshot.estimator import OneFaultShotEstimator
    from gearshot.experiments import rig_dataset
    from gearshot.rig import VirtualRig
    from gearshot.sim import GearPair, build_database, load_database
    from gearshot.transfer import TransferFunctionBank

    data = Path(args.data)
    store, campaign = data / "db-15-10", data / "campaign-15-10"
    build_database(store, GearPair.paper(), speeds=[15], loads=[10], grades=range(1, 13),
                   n_healthy=50, n_faulty=350, seed=0)
    if not (campaign / "index.csv").is_file():
        VirtualRig(seed=0).campaign(campaign, speed=15, load=10, duration=60)
    t0 = time.perf_counter()
    db = load_database(store, speed=15, load=10)
    t_load = time.perf_counter() - t0
    ds = rig_dataset(campaign, random_state=0)
    sel = TransferFunctionBank.synthetic(1, rng=[0, 99])[0]
    times = []
    for r in range(args.repeat):
        t0 = time.perf_counter()
        est = OneFaultShotEstimator(random_state=r).fit(*ds.fit_args(db), selection_tf=sel,
                                                        **ds.fit_kwargs())
        pred = est.predict(ds.test_sa)
        times.append(time.perf_counter() - t0)
    print(f"load average: {os.getloadavg()}")
    print(f"database: {db.sizes['signal']} SAs (12 grades); target healthy "
          f"{ds.target_healthy.shape[0]} SAs; test {ds.test_sa.shape[0]} SAs")
    print(f"load_database: {t_load:.2f} s")
    print(f"fit + predict (12-grade tuning, feature selection): best {min(times):.2f} s, "
          f"median {np.median(times):.2f} s  (target <= 10 s)")
    print(f"MAE of the last run: {100 * np.mean(np.abs(pred - ds.test_size)):.1f} %")


if __name__ == "__main__":
    main()
