"""Sec. 4.1 sweep on Dask: 1 worker vs 2 workers, and a paper-scale extrapolation.

Run:  python benchmarks/bench_sweep.py [--data DIR] [--frf-folder ../shared/data/frf]
Builds a grade-7 database (100 + 700 signals) for 4 speeds at 10 Nm, then runs the same
simulated sweep (every TF of the bank but the held-out one × 3 variants × 4 conditions) on a
LocalCluster of 1 and of 2 single-threaded workers, each into a fresh results folder.
Prints wall times, the speed-up, and the extrapolation to the paper's 26 × 4 × 23 datasets.
"""

from __future__ import annotations

import argparse
import os
import shutil
import time
from pathlib import Path


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--data", default="/tmp/gearshot-bench")
    parser.add_argument("--frf-folder", default=str(Path(__file__).resolve().parents[2]
                                                    / "shared" / "data" / "frf"))
    args = parser.parse_args()
    from dask.distributed import Client, LocalCluster

    from gearshot.experiments import simulated_experiment
    from gearshot.sim import GearPair, build_database

    speeds, loads = [10.0, 15.0, 20.0, 25.0], [10.0]
    store = Path(args.data) / "db-sweep-grade7"
    shutil.rmtree(store, ignore_errors=True)  # time a fresh build
    t0 = time.perf_counter()
    with Client(LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=":0")) as c:
        build_database(store, GearPair.paper(), speeds=speeds, loads=loads, grades=[7],
                       n_healthy=100, n_faulty=700, seed=0, client=c)
    t_db = time.perf_counter() - t0
    n_signals = len(speeds) * len(loads) * 800
    times = {}
    for workers in (1, 2):
        results = Path(args.data) / f"sweep-results-{workers}"
        shutil.rmtree(results, ignore_errors=True)
        with Client(LocalCluster(n_workers=workers, threads_per_worker=1,
                                 dashboard_address=":0")) as client:
            t0 = time.perf_counter()
            frame = simulated_experiment(store, speeds=speeds, loads=loads, grade=7,
                                         frf_folder=args.frf_folder, results_dir=results,
                                         client=client)
            times[workers] = time.perf_counter() - t0
    n_datasets = len(frame) // frame["variant"].nunique()
    per_dataset = times[2] / n_datasets
    per_signal_db = t_db / n_signals
    paper_datasets = 26 * 4 * 23
    paper_db = 26 * 4 * 800 * per_signal_db
    print(f"load average: {os.getloadavg()}")
    print(f"database build, {n_signals} signals on 2 workers: {t_db:.1f} s "
          f"({1000 * per_signal_db:.1f} ms/signal)")
    print(f"sweep of {n_datasets} datasets x {frame['variant'].nunique()} variants: "
          f"1 worker {times[1]:.1f} s, 2 workers {times[2]:.1f} s, "
          f"speed-up {times[1] / times[2]:.2f}x (target >= 1.7x)")
    print(f"paper scale ({paper_datasets} datasets + {26 * 4 * 800} signals) on 2 workers: "
          f"{(paper_datasets * per_dataset + paper_db) / 60:.0f} min extrapolated "
          f"(target <= 60 min)")
    print(frame.groupby("variant")["mae"].mean().mul(100).round(1).to_string())


if __name__ == "__main__":
    main()
