"""The rig's own fault pattern as a size estimator: how far the one example's spectrum goes.

A candidate of issue #30 item 2 (a template estimator) that needs no simulated spectral
shape: the one faulty example's difference spectrum, less the target's residue, is the
template of the rig's own fault; every test segment is read by the relative fault power
along it, and the size by the simulator's growth of that power with the fault size.

For each rig of the family (segments cached by ``benchmarks/rig_family.py``; draws 0 and 1
of the Sec. 4.2 split, library defaults otherwise) the default estimator is fitted, and:

* ``N`` = the fit's ``target_residue_power_`` (healthy differences), smoothed over 9 bins;
  bins of every mesh harmonic ± 2 and DC are left out (as the oracle does);
* template ``T`` = max(|rfft(d_example)|² − N, 0), smoothed over 5 bins; weights
  ``w = T / N²`` (the locally optimal statistic for a power change ``a · T`` on ``N``);
* ``a`` of a segment = ``Σ w (|rfft(d)|² − N) / Σ w T``: 0 healthy, 1 at the example;
* simulated growth: the same statistic on the family database's fault components
  (faulty SA − twin) through the fit's path, each grade's template its own components
  within ± 0.03 of the example's size, the median over grades on a 0.01 size grid
  (made non-decreasing); the size estimate is that curve's inverse at ``a``.

Printed per rig and draw: the library default's MAE, the template estimate's MAE and the
Spearman correlation of ``a`` with the true size; then the means.

    GEARSHOT_DATA=/work/data-w-estimator PYTHONPATH=src python benchmarks/rig_template.py \
        --seeds 100 101 102 103 104 105 106 107
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from scipy.ndimage import uniform_filter1d
from scipy.stats import spearmanr

from gearshot._paths import data_home
from gearshot.estimator import steps
from gearshot.estimator._database import _database_by_grade, _database_twins
from gearshot.experiments.family_rigs import cached_family_fits

GRID = np.round(np.arange(0.0, 1.001, 0.01), 2)


def off_mesh(n_points: int, orders) -> np.ndarray:
    """One-sided bins outside every mesh harmonic ± 2 and DC."""
    keep = np.ones(n_points // 2 + 1, bool)
    keep[0] = False
    for order in np.atleast_1d(orders):
        for h in range(int(order), keep.size, int(order)):
            keep[max(h - 2, 0):h + 3] = False
    return keep


def statistic(power: np.ndarray, template: np.ndarray, noise: np.ndarray) -> np.ndarray:
    """Relative fault power along ``template`` (1 at the template's own fault power)."""
    w = template / noise ** 2
    return (power - noise) @ w / (template @ w)


def simulated_growth(database, y0: float, tf: np.ndarray, noise: np.ndarray,
                     keep: np.ndarray) -> np.ndarray:
    """The statistic's median growth with size over the grades (on GRID), non-decreasing."""
    by_grade = _database_by_grade(database)
    twins = _database_twins(database, by_grade)
    curves = []
    for grade, (sa, y) in by_grade.items():
        comp = np.fft.rfft(sa - twins[grade], axis=-1) * tf[None, : sa.shape[1] // 2 + 1]
        power = np.abs(comp) ** 2
        template = power[np.abs(y - y0) < 0.03].mean(axis=0) * keep
        a = statistic(power * keep, template, noise)
        curves.append([np.median(a[np.abs(y - g) < 0.03]) if np.any(np.abs(y - g) < 0.03)
                       else np.nan for g in GRID])
    return np.maximum.accumulate(np.nan_to_num(np.nanmedian(np.array(curves), axis=0)))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, nargs="+", required=True)
    ap.add_argument("--draws", type=int, default=2)
    ap.add_argument("--data", type=Path, default=None, help="default $GEARSHOT_DATA")
    ap.add_argument("--frf-folder", type=Path,
                    default=Path(__file__).resolve().parents[2] / "shared" / "data" / "frf")
    args = ap.parse_args()
    data = args.data or data_home()
    rows = []
    for rig, draw, ds, database, est in cached_family_fits(args.seeds, data, args.frf_folder,
                                                           draws=args.draws):
        def spectrum(x, est=est):
            y = steps.normalize_rms(np.atleast_2d(x), scale=est.target_scale_)
            d = steps.suppress_harmonics_target(y, est.references_,
                                                upsample=est._options().upsample)
            return np.abs(np.fft.rfft(d, axis=-1)) ** 2

        keep = off_mesh(est.n_points_, est.mesh_orders_)
        noise = uniform_filter1d(est.target_residue_power_, 9)
        template = uniform_filter1d(
            np.clip(spectrum(ds.faulty_example)[0] - noise, 0, None) * keep, 5)
        a = statistic(spectrum(ds.test_sa) * keep, template, noise)
        growth = simulated_growth(database, ds.faulty_size, est.transfer_function_,
                                  noise, keep)
        size = np.interp(a, growth, GRID)
        rows.append((rig.seed, draw, rig.grade,
                     float(np.mean(np.abs(est.predict(ds.test_sa) - ds.test_size))),
                     float(np.mean(np.abs(size - ds.test_size))),
                     float(spearmanr(a, ds.test_size)[0])))
        seed, draw_, grade, mae_default, mae_template, rho = rows[-1]
        print(f"rig {seed} draw {draw_} grade {grade:2d}  default MAE {mae_default:.3f}  "
              f"template MAE {mae_template:.3f}  Spearman(a, size) {rho:.2f}", flush=True)
    r = np.array(rows)
    print(f"mean: default {100 * r[:, 3].mean():.1f} %, template {100 * r[:, 4].mean():.1f} %, "
          f"Spearman median {np.median(r[:, 5]):.2f}")


if __name__ == "__main__":
    main()
