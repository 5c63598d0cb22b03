"""Speed of issue #23: simulator per SA, paired databases, fit + predict, sweep fraction.

    python benchmarks/bench_speed.py sim                 # spur/helical ms per SA, 1 thread
    python benchmarks/bench_speed.py machine             # PHM09 spur paired machine database
    python benchmarks/bench_speed.py condition           # 12 grades x 800 + twins, one condition
    python benchmarks/bench_speed.py scheduler           # the same through --scheduler ADDRESS
    python benchmarks/bench_speed.py estimator           # fit + predict of one rig dataset
    python benchmarks/bench_speed.py sweep --conditions 8   # a measured fraction of the sweep
    python benchmarks/bench_speed.py sweep --full        # the whole paper sweep (2392 datasets)
    python benchmarks/bench_speed.py compare             # CPU of a small paired machine db
    python benchmarks/bench_speed.py breakdown           # CPU per step of 2 condition blocks
    PYTHONPATH=OLD/src python benchmarks/bench_speed.py compare   # ... with older code

Prints numbers (no asserts). The box is shared, so every timing is printed with the load
average and, for the simulator, as a ratio to a fixed numpy FFT workload timed in the same
run (``fft_ref``: 10 real FFTs of a 64 x 8192 array, best of 3, one thread). Peak memory:
the process's maximum resident set, its largest finished child process's (an upper bound:
a child started after the driver grew reports at least the driver's size then) and, where
a Dask cluster runs, its largest worker's own peak (VmHWM, asked before closing).
"""

from __future__ import annotations

import argparse
import math
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
PHM09_SPUR = ROOT / "examples" / "machines" / "phm09_spur.toml"
PHM09_SPEEDS = [30, 35, 40, 45, 50]        # input-shaft Hz of the PHM 2009 recordings


def load_avg() -> str:
    return "/".join(f"{v:.2f}" for v in os.getloadavg())


def peak_mb() -> str:
    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    kids = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    return f"peak RSS {own:.0f} MB (largest child process {kids:.0f} MB)"


def _own_peak_mb() -> float:
    """This process's peak resident set (VmHWM), MB. Not ``ru_maxrss``: a spawned
    process's ``ru_maxrss`` keeps the parent's resident set at the fork (Linux carries it
    over ``exec``), so a Dask worker started after an in-process build would report the
    builder's peak."""
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def workers_peak(client) -> str:
    """The largest peak RSS of the client's workers (asked before the cluster closes;
    their own, see :func:`_own_peak_mb`)."""
    try:
        peaks = client.run(_own_peak_mb).values()
    except Exception as exc:                    # a worker gone: say so, keep the timing
        return f"workers' peak RSS unknown ({type(exc).__name__})"
    return f"largest worker's peak RSS {max(peaks):.0f} MB"


def fft_ref() -> tuple[float, float]:
    """(wall, CPU) seconds of the fixed FFT workload, best of 3."""
    x = np.random.default_rng(0).standard_normal((64, 8192))
    best_w = best_c = math.inf
    for _ in range(3):
        t0, c0 = time.perf_counter(), time.process_time()
        for _ in range(10):
            np.fft.rfft(x, axis=-1)
        best_w = min(best_w, time.perf_counter() - t0)
        best_c = min(best_c, time.process_time() - c0)
    return best_w, best_c


def per_sa(pair, fault_type="ftff", batch=64, repeats=3, speed=15.0):
    """(wall, CPU) ms per SA, best of ``repeats`` batches, fresh fault sizes each."""
    from gearshot.sim import simulate_sa

    simulate_sa(pair, speed=speed, load=10, grade=7, fault_sizes=[0.5, 0.25], rng=0,
                fault_type=fault_type)                                   # compile / warm
    best_w = best_c = math.inf
    for rep in range(repeats):
        rng = np.random.default_rng([23, batch, rep, int(speed)])
        sizes = rng.uniform(0.0, 1.0, batch)
        t0, c0 = time.perf_counter(), time.process_time()
        simulate_sa(pair, speed=speed, load=10, grade=7, fault_sizes=sizes, rng=rng,
                    fault_type=fault_type)
        best_w = min(best_w, time.perf_counter() - t0)
        best_c = min(best_c, time.process_time() - c0)
    return 1e3 * best_w / batch, 1e3 * best_c / batch


