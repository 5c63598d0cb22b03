"""What limits rough gears (grades 10–12): the fault component against the gear's own content.

Run:  python benchmarks/rough_gears.py [--data DIR] [--speed 15] [--load 10]

Per grade of the paired database built by ``benchmarks/info_limit.py`` (100 healthy + 700
faulty, seed 0), printed as medians over signals:

* ``rms healthy``: RMS of the healthy SA (absolute, g) — what step 5 divides by;
* ``off-mesh share``: share of the healthy SA's power outside the mesh bands (orders other
  than the mesh harmonics and their ±2 sidebands): the profile-error content that the
  difference signal keeps and the twin (or the target's own healthy reference) removes;
* ``fault rms``: RMS of the fault component ``faulty − twin`` outside the mesh bands for
  sizes 0.4–0.6 (absolute, g), and the same after step 5 (÷ rms healthy);
* ``profile diff rms``: RMS outside the mesh bands of the difference of two *different*
  healthy gears of the grade (what step 6 leaves when the reference is not the same gear:
  the paper's first-healthy reference), ÷ rms healthy;
* ``twin change``: RMS of how the fault component of a size varies across gears (its
  scatter around the mean component of the neighbouring sizes), ÷ its mean RMS.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np


def main():
    from gearshot.estimator.oracle import fault_bins
    from gearshot.sim import load_database

    parser = argparse.ArgumentParser()
    parser.add_argument("--data", default=os.environ.get("GEARSHOT_DATA", "/tmp/gearshot-bench"))
    parser.add_argument("--speed", type=float, default=15.0)
    parser.add_argument("--load", type=float, default=10.0)
    args = parser.parse_args()
    store = Path(args.data) / "db-info"
    print("| grade | rms healthy (g) | off-mesh share | fault rms 0.4–0.6 (g) | fault ÷ rms "
          "healthy | profile diff ÷ rms healthy | fault scatter ÷ fault |")
    print("|---|---|---|---|---|---|---|")
    for grade in range(1, 13):
        db = load_database(store, speed=args.speed, load=args.load, grade=grade)
        sa, twin, y = db.sa.values, db.sa_twin.values, db.fault_size.values
        n = sa.shape[1]
        bins = fault_bins(n, 38)

        def off_mesh_rms(x, bins=bins, n=n):
            spec = np.fft.rfft(x, axis=-1)[:, bins]
            return np.sqrt(2 * np.sum(np.abs(spec) ** 2, axis=1)) / n

        healthy = sa[y == 0]
        rms_h = np.sqrt(np.mean(healthy ** 2, axis=1))
        share = off_mesh_rms(healthy) ** 2 / rms_h ** 2
        mid = (y >= 0.4) & (y <= 0.6)
        fault = off_mesh_rms(sa[mid] - twin[mid])
        prof = off_mesh_rms(healthy[1:] - healthy[:-1])
        spec = np.fft.rfft(sa[mid] - twin[mid], axis=-1)[:, bins]
        order = np.argsort(y[mid])
        ds = spec[order]
        local = ds - 0.5 * (np.roll(ds, 1, axis=0) + np.roll(ds, -1, axis=0))
        scatter = np.sqrt(np.mean(np.sum(np.abs(local[1:-1]) ** 2, axis=1)) / 1.5) \
            / np.sqrt(np.mean(np.sum(np.abs(ds) ** 2, axis=1)))
        print(f"| {grade} | {np.median(rms_h):.3g} | {np.median(share):.3f} | "
              f"{np.median(fault):.3g} | {np.median(fault) / np.median(rms_h):.4f} | "
              f"{np.median(prof) / np.median(rms_h):.4f} | {scatter:.2f} |", flush=True)


if __name__ == "__main__":
    main()
