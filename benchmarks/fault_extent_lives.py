"""Does the fault's angular extent in the difference signal grow with its size?

A full-tooth-face cut of size ``y`` spans the fraction ``y`` of the active profile, so the
stretch of the mesh cycle over which the contact meets it grows with ``y``; a measure of
that extent would be a ruler of size that needs no amplitude. For every ordinary
recording of the stored lives of ``benchmarks/monitor_lives.py`` the one-fault-shot
model's step 5-6 (RMS normalisation with the fit's scale, subtraction of its references)
and the difference signal are formed; on its energy (smoothed over an eighth of a tooth
period, less its median floor) the script measures, in tooth periods of the faulty gear,
the narrowest window about the peak that holds 80 % of the energy (``w80``) and the
energy's standard deviation about the peak (``spread``), beside the difference signal's
RMS. Prints per life the Spearman correlation of each with the true size over the
recordings of size 0.3 and more.

    PYTHONPATH=src python benchmarks/fault_extent_lives.py --lives WORK --seeds 1 … 10
    PYTHONPATH=src python benchmarks/fault_extent_lives.py --simulator   # noise-free, paired
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd


def extent(diff: np.ndarray, teeth: int) -> tuple[float, float, float]:
    """(w80, spread, rms) of one difference signal (module docstring)."""
    from scipy import ndimage

    n = diff.size
    tooth = n / teeth
    energy = ndimage.uniform_filter1d(diff ** 2, size=max(3, int(tooth / 8)), mode="wrap")
    excess = np.maximum(energy - np.median(energy), 0.0)
    centred = np.roll(excess, n // 2 - int(np.argmax(excess)))
    total = centred.sum()
    lo = hi = n // 2
    held = centred[lo]
    while held < 0.8 * total:      # grow the window toward the larger neighbour
        if centred[lo - 1] >= centred[(hi + 1) % n]:
            lo -= 1
            held += centred[lo]
        else:
            hi += 1
            held += centred[hi % n]
    offset = (np.arange(n) - n // 2) / tooth
    spread = float(np.sqrt(np.sum(centred * offset ** 2) / total))
    return (hi - lo + 1) / tooth, spread, float(np.sqrt(np.mean(diff ** 2)))


def simulator_extent() -> None:
    """The same measures on noise-free simulated fault components (the paper's pair at 15
    rps / 10 N m, grades 3, 7 and 11, sizes 0.1-0.9, three signals each, the healthy twin
    subtracted)."""
    from scipy.stats import spearmanr

    from gearshot.signal import difference_signal
    from gearshot.sim import GearPair
    from gearshot.sim.dynamics import simulate_sa_paired

    pair = GearPair.paper()
    sizes = np.repeat(np.round(np.arange(0.1, 0.95, 0.1), 1), 3)
    for grade in (3, 7, 11):
        sa, twins = simulate_sa_paired(pair, speed=15, load=10, grade=grade,
                                       fault_sizes=sizes, rng=list(range(sizes.size)))
        t = np.array([extent(d, pair.z_gear)
                      for d in difference_signal(sa - twins, pair.z_gear)])
        medians = [np.median(t[sizes == y, 0]) for y in np.unique(sizes)]
        print(f"grade {grade}: w80 by size {np.round(medians, 2).tolist()}; Spearman with "
              f"size: w80 {spearmanr(sizes, t[:, 0])[0]:+.2f}, rms "
              f"{spearmanr(sizes, t[:, 2])[0]:+.2f}", flush=True)


def main() -> None:
    from scipy.stats import spearmanr

    from gearshot.estimator import steps
    from gearshot.io import recording_segments
    from gearshot.monitor import load_model
    from gearshot.signal import difference_signal

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--lives", nargs="+", type=Path, default=[])
    parser.add_argument("--seeds", nargs="+", type=int, default=[])
    parser.add_argument("--simulator", action="store_true",
                        help="the noise-free simulated fault components instead")
    args = parser.parse_args()
    if args.simulator:
        simulator_extent()
        return
    for seed in args.seeds:
        rig = next((d / f"rig{seed}" for d in args.lives
                    if (d / f"rig{seed}" / "one_fault_shot.skops").is_file()), None)
        if rig is None:
            continue
        model = load_model(rig / "one_fault_shot.skops")
        est, cond = model.estimator, model.condition
        life = pd.read_csv(rig / "life" / "index.csv", keep_default_na=False)
        life = life[(life.event == "") & (life["size"] >= 0.3)]
        rows = []
        for f, y in zip(life.file, life["size"]):
            sa = recording_segments(rig / "life" / f, gear_teeth=cond["gear_teeth"],
                                    pinion_teeth=cond["pinion_teeth"])
            x = steps.normalize_rms(sa, scale=est.target_scale_)
            sub = steps.suppress_harmonics_target(x, est.references_,
                                                  upsample=est._options().upsample)
            for d in difference_signal(sub, est._mesh_orders()):
                rows.append((y, *extent(d, cond["gear_teeth"])))
        t = np.array(rows)
        rho = [spearmanr(t[:, 0], t[:, k])[0] for k in (1, 2, 3)]
        print(f"seed {seed}: {len(t)} segments of size 0.3-{t[:, 0].max():.2f}; Spearman "
              f"with size: w80 {rho[0]:+.2f}, spread {rho[1]:+.2f}, rms {rho[2]:+.2f}; "
              f"w80 median {np.median(t[:, 1]):.2f} tooth periods", flush=True)


if __name__ == "__main__":
    main()
