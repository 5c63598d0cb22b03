"""What ``gearshot monitor`` reports: the records, the alarm and the forecast of a history.

:func:`monitor_payload` turns a history (:mod:`gearshot.monitor.history`) and the model in
use into the JSON of ``gearshot monitor --json``: ``records`` (per recording, the current
model's estimate: ``recording``, ``time``, ``predicted``, ``low``, ``high``, ``trusted``,
``alarm``, ``threshold``; times in UTC; the estimate null for a recording that could not
be estimated, with its ``note``), ``alarm`` (``threshold``: the one in force at the
latest recording, ``first_time``; ``fit_threshold`` and ``commissioning``: the model's
and the history's own, :func:`gearshot.monitor.alarm.history_thresholds`) and
``forecast`` (``limit``, ``time``, ``low``, ``high``, ``law``; the last four null with a
``reason`` when no forecast is made), ``notice`` (:func:`gearshot.monitor.trust.change_notice`:
the latest recordings no longer look like the fitted machine; null otherwise) and the
estimates of earlier models (``earlier_estimates``).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .alarm import (
    COMMISSIONING,
    YOUNG_EXTRA,
    AlarmResult,
    Thresholds,
    alarm_states,
    history_sustain,
    history_thresholds,
)
from .forecast import Forecast, forecast_crossing, reading_spread_at
from .trust import change_notice, model_warning

__all__ = ["monitor_payload", "current_records", "describe_forecast", "DEFAULT_LIMIT",
           "ZERO_SHOT_FORECAST"]

DEFAULT_LIMIT = 0.6
#: Why a zero-shot model gives no forecast. Its sizes are not anchored by a faulty
#: example: on the virtual-rig lives its forecasts of 0.6 from 70 % of a life landed
#: within ±25 % in 3 of 20 development and 2 of 32 held-out lives, their 90 % intervals
#: holding the true time in 9 of 20 and 13 of 32 (one-fault-shot: 10/20, 17/20; 10/32,
#: 21/32; benchmarks/RESULTS.md "Monitoring").
ZERO_SHOT_FORECAST = ("zero-shot model: its sizes are not calibrated by a faulty example, so "
                      "a date from their trend is not dependable; refit with an inspected "
                      "recording (gearshot fit --faulty ... --faulty-size ...) to forecast")
_DAY = pd.Timedelta(days=1)


def current_records(history: pd.DataFrame, model: str) -> pd.DataFrame:
    """Per recording, the estimate of ``model`` (or, for a recording it has not estimated,
    the latest other one), in time order."""
    mine = history[history["model"] == model]
    others = history[(history["model"] != model)
                     & ~history["recording"].isin(set(mine["recording"]))]
    latest = others.sort_values("estimated_at", kind="stable").drop_duplicates(
        "recording", keep="last")
    rows = pd.concat([mine, latest], ignore_index=True)
    rows["time"] = pd.to_datetime(rows["time"])
    return rows.sort_values("time", kind="stable").reset_index(drop=True)


def _num(value) -> float | None:
    """A JSON number (None for a recording that could not be estimated)."""
    value = float(value)
    return value if np.isfinite(value) else None


def _iso(value) -> str | None:
    return None if value is None else pd.Timestamp(value).isoformat()


def monitor_payload(history: pd.DataFrame, model, *, limit: float = DEFAULT_LIMIT) -> dict:
    """The ``gearshot monitor --json`` payload (module docstring).

    Parameters
    ----------
    history : pandas.DataFrame
        :func:`gearshot.monitor.history.read_history`.
    model : MonitorModel
        The model in use (saved: its digest names its estimates).
    limit : float
        Size whose crossing is forecast.
    """
    digest = model.digest
    rows = current_records(history, digest)
    limits = history_thresholds(rows["predicted"].to_numpy(float),
                                rows["trusted"].to_numpy(bool), model.threshold,
                                false_alarm_rate=model.false_alarm_rate)
    state = alarm_states(rows["predicted"].to_numpy(float),
                         rows["trusted"].to_numpy(bool), limits.per_recording,
                         sustain=history_sustain(limits, model.sustain))
    records = [{"recording": r.recording, "time": _iso(r.time),
                "predicted": _num(r.predicted), "low": _num(r.low), "high": _num(r.high),
                "trusted": bool(r.trusted), "alarm": bool(a), "threshold": float(t),
                "model": r.model,
                "calibration": r.calibration, "segments": int(r.segments),
                "trusted_segments": int(r.trusted_segments),
                "note": str(getattr(r, "note", "") or "")}
               for r, a, t in zip(rows.itertuples(index=False), state.alarm,
                                  limits.per_recording, strict=True)]
    ok = rows["trusted"].to_numpy(bool)
    t0 = rows["time"].iloc[0] if len(rows) else pd.Timestamp(0)
    days = ((rows["time"] - t0) / _DAY).to_numpy(float)
    example = (getattr(model, "faulty", None) or {}).get("size")
    fc = forecast_crossing(days[ok], rows["predicted"].to_numpy(float)[ok], limit,
                           reading_spread=reading_spread_at(limit, example))
    if fc.time is not None and model.calibration == "zero_shot":
        fc = Forecast(fc.limit, None, None, None, None, ZERO_SHOT_FORECAST)

    def when(d):
        return None if d is None or not np.isfinite(d) else _iso(t0 + d * _DAY)

    forecast = {"limit": float(limit), "time": when(fc.time), "low": when(fc.low),
                "high": when(fc.high), "law": fc.law, "reason": fc.reason}
    if fc.fit is not None:
        forecast["fit"] = {"onset": when(fc.fit.onset), "level": fc.fit.level,
                           "amplitude": fc.fit.amplitude, "shape": fc.fit.shape,
                           "span": fc.fit.span, "sigma": fc.fit.sigma,
                           "days_from": _iso(t0)}
        forecast["law_weights"] = fc.law_weights
    earlier = history[history["model"] != digest]
    return {
        "kind": "monitor",
        "model": {"digest": digest, "calibration": model.calibration,
                  "description": model.describe(), "database": model.database,
                  "fit_check": model.fit_check, "condition": model.condition,
                  "warning": model_warning(model)},
        "calibration": model.calibration,
        "records": records,
        "alarm": _alarm(model, limits, state, rows),
        "forecast": forecast,
        "notice": change_notice([r["time"] for r in records], [r["trusted"] for r in records],
                                [r["note"] for r in records],
                                zero_shot=model.calibration == "zero_shot"),
        "earlier_estimates": [
            {"recording": r.recording, "time": _iso(r.time), "predicted": _num(r.predicted),
             "low": _num(r.low), "high": _num(r.high), "trusted": bool(r.trusted),
             "model": r.model, "calibration": r.calibration}
            for r in earlier.itertuples(index=False)],
    }


def _alarm(model, limits: Thresholds, state: AlarmResult, rows: pd.DataFrame) -> dict:
    """The payload's ``alarm``: the threshold in force at the latest recording, when the
    alarm was first raised, and the fit's and the history's own thresholds
    (``commissioning``: null until the history holds its commissioning recordings)."""
    ok = rows["trusted"].to_numpy(bool)
    first = None if state.first_index is None else _iso(rows["time"].iloc[state.first_index])
    own = None
    if limits.own is not None:
        start = limits.from_index
        own = {"recordings": COMMISSIONING, "threshold": float(limits.own),
               "used": bool(limits.own < limits.fit),
               "from_time": None if start is None else _iso(rows["time"].iloc[start])}
    return {"threshold": float(limits.per_recording[-1]) if len(rows)
            else float(model.threshold), "first_time": first,
            "active": bool(state.alarm[ok][-1]) if ok.any() else False,
            "false_alarm_rate": float(model.false_alarm_rate),
            "sustain": int(model.sustain), "young_sustain": int(model.sustain) + YOUNG_EXTRA,
            "fit_threshold": float(model.threshold),
            "commissioning": own}


def describe_forecast(forecast: dict, latest: str | None = None) -> str:
    """The payload's forecast in one sentence (``gearshot monitor`` and its report):
    times to the minute, and, given the ``latest`` recording's time, in days from it."""
    if not forecast.get("time"):
        return f"no forecast of size {forecast['limit']:g}: {forecast.get('reason')}"
    share = (forecast.get("law_weights") or {}).get(forecast["law"])
    law = forecast["law"] + (" law" if share is None else f" law, {share:.0%} of the weight")

    def minute(value):
        return pd.Timestamp(value).round("min").isoformat(timespec="minutes")

    def days(value):
        return (pd.Timestamp(value) - pd.Timestamp(latest)) / _DAY

    high = forecast.get("high")
    text = (f"forecast ({law}): size {forecast['limit']:g} reached {minute(forecast['time'])} "
            f"(90 % interval {minute(forecast['low'])} … "
            f"{minute(high) if high else 'open: part of the weight never reaches it'})")
    if latest is None:
        return text
    span = f"{days(forecast['low']):+.1f} to " + (f"{days(high):+.1f}" if high else "open")
    return text + (f"; {days(forecast['time']):+.1f} days from the latest recording "
                   f"({span})")
