"""``gearshot report`` of a ``gearshot monitor --json``: the trend figure and a summary."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from .markdown import md_table, write_markdown
from .report_schema import Field, check_fields, check_rows

__all__ = ["is_monitor_payload", "monitor_report", "check_monitor", "format_monitor",
           "threshold_source", "MONITOR_RECORD"]

#: One record of ``gearshot monitor --json`` (more keys are allowed).
MONITOR_RECORD = {
    "recording": Field("str"),
    "time": Field("str"),
    "predicted": Field("number", nullable=True, low=0.0, high=1.0),
    "low": Field("number", nullable=True, low=0.0, high=1.0),
    "high": Field("number", nullable=True, low=0.0, high=1.0),
    "trusted": Field("bool"),
    "alarm": Field("bool"),
}
_ALARM = {"threshold": Field("number", low=0.0, high=1.0),
          "first_time": Field("str", nullable=True)}
_FORECAST = {"limit": Field("number", low=0.0, high=1.0),
             "time": Field("str", nullable=True), "low": Field("str", nullable=True),
             "high": Field("str", nullable=True), "law": Field("str", nullable=True),
             "reason": Field("str", required=False, nullable=True),
             "law_weights": Field("numbers", required=False, nullable=True)}
_NOTICE = {"since": Field("str"), "recordings": Field("int", low=1),
           "message": Field("str")}


def check_monitor(payload, where: str) -> None:
    """Check a ``gearshot monitor --json`` against its declared keys (one line naming
    the first bad field)."""
    check_fields(payload, {"records": Field("any"), "alarm": Field("any"),
                           "forecast": Field("any")}, where, "")
    if payload["records"]:
        check_rows(payload["records"], MONITOR_RECORD, where, "records")
    check_fields(payload["alarm"], _ALARM, where, "alarm")
    check_fields(payload["forecast"], _FORECAST, where, "forecast")
    if payload.get("notice") is not None:
        check_fields(payload["notice"], _NOTICE, where, "notice")


def is_monitor_payload(payload) -> bool:
    """Whether ``payload`` is a ``gearshot monitor --json``."""
    return (isinstance(payload, dict) and payload.get("kind") == "monitor"
            and isinstance(payload.get("records"), list) and "alarm" in payload
            and "forecast" in payload)


def monitor_report(payload: dict, out: Path, source: Path) -> Path:
    """Write ``trend.png``, ``report.md`` and ``report.html`` (model, alarm, forecast, the
    latest records) into ``out``; returns the Markdown's path."""
    from ..monitor.figure import trend_figure
    from ..monitor.payload import describe_forecast

    out = Path(out)
    trend_figure(payload, out / "trend.png")
    recs = pd.DataFrame(payload["records"])
    al, fc = payload["alarm"], payload["forecast"]
    model = payload.get("model", {})
    lines = ["# gearshot monitor report", "", f"Source: `{source}`", "",
             model.get("description", ""), ""]
    if model.get("warning"):
        lines += [f"**Warning**: {model['warning']}.", ""]
    if payload.get("calibration") == "zero_shot":
        lines += ["**Zero-shot model**: no faulty example; sizes come from healthy data and "
                  "simulation alone.", ""]
    n_ok = int(recs["trusted"].sum()) if len(recs) else 0
    lines += [f"Recordings: {len(recs)} ({n_ok} trusted, {len(recs) - n_ok} untrusted and "
              f"not used)"
              + (f"; index: {payload['index_source']}" if payload.get("index_source") else "")
              + ".", "",
              f"Alarm threshold {al['threshold']:.3f}{threshold_source(al)}: "
              + (f"first raised {al['first_time']}." if al["first_time"] else "not raised."),
              ""]
    sentence = describe_forecast(fc, recs["time"].iloc[-1] if len(recs) else None)
    lines += [sentence[0].upper() + sentence[1:] + ".", ""]
    if payload.get("notice"):
        lines += [f"**Notice**: {payload['notice']['message']}.", ""]
    lines += ["![trend](trend.png)", ""]
    if len(recs):
        last = recs.tail(20).copy()
        last["recording"] = [Path(r).name for r in last["recording"]]
        cols = ["recording", "time", "predicted", "low", "high", "trusted", "alarm"]
        if "note" in last:   # why an untrusted recording is untrusted
            cols.append("note")
        lines += ["## Latest recordings", "", *md_table(last[cols])]
    return write_markdown(out, lines)


def threshold_source(alarm: dict) -> str:
    """Where the alarm's threshold in force comes from, when the history's own first
    trusted recordings set it (``alarm.commissioning``), or what a young history needs
    to raise the alarm (``alarm.young_sustain``), else ""."""
    from ..monitor.alarm import COMMISSIONING

    own = alarm.get("commissioning") or {}
    if not own and alarm.get("young_sustain"):
        return (f"; {alarm['young_sustain']} consecutive recordings over it raise the alarm "
                f"until the history holds {COMMISSIONING} trusted ones")
    if not own.get("used"):
        return ""
    return (f", set by the first {own['recordings']} trusted recordings, in force since "
            f"{own['from_time']}; the fit's {alarm.get('fit_threshold', float('nan')):.3f}")


def format_monitor(payload: dict) -> str:
    """What ``gearshot monitor`` prints: the model, the counts (and why recordings are
    untrusted), the alarm, the forecast."""
    from ..monitor.payload import describe_forecast
    from ..monitor.trust import untrusted_counts

    recs = payload["records"]
    n_ok = sum(r["trusted"] for r in recs)
    al, fc = payload["alarm"], payload["forecast"]
    warning = payload["model"].get("warning")
    lines = [payload["model"]["description"] + (f"\nwarning: {warning}" if warning else ""),
             f"{payload.get('new', 0)} new recording(s) estimated; {len(recs)} in the "
             f"history, {n_ok} trusted, {len(recs) - n_ok} untrusted (not used)"]
    if payload.get("index_source"):
        lines.append(f"index: {payload['index_source']}")
    why = untrusted_counts(r.get("note") for r in recs if not r["trusted"])
    if why:
        lines.append("untrusted: " + "; ".join(f"{n} {k}" for k, n in why.items()))
    if recs:
        last = recs[-1]
        if last["predicted"] is None:
            lines.append(f"latest {last['time']}: {last.get('note', 'not estimated')}")
        else:
            lines.append(f"latest {last['time']}: size {last['predicted']:.3f} "
                         f"[{last['low']:.3f}, {last['high']:.3f}]"
                         + ("" if last["trusted"] else
                            f" (untrusted: {last.get('note') or 'see the history'})"))
    lines.append(f"alarm (threshold {al['threshold']:.3f}{threshold_source(al)}): "
                 + (f"raised {al['first_time']}" + (", active" if al["active"] else
                                                      ", cleared since")
                    if al["first_time"] else "not raised"))
    lines.append(describe_forecast(fc, recs[-1]["time"] if recs else None))
    if payload.get("notice"):
        lines.append(f"notice: {payload['notice']['message']}")
    if payload["calibration"] == "zero_shot":
        lines.append("zero-shot model: sizes are from healthy data and simulation alone; "
                     "refit with an inspected recording (gearshot fit --faulty … "
                     "--faulty-size …) when one is measured")
    return "\n".join(lines)
