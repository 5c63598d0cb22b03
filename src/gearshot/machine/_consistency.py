"""The checks across a machine's parts (every name a part refers to exists, the monitored
gear is on its shaft) and the exact speed ratios of its gear train."""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction
from typing import Any

from .._errors import GearshotError
from .._validation import MAX_POINTS, describe
from ._values import int_key, unique_names
from .parts import FileLayout, GearStage, MonitoredGear, Sensor, Tacho, VibrationSpeed

__all__ = ["check_shafts", "check_stages", "check_tacho", "check_vibration_speed",
           "check_sensors", "check_layout", "check_monitored", "check_analysis", "gear_teeth",
           "solve_ratios"]


def check_shafts(name: Any, shafts: Sequence[str]) -> None:
    """The machine's name is a string; its shafts are unique names, at least one."""
    if not isinstance(name, str):
        raise GearshotError(f"name must be a string; got {describe(name)}")
    if not shafts:
        raise GearshotError("shafts must name at least one shaft; got []")
    unique_names(shafts, "shafts")


def check_stages(stages: Sequence[Any], shafts: Sequence[str]) -> None:
    """Every stage a :class:`GearStage` between two of ``shafts``."""
    known = set(shafts)
    for i, st in enumerate(stages):
        if not isinstance(st, GearStage):
            raise GearshotError(f"stage[{i}] must be a GearStage; got {describe(st)}")
        for key in ("driver", "driven"):
            if getattr(st, key) not in known:
                raise GearshotError(f"stage[{i}].{key}={getattr(st, key)!r} is not one of "
                                    f"the shafts {list(shafts)}")


def check_tacho(tacho: Any, shafts: Sequence[str]) -> None:
    """``tacho`` is ``None`` or a :class:`Tacho` on one of ``shafts``."""
    if tacho is not None and not isinstance(tacho, Tacho):
        raise GearshotError(f"tacho must be a Tacho or None; got {describe(tacho)}")
    if tacho is not None and tacho.shaft not in shafts:
        raise GearshotError(f"tacho.shaft={tacho.shaft!r} is not one of the shafts "
                            f"{list(shafts)}")


def check_vibration_speed(vibration_speed: Any, shafts: Sequence[str]) -> None:
    """``vibration_speed`` is ``None`` or a :class:`VibrationSpeed` of one of ``shafts``."""
    if vibration_speed is not None:
        if not isinstance(vibration_speed, VibrationSpeed):
            raise GearshotError(f"vibration_speed must be a VibrationSpeed; got "
                                f"{describe(vibration_speed)}")
        if vibration_speed.shaft not in shafts:
            raise GearshotError(f"speed.shaft={vibration_speed.shaft!r} is not one of "
                                f"the shafts {list(shafts)}")


def check_sensors(sensors: Sequence[Sensor], vibration_speed: VibrationSpeed | None) -> None:
    """At least one sensor, names unique; the ``[speed]`` sensor one of them."""
    if not sensors:
        raise GearshotError("the machine needs at least one [[sensor]]")
    names = [s.name for s in sensors]
    if len(set(names)) != len(names):
        raise GearshotError(f"sensor names must be unique; got {names}")
    vs = vibration_speed
    if isinstance(vs, VibrationSpeed) and vs.sensor is not None and vs.sensor not in names:
        raise GearshotError(f"speed.sensor={vs.sensor!r} is not a sensor; sensors: {names}")


def check_layout(layout: FileLayout | None, sensors: Sequence[Sensor],
                 tacho: Tacho | None) -> None:
    """Every sensor's and the tacho's channel is a column of the file layout."""
    if layout is not None:
        cols = set(layout.columns)
        for sensor in sensors:
            if sensor.channel not in cols:
                raise GearshotError(f"sensor {sensor.name!r}: channel={sensor.channel!r} is "
                                    f"not one of file.columns {list(layout.columns)}")
        if tacho is not None and tacho.channel not in cols:
            raise GearshotError(f"tacho.channel={tacho.channel!r} is not one of "
                                f"file.columns {list(layout.columns)}")


def gear_teeth(stages: Sequence[GearStage], shaft: str) -> tuple[int, ...]:
    """Tooth counts of the gears that ``shaft`` carries (in stage order)."""
    teeth: list[int] = []
    for st in stages:
        z = st.teeth_on(shaft)
        if z is not None and z not in teeth:
            teeth.append(z)
    return tuple(teeth)


def check_monitored(monitored: MonitoredGear | None, shafts: Sequence[str],
                    stages: Sequence[GearStage]) -> None:
    """The monitored gear's shaft is one of ``shafts`` and carries a gear of its teeth."""
    if monitored is not None:
        if monitored.shaft not in shafts:
            raise GearshotError(f"monitored.shaft={monitored.shaft!r} is not one of "
                                f"the shafts {list(shafts)}")
        if monitored.teeth not in gear_teeth(stages, monitored.shaft):
            raise GearshotError(
                f"monitored.teeth={monitored.teeth}: shaft "
                f"{monitored.shaft!r} carries gears of "
                f"{list(gear_teeth(stages, monitored.shaft))} teeth")


def check_analysis(samples_per_cycle: Any, cycles_per_segment: Any,
                   shaft_orders: Sequence[Any], n_sidebands: Any, antialias: Any) -> None:
    """The ``[analysis]`` values, each under its ``analysis.`` key."""
    int_key(samples_per_cycle, "analysis.samples_per_cycle", minimum=16,
            maximum=MAX_POINTS)
    if cycles_per_segment is not None:
        int_key(cycles_per_segment, "analysis.cycles_per_segment")
    for o in shaft_orders:
        int_key(o, "analysis.shaft_orders[]")
    int_key(n_sidebands, "analysis.n_sidebands", minimum=0)
    if not isinstance(antialias, bool):
        raise GearshotError(f"analysis.antialias must be true or false; got "
                            f"{describe(antialias)}")


def solve_ratios(shafts: Sequence[str], stages: Sequence[GearStage],
                 ref: str) -> dict[str, Fraction]:
    """Speed of every shaft relative to ``ref`` (the tacho shaft), exact fractions.

    Raises
    ------
    GearshotError
        Two paths through the train give a shaft two speeds, or a shaft is not connected.
    """
    speed = {ref: Fraction(1)}
    todo = [ref]
    while todo:
        shaft = todo.pop()
        for i, st in enumerate(stages):
            pairs = ((st.driver, st.driven, Fraction(st.driver_teeth, st.driven_teeth)),
                     (st.driven, st.driver, Fraction(st.driven_teeth, st.driver_teeth)))
            for a, b, r in pairs:
                if a != shaft:
                    continue
                value = speed[a] * r
                if b in speed:
                    if speed[b] != value:
                        raise GearshotError(
                            f"stage[{i}] ({st.driver_teeth}:{st.driven_teeth}) makes the "
                            f"speed of shaft {b!r} {value} but another path gives "
                            f"{speed[b]} (inconsistent gear train)")
                else:
                    speed[b] = value
                    todo.append(b)
    missing = [s for s in shafts if s not in speed]
    if missing:
        raise GearshotError(f"shaft(s) {missing} are not connected to the tacho shaft "
                            f"{ref!r} by any stage; their speed is unknown")
    return speed
