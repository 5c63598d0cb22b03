"""SAs of the shared PHM09 records (every shaft, acc_input; two without the tacho) and of
virtual-rig recordings,
saved as arrays, so two runs (before/after a numerical change) can be compared by their
largest relative difference (``--compare A.npz B.npz``).

    PYTHONPATH=src python benchmarks/sa_fingerprint_nosci.py --out before.npz
    PYTHONPATH=src python benchmarks/sa_fingerprint_nosci.py --compare before.npz after.npz

The rig recordings (seeds 0 and 1, surrogate engine, 8 s at 15 rev/s, 10 N m, one healthy
and one faulty each) are written once under ``--rig-dir`` and read back in later runs, so
both runs see the same input.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np

from gearshot import Machine
from gearshot.io import Recording
from gearshot.paper import GEAR_TEETH, PINION_TEETH

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data" / "phm09"
MACHINES = ROOT / "examples" / "machines"


def phm09(out: dict[str, np.ndarray]) -> None:
    for path in sorted(DATA.glob("*.zip")):
        kind = "spur" if path.name.startswith("spur") else "helical"
        m = Machine.from_toml(MACHINES / f"phm09_{kind}.toml")
        rec = Recording.read(path, machine=m).channel("acc_input")
        for shaft in m.shafts:
            out[f"{path.stem}/{shaft}/all"] = rec.to_sa_segments(shaft=shaft,
                                                                 cycles_per_segment=None)
            out[f"{path.stem}/{shaft}/seg"] = rec.to_sa_segments(
                shaft=shaft, cycles_per_segment=10, samples_per_cycle=512)


def notacho(out: dict[str, np.ndarray]) -> None:
    for name, kind in (("spur2_30hz_High_1.zip", "spur"), ("helical2_40hz_Low_1.zip", "helical")):
        m = Machine.from_toml(MACHINES / f"phm09_{kind}_notacho.toml")
        rec = Recording.read(DATA / name, machine=m)
        out[f"{name}/notacho"] = rec.to_sa_segments(shaft=m.monitored.shaft,
                                                    cycles_per_segment=None)


def rig(out: dict[str, np.ndarray], folder: Path) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    for seed in (0, 1):
        for size in (0.0, 0.5):
            path = folder / f"rig_{seed}_{size}.h5"
            if not path.exists():
                from gearshot.rig import VirtualRig
                VirtualRig(seed=seed, engine="surrogate").record(
                    speed=15.0, load=10.0, fault_size=size, duration=8.0).write(path)
            rec = Recording.read(path)
            out[f"{path.stem}/sa"] = rec.to_sa_segments(gear_teeth=GEAR_TEETH,
                                                        pinion_teeth=PINION_TEETH)


def compare(a_path: str, b_path: str) -> None:
    a, b = np.load(a_path), np.load(b_path)
    assert sorted(a.files) == sorted(b.files), "different keys"
    worst, where, same = 0.0, "", 0
    for key in a.files:
        x, y = a[key], b[key]
        assert x.shape == y.shape, key
        same += int(np.array_equal(x, y))
        rel = float(np.max(np.abs(x - y)) / np.max(np.abs(x)))
        if rel > worst:
            worst, where = rel, key
    print(f"{len(a.files)} arrays, {same} bit-identical; largest |a-b| / max|a| = "
          f"{worst:.3g} ({where})")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out")
    ap.add_argument("--compare", nargs=2)
    ap.add_argument("--rig-dir", default=os.path.join(os.environ.get(
        "GEARSHOT_DATA", "/tmp"), "sa_fingerprint_rig"))
    args = ap.parse_args()
    if args.compare:
        compare(*args.compare)
        return
    out: dict[str, np.ndarray] = {}
    phm09(out)
    notacho(out)
    rig(out, Path(args.rig_dir))
    np.savez(args.out, **out)
    print(f"{len(out)} arrays written to {args.out}")


if __name__ == "__main__":
    main()
