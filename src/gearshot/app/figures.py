"""Experiment figures and reports (used by the CLI)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from .._errors import GearshotError

__all__ = ["simulated_figures", "rig_figures", "estimator_figures", "report_from_json",
           "report_from_rows", "ablation_figure"]


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def ablation_figure(mae: dict, out, *, spread: dict | None = None,
                    draws: int | None = None, name: str = "fig14b_ablation") -> Path:
    """Fig. 14b as ``out/name.png`` (and .pdf): mean MAE per variant, ± 1 std over the
    draws when ``spread`` is given."""
    from .. import plotting

    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.5, 3.8))
    plotting.plot_ablation(mae, ax=ax, spread=spread or None, draws=draws)
    return plotting.save_figure(fig, Path(out) / name)[0]


def simulated_figures(results: pd.DataFrame, out) -> dict:
    """Fig. 13 a–d: MAE vs speed and vs TF (per load and averaged), one line per variant."""
    from .. import plotting

    plt = _plt()
    out = Path(out)
    figs = {}
    for by, name in (("speed", "fig13a_error_vs_speed"), ("tf", "fig13b_error_vs_tf"),
                     ("load", "fig13c_error_vs_load"),
                     ("attenuation_db", "fig13d_error_vs_attenuation")):
        if results[by].nunique() < 1:
            continue
        fig, ax = plt.subplots(figsize=(7, 3.5))
        plotting.plot_error_vs(results, by, ax=ax)
        figs[f"MAE vs {by}"] = plotting.save_figure(fig, out / name)[0]
    from .markdown import write_report

    table = results.groupby("variant")["mae"].mean() * 100
    write_report(out, {"mae": float(table.get("full", np.nan)),
                       "ablations": table.to_dict()}, figs)
    return figs


def rig_figures(results: pd.DataFrame, predictions: pd.DataFrame, out, *,
                estimator=None) -> dict:
    """Fig. 14 a–b: predicted vs true (full algorithm) and the ablation errors.

    With a fitted full-algorithm ``estimator`` (the first repeat's), also Fig. 11 (its
    feature-selection scatter) and its DIN tuning curve.
    """
    from .. import plotting

    plt = _plt()
    out = Path(out)
    figs = {}
    full = predictions[predictions["variant"] == "full"]
    n_draws = int(results["repeat"].nunique()) if "repeat" in results else 1
    fig, ax = plt.subplots(figsize=(4.5, 4.5))
    plotting.plot_predicted_vs_true(full["true"], full["predicted"], ax=ax,
                                    title=f"all {n_draws} draws pooled: MAE {{mae}} %")
    figs["Predicted vs true (Fig. 14a)"] = plotting.save_figure(fig, out / "fig14a")[0]
    grouped = results.groupby("variant", sort=False)["mae"]
    mae = grouped.mean()
    spread = grouped.std().fillna(0.0).to_dict() if n_draws > 1 else None
    figs["Ablations (Fig. 14b)"] = ablation_figure(mae.to_dict(), out, spread=spread,
                                                   draws=n_draws, name="fig14b")
    if estimator is not None:
        figs.update(estimator_figures(estimator, out))
    from .markdown import write_report

    write_report(out, {"mae": float(mae.get("full", np.nan)) * 100,
                       "ablations": (mae * 100).to_dict()}, figs)
    return figs


def estimator_figures(estimator, out) -> dict:
    """Figures of one fitted estimator: Fig. 11 (step 1's feature scatter, when features
    were selected) and the DIN tuning curve (when the grade was tuned).

    Returns {caption: png path}.
    """
    from .. import plotting

    plt = _plt()
    out = Path(out)
    figs = {}
    if getattr(estimator, "selection_features_", None) is not None:
        train, test = estimator.selection_features_
        plotting.plot_feature_invariance(train, test, estimator.candidate_features_,
                                         estimator.feature_errors_)
        figs["Feature invariance (step 1): estimated vs held-out TF, Fig. 11"] = \
            plotting.save_figure(plt.gcf(), out / "fig11_feature_invariance")[0]
    calibration = getattr(estimator, "calibration_", None)
    if estimator.tuning_curve_ is not None or (calibration is not None
                                               and calibration["strategy"] == "joint"):
        # left: the example's predicted size per grade (when the grade was tuned);
        # right: the weighted calibration settings (issue #19)
        fig, axes = plt.subplots(1, 2, figsize=(10, 3.5), squeeze=False)
        if estimator.tuning_curve_ is not None:
            plotting.plot_tuning_curve(estimator.tuning_curve_, estimator.faulty_size_,
                                       ax=axes[0, 0])
        else:
            axes[0, 0].set_axis_off()
        plotting.plot_calibration(calibration, ax=axes[0, 1])
        fig.tight_layout()
        figs["Simulation tuning: example prediction per DIN grade; calibration weights"] = \
            plotting.save_figure(fig, out / "tuning_curve")[0]
    return figs


def report_from_json(path, out) -> Path:
    """Rebuild figures and a report from a results JSON written by ``--json``."""
    path = Path(path)
    if not path.is_file():
        raise GearshotError(f"results file {str(path)!r} does not exist")
    try:
        payload = json.loads(path.read_text())
    except (ValueError, UnicodeDecodeError) as exc:
        raise GearshotError(f"{str(path)!r} is not a gearshot results JSON ({exc})") from None
    rows = payload.get("rows") if isinstance(payload, dict) else None
    if not isinstance(rows, list) or not rows or not all(isinstance(r, dict) for r in rows):
        raise GearshotError(f"{str(path)!r} is not a gearshot results JSON: it needs an "
                            f"object with 'rows', a non-empty list of objects (as written "
                            f"by --json)")
    need = {"variant", "mae"} | ({"speed", "load", "tf", "attenuation_db"}
                                 if payload.get("experiment") == "simulated" else set())
    missing = sorted(need - set().union(*rows))
    if missing:
        raise GearshotError(f"{str(path)!r}: its rows lack the key(s) {missing} (not a "
                            f"results JSON written by --json)")
    rows = pd.DataFrame(rows)
    if not np.issubdtype(rows["mae"].dtype, np.number):
        raise GearshotError(f"{str(path)!r}: its rows' 'mae' values are not numbers")
    return report_from_rows(rows, out, simulated=payload.get("experiment") == "simulated")


def report_from_rows(rows: pd.DataFrame, out, *, simulated: bool) -> Path:
    """Figures and ``report.md`` (and ``report.html``) from an experiment's rows."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    if simulated:
        simulated_figures(rows, out)
    else:
        from .markdown import write_report

        grouped = rows.groupby("variant", sort=False)["mae"]
        mae = grouped.mean()
        n_draws = int(rows["repeat"].nunique()) if "repeat" in rows else 1
        spread = grouped.std().fillna(0.0).to_dict() if n_draws > 1 else None
        figs = {"Ablations (Fig. 14b)": ablation_figure(mae.to_dict(), out, spread=spread,
                                                        draws=n_draws, name="fig14b")}
        write_report(out, {"mae": float(mae.get("full", np.nan)) * 100,
                           "ablations": (mae * 100).to_dict()}, figs)
    return out / "report.md"
