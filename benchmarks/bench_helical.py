"""Helical pairs and fault types: speed and the lab-model comparison (issue #13).

    PYTHONPATH=src python benchmarks/bench_helical.py            # speed + comparison
    PYTHONPATH=src python benchmarks/bench_helical.py --full     # + 12 grades x 800 helical
    PYTHONPATH=src python benchmarks/bench_helical.py --growth   # RMS growth per fault type
    PYTHONPATH=src python benchmarks/bench_helical.py --speed-only [--full]

Prints numbers (no asserts); the load average is printed with each timing.
"""

from __future__ import annotations

import argparse
import math
import os
import tempfile
import time
from pathlib import Path

import numpy as np

from gearshot.paper import GEAR_TEETH, PINION_TEETH
from gearshot.signal import difference_signal
from gearshot.sim import (
    GearPair,
    PartialFaceFault,
    ToothBreakage,
    ToothDestruction,
    build_database,
    mesh_stiffness,
    simulate_sa,
)

REF = Path(__file__).resolve().parents[2] / "shared" / "reference" / "bgu_fault_types.npz"


def _diff_rms(sa):
    return np.sqrt(np.mean(difference_signal(sa, GEAR_TEETH, n_sidebands=2) ** 2, axis=-1))


def per_sa_ms(pair, batch=64, fault_type="ftff", repeats=3):
    """(wall, CPU) ms per SA, best of ``repeats`` batches; CPU = process time (all threads),
    the figure that a loaded machine inflates least."""
    rng = np.random.default_rng(0)
    simulate_sa(pair, speed=15, load=10, grade=7, fault_sizes=[0.5], rng=0,
                fault_type=fault_type)
    best, best_cpu = np.inf, np.inf
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        simulate_sa(pair, speed=15, load=10, grade=7, fault_sizes=rng.uniform(0, 1, batch),
                    rng=rng, fault_type=fault_type)
        best = min(best, time.perf_counter() - t0)
        best_cpu = min(best_cpu, time.process_time() - c0)
    return 1e3 * best / batch, 1e3 * best_cpu / batch


def iso_c_gamma_alpha(pair):
    """ISO 6336-1 mesh stiffness c_gamma_alpha (N/m over the face width), basic rack,
    solid wheels, x = 0: c' = c'_th C_M C_R C_B cos(beta), c_ga = c' (0.75 eps_a + 0.25)."""
    b = pair.helix_angle
    zn1, zn2 = pair.z_pinion / math.cos(b) ** 3, pair.z_gear / math.cos(b) ** 3
    q = 0.04723 + 0.15551 / zn1 + 0.25791 / zn2
    c_prime = (1 / q) * 0.8 * 1.0 * 1.0 * math.cos(b)          # N / (mm um)
    c_ga = c_prime * (0.75 * pair.contact_ratio + 0.25)
    return c_ga * pair.face_width * 1e3 * 1e6                     # N/m


