"""Before/after check of the simulator's outputs (refactors must keep them bit-identical).

    PYTHONPATH=src python benchmarks/check_sim_identity.py save REF.npz   # on the old code
    PYTHONPATH=src python benchmarks/check_sim_identity.py check REF.npz  # on the new code

Cases: spur and helical (20 deg) pairs, the four fault types, grades 4 / 7 / 12, speeds
10 / 15 / 35 rev/s, fresh fault sizes (fixed seeds), ``simulate_sa`` SAs and one
``simulate`` time signal with a speed ramp, the rig surrogate's TE tables, and the SAs and
healthy twins of small paired stores. Prints, per
case, the largest |new - old| / max|old| (0 = bit-identical).
"""

from __future__ import annotations

import sys

import numpy as np

FAULT_TYPES = ("ftff", "partial_face", "breakage", "destruction")


def cases():
    from gearshot.rig.surrogate import SurrogateEngine
    from gearshot.sim import GearPair, simulate, simulate_sa

    pairs = {"spur": GearPair(), "helical": GearPair(helix_angle=np.radians(20.0))}
    out = {}
    for pname, pair in pairs.items():
        for ft in FAULT_TYPES:
            for grade, speed in ((4, 10.0), (7, 15.0), (12, 35.0)):
                rng = np.random.default_rng([21, grade, int(speed), len(ft)])
                sizes = np.concatenate([[0.0, 1.0, 0.5], rng.uniform(0, 1, 9)])
                out[f"sa/{pname}/{ft}/g{grade}/s{speed:g}"] = simulate_sa(
                    pair, speed=speed, load=10, grade=grade, fault_sizes=sizes, rng=rng,
                    fault_type=ft, n_points=1024)
        res = simulate(pair, speed=lambda t: 15.0 + 20.0 * t, load=10.0, grade=7,
                       fault_sizes=[0.0, 0.4], fs=20e3, duration=0.05, rng=3)
        out[f"time/{pname}"] = res.acceleration
    eng = SurrogateEngine()
    for size in (0.0, 0.3, 0.8):
        geom, compl = eng.tables(fault_size=size, reality=None,
                                 rng=np.random.default_rng(5))
        out[f"surrogate/{size}"] = np.stack([geom, compl])
    out.update(database_cases())
    return out


def database_cases():
    """``sa`` and ``sa_twin`` of small paired stores (spur FTFF and breakage, helical
    FTFF; two grades) built in-process, read back with ``load_database``."""
    import tempfile
    from pathlib import Path

    from gearshot.sim import GearPair, build_database, load_database

    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        for pname, pair, types in (("spur", GearPair.paper(), ("ftff", "breakage")),
                                   ("helical", GearPair.helical(np.radians(20.0)),
                                    ("ftff",))):
            store = Path(tmp) / pname
            build_database(store, pair, speeds=[15.0], loads=[10.0], grades=[4, 9],
                           n_healthy=3, n_faulty=37, seed=5, paired=True,
                           fault_types=types, client=False, progress=False)
            for ft in types:
                db = load_database(store, speed=15.0, load=10.0, fault_type=ft)
                out[f"db/{pname}/{ft}/sa"] = np.asarray(db["sa"])
                out[f"db/{pname}/{ft}/sa_twin"] = np.asarray(db["sa_twin"])
    return out


def main(argv):
    mode, path = argv
    new = cases()
    if mode == "save":
        np.savez(path, **new)
        print(f"saved {len(new)} cases to {path}")
        return 0
    old = np.load(path)
    worst = 0.0
    for key, a in new.items():
        b = old[key]
        rel = float(np.max(np.abs(a - b)) / np.max(np.abs(b)))
        worst = max(worst, rel)
        print(f"{key:40s} max|diff|/max|old| = {rel:.3g}"
              + ("  (bit-identical)" if np.array_equal(a, b) else ""))
    print(f"largest relative difference: {worst:.3g}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
