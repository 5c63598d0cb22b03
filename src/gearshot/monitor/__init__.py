"""Monitoring a machine over time: fit once, estimate every new recording, alarm, forecast.

:mod:`.model`     the model file (fitted estimator, machine, database identity, fit check,
                  healthy baseline and alarm threshold; skops, no pickle)
:mod:`.history`   the index of recordings and the Parquet history of estimates (atomic)
:mod:`.trust`     which estimates can be acted on (one rule for every caller)
:mod:`.combine`   one estimate per recording from its segments
:mod:`.alarm`     threshold from the healthy baseline, sustained alarm
:mod:`.forecast`  growth laws and the time a limit is reached
:mod:`.payload`   the ``gearshot monitor --json`` payload;  :mod:`.figure` its trend figure

The ``gearshot fit`` and ``gearshot monitor`` services are in :mod:`gearshot.app.monitor`.
"""

from __future__ import annotations

from .alarm import FALSE_ALARM_RATE, SUSTAIN, AlarmResult, alarm_states, alarm_threshold
from .combine import combine_segments
from .forecast import Forecast, GrowthFit, fit_growth, forecast_crossing
from .history import HISTORY_COLUMNS, append_history, pending, read_history, read_index
from .model import MonitorModel, database_identity, file_digest, load_model
from .payload import DEFAULT_LIMIT, current_records, monitor_payload
from .trust import recording_trust, row_trust

__all__ = ["MonitorModel", "load_model", "file_digest", "database_identity",
           "read_index", "read_history", "append_history", "pending", "HISTORY_COLUMNS",
           "row_trust", "recording_trust", "combine_segments", "alarm_threshold",
           "alarm_states", "AlarmResult", "FALSE_ALARM_RATE", "SUSTAIN", "fit_growth",
           "forecast_crossing", "Forecast", "GrowthFit", "monitor_payload",
           "current_records", "DEFAULT_LIMIT"]