def growth(pair, seeds=(3, 4, 5, 6)):
    """Ratio faulty/healthy of the difference-signal RMS at sizes 0, 0.1 ... 1 on one gear
    (per seed), and its Spearman correlation with the size."""
    from scipy.stats import spearmanr
    sizes = np.linspace(0.0, 1.0, 11)
    print("difference-signal RMS / healthy at sizes 0, 0.1 ... 1, 15 rps 10 Nm DIN 7")
    for ft in ("ftff", "partial_face", "breakage", "destruction"):
        for seed in seeds:
            r = _diff_rms(simulate_sa(pair, speed=15, load=10, grade=7, fault_sizes=sizes,
                                      same_gear=True, rng=seed, fault_type=ft))
            print(f"  {ft:12s} seed {seed}: {' '.join(f'{v:.2f}' for v in r / r[0])}  "
                  f"Spearman {spearmanr(sizes, r).statistic:.3f}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--full", action="store_true")
    ap.add_argument("--compare-only", action="store_true",
                    help="only the lab-model comparison")
    ap.add_argument("--speed-only", action="store_true",
                    help="only the per-SA times (and --full's database run)")
    ap.add_argument("--growth", action="store_true",
                    help="only the difference-signal RMS growth with size per fault type")
    args = ap.parse_args()
    spur, hel = GearPair.paper(), GearPair.helical(math.radians(20))
    if args.growth:
        growth(spur)
        return
    theta = np.linspace(0, 2 * np.pi * GEAR_TEETH / PINION_TEETH, 20000, endpoint=False)
    print("mesh stiffness: mean, (max-min)/mean, ISO 6336-1 c_gamma_alpha")
    for name, p in (("spur", spur), ("helical 20 deg", hel)):
        k = mesh_stiffness(p, theta)
        print(f"  {name:15s} eps_a {p.contact_ratio:.3f} eps_b {p.overlap_ratio:.3f}: "
              f"mean {k.mean():.4g} N/m, fluct {np.ptp(k) / k.mean():.3f}, "
              f"ISO {iso_c_gamma_alpha(p):.4g} N/m (ratio {k.mean() / iso_c_gamma_alpha(p):.2f})")

    print(f"\nper-SA time, batch 64, 15 rps, best of 3; load avg {os.getloadavg()[0]:.2f}")
    for name, p in (() if args.compare_only else (("spur", spur), ("helical 20 deg", hel))):
        for ft in ("ftff", "breakage"):
            wall, cpu = per_sa_ms(p, fault_type=ft)
            print(f"  {name:15s} {ft:9s}: wall {wall:6.2f} ms/SA, CPU {cpu:6.2f} ms/SA "
                  f"(load avg {os.getloadavg()[0]:.2f})")

    if REF.exists() and not args.speed_only:
        d = np.load(REF)
        ref = {k: float(_diff_rms(d[k])) for k in
               ("healthy", "PartialFaceFault", "ToothBreakage", "ToothDestruction")}
        faults = [None, PartialFaceFault(size=2 / 15, profile_size=0.6),
                  ToothBreakage(size=3e-3 / ToothBreakage.active_height(spur),
                                face_share=1.0),
                  ToothDestruction(size=10 / 14, center=8 / 14),
                  ToothBreakage(size=1.0)]
        names = ["healthy", "PartialFaceFault", "ToothBreakage", "ToothDestruction",
                 "missing tooth (breakage y=1)"]
        out = np.array([_diff_rms(simulate_sa(spur, speed=15, load=10, grade=7,
                                              faults=faults, same_gear=True, rng=s))
                        for s in range(6)])
        ratio = out / out[:, :1]
        print("\ndifference-signal RMS ratio faulty/healthy, 15 rps 10 Nm DIN 7, "
              "6 gears (mean, min-max) vs the lab model")
        for i, n in enumerate(names):
            lab = f"{ref[n] / ref['healthy']:.2f}" if n in ref else "-"
            print(f"  {n:30s} ours {ratio[:, i].mean():5.2f} ({ratio[:, i].min():.2f}-"
                  f"{ratio[:, i].max():.2f})  lab {lab}")

    if args.full:
        load0 = os.getloadavg()
        with tempfile.TemporaryDirectory() as tmp:
            t0, c0 = time.perf_counter(), time.process_time()
            build_database(os.path.join(tmp, "db"), hel, speeds=[15], loads=[10],
                           grades=range(1, 13), client=False, progress=False,
                           fault_types=["breakage"])
            wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        load1 = os.getloadavg()
        print(f"\nhelical 20 deg, one condition x 12 grades x 800 breakage signals "
              f"(build_database in-process, incl. Zarr writes): wall {wall:.1f} s "
              f"({1e3 * wall / 9600:.2f} ms/signal), CPU {cpu:.1f} s "
              f"({1e3 * cpu / 9600:.2f} ms/signal); load avg 1/5/15 min before "
              f"{load0[0]:.2f}/{load0[1]:.2f}/{load0[2]:.2f}, after "
              f"{load1[0]:.2f}/{load1[1]:.2f}/{load1[2]:.2f}")


if __name__ == "__main__":
    main()
