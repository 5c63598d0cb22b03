"""The declared schema of every output ``gearshot report`` reads, and its checks.

Each kind of output (``predict`` rows, the demo's ``results.json``, an experiment's rows,
a rig-family table, an indicators payload) declares the fields it needs as
:class:`Field` s; :func:`check_fields` and :func:`check_rows` refuse anything else with
one :class:`~gearshot.GearshotError` line naming the file, the place (``rows[3].high``)
and the bad value, before a figure is drawn.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._errors import GearshotError

__all__ = ["Field", "check_fields", "check_rows", "PREDICT_ROW", "PREDICT_ROW_WITHHELD",
           "check_predict_rows", "EXPERIMENT_ROW",
           "SIMULATED_ROW", "DEMO", "INDICATOR_RECORD", "FAMILY", "check_family_tables",
           "check_indicators", "check_name", "MAX_ROWS"]

#: The most rows (or records) a report reads: more is not a file gearshot writes.
MAX_ROWS = 1_000_000
#: The largest magnitude of a number in a report (beyond it a float64 sum overflows).
_MAX_ABS = 1e300


@dataclass(frozen=True)
class Field:
    """One declared field: its type, whether it is required or may be null, its bounds.

    ``kind`` is one of ``"str"``, ``"number"`` (an int or a finite float, not a bool),
    ``"int"``, ``"bool"``, ``"tf"`` (a TF index or name: int or str), ``"strings"`` (a
    list of str), ``"numbers"`` (an object of name: number or null) or ``"any"``.
    """

    kind: str
    required: bool = True
    nullable: bool = False
    low: float | None = None
    high: float | None = None
    choices: tuple[str, ...] | None = None


def _plain(value: Any) -> Any:
    """numpy scalars (from a CSV) as Python ones."""
    return value.item() if isinstance(value, np.generic) else value


def _show(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _is_null(value: Any) -> bool:
    return value is None or (isinstance(value, float) and math.isnan(value))


def _is_number(value: Any) -> bool:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    if isinstance(value, float) and not math.isfinite(value):
        return False
    return bool(-_MAX_ABS <= value <= _MAX_ABS)   # int vs float compares exactly


def _bad(where: str, place: str, want: str, value: Any) -> GearshotError:
    return GearshotError(f"{where}: {place} must be {want}; got {_show(value)}")


def _check_value(value: Any, field: Field, where: str, place: str) -> None:
    value = _plain(value)
    if _is_null(value):
        if field.nullable:
            return
        raise _bad(where, place, f"a {_WANT[field.kind]} (not null or NaN)", value)
    kind = field.kind
    if kind in ("number", "int"):
        if not _is_number(value) or (kind == "int" and not isinstance(value, int)
                                     and not float(value).is_integer()):
            raise _bad(where, place, f"a finite {_WANT[kind]}", value)
        low = -math.inf if field.low is None else field.low
        high = math.inf if field.high is None else field.high
        if not low <= value <= high:
            raise _bad(where, place, f"a {_WANT[kind]} in [{low:g}, {high:g}]", value)
    elif kind == "str":
        if not isinstance(value, str):
            raise _bad(where, place, "a string", value)
        if field.choices is not None and value not in field.choices:
            raise _bad(where, place, f"one of {list(field.choices)}", value)
    elif kind == "bool":
        if not isinstance(value, bool) and value not in (0, 1):
            raise _bad(where, place, "true or false", value)
    elif kind == "tf":
        if not (isinstance(value, str) or (_is_number(value) and not isinstance(value, bool)
                                           and float(value).is_integer())):
            raise _bad(where, place, "a transfer-function index or name", value)
    elif kind == "strings":
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise _bad(where, place, "a list of strings", value)
    elif kind == "numbers":
        if not isinstance(value, dict):
            raise _bad(where, place, "an object of name: number", value)
        for key, v in value.items():
            if not _is_null(_plain(v)) and not _is_number(_plain(v)):
                raise _bad(where, f"{place}.{key}", "a finite number or null", v)


_WANT = {"number": "number", "int": "whole number", "str": "string", "bool": "boolean",
         "tf": "transfer-function index or name", "strings": "list of strings",
         "numbers": "object of numbers", "any": "value"}


def check_fields(record: Any, schema: dict[str, Field], where: str, place: str) -> None:
    """Check one object against ``schema`` (extra keys are allowed and left alone).

    Raises
    ------
    GearshotError
        One line naming ``where`` (the file), ``place`` and the first bad field.
    """
    if not isinstance(record, dict):
        raise _bad(where, place, "an object", record)
    for name, field in schema.items():
        if name not in record:
            if field.required:
                raise GearshotError(f"{where}: {place} lacks the key {name!r} (the keys "
                                    f"gearshot writes there: {sorted(schema)})")
            continue
        _check_value(record[name], field, where, f"{place}.{name}" if place else name)


def check_rows(rows: Any, schema: dict[str, Field], where: str, name: str = "rows") -> None:
    """Check a non-empty list of row objects, each against ``schema``."""
    if not isinstance(rows, list) or not rows:
        raise _bad(where, name, "a non-empty list of objects", rows)
    if len(rows) > MAX_ROWS:
        raise GearshotError(f"{where}: {name} has {len(rows)} entries; a gearshot output "
                            f"has at most {MAX_ROWS}")
    for i, row in enumerate(rows):
        check_fields(row, schema, where, f"{name}[{i}]")



#: One row of ``gearshot predict`` (CSV or JSON); trust columns of other commands are
#: extra keys, read when present.
PREDICT_ROW = {
    "recording": Field("str"),
    "role": Field("str", required=False, choices=("healthy_fitted", "example", "faulty_rest",
                                                  "healthy_holdout", "test")),
    "segment": Field("int", required=False, low=0),
    "predicted": Field("number", low=0.0, high=1.0),
    "low": Field("number", low=0.0, high=1.0),
    "high": Field("number", low=0.0, high=1.0),
    "comparability": Field("number", required=False, nullable=True),
    "comparable": Field("bool", required=False),
    "input_check": Field("str", required=False),
    "fit_check": Field("str", required=False),
    "trusted": Field("bool", required=False),
}

#: A predict row whose input failed its check (``input_check`` not ``"ok"``): its
#: estimate and interval are withheld (null).
PREDICT_ROW_WITHHELD = {**PREDICT_ROW, **{name: Field("number", nullable=True, low=0.0,
                                                      high=1.0)
                                          for name in ("predicted", "low", "high")}}


def check_predict_rows(rows: Any, where: str) -> None:
    """Check the rows of a predict output: :data:`PREDICT_ROW`, or
    :data:`PREDICT_ROW_WITHHELD` for a row whose ``input_check`` failed."""
    check_rows(rows, PREDICT_ROW_WITHHELD, where)
    for i, row in enumerate(rows):
        if row.get("input_check", "ok") == "ok":
            check_fields(row, PREDICT_ROW, where, f"rows[{i}]")

#: One row of ``experiment rig --json`` (and of the demo's ``ablations.csv``).
EXPERIMENT_ROW = {
    "variant": Field("str"),
    "mae": Field("number", low=0.0, high=1.0),
    "repeat": Field("int", required=False, low=0),
}

#: One row of ``experiment simulated --json``.
SIMULATED_ROW = {
    **EXPERIMENT_ROW,
    "speed": Field("number", low=0.0), "load": Field("number", low=0.0),
    "tf": Field("tf"), "attenuation_db": Field("number"),
}

#: The demo's ``results.json`` (MAE in %).
DEMO = {
    "speed": Field("number", required=False, low=0.0),
    "load": Field("number", required=False, low=0.0),
    "seed": Field("int", required=False, nullable=True),
    "draws": Field("int", required=False, low=1),
    "mae": Field("number", low=0.0, high=100.0),
    "mae_std": Field("number", required=False, low=0.0, high=100.0),
    "ablations": Field("numbers"),
    "ablations_std": Field("numbers", required=False),
    "grade": Field("int", required=False, low=1, high=12),
    "rig_grade": Field("int", required=False, low=1, high=12),
    "selected_features": Field("strings", required=False),
    "feature_errors": Field("numbers", required=False),
    "grade_note": Field("str", required=False, nullable=True),
    "ablation_note": Field("str", required=False, nullable=True),
    "n_neighbors": Field("int", required=False, low=1),
}

#: ``experiment rig-family --json``: its header (the tables are checked by
#: :func:`check_family_tables`).
FAMILY = {
    "range": Field("str", required=False, nullable=True),
    "seeds": Field("any", required=False),
    "draws": Field("int", required=False, nullable=True, low=1),
}

#: One record of ``gearshot indicators --json``.
INDICATOR_RECORD = {
    "file": Field("str"),
    "sensor": Field("str", required=False),
    "tacho_speed_hz": Field("number", required=False, nullable=True, low=0.0),
    "shaft_speed_hz": Field("number", required=False, nullable=True, low=0.0),
    "n_cycles": Field("int", nullable=True, low=0),
    "input_check": Field("str", required=False),
    "indicators": Field("numbers"),
}

_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.+-]{0,79}$")


def check_name(name: Any, where: str, place: str) -> str:
    """A name that becomes a figure's file name: letters, digits, ``_.+-`` (no path)."""
    if not isinstance(name, str) or not _NAME.match(name):
        raise _bad(where, place, "a name of letters, digits and _.+- (it names a figure "
                   "file)", name)
    return name


