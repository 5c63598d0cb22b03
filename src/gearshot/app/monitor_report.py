"""``gearshot report`` of a ``gearshot monitor --json``: the trend figure and a summary."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from .._atomic import write_text_atomic
from .markdown import md_table

__all__ = ["is_monitor_payload", "monitor_report"]


def is_monitor_payload(payload) -> bool:
    """Whether ``payload`` is a ``gearshot monitor --json``."""
    return (isinstance(payload, dict) and payload.get("kind") == "monitor"
            and isinstance(payload.get("records"), list) and "alarm" in payload
            and "forecast" in payload)


def monitor_report(payload: dict, out: Path, *, source: Path) -> Path:
    """Write ``trend.png`` and ``report.md`` (model, alarm, forecast, the latest records)
    into ``out``; returns the report's path."""
    from ..monitor.figure import trend_figure

    out = Path(out)
    trend_figure(payload, out / "trend.png")
    recs = pd.DataFrame(payload["records"])
    al, fc = payload["alarm"], payload["forecast"]
    model = payload.get("model", {})
    lines = ["# gearshot monitor report", "", f"Source: `{source}`", "",
             model.get("description", ""), ""]
    if payload.get("calibration") == "zero_shot":
        lines += ["**Zero-shot model**: no faulty example; sizes come from healthy data and "
                  "simulation alone.", ""]
    n_ok = int(recs["trusted"].sum()) if len(recs) else 0
    lines += [f"Recordings: {len(recs)} ({n_ok} trusted, {len(recs) - n_ok} untrusted and "
              f"not used).", "",
              f"Alarm threshold {al['threshold']:.3f}: "
              + (f"first raised {al['first_time']}." if al["first_time"] else "not raised."),
              ""]
    if fc.get("time"):
        lines += [f"Forecast ({fc['law']} law): size {fc['limit']:g} reached {fc['time']} "
                  f"(interval {fc['low']} … {fc['high']}).", ""]
    else:
        lines += [f"No forecast of size {fc['limit']:g}: {fc.get('reason')}.", ""]
    lines += ["![trend](trend.png)", ""]
    if len(recs):
        last = recs.tail(20).copy()
        last["recording"] = [Path(r).name for r in last["recording"]]
        cols = ["recording", "time", "predicted", "low", "high", "trusted", "alarm"]
        lines += ["## Latest recordings", "", *md_table(last[cols])]
    path = out / "report.md"
    write_text_atomic(path, "\n".join(lines))
    return path
