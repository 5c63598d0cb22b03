"""The rig-family benchmark (issue #12): accuracy over many virtual rigs, resumable.

Run (development range; every choice is made on it):

    GEARSHOT_DATA=DIR python benchmarks/rig_family.py --range dev \
        --variants full no_feature_selection no_tuning before_da rms_only zero_shot

and once, at the end, the held-out range (``--range heldout``). Rigs are drawn by
:func:`gearshot.experiments.family.draw_family` (grade 1–12, the 12 real FRFs + 4 + 4
synthetic paths, the paper's four conditions, drawn attenuation 10–30 dB); each rig records
6 healthy + 3 sizes × ``--repetitions`` (2) recordings long enough for ``--segments`` (4)
50-cycle SAs (30.5 s at 15 rps, 15.3 s at 30 rps), cached as SA segments (one folder for
every range and tag, ``DIR/family/rigs``; the key covers the rig, the campaign and the SA
pipeline's version); ``--draws``
example draws per rig. One 12-grade database (50 healthy + 350
faulty per grade and condition) serves every rig. Results are appended to
``DIR/family/<range>.jsonl``; a re-run skips what is there. ``--workers N`` (N > 1) runs
rigs on a Dask LocalCluster of N single-threaded processes.

``--param NAME=VALUE`` sets an estimator parameter for every variant (a new configuration:
its rows are computed afresh; VALUE is parsed as JSON when it can be). The database holds
the healthy twins (paired, the default), which ``simulated_reference="auto"`` then
subtracts; ``--no-paired`` uses the old unpaired one.

The same run from the command line: ``gearshot experiment rig-family`` (same options).
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path


def main(argv=None):
    from gearshot import data_home
    from gearshot.experiments import family

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--range", choices=list(family.RANGES), default="dev")
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
    parser.add_argument("--paired", action=argparse.BooleanOptionalAction, default=True,
                        help="use the paired database (healthy twins stored; the default; "
                        "its SAs equal the plain database's); --no-paired: the old one")
    parser.add_argument("--rigs-cache", default=None, help="folder of the rigs' cached SA "
                        "segments, shared by every range and tag (default DATA/family/rigs)")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--rigs-table", action="store_true", help="print the per-rig table")
    parser.add_argument("--checked", action="store_true", help="fit as gearshot predict "
                        "does, checking itself (held-out healthy segments, the example "
                        "recording's other segments); a new configuration")
    args = parser.parse_args(argv)

    data = Path(args.data) if args.data else data_home()
    frf = Path(args.frf_folder)
    if not frf.is_dir():
        frf = Path("/work/shared/data/frf")
    seeds = list(args.seeds) if args.seeds else list(family.RANGES[args.range])
    if args.n_rigs:
        seeds = seeds[: args.n_rigs]
    tag = args.tag or (args.range if not args.seeds else "seeds")
    params = family.parse_params(args.param)
    t0 = time.perf_counter()
    store = family.family_database(data / "family", paired=args.paired)
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
            segments=args.segments, repetitions=args.repetitions, params=params,
            cache_dir=Path(args.rigs_cache) if args.rigs_cache else data / "family" / "rigs",
            client=client, checked=args.checked)
    finally:
        if client is not None:
            client.close()
            cluster.close()
    print(f"{len(seeds)} rigs, {args.draws} draws, {len(frame)} rows, "
          f"{time.perf_counter() - t0:.0f} s this run; params {params}")
    print()
    print(family.format_family_tables(frame, rigs_table=args.rigs_table))


if __name__ == "__main__":
    main()