def bench_sim(args):
    import numba

    from gearshot.sim import GearPair

    numba.set_num_threads(1)
    ref_w, ref_c = fft_ref()
    print(f"one numba thread; fft_ref {1e3 * ref_w:.1f} ms wall / {1e3 * ref_c:.1f} ms CPU; "
          f"load avg {load_avg()}")
    pairs = [("spur", GearPair.paper()), ("helical 20 deg", GearPair.helical(math.radians(20)))]
    for name, pair in pairs:
        for ft in ("ftff", "breakage"):
            w, c = per_sa(pair, ft)
            print(f"  {name:15s} {ft:9s} batch 64, 15 rps: wall {w:5.2f} ms/SA, CPU "
                  f"{c:5.2f} ms/SA = {c / (1e3 * ref_c):.3f} fft_ref (load avg {load_avg()})")
    for speed in (10, 35):
        w, c = per_sa(GearPair.paper(), speed=speed)
        print(f"  spur ftff at {speed} rps: wall {w:5.2f} ms/SA, CPU {c:5.2f} ms/SA")
    ref_w2, ref_c2 = fft_ref()
    print(f"fft_ref again {1e3 * ref_w2:.1f} ms wall / {1e3 * ref_c2:.1f} ms CPU; {peak_mb()}")


def _timed_build(store, pair, client=None, **kw):
    from gearshot.sim import build_database

    shutil.rmtree(store, ignore_errors=True)
    l0 = load_avg()
    t0, c0 = time.perf_counter(), time.process_time()
    build_database(store, pair, client=client, progress=False, **kw)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    return wall, cpu, l0


