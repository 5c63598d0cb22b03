"""The parts of a machine: gear stages, tacho, vibration speed source, sensors, file layout
and monitored gear. Each checks its own values on construction, naming the key."""

from __future__ import annotations

import math
from dataclasses import dataclass

from .._errors import GearshotError
from .._validation import describe
from ._values import DELIMITERS, float_key, int_key, name_key, unique_names

__all__ = ["GearStage", "Tacho", "VibrationSpeed", "Sensor", "FileLayout", "MonitoredGear"]


@dataclass(frozen=True)
class GearStage:
    """One gear mesh: a driving gear on one shaft and a driven gear on another.

    Parameters
    ----------
    driver, driven : str
        Shaft names.
    driver_teeth, driven_teeth : int
        Tooth counts.
    module, face_width : float or None
        m; ``None`` where the description is silent.
    pressure_angle : float or None
        Normal pressure angle, rad.
    helix_angle : float
        rad (0 for spur gears, or for helical gears whose angle is not stated).
    helical : bool or None
        Helical teeth (``helical = true`` in the file, with or without
        ``helix_angle_deg``); default: ``helix_angle > 0``. A helical stage without its
        angle cannot be simulated (:meth:`gearshot.Machine.gear_pair` refuses it).
    """

    driver: str
    driver_teeth: int
    driven: str
    driven_teeth: int
    module: float | None = None
    face_width: float | None = None
    pressure_angle: float | None = None
    helix_angle: float = 0.0
    helical: bool | None = None

    def __post_init__(self) -> None:
        if self.helical is None:
            object.__setattr__(self, "helical", self.helix_angle > 0.0)
        name_key(self.driver, "stage.driver")
        name_key(self.driven, "stage.driven")
        int_key(self.driver_teeth, "stage.driver_teeth")
        int_key(self.driven_teeth, "stage.driven_teeth")
        if self.driver == self.driven:
            raise GearshotError(f"stage.driver and stage.driven must be different shafts; "
                                f"both are {self.driver!r}")
        for key in ("module", "face_width", "pressure_angle"):
            if getattr(self, key) is not None:
                float_key(getattr(self, key), f"stage.{key}")
        float_key(self.helix_angle, "stage.helix_angle", allow_zero=True)
        if self.helix_angle >= math.pi / 2:
            raise GearshotError(f"stage.helix_angle must be below 90 deg; got "
                                f"{math.degrees(self.helix_angle):g} deg")

    def teeth_on(self, shaft: str) -> int | None:
        """Teeth of this stage's gear on ``shaft`` (``None`` if the stage does not touch it)."""
        if shaft == self.driver:
            return self.driver_teeth
        if shaft == self.driven:
            return self.driven_teeth
        return None


@dataclass(frozen=True)
class Tacho:
    """The tacho: its channel, the shaft it watches, pulses per revolution, trigger level."""

    channel: str
    shaft: str
    pulses_per_rev: int = 1
    threshold: float | None = None

    def __post_init__(self) -> None:
        name_key(self.channel, "tacho.channel")
        name_key(self.shaft, "tacho.shaft")
        int_key(self.pulses_per_rev, "tacho.pulses_per_rev")
        if self.threshold is not None:
            float_key(self.threshold, "tacho.threshold", positive=False)


@dataclass(frozen=True)
class VibrationSpeed:
    """No tacho: the speed of ``shaft`` is estimated from the vibration (``[speed]`` table).

    Parameters
    ----------
    shaft : str
        The shaft whose speed and angle are tracked (every other shaft follows through the
        gear train).
    speed_range : (float, float) or None
        Speeds of ``shaft`` searched, rev/s (``range_hz``). ``None``: the recording's
        nominal ``speed`` ±10 %, else an error.
    track : int or None
        Order of ``shaft`` whose phase gives the angle; default: the strongest harmonic of
        the first gear on ``shaft``.
    sensor : str or None
        Sensor whose signal is tracked; default: the first.
    """

    shaft: str
    speed_range: tuple[float, float] | None = None
    track: int | None = None
    sensor: str | None = None

    def __post_init__(self) -> None:
        name_key(self.shaft, "speed.shaft")
        if self.speed_range is not None:
            rng = self.speed_range
            if not isinstance(rng, (list, tuple)) or len(rng) != 2:
                raise GearshotError(f"speed.range_hz must be [low, high] (rev/s of the shaft); "
                                    f"got {describe(rng)}")
            lo = float_key(rng[0], "speed.range_hz[0]")
            hi = float_key(rng[1], "speed.range_hz[1]")
            if not lo < hi:
                raise GearshotError(f"speed.range_hz must be [low, high] with low < high; got "
                                    f"{list(rng)}")
            object.__setattr__(self, "speed_range", (lo, hi))
        if self.track is not None:
            int_key(self.track, "speed.track")
        if self.sensor is not None:
            name_key(self.sensor, "speed.sensor")


@dataclass(frozen=True)
class Sensor:
    """A vibration sensor: its name, file channel, sensitivity and physical unit.

    ``sensitivity`` is in file units per physical unit (0.01 for 10 mV/g); the physical
    signal is the file's column divided by it. ``ac_coupled`` (default): the record's mean
    (a bias voltage, not an acceleration) is removed, as an AC-coupled input would.
    """

    name: str
    channel: str
    sensitivity: float = 1.0
    unit: str = "g"
    ac_coupled: bool = True

    def __post_init__(self) -> None:
        name_key(self.name, "sensor.name")
        name_key(self.channel, "sensor.channel")
        float_key(self.sensitivity, "sensor.sensitivity")
        name_key(self.unit, "sensor.unit")


@dataclass(frozen=True)
class FileLayout:
    """How a recording file is laid out: column names, delimiter, header, sampling rate.

    ``delimiter=None`` means any run of whitespace.
    """

    columns: tuple[str, ...]
    fs: float
    delimiter: str | None = None
    header: bool = False
    skip_rows: int = 0

    def __post_init__(self) -> None:
        if not self.columns:
            raise GearshotError("file.columns must name at least one column; got []")
        unique_names(self.columns, "file.columns")
        float_key(self.fs, "file.fs")
        if self.delimiter not in (None, ",", ";", "\t"):
            raise GearshotError(f"file.delimiter must be one of {sorted(DELIMITERS)}; got "
                                f"{self.delimiter!r}")
        if not isinstance(self.header, bool):
            raise GearshotError(f"file.header must be true or false; got {describe(self.header)}")
        int_key(self.skip_rows, "file.skip_rows", minimum=0, maximum=10**9)


@dataclass(frozen=True)
class MonitoredGear:
    """The gear whose fault size is estimated: its shaft and tooth count."""

    shaft: str
    teeth: int

    def __post_init__(self) -> None:
        name_key(self.shaft, "monitored.shaft")
        int_key(self.teeth, "monitored.teeth")
