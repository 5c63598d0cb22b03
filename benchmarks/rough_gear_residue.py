"""Rough gears on the rig family: the target's residue against the fault component.

Run:  GEARSHOT_DATA=DIR python benchmarks/rough_gear_residue.py [SEED ...]   (default 100–107)

Per rig (its SA segments cached by ``benchmarks/rig_family.py``; draw 0; library defaults):
the RMS outside the mesh bands of the target's residue (its healthy differences after
step 6, ÷ the target's healthy RMS: ``target_residue_power_``) and of the simulated fault
component (faulty − twin, sizes 0.4–0.6, through the fit's path and step 5's scale) for
the rig's true grade and for the fit's best grade; and the fit's ``detection_limit_``.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np


def main():
    from gearshot.estimator import OneFaultShotEstimator, steps
    from gearshot.estimator.oracle import fault_bins
    from gearshot.experiments.family import (
        SA_PIPELINE_VERSION,
        draw_family,
        family_database,
        family_paths,
    )
    from gearshot.experiments.family_rigs import rig_segments
    from gearshot.experiments.rig import rig_dataset
    from gearshot.paper import RIG_HEALTHY_RECORDINGS, TABLE1_SIZES
    from gearshot.sim import load_database
    from gearshot.transfer import TransferFunctionBank
    from gearshot.transfer.estimation import one_sided_response

    data = Path(os.environ.get("GEARSHOT_DATA", "/tmp/gearshot-bench"))
    seeds = [int(a) for a in sys.argv[1:]] or list(range(100, 108))
    paths = family_paths(Path(__file__).resolve().parents[2] / "shared" / "data" / "frf",
                         n_synthetic=4, seed=2023)
    store = family_database(data / "family", paired=True, progress=False)
    campaign = dict(duration=None, segments=4, healthy=int(RIG_HEALTHY_RECORDINGS),
                    sizes=[float(y) for y in TABLE1_SIZES], repetitions=2,
                    sa_pipeline=SA_PIPELINE_VERSION)
    print("| rig | condition | true grade | fitted grade | residue rms (÷ healthy rms) | "
          "fault 0.4–0.6 rms, true grade | fault, fitted grade | detection limit |")
    print("|---|---|---|---|---|---|---|---|")
    for rig in draw_family(seeds, paths):
        index, segments = rig_segments(rig, paths, data / "family" / "rigs", campaign)
        database = load_database(store, speed=rig.speed, load=rig.load)
        ds = rig_dataset(index, random_state=[rig.seed, 0], segments=segments)
        sel = TransferFunctionBank.synthetic(1, rng=np.random.default_rng([rig.seed, 99]))[0]
        est = OneFaultShotEstimator(random_state=1000 * rig.seed).fit(
            *ds.fit_args(database), selection_tf=sel, **ds.fit_kwargs())
        n = est.n_points_
        bins = fault_bins(n, 38)
        res = np.sqrt(2 * est.target_residue_power_[bins].sum()) / n
        path = one_sided_response(est.transfer_function_)
        out = []
        for g in (rig.grade, est.grade_):
            db = load_database(store, speed=rig.speed, load=rig.load, grade=g)
            sa, tw, y = db.sa.values, db.sa_twin.values, db.fault_size.values
            scale = steps.rms_scale(steps.propagate_simulated(sa[y == 0],
                                                              est.transfer_function_))
            mid = (y >= 0.4) & (y <= 0.6)
            spec = np.fft.rfft(sa[mid] - tw[mid], axis=1) / scale * path
            out.append(np.median(np.sqrt(2 * np.sum(np.abs(spec[:, bins]) ** 2, axis=1)) / n))
        print(f"| {rig.seed} | {rig.speed:g}/{rig.load:g} | {rig.grade} | {est.grade_} | "
              f"{res:.3f} | {out[0]:.3f} | {out[1]:.3f} | {est.detection_limit_:.2f} |",
              flush=True)


if __name__ == "__main__":
    main()
