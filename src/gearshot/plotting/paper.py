"""Figures of the paper and of gearshot's diagnostics (matplotlib).

The library never picks a matplotlib backend; the command line (:mod:`gearshot.app`) does.

Every function takes ``ax=None`` (a new figure is made when omitted) and returns the
artists it drew; :func:`save_figure` writes PNG and PDF side by side.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

__all__ = [
    "VARIANT_LABELS",
    "save_figure",
    "plot_sa_and_difference",
    "plot_spectrum_background",
    "plot_tf_estimate",
    "plot_tuning_curve",
    "plot_calibration",
    "plot_feature_invariance",
    "plot_predicted_vs_true",
    "plot_ablation",
    "plot_error_vs",
]

VARIANT_LABELS = {
    "before_da": "before DA",
    "rms_only": "RMS normalization only",
    "no_feature_selection": "no feature selection",
    "no_tuning": "no tuning",
    "full": "full algorithm",
}


def _ax(ax, **kw):
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(**kw)
    return ax


def save_figure(fig, path) -> list[Path]:
    """Save ``fig`` as ``path`` with suffixes .png and .pdf; returns the written paths."""
    import matplotlib.pyplot as plt

    from .._atomic import atomic_path

    path = Path(path)
    out = []
    for suffix in (".png", ".pdf"):
        target = path.with_suffix(suffix)
        with atomic_path(target, make_parents=True) as tmp:
            fig.savefig(tmp, dpi=130, bbox_inches="tight", format=suffix[1:])
        out.append(target)
    plt.close(fig)
    return out


def plot_sa_and_difference(sa, mesh_order, *, ax=None, n_sidebands=2, unit="g",
                           fault_size=None):
    """An SA and its difference signal over one cycle (``unit``: of the signal;
    ``fault_size``: shown in the title when given)."""
    from ..signal import difference_signal

    ax = _ax(ax, figsize=(8, 3.5))
    sa = np.asarray(sa, float)
    angle = np.arange(sa.size) / sa.size * 360
    lines = ax.plot(angle, sa, lw=0.8, label="synchronous average")
    lines += ax.plot(angle, difference_signal(sa, mesh_order, n_sidebands=n_sidebands),
                     lw=0.8, label="difference signal")
    ax.set_xlabel("gear angle [deg]")
    ax.set_ylabel(f"acceleration [{unit}]")
    if fault_size is not None:
        ax.set_title(f"fault size y = {fault_size:.2f}", fontsize=9)
    ax.legend(loc="upper right", fontsize=8)
    return lines


def plot_spectrum_background(spectrum, background, *, ax=None, fs=None,
                             samples_per_cycle=None, unit="g"):
    """A one-sided amplitude spectrum with its ACS background.

    The x axis is in Hz with ``fs`` (a time signal's rate), in orders (cycles per gear
    revolution) with ``samples_per_cycle`` (an angle-domain signal), else in FFT bins.
    """
    ax = _ax(ax, figsize=(8, 3.5))
    n = spectrum.size // 2 + 1
    if fs is not None:
        x, label = np.arange(n) * fs / spectrum.size, "frequency [Hz]"
    elif samples_per_cycle is not None:
        x = np.arange(n) * samples_per_cycle / spectrum.size
        label = "order [cycles per gear revolution]"
    else:
        x, label = np.arange(n), "FFT bin"
    lines = ax.semilogy(x, spectrum[:n], lw=0.5, label="amplitude spectrum")
    lines += ax.semilogy(x, background[:n], lw=1.5, label="ACS background")
    ax.set_xlabel(label)
    ax.set_ylabel(f"amplitude [{unit}]")
    ax.legend(fontsize=8)
    return lines


def plot_tf_estimate(tf_true, tf_est, *, ax=None):
    """Magnitude of a true TF and its estimate on the SA grid (each scaled to unit RMS)."""
    ax = _ax(ax, figsize=(8, 3.5))
    n = len(tf_true) // 2 + 1
    orders = np.arange(n)

    def db(h):
        h = np.abs(np.asarray(h)[:n])
        return 20 * np.log10(h / np.sqrt(np.mean(h ** 2)))

    d_true, d_est = db(tf_true), db(tf_est)
    lines = ax.plot(orders, d_true, lw=0.7, label="true TF")
    lines += ax.plot(orders, d_est, lw=1.5, label="estimate (ACS + minimum phase)")
    ok = np.isfinite(d_true) & np.isfinite(d_est)
    dist = float(np.sqrt(np.mean((d_true[ok] - d_est[ok]) ** 2))) if ok.any() else np.nan
    ax.set_title(f"estimate vs path: RMS difference {dist:.1f} dB over orders 0-{n - 1}",
                 fontsize=9)
    ax.set_xlabel("order [cycles per gear revolution] (SA grid)")
    ax.set_ylabel("|H| [dB re RMS]")
    ax.legend(fontsize=8)
    return lines


def plot_tuning_curve(curve, true_size=None, *, ax=None):
    """Step 2: predicted size of the faulty example for each simulated grade."""
    ax = _ax(ax, figsize=(5, 3.5))
    lines = ax.plot(curve["grade"], curve["prediction"], "o-", label="predicted example size")
    if "smoothed" in curve:
        lines += ax.plot(curve["grade"], curve["smoothed"], "-", lw=2, alpha=0.6,
                         label="monotone fit")
    if true_size is not None:
        lines.append(ax.axhline(true_size, color="k", ls="--", lw=1, label="true size"))
    best = int(np.argmin(curve["abs_error"]))
    lines += ax.plot([curve["grade"][best]], [curve.get("smoothed", curve["prediction"])[best]],
                     "r*", ms=14,
                     label="chosen grade")
    ax.set_xlabel("DIN grade of the simulation")
    ax.set_ylabel("predicted size y")
    ax.legend(fontsize=8)
    return lines


def plot_calibration(calibration, *, ax=None):
    """What the example calibrated (``OneFaultShotEstimator.calibration_``): one bar per
    weighted setting (grade, fault gain, fault width, TF mode), its weight as height."""
    ax = _ax(ax, figsize=(5, 3.5))
    settings = list(calibration["settings"])
    labels = [f"G{s['grade']}" + ("" if s["gain"] == 1 and s["width"] == 1 else
                                  f"\n×{s['gain']:g} w{s['width']:g}")
              + ("" if s["tf"] == "tf" else "\nRMS") for s in settings]
    bars = ax.bar(range(len(settings)), [s["weight"] for s in settings], color="C2")
    ax.set_xticks(range(len(settings)), labels, fontsize=7)
    ax.set_ylabel("weight")
    ax.set_title(f"calibration ({calibration['strategy']}): settings that predict",
                 fontsize=9)
    return bars


def plot_feature_invariance(train, test, names, errors, *, axes=None):
    """Fig. 11: each feature on the training (estimated TF) vs test (true TF) signals."""
    import matplotlib.pyplot as plt

    train, test = np.asarray(train), np.asarray(test)
    if axes is None:
        _, axes = plt.subplots(1, len(names), figsize=(3.2 * len(names), 3.2), squeeze=False)
        axes = axes[0]
    artists = []
    for i, (ax, name) in enumerate(zip(axes, names)):
        artists.append(ax.scatter(train[:, i], test[:, i], s=6, alpha=0.6))
        lo = min(train[:, i].min(), test[:, i].min())
        hi = max(train[:, i].max(), test[:, i].max())
        ax.plot([lo, hi], [lo, hi], "k--", lw=0.8)
        ax.set_title(f"{name}\nerror {100 * errors[name]:.1f} %", fontsize=9)
        ax.set_xlabel("training (estimated TF)")
        ax.set_ylabel("test (true TF)")
    axes[0].figure.tight_layout()
    return artists


def plot_predicted_vs_true(true, predicted, *, ax=None, low=None, high=None, title=None):
    """Fig. 14a: predicted vs true size per test SA (with intervals when given).

    ``title``: default ``"MAE x %"`` of these points; ``"{mae}"`` in a given title is
    replaced by that number (``"draw 1 of 5: MAE {mae} %"``).
    """
    ax = _ax(ax, figsize=(4.5, 4.5))
    true, predicted = np.asarray(true), np.asarray(predicted)
    rng = np.random.default_rng(0)
    jitter = true + rng.uniform(-0.012, 0.012, true.size)
    artists = []
    if low is not None and high is not None:
        artists.append(ax.vlines(jitter, low, high, color="0.8", lw=0.8,
                                 label="90 % interval"))
    artists.append(ax.scatter(jitter, predicted, s=10, label="test SA"))
    artists += ax.plot([0, 1], [0, 1], "k--", lw=0.8)
    ax.set_xlim(-0.05, 1.05)
    ax.set_ylim(-0.05, 1.05)
    ax.set_xlabel("true size y")
    ax.set_ylabel("predicted size y")
    mae = f"{100 * np.mean(np.abs(true - predicted)):.1f}"
    ax.set_title(f"MAE {mae} %" if title is None else title.replace("{mae}", mae),
                 fontsize=9)
    return artists


def plot_ablation(mae_by_variant, *, ax=None, spread=None, draws=None):
    """Fig. 14b: MAE (%) of each variant; ``spread`` (same keys, std over draws as a
    fraction) draws ± 1 std error bars, ``draws`` names their number on the axis."""
    ax = _ax(ax, figsize=(6.5, 3.8))
    names = list(mae_by_variant)
    values = np.array([100 * mae_by_variant[n] for n in names], float)
    err = None if not spread else np.array([100 * spread.get(n, 0.0) for n in names])
    bars = ax.bar(range(len(names)), values, yerr=err, capsize=4,
                  error_kw={"lw": 1.0, "ecolor": "0.25"})
    labels = [f"{v:.1f}" if err is None else f"{v:.1f} ± {e:.1f}"
              for v, e in zip(values, err if err is not None else values)]
    ax.bar_label(bars, labels=labels, padding=3, fontsize=8)
    top = np.nanmax(values + (err if err is not None else 0)) if values.size else 1.0
    ax.set_ylim(0, 1.18 * top if np.isfinite(top) and top > 0 else 1.0)  # room for labels
    ax.set_xticks(range(len(names)), [VARIANT_LABELS.get(n, n) for n in names],
                  rotation=20, ha="right")
    over = f" over {draws} draws" if draws else ""
    ax.set_ylabel("MAE [%]" + (f" (mean ± std{over})" if err is not None else ""))
    return bars


AXIS_LABELS = {"speed": "speed [rps]", "load": "load [N m]", "tf": "transfer function",
               "attenuation_db": "attenuation [dB]"}


def plot_error_vs(results, by, *, ax=None, variants=None):
    """Fig. 13: MAE (%) against ``by`` (e.g. 'speed' or 'tf'), one line per variant."""
    ax = _ax(ax, figsize=(7, 3.5))
    variants = variants or list(dict.fromkeys(results["variant"]))
    lines = []
    for v in variants:
        part = results[results["variant"] == v].groupby(by)["mae"].mean() * 100
        numeric = pd.api.types.is_numeric_dtype(part.index)
        x = part.index.to_numpy() if numeric else np.arange(part.size)
        lines += ax.plot(x, part.to_numpy(), "o-", label=VARIANT_LABELS.get(v, v))
        if not numeric:  # names (e.g. TFs, stored as object or pyarrow strings)
            ax.set_xticks(x, [str(n) for n in part.index], rotation=45, ha="right",
                          fontsize=7)
    ax.set_xlabel(AXIS_LABELS.get(by, by))
    ax.set_ylabel("MAE [%]")
    ax.legend(fontsize=8)
    return lines
