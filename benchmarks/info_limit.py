"""The information limit in the simulated domain: oracle, the paper's estimator, candidates.

Run:  python benchmarks/info_limit.py [--data DIR] [--speeds 15 30] [--noise-scale 1]
                                      [--seed 0] [--candidates]
      python benchmarks/info_limit.py --rigs 100 101 ... [--candidates]

Two noise models. **Sec. 4.1 noise** (the first form) is described below. **Rig-matched**
(``--rigs``): for each rig of the family (its SA segments cached by
``benchmarks/rig_family.py``; draw 0), the estimator with library defaults is fitted and
its own path (``transfer_function_``), scale and residue (``target_residue_power_``: the
target's healthy differences) are applied to the family database's SAs of the rig's
condition, every grade: the simulated domain of the estimator's simulated floor, with the
noise that rig's target leaves. The paper's estimator then uses the fit's selected features.

For every grade of a paired database (one load, the given speeds; 100 healthy + 700 faulty
per grade) the fault components ``Δ = (sa − twin) / rms(healthy)`` are split 70/30 (seeded,
healthy and faulty alike). The target's matched noise is the Sec. 4.1 convention: white
noise of 10 % of the healthy RMS per cycle averaged over 50 cycles, in both the faulty SA
and the healthy reference it is compared with (noise power per one-sided bin
``n · 2 · 0.1² / 50``, times ``--noise-scale``²). A TF applied before the noise leaves every
bin's signal-to-noise ratio as it is, so the identity path stands for all paths.

* **oracle** (:mod:`gearshot.estimator.oracle`): templates of Δ on a size grid from the
  noise-free training components, Gaussian likelihood of the test's noisy difference
  spectrum outside the mesh bands, posterior median: the lowest MAE reachable there.
* **oracle_magnitude**: the same with the spectra's magnitudes only (Rice likelihood per
  bin): the limit when the fault's place in the cycle and the path's phase are unknown.
* **paper**: step 7's four features of the noisy differences, centred on the healthy
  training rows, KNN with K chosen on a 70/30 split of the training rows (step 8): the
  paper's estimator with no domain gap (its simulated floor).
* **default**: the library's default regressor (``estimator="boosting"``: boosted trees,
  :func:`gearshot.estimator.regressors.fit_regressor`) on the same features: the
  default's simulated floor.
* ``--candidates``: regressors and features beyond the paper (development screen): KNN on
  the 10 indicators (``knn_10``), on those and the 8 band RMS (``knn_18``), on ``rms_diff``
  alone; isotonic on ``rms_diff``; gradient boosting (absolute error) on the paper's four,
  the 10 indicators, the 18, and the 10 with 26 log band energies between mesh harmonics.

Printed: MAE (%) by size band and grade band on the test rows.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

INDICATORS = ("rms_diff", "kurtosis_diff", "rms_env_diff", "skewness_env_diff", "fm0", "fm4",
              "m6a", "m8a", "na4", "er")
BANDS = tuple(f"band_rms_{k}" for k in range(1, 9))
SIZE_BANDS = [(0.0, 0.0), (0.0, 0.2), (0.2, 0.4), (0.4, 0.6), (0.6, 0.8), (0.8, 1.0)]
GRADE_BANDS = [(1, 4), (5, 9), (10, 12)]


def band_energies(spec, n_points, mesh_order=38, guard=3):
    """Log energy of the difference spectrum between consecutive mesh harmonics (guarded)."""
    out = []
    for k in range(0, (n_points // 2) // mesh_order):
        lo, hi = k * mesh_order + guard, (k + 1) * mesh_order - guard
        out.append(np.log(np.sum(np.abs(spec[:, lo:hi + 1]) ** 2, axis=1) + 1e-12))
    return np.stack(out, axis=1)


def split(y, seed):
    rng = np.random.default_rng(seed)
    train = []
    for rows in (np.flatnonzero(y == 0), np.flatnonzero(y > 0)):
        rows = rng.permutation(rows)
        train.append(rows[: int(round(0.7 * rows.size))])
    train = np.sort(np.concatenate(train))
    test = np.setdiff1d(np.arange(y.size), train)
    return train, test


def grade_rows(db, grade, noise_scale, seed, candidates, *, tf=None, power=None,
               paper_features=None):
    from gearshot.estimator import steps
    from gearshot.estimator._simulated import residue_noise_spectrum
    from gearshot.estimator.oracle import fit_template_oracle
    from gearshot.estimator.regressors import fit_regressor
    from gearshot.features import PAPER_FEATURES, spectrum_features
    from gearshot.transfer.estimation import one_sided_response

    sa, twin, y = db.sa.values, db.sa_twin.values, db.fault_size.values
    n = sa.shape[1]
    scale = steps.rms_scale(steps.propagate_simulated(sa[y == 0], tf))
    delta = np.fft.rfft(sa - twin, axis=1) / scale
    if tf is not None:
        delta = delta * one_sided_response(tf)
    if power is None:
        power = np.full(n // 2 + 1, n * 2 * 0.1 ** 2 / 50)
    power = np.maximum(power * noise_scale ** 2, 1e-30)
    rng = np.random.default_rng([seed, grade])
    noisy = delta + residue_noise_spectrum(power, len(y), n, rng)
    train, test = split(y, seed + grade)
    out = {"y": y[test]}

    oracle = fit_template_oracle(delta[train], y[train], power, mesh_order=38, n_points=n)
    out["oracle"] = oracle.predict(noisy[test])
    blind = fit_template_oracle(delta[train], y[train], power, mesh_order=38, n_points=n,
                                phase=False)
    out["oracle_magnitude"] = blind.predict(noisy[test])

    def centred(names):
        X = spectrum_features(noisy, n, 38, names=names)
        return X - X[train][y[train] == 0].mean(axis=0)

    def knn(X):
        model = steps.fit_knn(X[train], y[train], random_state=seed)
        return model.predict(X[test])

    X4 = centred(PAPER_FEATURES)
    X_sel = X4 if paper_features is None else centred(paper_features)
    out["paper"] = knn(X_sel)
    # the library's default regressor (boosted trees) on the same selected features
    out["default"] = fit_regressor("boosting", X_sel[train], y[train],
                                   random_state=seed).predict(X_sel[test])
    if candidates:
        from sklearn.ensemble import HistGradientBoostingRegressor
        from sklearn.isotonic import IsotonicRegression

        X10 = centred(INDICATORS)
        X18 = centred(INDICATORS + BANDS)
        E = band_energies(noisy, n)
        out["knn_10"] = knn(X10)
        out["knn_18"] = knn(X18)
        out["knn_rms"] = knn(X4[:, :1])
        iso = IsotonicRegression(out_of_bounds="clip").fit(X4[train, 0], y[train])
        out["isotonic_rms"] = iso.predict(X4[test, 0])
        for name, X in (("gbm_paper4", X4), ("gbm_10", X10), ("gbm_18", X18),
                        ("gbm_10_bands26", np.hstack([X10, E]))):
            gbm = HistGradientBoostingRegressor(loss="absolute_error", max_iter=100,
                                                learning_rate=0.05, random_state=seed)
            out[name] = np.clip(gbm.fit(X[train], y[train]).predict(X[test]), 0, 1)
    return out


def mae_table(rows, methods):
    lines = []
    header = ["method", "all"] + [f"y={a:g}" if a == b else f"{a:g}–{b:g}" for a, b in SIZE_BANDS] \
        + [f"grades {a}–{b}" for a, b in GRADE_BANDS]
    lines.append("| " + " | ".join(header) + " |")
    lines.append("|" + "---|" * len(header))
    y = np.concatenate([r["y"] for r in rows])
    g = np.concatenate([np.full(r["y"].size, r["grade"]) for r in rows])
    for m in methods:
        err = np.abs(np.concatenate([r[m] for r in rows]) - y) * 100
        cells = [f"{err.mean():.1f}"]
        for a, b in SIZE_BANDS:
            sel = (y == 0) if a == b else (y > a) & (y <= b)
            cells.append(f"{err[sel].mean():.1f}")
        for a, b in GRADE_BANDS:
            cells.append(f"{err[(g >= a) & (g <= b)].mean():.1f}")
        lines.append(f"| {m} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main():
    from gearshot.sim import GearPair, build_database, load_database

    parser = argparse.ArgumentParser()
    parser.add_argument("--data", default=os.environ.get("GEARSHOT_DATA", "/tmp/gearshot-bench"))
    parser.add_argument("--speeds", type=float, nargs="+", default=[15.0, 30.0])
    parser.add_argument("--load", type=float, default=10.0)
    parser.add_argument("--grades", type=int, nargs="+", default=list(range(1, 13)))
    parser.add_argument("--noise-scale", type=float, default=1.0)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--candidates", action="store_true")
    parser.add_argument("--rigs", type=int, nargs="+", help="rig seeds: rig-matched noise")
    args = parser.parse_args()
    if args.rigs:
        return rig_matched(args)
    store = Path(args.data) / "db-info"
    build_database(store, GearPair.paper(), speeds=[15, 30], loads=[10],
                   grades=list(range(1, 13)), n_healthy=100, n_faulty=700, seed=0,
                   progress=False)
    rows = []
    start = time.perf_counter()
    for speed in args.speeds:
        for grade in args.grades:
            db = load_database(store, speed=speed, load=args.load, grade=grade)
            r = grade_rows(db, grade, args.noise_scale, args.seed, args.candidates)
            r["grade"], r["speed"] = grade, speed
            rows.append(r)
            line = " ".join(f"{m} {100 * np.mean(np.abs(r[m] - r['y'])):5.1f}"
                            for m in r if m not in ("y", "grade", "speed"))
            print(f"{speed:g} rps grade {grade:2d}: {line}", flush=True)
    methods = [m for m in rows[0] if m not in ("y", "grade", "speed")]
    print(f"\nnoise scale {args.noise_scale:g}, seed {args.seed}, speeds {args.speeds}, "
          f"{time.perf_counter() - start:.0f} s\n")
    print(mae_table(rows, methods))


def rig_matched(args):
    from gearshot.estimator import OneFaultShotEstimator
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

    data = Path(args.data)
    frf = Path(__file__).resolve().parents[2] / "shared" / "data" / "frf"
    paths = family_paths(frf, n_synthetic=4, seed=2023)
    store = family_database(data / "family", paired=True, progress=False)
    campaign = dict(duration=None, segments=4, healthy=int(RIG_HEALTHY_RECORDINGS),
                    sizes=[float(y) for y in TABLE1_SIZES], repetitions=2,
                    sa_pipeline=SA_PIPELINE_VERSION)
    rows, start = [], time.perf_counter()
    for rig in draw_family(args.rigs, paths):
        index, segments = rig_segments(rig, paths, data / "family" / "rigs", campaign)
        database = load_database(store, speed=rig.speed, load=rig.load)
        ds = rig_dataset(index, random_state=[rig.seed, 0], segments=segments)
        selection = TransferFunctionBank.synthetic(
            1, rng=np.random.default_rng([rig.seed, 99]))[0]
        est = OneFaultShotEstimator(random_state=1000 * rig.seed).fit(
            *ds.fit_args(database), selection_tf=selection, **ds.fit_kwargs())
        for grade in args.grades:
            db = load_database(store, speed=rig.speed, load=rig.load, grade=grade)
            r = grade_rows(db, grade, args.noise_scale, args.seed + rig.seed, args.candidates,
                           tf=est.transfer_function_, power=est.target_residue_power_,
                           paper_features=est.selected_features_)
            r["grade"], r["speed"] = grade, rig.speed
            rows.append(r)
        mine = rows[-len(args.grades):]
        line = " ".join(
            f"{m} {100 * np.mean(np.abs(np.concatenate([q[m] - q['y'] for q in mine]))):5.1f}"
            for m in rows[-1] if m not in ("y", "grade", "speed"))
        print(f"rig {rig.seed} ({rig.speed:g}/{rig.load:g}, grade {rig.grade}, "
              f"selected {','.join(est.selected_features_)}): {line}", flush=True)
    methods = [m for m in rows[0] if m not in ("y", "grade", "speed")]
    print(f"\nrig-matched noise, rigs {args.rigs}, noise scale {args.noise_scale:g}, "
          f"{time.perf_counter() - start:.0f} s\n")
    print(mae_table(rows, methods))


if __name__ == "__main__":
    main()
