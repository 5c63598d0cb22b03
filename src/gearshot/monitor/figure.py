"""The trend figure of a monitored machine, drawn from a ``gearshot monitor`` payload."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pandas as pd

from .._atomic import atomic_path
from .forecast import GrowthFit

__all__ = ["trend_figure"]


def trend_figure(payload: dict, path: str | Path, *, title: str | None = None) -> Path:
    """Size against time: trusted estimates with their intervals, untrusted ones apart
    (grey crosses), the alarm threshold, the limit and the forecast band.

    Parameters
    ----------
    payload : dict
        :func:`gearshot.monitor.payload.monitor_payload`.
    path : path
        PNG to write (atomically).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    recs = pd.DataFrame(payload["records"])
    if len(recs):   # recordings that could not be estimated have no point to draw
        recs = recs[recs["predicted"].notna()].astype({"predicted": float, "low": float,
                                                         "high": float})
    fig, ax = plt.subplots(figsize=(9, 4.5))
    if len(recs):
        t = pd.to_datetime(recs["time"], format="ISO8601")
        ok = recs["trusted"].to_numpy(bool)
        err = np.vstack([recs["predicted"] - recs["low"], recs["high"] - recs["predicted"]])
        ax.errorbar(t[ok], recs["predicted"][ok], yerr=err[:, ok], fmt="o", ms=4,
                    color="tab:blue", ecolor="tab:blue", alpha=0.8, capsize=2,
                    label="estimate (trusted), interval")
        if (~ok).any():
            ax.plot(t[~ok], recs["predicted"][~ok], "x", color="0.5",
                    label="untrusted (not used)")
        alarm = recs["alarm"].to_numpy(bool)
        if alarm.any():
            ax.plot(t[alarm], recs["predicted"][alarm], "o", mfc="none", mec="tab:red",
                    ms=8, label="in alarm")
    al = payload["alarm"]
    if len(recs) and "threshold" in recs and recs["threshold"].nunique() > 1:
        # the history's own threshold took over after its commissioning recordings
        ax.step(pd.to_datetime(recs["time"], format="ISO8601"), recs["threshold"],
                where="post", color="tab:orange", ls="--",
                label=f"alarm threshold {recs['threshold'].iloc[0]:.2f} (the fit's) → "
                      f"{al['threshold']:.2f} (the history's own)")
    else:
        ax.axhline(al["threshold"], color="tab:orange", ls="--",
                   label=f"alarm threshold {al['threshold']:.2f}")
    fc = payload["forecast"]
    ax.axhline(fc["limit"], color="tab:red", ls=":", label=f"limit {fc['limit']:g}")
    lines = _draw_forecast(ax, fc, recs)
    ax.set_ylim(-0.05, 1.05)
    ax.set_xlabel("time")
    ax.set_ylabel("estimated fault size")
    calib = payload.get("calibration", "")
    ax.set_title(title or f"fault size over time ({calib.replace('_', ' ')} model)")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(0, 0.97 - 0.05 * lines))
    fig.autofmt_xdate()
    fig.tight_layout()
    path = Path(path)
    with atomic_path(path, make_parents=True) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
    return path


def _draw_forecast(ax, fc: dict, recs: pd.DataFrame) -> int:
    """The forecast band and the fitted law (or the reason there is none); the lines of
    text written at the top of the axes."""
    if fc.get("time"):
        lo = pd.Timestamp(fc["low"]) if fc.get("low") else pd.Timestamp(fc["time"])
        hi = pd.Timestamp(fc["high"]) if fc.get("high") else pd.Timestamp(fc["time"])
        ax.axvspan(lo, hi, color="tab:red", alpha=0.15,
                   label=f"forecast ({fc['law']}) reaches the limit")
        ax.axvline(pd.Timestamp(fc["time"]), color="tab:red", lw=1)
        fit = fc.get("fit")
        if fit and len(recs):
            t0 = pd.Timestamp(fit["days_from"])
            onset = (pd.Timestamp(fit["onset"]) - t0) / pd.Timedelta(days=1)
            latest = pd.to_datetime(recs["time"], format="ISO8601").max()
            end = (max(hi, latest) - t0) / pd.Timedelta(days=1)
            days = np.linspace(0, end, 200)
            # the law's own span (onset to its last trusted recording); older payloads
            # without it: up to the latest recording
            span = fit.get("span") or (latest - t0) / pd.Timedelta(days=1) - onset
            law = GrowthFit(fc["law"], onset, max(span, 1e-9), fit["level"],
                            fit["amplitude"], fit["shape"], fit.get("sigma", np.nan), np.nan)
            ax.plot(t0 + pd.to_timedelta(days, unit="D"), law(days), color="tab:red", lw=1,
                    alpha=0.7, label=f"best {fc['law']} fit")
    else:
        text = textwrap.fill(f"no forecast: {fc.get('reason')}", 120)
        ax.text(0.01, 0.97, text, transform=ax.transAxes, va="top", fontsize=8)
        return text.count("\n") + 1
    return 1
