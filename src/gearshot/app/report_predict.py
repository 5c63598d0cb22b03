"""The report of a ``gearshot predict`` output: its inputs and fit, the trust counts, the
summary per recording and role, and the estimates figure (untrusted estimates apart)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from .markdown import md_table as _md_table
from .markdown import write_markdown

__all__ = ["predict_report", "predict_rows", "short_value"]


def predict_rows(payload: Any) -> list:
    """The rows of a predict output: the bare list (older JSON) or its ``rows``."""
    return payload if isinstance(payload, list) else payload.get("rows")


def short_value(value: Any) -> str:
    """A value as a short text for a report's bullet lists."""
    if isinstance(value, list) and len(value) > 4:
        return f"{', '.join(map(str, value[:4]))} and {len(value) - 4} more"
    if isinstance(value, list):
        return ", ".join(map(str, value)) or "none"
    if isinstance(value, float):
        return f"{value:.4g}"
    text = str(value)
    return text if len(text) <= 200 else text[:197] + "..."


def predict_report(payload, out: Path, source: Path) -> Path:
    import pandas as pd

    from .predict import failed_check_summary, summary_table

    frame = pd.DataFrame(predict_rows(payload))
    table = summary_table(frame)
    figs = {"Estimated size per segment and its interval, by recording":
            _predict_figure(frame, out / "estimates.png")}
    lines = ["# gearshot report: fault-size estimates", "", f"From `{source.name}`: "
             f"{len(frame)} SA segments of {frame['recording'].nunique()} recording(s). "
             "Role: what a segment was to the fit (healthy_fitted and example were fitted "
             "on; healthy_holdout, faulty_rest and test were not).", ""]
    if isinstance(payload, dict):
        lines += _predict_header(payload)
    if "fit_check" in frame and len(frame):
        lines += [f"Fit check: {frame['fit_check'].iloc[0]}.", ""]
    if "comparable" in frame:
        lines += [f"Comparable segments: {int(frame['comparable'].astype(bool).sum())} of "
                  f"{len(frame)}.", ""]
    for column in ("speed_check", "path_check"):
        if line := failed_check_summary(frame, column):
            lines += ["`" + line.replace(": ", "`: ", 1) + ".", ""]
    if "trusted" in frame:
        lines += [f"Trusted segments: {int(frame['trusted'].astype(bool).sum())} of "
                  f"{len(frame)} (input, speed and path checks ok, comparable, fit check passed, "
                  "in a recording most of whose segments pass); the figure draws the "
                  "untrusted ones as hollow grey markers.", ""]
    lines += _md_table(table)
    for caption, fig in figs.items():
        lines += [f"## {caption}", "", f"![{caption}]({fig.name})", ""]
    return write_markdown(out, lines)


def _predict_header(payload: dict) -> list[str]:
    """The inputs and the fit of a predict JSON, as bullet lists."""
    lines = []
    if payload.get("gearshot_version"):
        lines += [f"Written by gearshot {payload['gearshot_version']}.", ""]
    for key, title in (("inputs", "Inputs"), ("fit", "Fit")):
        part = payload.get(key) or {}
        if part:
            lines += [f"## {title}", ""]
            lines += [f"* {name.replace('_', ' ')}: {short_value(value)}"
                      for name, value in part.items()]
            lines.append("")
    return lines


def _predict_figure(frame, path: Path) -> Path:
    """Estimates and intervals per recording, one colour per role; untrusted estimates
    (``trusted`` False) apart, as hollow grey markers with one legend entry."""
    import numpy as np
    from matplotlib.figure import Figure

    from .._atomic import atomic_path

    names = list(dict.fromkeys(frame["recording"]))
    fig = Figure(figsize=(7, 1.4 + 0.35 * min(len(names), 60)), layout="constrained")
    ax = fig.subplots()
    roles = list(dict.fromkeys(frame["role"])) if "role" in frame else [None]
    trusted = frame["trusted"].astype(bool) if "trusted" in frame else None
    untrusted_label = "untrusted (any role)"
    for k, role in enumerate(roles):
        part = frame if role is None else frame[frame["role"] == role]
        y = np.array([names.index(r) + 0.12 * (k - (len(roles) - 1) / 2)
                      for r in part["recording"]])
        ok = np.ones(len(part), bool) if trusted is None else trusted[part.index].to_numpy()
        for keep, style in ((ok, dict(fmt="o", color=f"C{k % 10}", label=role)),
                            (~ok, dict(fmt="o", color="0.6", mfc="none",
                                       label=untrusted_label))):
            if not keep.any():
                continue
            sub = part[keep]
            ax.errorbar(sub["predicted"], y[keep],
                        xerr=[sub["predicted"] - sub["low"], sub["high"] - sub["predicted"]],
                        ms=3, lw=0.6, **style)
            if style["label"] == untrusted_label:
                untrusted_label = "_nolegend_"  # one legend entry for every untrusted role
    if len(names) <= 60:
        ax.set_yticks(range(len(names)), [Path(n).name for n in names], fontsize=7)
    ax.set_xlim(-0.02, 1.02)
    ax.set_xlabel("estimated fault size y (0 healthy ... 1), bars: prediction interval")
    if roles != [None] or trusted is not None:
        ax.legend(fontsize=7, title="role", title_fontsize=7, loc="lower right")
    with atomic_path(path, make_parents=True) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    return path