def check_family_tables(tables: Any, where: str) -> None:
    """``tables`` of a rig-family JSON: {name: pandas split {columns, index, data}}."""
    if not isinstance(tables, dict) or not tables:
        raise _bad(where, "tables", "a non-empty object of tables", tables)
    for name, split in tables.items():
        place = f"tables.{name}"
        check_fields(split, {"columns": Field("any"), "index": Field("any"),
                             "data": Field("any")}, where, place)
        cols, index, data = split["columns"], split["index"], split["data"]
        for key, seq in (("columns", cols), ("index", index)):
            if not isinstance(seq, list) or not all(
                    isinstance(v, str) or _is_number(v) for v in seq):
                raise _bad(where, f"{place}.{key}", "a list of names", seq)
        if not isinstance(data, list) or len(data) != len(index):
            raise _bad(where, f"{place}.data", f"a list of {len(index)} rows (one per index "
                       "entry)", data)
        for i, row in enumerate(data):
            if not isinstance(row, list) or len(row) != len(cols):
                raise _bad(where, f"{place}.data[{i}]", f"a list of {len(cols)} values",
                           row)
            for j, v in enumerate(row):
                if not _is_null(v) and not (_is_number(v) and v >= 0):
                    raise _bad(where, f"{place}.data[{i}][{j}]",
                               "a non-negative number (MAE or coverage in %) or null", v)


def check_indicators(payload: dict, where: str) -> None:
    """An indicators payload: its records, names that become figure files, its units."""
    check_rows(payload.get("records"), INDICATOR_RECORD, where, "records")
    for i, rec in enumerate(payload["records"]):
        for name in rec["indicators"]:
            check_name(name, where, f"records[{i}].indicators key")
    for key in ("machine", "shaft"):
        if key in payload and not isinstance(payload[key], (str, type(None))):
            raise _bad(where, key, "a string", payload[key])
    units = payload.get("units", {})
    ind = units.get("indicators", {}) if isinstance(units, dict) else None
    if not isinstance(ind, dict) or not all(
            isinstance(v, dict) and all(isinstance(u, str) for u in v.values())
            for v in ind.values()):
        raise _bad(where, "units.indicators", "an object of sensor: {indicator: unit}",
                   ind)
    ranking = payload.get("ranking")
    if ranking is not None:
        check_rows(ranking, {"indicator": Field("str")}, where, "ranking")
        for i, row in enumerate(ranking):
            for key, v in row.items():
                if not isinstance(v, str) and not _is_null(v) and not _is_number(v):
                    raise _bad(where, f"ranking[{i}].{key}", "a string or a number", v)
