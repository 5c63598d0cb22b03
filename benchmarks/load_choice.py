"""Unknown load: does the load chosen from the healthy recordings find the true one?

Virtual rig (simulator engine, the paper's 17/38 pair, 15 rev/s): for each rig seed and
each true load, one healthy 10 s recording gives the healthy SA segments (10 gear cycles
each) and the long healthy signal; :func:`gearshot.app.load_choice.choose_load` picks a
load from a database over the paper's four loads (5, 10, 15, 20 N m). Printed: the chosen
load, the clarity and every load's distance; written to
``benchmarks/results/load_choice_<range>.csv``.

    python benchmarks/load_choice.py --range dev        # seeds 0-3: MIN_CLARITY chosen here
    python benchmarks/load_choice.py --range heldout    # seeds 100-103: reported once
    python benchmarks/load_choice.py --phm09            # what the PHM09 High/Low records pick

``--phm09``: the spur machine (``examples/machines/phm09_spur.toml``), a database at the
tacho's 30 Hz over loads 5, 20, 80 and 320 N m (the records' load is only "High"/"Low"),
each 30 Hz record's SA segments of the input shaft as the healthy recordings.

Recordings and the database are cached under ``$GEARSHOT_DATA/load_choice``.
"""

from __future__ import annotations

import argparse
import csv
import os
import time
from pathlib import Path

import numpy as np

SEEDS = {"dev": range(0, 4), "heldout": range(100, 104)}
LOADS = (5.0, 10.0, 15.0, 20.0)
SPEED = 15.0
GRADES = tuple(range(3, 11))


def _home() -> Path:
    from gearshot.sim import default_database_path

    home = default_database_path("load-choice").parent / "load_choice"
    home.mkdir(parents=True, exist_ok=True)
    return home


def database(home: Path) -> Path:
    from gearshot.sim import GearPair, build_database

    store = home / "db"
    if not (store / "manifest.json").exists() or not any(store.glob("*.zarr")):
        build_database(store, GearPair.paper(), speeds=[SPEED], loads=list(LOADS),
                       grades=GRADES, n_healthy=8, n_faulty=0, seed=0)
    return store


def recording(home: Path, seed: int, load: float) -> tuple[np.ndarray, np.ndarray]:
    """(healthy SA segments, long angle-domain signal) of one rig recording (cached)."""
    from gearshot.rig import VirtualRig

    cache = home / f"rig_s{seed}_l{load:g}.npz"
    if cache.exists():
        got = np.load(cache)
        return got["sa"], got["long"]
    rec = VirtualRig(seed=seed).record(speed=SPEED, load=load, duration=10.0)
    kw = dict(gear_teeth=38, pinion_teeth=17, samples_per_cycle=2048)
    sa = rec.to_sa_segments(cycles_per_segment=10, **kw)
    long = rec.angle_domain(**kw)
    np.savez(cache, sa=sa, long=long)
    return sa, long


PHM09 = Path(__file__).resolve().parents[2] / "shared" / "data" / "phm09"
PHM09_LOADS = (5.0, 20.0, 80.0, 320.0)


def phm09(home: Path) -> list[dict]:
    """The load each PHM09 30 Hz spur record picks (its own segments as the healthy set)."""
    from gearshot import Machine
    from gearshot.app.load_choice import choose_load
    from gearshot.app.predict_machine import machine_segments
    from gearshot.sim import build_database

    machine = Machine.from_toml(Path(__file__).resolve().parents[1] / "examples" / "machines"
                                / "phm09_spur.toml")
    store = home / "phm09_db"
    speed = machine.sim_speed(30.0)
    if not (store / "manifest.json").exists() or not any(store.glob("*.zarr")):
        build_database(store, machine.gear_pair(), speeds=[speed], loads=list(PHM09_LOADS),
                       grades=GRADES, n_healthy=8, n_faulty=0, seed=0)
    rows = []
    for build in ("spur1", "spur3", "spur2"):
        for load in ("High", "Low"):
            path = PHM09 / f"{build}_30hz_{load}_1.zip"
            sa, x, _ = machine_segments(path, machine, cycles_per_segment=10)
            c = choose_load(store, speed, sa, x, mesh_order=machine.monitored.teeth)
            rows.append({"record": path.name, "chosen": c.load, "clarity": round(c.clarity, 3),
                         **{f"d_{x:g}": round(d, 3) for x, d in zip(c.loads, c.distances)}})
            print(rows[-1], flush=True)
    return rows


def main() -> None:
    from gearshot.app.load_choice import choose_load

    ap = argparse.ArgumentParser()
    ap.add_argument("--range", choices=sorted(SEEDS), default="dev")
    ap.add_argument("--phm09", action="store_true")
    args = ap.parse_args()
    home = _home()
    if args.phm09:
        _write(phm09(home), "phm09")
        return
    t0 = time.perf_counter()
    store = database(home)
    print(f"database {store} ({time.perf_counter() - t0:.0f} s); load average "
          f"{os.getloadavg()[0]:.1f}", flush=True)
    rows = []
    for seed in SEEDS[args.range]:
        for load in LOADS:
            sa, long = recording(home, seed, load)
            c = choose_load(store, SPEED, sa, long, mesh_order=38)
            rows.append({"seed": seed, "true_load": load, "chosen": c.load,
                         "clarity": round(c.clarity, 3),
                         **{f"d_{x:g}": round(d, 3) for x, d in zip(c.loads, c.distances)},
                         **{f"grade_{x:g}": g for x, g in zip(c.loads, c.grades)}})
            print(rows[-1], flush=True)
    _write(rows, args.range)
    right = sum(r["chosen"] == r["true_load"] for r in rows)
    print(f"{right} of {len(rows)} right; {time.perf_counter() - t0:.0f} s; load average "
          f"{os.getloadavg()[0]:.1f}")


def _write(rows: list[dict], name: str) -> None:
    out = Path(__file__).with_name("results") / f"load_choice_{name}.csv"
    out.parent.mkdir(exist_ok=True)
    with out.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


if __name__ == "__main__":
    main()
