"""Before/after snapshot of what the simulator, the database and the virtual rig write.

Run it on two versions of the code and compare: every array must be byte-identical.

    python benchmarks/store_snapshot.py OUT_DIR            # writes OUT_DIR/snap.npz
    python benchmarks/store_snapshot.py --compare A.npz B.npz

A snapshot holds: a paired store of every fault type (seed 3, 15 rev/s, 10 N m, grade 7,
1 + 2 signals of 256 points per type) and an unpaired FTFF-only store (seed 5, two speeds),
each loaded back (SAs, twins, seeds, sizes, grades); a 0.3 s recording of every fault type
on the virtual rig (seed 4, simulator engine); a run-up on the surrogate engine; a tiny
campaign (files read back and its index text). The stores themselves stay in OUT_DIR, so
``diff -r`` on the two folders compares them file by file.
"""

from __future__ import annotations

import argparse
import shutil
from pathlib import Path

import numpy as np


def snapshot(out: Path) -> dict[str, np.ndarray]:
    from gearshot.io import Recording
    from gearshot.rig import VirtualRig
    from gearshot.sim import FAULT_TYPES, GearPair, build_database, load_database

    FAULT_TYPE_NAMES = tuple(FAULT_TYPES)     # runs on versions before the registry too

    arrs: dict[str, np.ndarray] = {}
    store, plain = out / "store", out / "store_ftff"
    for folder in (store, plain, out / "camp"):
        shutil.rmtree(folder, ignore_errors=True)
    common = dict(client=False, progress=False, n_points=256)
    build_database(store, GearPair.paper(), speeds=[15.0], loads=[10.0], grades=[7],
                   n_healthy=1, n_faulty=2, seed=3, fault_types=list(FAULT_TYPE_NAMES),
                   paired=True, **common)
    for t in FAULT_TYPE_NAMES:
        ds = load_database(store, speed=15, load=10, fault_type=t)
        for v in ("sa", "sa_twin", "seed", "fault_size", "grade"):
            arrs[f"db_{t}_{v}"] = np.asarray(ds[v].values)
    build_database(plain, GearPair.paper(), speeds=[15.0, 20.0], loads=[10.0], grades=[7],
                   n_healthy=1, n_faulty=1, seed=5, paired=False, **common)
    for sp in (15.0, 20.0):
        ds = load_database(plain, speed=sp, load=10)
        arrs[f"db2_{sp}_sa"], arrs[f"db2_{sp}_seed"] = ds["sa"].values, ds["seed"].values
    for t in FAULT_TYPE_NAMES:
        rec = VirtualRig(seed=4, fault_type=t).record(speed=15, load=10, fault_size=0.5,
                                                      duration=0.3, repetition=1)
        arrs[f"rig_{t}_acc"], arrs[f"rig_{t}_tach"] = rec.acceleration, rec.tacho
    rig = VirtualRig(seed=4, engine="surrogate")
    rec = rig.record(speed=15, load=10, fault_size=0.3, duration=0.5, end_speed=20)
    arrs["rig_ramp_acc"], arrs["rig_ramp_tach"] = rec.acceleration, rec.tacho
    rig.campaign(out / "camp", speed=15, load=10, duration=0.3, healthy=1, sizes=[0.5],
                 repetitions=1, progress=False)
    for p in sorted((out / "camp").glob("*.h5")):
        arrs[f"camp_{p.name}"] = Recording.read(p).acceleration
    arrs["camp_index"] = np.array((out / "camp" / "index.csv").read_text())
    return arrs


def compare(a_path: Path, b_path: Path) -> list[str]:
    a, b = np.load(a_path), np.load(b_path)
    if sorted(a.files) != sorted(b.files):
        return sorted(set(a.files) ^ set(b.files))
    return [k for k in a.files if not (a[k].dtype == b[k].dtype and a[k].shape == b[k].shape
                                       and a[k].tobytes() == b[k].tobytes())]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("paths", nargs="+", type=Path)
    ap.add_argument("--compare", action="store_true")
    args = ap.parse_args()
    if args.compare:
        bad = compare(*args.paths)
        print(f"{len(np.load(args.paths[0]).files)} arrays compared; differing: {bad}")
        raise SystemExit(1 if bad else 0)
    out = args.paths[0]
    out.mkdir(parents=True, exist_ok=True)
    arrs = snapshot(out)
    np.savez(out / "snap.npz", **arrs)
    print(f"{len(arrs)} arrays written to {out / 'snap.npz'}")


if __name__ == "__main__":
    main()
