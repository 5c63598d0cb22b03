"""``gearshot demo``: the whole method end to end on one operating condition.

Builds (and caches under :func:`gearshot.data_home`) a small simulated database for
15 rps / 10 Nm over the 12 DIN grades, records a virtual-rig campaign, fits the estimator
and its four ablations on several draws of the one faulty example (as the paper reports
averages over draws), and writes figures plus a Markdown report into a folder.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.table import Table

from .._atomic import atomic_path, write_json_atomic
from ..paper import RIG_LOAD as LOAD
from ..paper import RIG_SPEED as SPEED

__all__ = ["run_demo"]


def run_demo(out="gearshot-demo", *, seed=0, n_healthy=50, n_faulty=350, duration=30.0,
             repetitions=6, draws=5, console=None):
    """Run the demo; returns the output folder.

    Parameters
    ----------
    out : path
        Folder for the figures, tables and report (created).
    seed : int
        Seeds the database, the rig's hidden reality and every split.
    n_healthy, n_faulty : int
        Simulated signals per grade in the cached demo database.
    duration : float
        Seconds per rig recording.
    repetitions : int
        Recordings per fault size (6 healthy recordings are always made).
    draws : int
        Draws of the faulty example (and of the training/test split); the error table
        gives the mean and spread over them, the figures show the first draw.
    """
    from .._validation import check_int

    draws = check_int(draws, "draws", minimum=1, maximum=100)
    # off a terminal (a pipe, a file) rich would cut the tables at 80 columns
    console = console or Console(width=None if sys.stdout.isatty() else 200)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    t_start = time.perf_counter()
    database = _demo_database(console, seed=seed, n_healthy=n_healthy, n_faulty=n_faulty)
    campaign, rig = _demo_campaign(console, seed=seed, duration=duration,
                                   repetitions=repetitions)
    console.rule("3. one-fault-shot estimation and ablations")
    results, predictions = _demo_fit(campaign, database, seed=seed, draws=draws)
    stats = _mae_stats(results)
    first = results[results["repeat"] == 0]
    full = first[first["variant"] == "full"].iloc[0]
    est = full["estimator"]
    full_pred = predictions[(predictions["variant"] == "full") & (predictions["repeat"] == 0)]
    _print_tables(console, stats, first, full_pred, draws)
    grades = [int(g) for g in np.unique(database["grade"].values)]
    grade_note = edge_grade_note(int(est.grade_), grades)
    console.print(f"example: size {full['example_size']:.2f}; chosen grade {est.grade_} "
                  f"(hidden rig grade {rig.reveal().grade}){grade_note}")
    ablation_note = ablation_spread_note(stats)
    if ablation_note:
        console.print(ablation_note)

    console.rule("4. figures and report")
    figures = _figures(out, est, stats, full_pred, campaign, rig)
    summary = {
        "speed": SPEED, "load": LOAD, "seed": seed, "draws": draws,
        "mae_unit": "%",
        "mae": _round(stats.loc["full", "mean"]),
        "mae_std": _round(stats.loc["full", "std"]),
        "ablations": {v: _round(r["mean"]) for v, r in stats.iterrows()},
        "ablations_std": {v: _round(r["std"]) for v, r in stats.iterrows()},
        "grade": int(est.grade_), "rig_grade": int(rig.reveal().grade),
        "grade_note": grade_note.strip("; ") or None,
        "ablation_note": ablation_note or None,
        "selected_features": list(est.selected_features_),
        "feature_errors": {k: _round(v, 4) for k, v in est.feature_errors_.items()}
        if isinstance(est.feature_errors_, dict) else est.feature_errors_,
        "n_neighbors": int(est.n_neighbors_),
        "seconds": round(time.perf_counter() - t_start, 1),
    }
    report = _write_outputs(out, summary, figures, results, full_pred)
    console.print(f"report: {report.resolve()}")
    console.print(f"done in {summary['seconds']:.0f} s; outputs in {out.resolve()}")
    return out


def _demo_database(console, *, seed, n_healthy, n_faulty):
    """Step 1: the cached demo database (grades 1–12 at the demo's condition, paired)."""
    from .. import data_home
    from ..sim import GearPair, build_database, load_database

    store = data_home() / f"demo-db-h{n_healthy}-f{n_faulty}-s{seed}-paired"
    console.rule(f"1. simulated database ({SPEED:g} rps, {LOAD:g} Nm, DIN grades 1–12)")
    build_database(store, GearPair.paper(), speeds=[SPEED], loads=[LOAD], grades=range(1, 13),
                   n_healthy=n_healthy, n_faulty=n_faulty, seed=seed, paired=True)
    database = load_database(store, speed=SPEED, load=LOAD)
    console.print(f"{database.sizes['signal']} simulated SAs in {store}")
    return database


def _demo_campaign(console, *, seed, duration, repetitions):
    """Step 2: the cached campaign of the rig ``seed``; returns (folder, rig)."""
    from .. import data_home
    from ..rig import VirtualRig

    console.rule("2. virtual-rig campaign")
    campaign = data_home() / f"demo-campaign-s{seed}-d{duration:g}-r{repetitions}"
    rig = VirtualRig(seed=seed)
    if not (campaign / "index.csv").is_file():
        rig.campaign(campaign, speed=SPEED, load=LOAD, duration=duration,
                     repetitions=repetitions)
    console.print(f"recordings in {campaign}")
    return campaign, rig


def _demo_fit(campaign, database, *, seed, draws):
    """Step 3: the full algorithm and its ablations over ``draws`` draws of the example
    (the first draw's estimators kept)."""
    from ..experiments import RIG_VARIANTS, rig_experiment
    from ..transfer import TransferFunctionBank

    selection_tf = TransferFunctionBank.synthetic(1, rng=np.random.default_rng([seed, 99]))[0]
    return rig_experiment(campaign, database, speed=SPEED, load=LOAD,
                          selection_tf=selection_tf, variants=RIG_VARIANTS,
                          n_repeats=draws, seed=seed, keep_estimators="first",
                          params=dict(estimator="paper"))   # the paper's ablation table


def _print_tables(console, stats, first, full_pred, draws):
    """The MAE table over draws and the first draw's predicted-vs-true table."""
    table = Table(title=f"MAE of the fault-size estimate on the rig's test segments, over "
                        f"{draws} draws of the faulty example")
    for col in ("variant", "MAE mean ± std [%]", "min–max [%]", "grade (draw 1)",
                "features (draw 1)"):
        table.add_column(col)
    for variant, row in stats.iterrows():
        one = first[first["variant"] == variant].iloc[0]
        table.add_row(variant, f"{row['mean']:.1f} ± {row['std']:.1f}",
                      f"{row['min']:.1f}–{row['max']:.1f}", str(one["grade"]), one["selected"])
    console.print(table)
    sizes = Table(title="full algorithm, draw 1: predicted vs true size")
    for col in ("true size", "n segments", "mean predicted", "std"):
        sizes.add_column(col)
    for size, part in full_pred.groupby("true"):
        sizes.add_row(f"{size:.2f}", str(len(part)), f"{part['predicted'].mean():.3f}",
                      f"{part['predicted'].std():.3f}")
    console.print(sizes)


def _write_outputs(out, summary, figures, results, full_pred):
    """results.json, ablations.csv, predictions.csv and report.md; returns the report."""
    from .markdown import write_report

    write_json_atomic(summary, out / "results.json", indent=2, sort_keys=False)
    table = results.drop(columns=["estimator"])
    table.insert(list(table.columns).index("mae"), "mae_percent", 100 * table["mae"])
    with atomic_path(out / "ablations.csv") as tmp:   # MAE in %, as in the report
        table.drop(columns=["mae"]).to_csv(tmp, index=False, float_format="%.4g")
    with atomic_path(out / "predictions.csv") as tmp:
        full_pred.to_csv(tmp, index=False, float_format="%.4g")
    return write_report(out, summary, figures)


def _round(value, digits: int = 2):
    """A float rounded for the outputs (None stays None)."""
    return None if value is None else round(float(value), digits)


def edge_grade_note(grade: int, grades) -> str:
    """A note when the chosen grade is the first or last of the database's grades: the
    search stopped at a bound of its range, so the rig's best match may lie beyond it."""
    lo, hi = min(grades), max(grades)
    if grade not in (lo, hi) or lo == hi:
        return ""
    side = "smoothest" if grade == lo else "roughest"
    return (f"; grade {grade} is the {side} grade of the database's range {lo}-{hi}, at the "
            f"edge of the search: the example fits best at a bound, so the closest "
            f"simulated build may lie outside the range (or no grade fits it well); read "
            f"the estimates as extrapolated from the edge")


def ablation_spread_note(stats) -> str:
    """A comment for every ablation whose mean MAE is below the full algorithm's, with
    the spread over the draws: whether the difference is larger than that spread."""
    if "full" not in stats.index:
        return ""
    full_mean, full_std = float(stats.loc["full", "mean"]), float(stats.loc["full", "std"])
    draws = int(stats.attrs.get("draws", 1))
    notes = []
    for variant, row in stats.iterrows():
        if variant == "full" or float(row["mean"]) >= full_mean:
            continue
        diff = full_mean - float(row["mean"])
        spread = max(full_std, float(row["std"]))
        verdict = ("within the spread over the draws: no evidence that it is better"
                   if diff <= spread else
                   "larger than the spread over the draws: on this rig and condition the "
                   "ablated step costs accuracy; one rig is one draw of a machine, see the "
                   "rig family in benchmarks/RESULTS.md for the average over rigs")
        notes.append(f"note: {variant} ({float(row['mean']):.1f} ± {float(row['std']):.1f} "
                     f"%) is below the full algorithm ({full_mean:.1f} ± {full_std:.1f} %) "
                     f"by {diff:.1f} points over {draws} draw(s), {verdict}")
    return "\n".join(notes)


def _mae_stats(results):
    """Mean, std, min and max of the MAE (in %) over draws, per variant (in run order)."""
    order = list(dict.fromkeys(results["variant"]))
    grouped = results.groupby("variant")["mae"]
    stats = (100 * grouped.agg(["mean", "std", "min", "max"])).fillna(0.0).loc[order]
    stats.attrs["draws"] = int(results["repeat"].nunique()) if "repeat" in results else 1
    return stats


def _figures(out, est, stats, full_pred, campaign, rig):
    """The demo's figures; returns {caption: png path}."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .. import plotting
    from ..io import read_campaign, recording_segments
    from ..signal import acs_background, amplitude_spectrum
    from .figures import ablation_figure, estimator_figures

    figs = {}
    draws = int(stats.attrs.get("draws", 0)) or None
    fig, ax = plt.subplots(figsize=(4.5, 4.5))
    plotting.plot_predicted_vs_true(
        full_pred["true"], full_pred["predicted"], ax=ax,
        title="draw 1" + (f" of {draws}" if draws else "") + ": MAE {mae} %")
    figs["Predicted vs true size (full algorithm, the first draw), Fig. 14a"] = \
        plotting.save_figure(fig, out / "fig14a_predicted_vs_true")[0]
    figs["Mean MAE of the ablations over the example draws (bars: ± 1 std), Fig. 14b"] = \
        ablation_figure({v: m / 100 for v, m in stats["mean"].items()}, out,
                        spread={v: s / 100 for v, s in stats["std"].items()}, draws=draws)
    figs.update(estimator_figures(est, out))
    index = read_campaign(campaign)
    healthy_path = index[index["fault_size"] == 0]["path"].iloc[0]
    faulty_path = index[index["fault_size"] == index["fault_size"].max()]["path"].iloc[0]
    _, long = recording_segments(healthy_path, long=True)
    spec = amplitude_spectrum(long)
    fig, ax = plt.subplots(figsize=(8, 3.5))
    plotting.plot_spectrum_background(spec, acs_background(spec), ax=ax,
                                      samples_per_cycle=est.n_points_)
    figs["Spectrum of a long healthy signal and its ACS background"] = \
        plotting.save_figure(fig, out / "spectrum_acs")[0]
    true_tf = _hidden_path_on_sa_grid(rig, SPEED, est.n_points_)
    fig, ax = plt.subplots(figsize=(8, 3.5))
    plotting.plot_tf_estimate(true_tf, est.transfer_function_, ax=ax)
    figs["Transfer-function estimate vs the rig's hidden path"] = \
        plotting.save_figure(fig, out / "tf_estimate")[0]
    sa = recording_segments(faulty_path)[0]
    fig, ax = plt.subplots(figsize=(8, 3.5))
    plotting.plot_sa_and_difference(sa, list(est.mesh_orders_), ax=ax,
                                    fault_size=float(index["fault_size"].max()))
    figs["A faulty SA and its difference signal"] = \
        plotting.save_figure(fig, out / "sa_difference")[0]
    return figs


def _hidden_path_on_sa_grid(rig, speed, n_points):
    """The rig's hidden path (its FIR) at the SA grid's orders, for the demo's figure only."""
    import scipy.signal

    _, fir = rig.reveal_path()
    gear_rate = speed * rig.pinion_teeth / rig.gear_teeth  # gear revolutions per second
    orders = np.arange(n_points // 2 + 1)
    _, h = scipy.signal.freqz(fir, worN=orders * gear_rate, fs=rig.fs)
    return np.concatenate([h, np.conj(h[1:n_points - h.size + 1][::-1])])