def children_cpu() -> float:
    """CPU seconds of the finished child processes (e.g. a closed LocalCluster's workers)."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _local_client(workers=2):
    """The LocalCluster ``gearshot simulate`` starts (``gearshot._cluster``: one thread per
    worker, its workers' allocator settings; none with an older tree's code)."""
    import dask
    from dask.distributed import Client, LocalCluster

    try:
        from gearshot._cluster import WORKER_MALLOC
    except ImportError:
        WORKER_MALLOC = {}
    key = "distributed.nanny.pre-spawn-environ"
    with dask.config.set({key: {**dask.config.get(key), **WORKER_MALLOC}}):
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=":0")
    return Client(cluster), cluster


def bench_machine(args):
    from gearshot.machine import Machine

    mach = Machine.from_toml(PHM09_SPUR)
    pair = mach.gear_pair()
    speeds = [mach.sim_speed(s) for s in PHM09_SPEEDS]
    n = len(speeds) * 12 * 160
    kw = dict(speeds=speeds, loads=[10.0], grades=range(1, 13), n_healthy=20, n_faulty=140,
              seed=0)
    with tempfile.TemporaryDirectory(dir=args.tmp) as tmp:
        for paired in (True, False)[:1 if args.paired_only else 2]:
            t0 = time.perf_counter()
            k0 = children_cpu()
            client, cluster = _local_client()
            start = time.perf_counter() - t0
            try:
                wall, cpu, l0 = _timed_build(Path(tmp) / "db", pair, client, paired=paired,
                                             **kw)
                wpeak = workers_peak(client)
            finally:
                client.close()
                cluster.close()
            workers_cpu = children_cpu() - k0
            print(f"PHM09 spur machine database, {len(speeds)} speeds x 12 grades x 160 "
                  f"{'+ twins' if paired else '(unpaired)'} = {n} signals, LocalCluster 2 x 1 "
                  f"thread: {wall:.1f} s wall (+ {start:.1f} s cluster start), workers' CPU "
                  f"{workers_cpu:.1f} s (/2 = {workers_cpu / 2:.1f} s on 2 free cores); load "
                  f"avg before {l0}, after {load_avg()}; {peak_mb()}; {wpeak}")
    print(f"fft_ref {1e3 * fft_ref()[1]:.1f} ms CPU")


def bench_condition(args):
    from gearshot.sim import GearPair

    kw = dict(speeds=[15.0], loads=[10.0], grades=range(1, 13), n_healthy=100, n_faulty=700,
              seed=0)
    with tempfile.TemporaryDirectory(dir=args.tmp) as tmp:
        for paired in (True, False):
            wall, cpu, l0 = _timed_build(Path(tmp) / "db", GearPair.paper(), None,
                                         paired=paired, **kw)
            print(f"one condition (15 rps, 10 N m) x 12 grades x 800 "
                  f"{'+ twins' if paired else '(unpaired)'}, in-process (client=None): "
                  f"{wall:.1f} s wall, {cpu:.1f} s CPU; load avg before {l0}, after "
                  f"{load_avg()}; {peak_mb()}")
        k0 = children_cpu()
        client, cluster = _local_client()
        try:
            wall, cpu, l0 = _timed_build(Path(tmp) / "db", GearPair.paper(), client,
                                         paired=True, **kw)
            wpeak = workers_peak(client)
        finally:
            client.close()
            cluster.close()
        workers_cpu = children_cpu() - k0
        print(f"  + twins on a LocalCluster (2 x 1 thread, started before timing): "
              f"{wall:.1f} s wall, workers' CPU {workers_cpu:.1f} s (/2 = "
              f"{workers_cpu / 2:.1f} s on 2 free cores); load avg before {l0}, after "
              f"{load_avg()}; {peak_mb()}; {wpeak}")
    print(f"fft_ref {1e3 * fft_ref()[1]:.1f} ms CPU")


def bench_scheduler(args):
    """``gearshot simulate --scheduler ADDRESS`` against a cluster started apart."""
    from dask.distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=":0")
    try:
        with tempfile.TemporaryDirectory(dir=args.tmp) as tmp:
            cmd = [sys.executable, "-m", "gearshot.app.cli", "simulate", "--store",
                   str(Path(tmp) / "db"), "--speed", "15", "--load", "10",
                   *[a for g in range(1, 13) for a in ("--grade", str(g))],
                   "--paired", "--scheduler", cluster.scheduler_address]
            l0 = load_avg()
            t0 = time.perf_counter()
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
            wall = time.perf_counter() - t0
        with Client(cluster) as client:
            wpeak = workers_peak(client)
    finally:
        cluster.close()
    print(f"gearshot simulate --paired --scheduler ADDRESS (a LocalCluster of 2 x 1 thread "
          f"started apart), one condition x 12 grades x 800 + twins: {wall:.1f} s wall "
          f"incl. the CLI's start; load avg before {l0}, after {load_avg()}; {peak_mb()} "
          f"(children: the CLI and the closed workers); {wpeak}")


def bench_estimator(args):
    from gearshot.estimator import OneFaultShotEstimator
    from gearshot.experiments import rig_dataset
    from gearshot.rig import VirtualRig
    from gearshot.sim import GearPair, build_database, load_database
    from gearshot.transfer import TransferFunctionBank

    data = Path(args.data)
    for paired in (False, True):
        store = data / ("db-15-10" + ("-paired" if paired else ""))
        campaign = data / "campaign-15-10"
        build_database(store, GearPair.paper(), speeds=[15], loads=[10],
                       grades=range(1, 13), n_healthy=50, n_faulty=350, seed=0,
                       paired=paired, progress=False)
        if not (campaign / "index.csv").is_file():
            VirtualRig(seed=0).campaign(campaign, speed=15, load=10, duration=60)
        db = load_database(store, speed=15, load=10)
        ds = rig_dataset(campaign, random_state=0)
        sel = TransferFunctionBank.synthetic(1, rng=[0, 99])[0]
        times, cpus = [], []
        for r in range(args.repeat + 1):
            t0, c0 = time.perf_counter(), time.process_time()
            est = OneFaultShotEstimator(random_state=r).fit(*ds.fit_args(db),
                                                            selection_tf=sel)
            pred = est.predict(ds.test_sa)
            if r:                                   # the first run warms the caches
                times.append(time.perf_counter() - t0)
                cpus.append(time.process_time() - c0)
        ref_c = fft_ref()[1]
        print(f"fit + predict, rig dataset 15 rps / 10 N m, {db.sizes['signal']} SAs "
              f"{'+ twins' if paired else '(unpaired)'}, {ds.test_sa.shape[0]} test SAs: "
              f"median {np.median(times):.3f} s wall, {np.median(cpus):.3f} s CPU "
              f"= {np.median(cpus) / ref_c:.0f} fft_ref (fft_ref {1e3 * ref_c:.1f} ms CPU) "
              f"(best {min(times):.3f} s); MAE {100 * np.mean(np.abs(pred - ds.test_size)):.2f} "
              f"%; load avg {load_avg()}; {peak_mb()}")


def bench_compare(args):
    """CPU seconds of a small paired machine database built in-process on one thread:
    run once with this tree and once with an older one (PYTHONPATH=OLD/src) to compare
    the code on the same box at the same time."""
    import numba

    from gearshot.machine import Machine

    numba.set_num_threads(1)
    mach = Machine.from_toml(PHM09_SPUR)
    with tempfile.TemporaryDirectory(dir=args.tmp) as tmp:
        wall, cpu, l0 = _timed_build(
            Path(tmp) / "db", mach.gear_pair(), False, speeds=[mach.sim_speed(40)],
            loads=[10.0], grades=range(1, 13), n_healthy=20, n_faulty=140, seed=0,
            paired=True)
    ref_w, ref_c = fft_ref()
    print(f"PHM09 spur, 40 Hz x 12 grades x 160 + twins, in-process, one thread: {cpu:.1f} s "
          f"CPU ({wall:.1f} s wall), = {cpu / ref_c:.0f} fft_ref (fft_ref {1e3 * ref_c:.1f} "
          f"ms CPU); load avg before {l0}, after {load_avg()}; {peak_mb()}")


def _workers_usage(client) -> tuple[float, float]:
    """(CPU seconds so far summed over the workers, largest worker peak RSS in MB: their
    own, VmHWM, see :func:`_own_peak_mb`)."""
    def usage():
        r = resource.getrusage(resource.RUSAGE_SELF)
        return r.ru_utime + r.ru_stime, _own_peak_mb()

    got = client.run(usage).values()
    return sum(c for c, _ in got), max(m for _, m in got)


def _sweep_conditions(args) -> tuple[list, list]:
    """(speeds, loads) of the sweep: every paper condition with ``--full`` (26 x 4), else
    ``--conditions`` spread over the speeds at every load."""
    from gearshot.paper import PAPER_LOADS, PAPER_SPEEDS

    if args.full:
        return list(PAPER_SPEEDS), list(PAPER_LOADS)
    k = max(1, min(args.conditions // len(PAPER_LOADS), len(PAPER_SPEEDS)))
    return ([PAPER_SPEEDS[i] for i in np.linspace(0, len(PAPER_SPEEDS) - 1, k).astype(int)],
            list(PAPER_LOADS))


def bench_sweep(args):
    """The paper sweep end to end (``--full``: 26 speeds x 4 loads, 2392 datasets) or a
    measured fraction of it (``--conditions``): the paired grade-7 database built fresh,
    then the Sec. 4.1 datasets x 3 variants, on a LocalCluster of 2 single-threaded
    workers. Prints the wall and the workers' CPU of each part, peak memory and the MAE by
    variant; a fraction is also extrapolated to the whole sweep."""
    from gearshot._cluster import dask_client
    from gearshot.experiments import simulated_experiment
    from gearshot.paper import PAPER_LOADS, PAPER_SPEEDS
    from gearshot.sim import GearPair, build_database

    speeds, loads = _sweep_conditions(args)
    n_cond, n_all = len(speeds) * len(loads), len(PAPER_SPEEDS) * len(PAPER_LOADS)
    # the commands' cluster (gearshot._cluster): 2 single-thread workers, their allocator set
    with dask_client(None, workers=2) as client:
        with tempfile.TemporaryDirectory(dir=args.tmp) as tmp:
            store = Path(tmp) / "db"
            l0, (c0, _) = load_avg(), _workers_usage(client)
            t0 = time.perf_counter()
            build_database(store, GearPair.paper(), speeds=speeds, loads=loads, grades=[7],
                           n_healthy=100, n_faulty=700, seed=0, client=client, paired=True,
                           progress=False)
            t_db, (c1, _) = time.perf_counter() - t0, _workers_usage(client)
            t0 = time.perf_counter()
            frame = simulated_experiment(store, speeds=speeds, loads=loads, grade=7,
                                         results_dir=Path(tmp) / "res", client=client)
            t_sweep, (c2, rss) = time.perf_counter() - t0, _workers_usage(client)
    n_sets = len(frame) // frame["variant"].nunique()
    print(f"{'whole sweep' if n_cond == n_all else 'sweep fraction'}: {n_cond} conditions "
          f"({len(speeds)} speeds x {len(loads)} loads), {n_sets} datasets x "
          f"{frame['variant'].nunique()} variants; load avg before {l0}, after {load_avg()}")
    print(f"  total {t_db + t_sweep:.1f} s wall = database {t_db:.1f} s "
          f"({t_db / n_cond:.2f} s per condition) + datasets {t_sweep:.1f} s "
          f"({t_sweep / n_sets:.3f} s per dataset)")
    print(f"  workers' CPU {c2 - c0:.1f} s = database {c1 - c0:.1f} s + datasets "
          f"{c2 - c1:.1f} s ({(c2 - c1) / n_sets:.3f} s per dataset); largest worker peak "
          f"RSS {rss:.0f} MB; {peak_mb()}")
    if n_cond != n_all:
        full_db, full_sets = t_db / n_cond * n_all, t_sweep / n_sets * 2392
        print(f"  extrapolated to the paper sweep ({n_all} conditions, 2392 datasets): "
              f"database {full_db / 60:.1f} min + datasets {full_sets / 60:.1f} min = "
              f"{(full_db + full_sets) / 60:.1f} min on 2 workers")
        # on a shared box the walls carry the other jobs; the CPU / 2 does not
        cpu_db, cpu_sets = (c1 - c0) / n_cond * n_all / 2, (c2 - c1) / n_sets * 2392 / 2
        print(f"  from the workers' CPU (2 workers kept busy): database {cpu_db / 60:.1f} min "
              f"+ datasets {cpu_sets / 60:.1f} min = {(cpu_db + cpu_sets) / 60:.1f} min")
    print(frame.groupby("variant")["mae"].mean().mul(100).round(2).to_string())


def bench_breakdown(args):
    """CPU of the steps of 2 paired condition blocks (grades 7, 8 at 15 rps / 10 N m,
    800 + twins each), in-process, numba one thread: wrappers around the steps."""
    import numba

    import gearshot.sim._system as system
    import gearshot.sim.database as database
    import gearshot.sim.dynamics as dyn
    from gearshot.sim import GearPair, build_database

    numba.set_num_threads(1)
    if hasattr(database, "block_threads"):        # blocks one after another, timed apart
        database.block_threads = lambda n: 1
    acc: dict = {}

    def wrap(owner, name, key):
        func = getattr(owner, name)

        def timed(*a, **k):
            c = time.process_time()
            try:
                return func(*a, **k)
            finally:
                acc[key] = acc.get(key, 0.0) + time.process_time() - c
        setattr(owner, name, timed)

    for owner, name, key in ((system, "newmark_spur", "kernel"),
                             (dyn, "make_batch", "fault tables (make_batch)"),
                             (dyn, "_fft_resample", "FFT resampling"),
                             (dyn, "draw_errors", "profile errors"),
                             (dyn, "as_rng", "one Generator per seed"),
                             (dyn, "resolve_faults", "fault objects"),
                             (system.Batch, "shared", "batch-shared contacts")):
        wrap(owner, name, key)
    kw = dict(speeds=[15.0], loads=[10.0], seed=0, paired=True, progress=False)
    with tempfile.TemporaryDirectory(dir=args.tmp) as tmp:
        build_database(Path(tmp) / "warm", GearPair.paper(), grades=[3], n_healthy=2,
                       n_faulty=2, **kw)
        acc.clear()
        c0 = time.process_time()
        build_database(Path(tmp) / "db", GearPair.paper(), grades=[7, 8], n_healthy=100,
                       n_faulty=700, **kw)
        total = time.process_time() - c0
    print(f"2 paired condition blocks (3200 SAs), numba one thread: {total:.2f} s CPU = "
          f"{1e3 * total / 3200:.3f} ms per SA; load avg {load_avg()}")
    for key, v in sorted(acc.items(), key=lambda kv: -kv[1]):
        print(f"  {key:28s} {v:6.2f} s  {100 * v / total:5.1f} %")
    print(f"  {'rest (zarr, checksums, ...)':28s} {total - sum(acc.values()):6.2f} s")
    print(f"  {peak_mb()}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("part", choices=["sim", "machine", "condition", "scheduler", "estimator",
                                     "sweep", "compare", "breakdown"])
    ap.add_argument("--paired-only", action="store_true")
    ap.add_argument("--data", default=os.path.join(tempfile.gettempdir(), "gearshot-bench"))
    ap.add_argument("--tmp", default=None, help="folder for temporary stores")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--conditions", type=int, default=8)
    ap.add_argument("--full", action="store_true",
                    help="sweep: the whole paper sweep (26 speeds x 4 loads, 2392 datasets)")
    args = ap.parse_args()
    print(f"{time.strftime('%Y-%m-%d %H:%M:%S UTC', time.gmtime())}, {os.cpu_count()} cores, "
          f"load avg {load_avg()}")
    globals()[f"bench_{args.part}"](args)


if __name__ == "__main__":
    main()
