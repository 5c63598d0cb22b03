"""A parsed machine file → the fields of a :class:`~gearshot.machine.Machine`, one parser
per table: ``[[stage]]``, ``[tacho]``, ``[speed]``, ``[[sensor]]``, ``[file]``,
``[monitored]``, ``[analysis]``. Every error names the table or key and the bad value."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from .._errors import GearshotError
from .._validation import MAX_POINTS, describe
from ._values import (
    DELIMITERS,
    check_keys,
    float_key,
    int_key,
    name_key,
    parse_sensitivity,
    rate_key,
    table,
    tables,
)
from .parts import FileLayout, GearStage, MonitoredGear, Sensor, Tacho, VibrationSpeed

__all__ = ["machine_fields"]

_TOP = {"name", "shafts", "stage", "tacho", "sensor", "file", "monitored", "analysis", "speed"}
_STAGE = {"driver", "driver_teeth", "driven", "driven_teeth", "module_mm", "face_width_mm",
          "pressure_angle_deg", "helix_angle_deg", "helical"}
#: optional stage geometry: file key, factor to SI, GearStage field
_GEOMETRY = (("module_mm", 1e-3, "module"), ("face_width_mm", 1e-3, "face_width"),
             ("pressure_angle_deg", math.pi / 180, "pressure_angle"))


def machine_fields(data: Mapping[str, Any]) -> dict[str, Any]:
    """The keyword arguments of :class:`~gearshot.machine.Machine` from a parsed machine
    file, each table checked by its parser (top level, stages, tacho, speed, sensors, file,
    monitored gear, analysis: the first error found is raised)."""
    check_keys(data, _TOP, "the top level")
    name = data.get("name", "")
    if not isinstance(name, str):
        raise GearshotError(f"name must be a string; got {describe(name)}")
    shafts = data.get("shafts")
    if not isinstance(shafts, list) or not shafts:
        raise GearshotError(f"shafts must be a list of shaft names; got {describe(shafts)}")
    stages = tuple(_stage(st, i) for i, st in enumerate(tables(data, "stage")))
    tacho = _tacho(data)
    vibration_speed = _speed(data)
    sensors = tuple(_sensor(s, i) for i, s in enumerate(tables(data, "sensor")))
    layout = _file(data)
    monitored = _monitored(data)
    at, cps, orders = _analysis(data)
    return dict(
        name=name, shafts=tuple(name_key(s, "shafts[]") for s in shafts),
        stages=stages, tacho=tacho, sensors=sensors, layout=layout, monitored=monitored,
        samples_per_cycle=int_key(at.get("samples_per_cycle", 2048),
                                  "analysis.samples_per_cycle", minimum=16,
            maximum=MAX_POINTS),
        cycles_per_segment=cps,
        shaft_orders=tuple(int_key(o, "analysis.shaft_orders[]") for o in orders),
        n_sidebands=int_key(at.get("n_sidebands", 2), "analysis.n_sidebands", minimum=0),
        antialias=at.get("antialias", True), vibration_speed=vibration_speed)


def _stage(st: Mapping[str, Any], i: int) -> GearStage:
    """``[[stage]]`` number ``i``: shafts, tooth counts, optional geometry in mm and deg."""
    check_keys(st, _STAGE, f"[[stage]] {i}")
    for key in ("driver", "driver_teeth", "driven", "driven_teeth"):
        if key not in st:
            raise GearshotError(f"stage[{i}] needs {key!r}")
    opt = {}
    for key, scale, field_name in _GEOMETRY:
        if key in st:
            opt[field_name] = float_key(st[key], f"stage[{i}].{key}") * scale
    helix = math.radians(float_key(st.get("helix_angle_deg", 0.0),
                                   f"stage[{i}].helix_angle_deg", allow_zero=True))
    helical = st.get("helical", helix > 0.0)
    if not isinstance(helical, bool):
        raise GearshotError(f"stage[{i}].helical must be true or false; got {helical!r}")
    if helix > 0.0 and not helical:
        raise GearshotError(f"stage[{i}]: helical = false contradicts helix_angle_deg = "
                            f"{math.degrees(helix):g}")
    try:
        return GearStage(name_key(st["driver"], f"stage[{i}].driver"),
                         int_key(st["driver_teeth"], f"stage[{i}].driver_teeth"),
                         name_key(st["driven"], f"stage[{i}].driven"),
                         int_key(st["driven_teeth"], f"stage[{i}].driven_teeth"),
                         helix_angle=helix, helical=helical, **opt)
    except GearshotError as exc:
        raise GearshotError(f"stage[{i}]: {exc}") from None


def _tacho(data: Mapping[str, Any]) -> Tacho | None:
    """``[tacho]``: channel, shaft and pulses per revolution (never guessed), threshold."""
    tt = table(data, "tacho", required=False)
    if tt is None:
        return None
    check_keys(tt, {"channel", "shaft", "pulses_per_rev", "threshold"}, "[tacho]")
    for key in ("channel", "shaft", "pulses_per_rev"):
        if key not in tt:
            raise GearshotError(f"[tacho] needs {key!r} (pulses_per_rev is never "
                                f"guessed)")
    return Tacho(name_key(tt["channel"], "tacho.channel"),
                 name_key(tt["shaft"], "tacho.shaft"),
                 int_key(tt["pulses_per_rev"], "tacho.pulses_per_rev"),
                 None if tt.get("threshold") is None
                 else float_key(tt["threshold"], "tacho.threshold", positive=False))


def _speed(data: Mapping[str, Any]) -> VibrationSpeed | None:
    """``[speed]`` (no tacho: the speed from the vibration): shaft (default: the first),
    searched range, tracked order, sensor."""
    st_ = table(data, "speed", required=False)
    if st_ is None:
        return None
    check_keys(st_, {"shaft", "range_hz", "track", "sensor"}, "[speed]")
    shafts_ = data.get("shafts") if isinstance(data.get("shafts"), list) else []
    return VibrationSpeed(
        name_key(st_.get("shaft", shafts_[0] if shafts_ else None), "speed.shaft"),
        st_.get("range_hz"),
        None if st_.get("track") is None else int_key(st_["track"], "speed.track"),
        None if st_.get("sensor") is None else name_key(st_["sensor"], "speed.sensor"))


def _sensor(s: Mapping[str, Any], i: int) -> Sensor:
    """``[[sensor]]`` number ``i``: name, channel (default: the name), sensitivity as
    ``"10 mV/g"`` or a number with ``unit``, AC coupling."""
    check_keys(s, {"name", "channel", "sensitivity", "unit", "ac_coupled"}, f"[[sensor]] {i}")
    ac = s.get("ac_coupled", True)
    if not isinstance(ac, bool):
        raise GearshotError(f"sensor[{i}].ac_coupled must be true or false; got "
                            f"{describe(ac)}")
    if "name" not in s:
        raise GearshotError(f"sensor[{i}] needs 'name'")
    sname = name_key(s["name"], f"sensor[{i}].name")
    channel = name_key(s.get("channel", sname), f"sensor[{i}].channel")
    sens = s.get("sensitivity", 1.0)
    if isinstance(sens, str):
        value, unit = parse_sensitivity(sens, key=f"sensor[{i}].sensitivity")
        if "unit" in s and s["unit"] != unit:
            raise GearshotError(f"sensor[{i}].unit={s['unit']!r} contradicts "
                                f"sensitivity={sens!r}")
    else:
        value = float_key(sens, f"sensor[{i}].sensitivity")
        unit = name_key(s.get("unit", "g"), f"sensor[{i}].unit")
    return Sensor(sname, channel, value, unit, ac)


def _file(data: Mapping[str, Any]) -> FileLayout | None:
    """``[file]``: column names, delimiter word, header, sampling rate, rows skipped."""
    ft = table(data, "file", required=False)
    if ft is None:
        return None
    check_keys(ft, {"columns", "delimiter", "header", "fs", "skip_rows"}, "[file]")
    cols = ft.get("columns")
    if not isinstance(cols, list) or not cols:
        raise GearshotError(f"file.columns must list the column names; got "
                            f"{describe(cols)}")
    if "fs" not in ft:
        raise GearshotError("[file] needs 'fs' (sampling rate, Hz)")
    delim = ft.get("delimiter", "whitespace")
    if not isinstance(delim, str) or delim not in DELIMITERS:
        raise GearshotError(f"file.delimiter must be one of {sorted(DELIMITERS)}; got "
                            f"{delim!r}")
    header = ft.get("header", False)
    if not isinstance(header, bool):
        raise GearshotError(f"file.header must be true or false; got {describe(header)}")
    return FileLayout(tuple(name_key(c, "file.columns[]") for c in cols),
                      rate_key(ft["fs"], "file.fs"), DELIMITERS[delim], header,
                      int_key(ft.get("skip_rows", 0), "file.skip_rows", minimum=0,
                              maximum=10**9))


def _monitored(data: Mapping[str, Any]) -> MonitoredGear | None:
    """``[monitored]``: the shaft and tooth count of the gear whose fault is estimated."""
    mt = table(data, "monitored", required=False)
    if mt is None:
        return None
    check_keys(mt, {"shaft", "teeth"}, "[monitored]")
    for key in ("shaft", "teeth"):
        if key not in mt:
            raise GearshotError(f"[monitored] needs {key!r}")
    return MonitoredGear(name_key(mt["shaft"], "monitored.shaft"),
                         int_key(mt["teeth"], "monitored.teeth"))


def _analysis(data: Mapping[str, Any]) -> tuple[dict[str, Any], int | None, list[Any]]:
    """``[analysis]`` (optional): the table, its cycles per segment (``None`` for
    ``"all"``, the default) and its list of shaft orders (each checked with the machine)."""
    at = table(data, "analysis", required=False) or {}
    check_keys(at, {"samples_per_cycle", "cycles_per_segment", "shaft_orders",
                    "n_sidebands", "antialias"}, "[analysis]")
    cps = at.get("cycles_per_segment", "all")
    if cps == "all":
        cps = None
    elif isinstance(cps, str):
        raise GearshotError(f"analysis.cycles_per_segment must be an integer or 'all'; "
                            f"got {cps!r}")
    else:
        cps = int_key(cps, "analysis.cycles_per_segment")
    orders = at.get("shaft_orders", [1, 2])
    if not isinstance(orders, list):
        raise GearshotError(f"analysis.shaft_orders must be a list of integers; got "
                            f"{describe(orders)}")
    return at, cps, orders
