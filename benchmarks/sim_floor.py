"""The simulator's own floor on Sec. 4.1 data: KNN error with no domain gap at all.

Run:  python benchmarks/sim_floor.py [--data DIR]

Every simulated SA of one grade-7 block (15 rps, 10 Nm, 100 healthy + 700 faulty) goes
through the *same* path: nothing (identity) or one real FRF of ../shared/data/frf. Steps
5–8 then run on the simulated side only (RMS normalization, subtract the first healthy SA,
centred features, KNN with K chosen on a 70/30 split). Training and validation come from
one domain, so the validation MAE at the best K is a lower bound for what any domain
adaptation can reach on Sec. 4.1 datasets built from that block and FRF. Printed per FRF:
the paper's four features together and each feature alone, plus the other registered
features together.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

PAPER = ("rms_diff", "kurtosis_diff", "rms_env_diff", "skewness_env_diff")


def main():
    from gearshot.estimator import steps
    from gearshot.features import available_features
    from gearshot.sim import GearPair, build_database, load_database
    from gearshot.transfer import TransferFunctionBank

    parser = argparse.ArgumentParser()
    parser.add_argument("--data", default="/tmp/gearshot-bench")
    parser.add_argument("--frf-folder",
                        default=Path(__file__).resolve().parents[2] / "shared/data/frf")
    args = parser.parse_args()
    store = Path(args.data) / "db-15rps-10Nm-grade7"
    build_database(store, GearPair.paper(), speeds=[15], loads=[10], grades=[7],
                   n_healthy=100, n_faulty=700, seed=0)
    db = load_database(store, speed=15, load=10, grade=7)
    sa, y = db.sa.values, db.fault_size.values
    healthy = y == 0
    everything = tuple(available_features())

    def floor(tf, names):
        s = steps.propagate_simulated(sa, tf)
        s = steps.normalize_rms(s, s[healthy])
        s = steps.suppress_harmonics_simulated(s, healthy)
        X, _ = steps.centred_features(s, mesh_order=38, names=names, healthy_mask=healthy)
        return 100 * steps.fit_knn(X, y, random_state=0).validation_mae.min()

    bank = TransferFunctionBank.from_folder(args.frf_folder)
    print(f"{'path':16s} {'paper 4':>8s} " + " ".join(f"{n:>17s}" for n in PAPER)
          + f" {'all ' + str(len(everything)):>8s}")
    rows = []
    for name in [None, *bank.names]:
        tf = None if name is None else bank[name].to_signal_grid(sa.shape[1])
        row = [floor(tf, PAPER)] + [floor(tf, (n,)) for n in PAPER] + [floor(tf, everything)]
        rows.append(row)
        print(f"{name or 'identity':16s} {row[0]:8.1f} " + " ".join(f"{v:17.1f}" for v in row[1:-1])
              + f" {row[-1]:8.1f}", flush=True)
    real = np.array(rows[1:])
    print(f"{'mean real FRFs':16s} {real[:, 0].mean():8.1f} "
          + " ".join(f"{v:17.1f}" for v in real[:, 1:-1].mean(axis=0))
          + f" {real[:, -1].mean():8.1f}")


if __name__ == "__main__":
    main()
