"""Input health (issue #29): the statistics its thresholds were chosen on, and the pass rates.

Usage::

    python benchmarks/input_health.py FOLDER {dev,heldout,zero_tail}

Development records (the thresholds of :mod:`gearshot.io.input_health` were chosen on
them): virtual-rig seeds 0 and 1 (15 rps, 10 N m) and the PHM09 run 1 records of
``../shared/data/phm09``. Held out (run once, after the choice): virtual-rig seeds 2-5
(30 rps, 5 N m) and the PHM09 run 2 records. Prints per set: the largest peak (g), the
smallest standard deviation of a raw channel and of an SA segment (g), the largest share of
samples at a channel's extremes, and how many recordings / segments pass every check.
Also times the zero-tail recipe's refusal by ``Recording.read``.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from gearshot import Machine
from gearshot.io import Recording
from gearshot.io.input_health import check_input, check_segments
from gearshot.paper import GEAR_TEETH, PINION_TEETH
from gearshot.rig import VirtualRig

ROOT = Path(__file__).resolve().parents[1]
PHM = ROOT.parent / "shared" / "data" / "phm09"
MACHINES = ROOT / "examples" / "machines"


def _stats(label, items):
    """items: (raw channels (k, n) in g, SA segments (m, spc) in g) per recording."""
    peak = max(float(np.abs(r).max()) for r, _ in items)
    std_raw = min(float(r.std(axis=-1).min()) for r, _ in items)
    std_sa = min(float(s.std(axis=-1).min()) for _, s in items)
    edge = max(float(max((np.count_nonzero(c == c.min()) + np.count_nonzero(c == c.max()))
                         / c.size for c in r)) for r, _ in items)
    rec_ok = sum(check_input(r).ok for r, _ in items)
    seg = [c.ok for _, s in items for c in check_segments(s)]
    print(f"| {label} | {len(items)} | {peak:.3g} | {std_raw:.3g} | {std_sa:.3g} | "
          f"{edge:.2g} | {rec_ok}/{len(items)} | {sum(seg)}/{len(seg)} |")


def _clip_shares(label, items):
    """Share of samples at the extremes after clipping every raw channel at a level."""
    levels = {"90 % of the peak": lambda c: 0.9 * np.abs(c).max(),
              "half the peak": lambda c: 0.5 * np.abs(c).max(),
              "3 standard deviations": lambda c: 3 * c.std()}
    for name, level in levels.items():
        shares = []
        for raw, _ in items:
            for c in raw:
                rail = level(c)
                x = np.clip(c, -rail, rail)
                shares.append((np.count_nonzero(x == x.min()) + np.count_nonzero(x == x.max()))
                              / x.size)
        caught = sum(check_input(np.clip(c, -level(c), level(c))).failed == "clipped"
                     for raw, _ in items for c in raw)
        print(f"| {label} | clipped at {name} | {min(shares):.2g} - {max(shares):.2g} | "
              f"{caught}/{len(shares)} |")


def _rig(folder: Path, seeds, speed, load):
    items = []
    for seed in seeds:
        sub = folder / f"rig{seed}"
        if not any(sub.glob("*.h5")):
            VirtualRig(seed=seed).campaign(sub, speed=speed, load=load, duration=8,
                                           healthy=2, sizes=(0.3, 0.6), repetitions=1)
        for p in sorted(sub.glob("*.h5")):
            rec = Recording.read(p)
            items.append((rec.acceleration[None], rec.to_sa_segments(
                gear_teeth=GEAR_TEETH, pinion_teeth=PINION_TEETH, cycles_per_segment=10)))
    return items


def _phm(names):
    items = []
    for name in names:
        machine = Machine.from_toml(MACHINES / ("phm09_helical.toml" if name.startswith(
            "helical") else "phm09_spur.toml"))
        rec = Recording.read(PHM / name, machine=machine)
        spc, cps = machine.samples_per_cycle, machine.cycles_per_segment
        sas = []
        for s in machine.sensors:
            x = rec.angle_domain(shaft=machine.monitored.shaft, sensor=s.name,
                                 samples_per_cycle=spc, antialias=machine.antialias)
            n = x.size // (spc * cps)
            sas.append(x[: n * spc * cps].reshape(n, cps, spc).mean(axis=1))
        items.append((rec.acceleration, np.vstack(sas)))
    return items


def zero_tail(folder: Path) -> None:
    """Time the refusal of the zero-tail recipe: ``Recording.read`` (5 runs), then the same
    read without the heap walk, where only the child process's budget stops libhdf5."""
    import functools

    from gearshot.io._format_hdf5 import read_hdf5
    from gearshot.io.recording import READ_BUDGET_S, _bounded_read

    sub = folder / "zero_tail"
    VirtualRig(seed=3).campaign(sub, speed=15, load=10, duration=4, healthy=1, sizes=(),
                                repetitions=1)
    src = sorted(sub.glob("s*.h5"))[0]
    data = src.read_bytes()
    bad = sub / "zero_tail.h5"
    bad.write_bytes(data[:2249] + bytes(len(data) - 2249))
    print(f"zero-tail file: {bad.stat().st_size} bytes, budget "
          f"{READ_BUDGET_S + bad.stat().st_size / 1e6:.1f} s")
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        try:
            Recording.read(bad)
            print("zero tail: read without error")
        except Exception as exc:  # noqa: BLE001 -- printed
            times.append(time.perf_counter() - t0)
            message = f"{type(exc).__name__}: {exc}"
    print(f"Recording.read refused it in {min(times):.3f} s best, {np.median(times):.3f} s "
          f"median of {len(times)}: {message}")
    t0 = time.perf_counter()
    try:
        _bounded_read(functools.partial(read_hdf5, walk_heaps=False), bad, isolate=True)
    except Exception as exc:  # noqa: BLE001 -- printed
        print(f"without the heap walk: {type(exc).__name__} after "
              f"{time.perf_counter() - t0:.1f} s: {exc}")


def main(folder: str, part: str) -> None:
    out = Path(folder)
    if part == "zero_tail":
        zero_tail(out)
        return
    print("| set | recordings | peak (g) | min std raw (g) | min std SA (g) | "
          "max share at extremes | recordings ok | segments ok |")
    print("|---|---|---|---|---|---|---|---|")
    if part == "dev":
        rig = _rig(out, (0, 1), 15, 10)
        _stats("dev: rig seeds 0-1, 15 rps 10 N m", rig)
        run1 = _phm(sorted(p.name for p in PHM.glob("*_1.zip")))
        _stats("dev: PHM09 run 1", run1)
        print("\n| set | clip | share of samples at the extremes | channels refused as clipped |")
        print("|---|---|---|---|")
        _clip_shares("dev: rig seeds 0-1", rig)
        _clip_shares("dev: PHM09 run 1", run1)
        return
    _stats("held out: rig seeds 2-5, 30 rps 5 N m", _rig(out, (2, 3, 4, 5), 30, 5))
    run2 = sorted(p.name for p in PHM.glob("*_2.zip"))
    _stats("held out: PHM09 run 2", _phm(run2))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
