"""Signature of each fault type over the mesh cycle against the FTFF's at equal size.

    PYTHONPATH=src python benchmarks/fig_fault_signatures.py [--size 0.5]

One gear (same profile errors in every run), 15 rps, 10 Nm, DIN 7; signature = faulty SA
minus healthy SA. Writes benchmarks/figures/fault_type_signatures.{png,pdf}.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402

from gearshot.plotting import plot_fault_signatures, save_figure  # noqa: E402
from gearshot.sim import GearPair, fault_of_type, simulate_sa  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=float, default=0.5)
    args = ap.parse_args()
    pair = GearPair.paper()
    names = ["ftff", "partial_face", "breakage", "destruction"]
    faults = [None] + [fault_of_type(n, args.size) for n in names]
    sa = simulate_sa(pair, speed=15, load=10, grade=7, faults=faults, same_gear=True, rng=3)
    sig = {n: sa[i + 1] - sa[0] for i, n in enumerate(names)}
    for n in names:
        level = np.sqrt(np.mean(sig[n] ** 2))
        print(f"{n:13s} size {args.size}: RMS of faulty - healthy {level:8.2f} g, "
              f"peak {np.abs(sig[n]).max():8.1f} g")
    lines = plot_fault_signatures(sig, 38, n_mesh=4)
    fig = lines[0][0].figure
    fig.suptitle(f"fault signatures at size {args.size} vs the FTFF (15 rps, 10 Nm, DIN 7)")
    out = save_figure(fig, Path(__file__).parent / "figures" / "fault_type_signatures")
    print("wrote", *out)


if __name__ == "__main__":
    main()
