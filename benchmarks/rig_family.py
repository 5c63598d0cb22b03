"""The rig-family benchmark (issue #12): accuracy over many virtual rigs, resumable.

Run (development range; every choice is made on it):

    GEARSHOT_DATA=DIR python benchmarks/rig_family.py --range dev \
        --variants full no_feature_selection no_tuning before_da rms_only zero_shot

and once, at the end, the held-out range (``--range heldout``). Rigs are drawn by
:func:`gearshot.experiments.family.draw_family` (grade 1–12, the 12 real FRFs + 4 + 4
synthetic paths, the paper's four conditions, drawn attenuation 10–30 dB); each rig records
6 healthy + 3 sizes × ``--repetitions`` (2) recordings long enough for ``--segments`` (4)
50-cycle SAs (30.5 s at 15 rps, 15.3 s at 30 rps), cached as SA segments; ``--draws``
example draws per rig. One 12-grade database (50 healthy + 350
faulty per grade and condition) serves every rig. Results are appended to
``DIR/family/<range>.jsonl``; a re-run skips what is there. ``--workers N`` (N > 1) runs
rigs on a Dask LocalCluster of N single-threaded processes.

``--param NAME=VALUE`` sets an estimator parameter for every variant (a new configuration:
its rows are computed afresh; VALUE is parsed as JSON when it can be).
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import pandas as pd

RANGES = {"dev": "DEV_SEEDS", "heldout": "HELDOUT_SEEDS"}


def main(argv=None):
    from gearshot import data_home
    from gearshot.experiments import family
    from gearshot.sim import GearPair, build_database

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--range", choices=list(RANGES), default="dev")
    parser.add_argument("--seeds", type=int, nargs="+", help="explicit rig seeds "
                        "(instead of --range; results go to <tag>.jsonl)")
    parser.add_argument("--n-rigs", type=int, help="first N seeds of the range only")
    parser.add_argument("--variants", nargs="+", default=["full"])
    parser.add_argument("--draws", type=int, default=2)
    parser.add_argument("--duration", type=float, default=None,
                        help="seconds per recording (default: enough for --segments SAs)")
    parser.add_argument("--segments", type=int, default=4)
    parser.add_argument("--repetitions", type=int, default=2)
    parser.add_argument("--frf-folder", default=str(Path(__file__).resolve().parents[1].parent
                                                    / "shared" / "data" / "frf"))
    parser.add_argument("--data", default=None, help="default $GEARSHOT_DATA")
    parser.add_argument("--tag", default=None, help="results file name (default the range)")
    parser.add_argument("--param", action="append", default=[])
    parser.add_argument("--paired", action="store_true", help="use the paired database "
                        "(healthy twins stored; needed by simulated_reference=twin; its "
                        "SAs equal the plain database's)")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--rigs-table", action="store_true", help="print the per-rig table")
    args = parser.parse_args(argv)

    data = Path(args.data) if args.data else data_home()
    frf = Path(args.frf_folder)
    if not frf.is_dir():
        frf = Path("/work/shared/data/frf")
    seeds = list(args.seeds) if args.seeds else list(getattr(family, RANGES[args.range]))
    if args.n_rigs:
        seeds = seeds[: args.n_rigs]
    tag = args.tag or (args.range if not args.seeds else "seeds")
    params = {}
    for item in args.param:
        name, _, value = item.partition("=")
        try:
            params[name] = json.loads(value)
        except json.JSONDecodeError:
            params[name] = value
    store = data / "family" / ("db-4conditions-h50-f350-s0" + ("-paired" if args.paired
                                                               else ""))
    t0 = time.perf_counter()
    build_database(store, GearPair.paper(), speeds=[15, 30], loads=[5, 10],
                   grades=range(1, 13), n_healthy=50, n_faulty=350, seed=0, client=False,
                   paired=args.paired)
    client = None
    if args.workers > 1:
        from dask.distributed import Client, LocalCluster

        os.environ.setdefault("NUMBA_NUM_THREADS", "1")
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1,
                               processes=True)
        client = Client(cluster)
    try:
        frame = family.rig_family_experiment(
            store, seeds, results=data / "family" / f"{tag}.jsonl", frf_folder=frf,
            n_draws=args.draws, variants=args.variants, duration=args.duration,
            segments=args.segments,
            repetitions=args.repetitions, params=params, client=client)
    finally:
        if client is not None:
            client.close()
            cluster.close()
    print(f"{len(seeds)} rigs, {args.draws} draws, {len(frame)} rows, "
          f"{time.perf_counter() - t0:.0f} s this run; params {params}")
    report(frame, rigs_table=args.rigs_table)


def report(frame: pd.DataFrame, *, rigs_table=False):
    from gearshot.experiments.family import family_tables

    tables = family_tables(frame)
    pd.set_option("display.width", 200)
    print("\nMAE % by condition (speed/load), rig mean over draws; p90/max over rigs:")
    print(tables["condition"].to_string())
    print("\nMAE % by path type:")
    print(tables["kind"].to_string())
    print("\nMAE % by the rig's true grade:")
    print(tables["grade"].to_string())
    print("\nMAE % by path attenuation:")
    print(tables["attenuation"].to_string())
    print("\n90 % interval coverage %:")
    print(tables["coverage"].to_string())
    full = frame[frame["variant"] == "full"]
    if not full.empty:
        print(f"\nfull: fit+predict median {full['seconds'].median():.2f} s per dataset; "
              f"recording {full.groupby('seed')['record_seconds'].first().median():.1f} s "
              f"per rig (median, first run)")
    if rigs_table:
        rigs = tables["rigs"].pivot_table(index=["seed", "condition", "kind", "path", "grade",
                                                 "attenuation_db"], columns="variant",
                                          values="mae")
        print(rigs.round(1).to_string())


if __name__ == "__main__":
    main()
