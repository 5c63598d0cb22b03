"""Machine descriptions: gear train, shafts, tacho, sensors, file layout, monitored gear.

A :class:`Machine` says everything gearshot needs to turn a real recording into
synchronous averages of any shaft: which column of the file is which channel, how volts
become physical units, which shaft the tacho watches and with how many pulses per
revolution, and the tooth counts of every gear stage (so the speed ratio between any two
shafts is an exact fraction). It is read from a TOML file (:meth:`Machine.from_toml`)::

    name = "PHM09 gearbox, spur train"
    shafts = ["input", "idler", "output"]

    [[stage]]                      # one per gear mesh
    driver = "input"               # shaft of the driving gear
    driver_teeth = 32
    driven = "idler"
    driven_teeth = 96
    module_mm = 3.0                # optional geometry (defaults: the paper's pair)
    face_width_mm = 15.0
    pressure_angle_deg = 20.0
    helix_angle_deg = 0.0

    [tacho]
    channel = "tacho"              # a name from [file].columns
    shaft = "input"
    pulses_per_rev = 10
    # threshold = 2.5              # optional trigger level, file units

    # No [tacho] table: the speed is estimated from the vibration (gearshot.signal.tracking)
    # [speed]                      # optional; used only when a recording has no tacho
    # shaft = "input"              # the shaft tracked (default: the first shaft)
    # range_hz = [26, 52]          # its speeds searched, rev/s (keep within an octave)
    # track = 32                   # optional: the order whose phase gives the angle
    # sensor = "acc_input"         # optional: the sensor tracked (default: the first)

    [[sensor]]                     # in order; the first is the default sensor
    name = "acc_input"
    channel = "acc_input"
    sensitivity = "10 mV/g"        # or a number (file units per `unit`) with unit = "g"
    ac_coupled = true              # remove the record's mean (sensor bias); default true

    [file]
    columns = ["acc_input", "acc_output", "tacho"]
    delimiter = "whitespace"       # or ",", ";", "tab"
    header = false
    fs = "200000/3"                # Hz: a number or an exact fraction "a/b"

    [monitored]
    shaft = "input"
    teeth = 32

    [analysis]                     # all optional
    samples_per_cycle = 2048
    cycles_per_segment = "all"     # or an integer
    shaft_orders = [1, 2]          # shaft orders removed for FM4, M6A, M8A, NA4, ER
    n_sidebands = 2
    antialias = true

Every error is a :class:`gearshot.GearshotError` naming the key and the bad value.
"""

from __future__ import annotations

import math
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

from ._errors import GearshotError
from ._validation import MAX_FS, describe

__all__ = ["Machine", "GearStage", "Tacho", "VibrationSpeed", "Sensor", "FileLayout",
           "MonitoredGear", "parse_sensitivity"]

_DELIMITERS = {"whitespace": None, "space": None, ",": ",", "comma": ",", ";": ";",
               "semicolon": ";", "tab": "\t", "\t": "\t"}
_PREFIX = {"": 1.0, "m": 1e-3, "u": 1e-6, "µ": 1e-6, "μ": 1e-6, "n": 1e-9, "k": 1e3}


# --------------------------------------------------------------------------- helpers
def _int(value: Any, key: str, *, minimum: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise GearshotError(f"{key} must be an integer; got {describe(value)}")
    if value < minimum:
        raise GearshotError(f"{key} must be >= {minimum}; got {value}")
    return int(value)


def _float(value: Any, key: str, *, positive: bool = True, allow_zero: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise GearshotError(f"{key} must be a number; got {describe(value)}")
    value = float(value)
    if not math.isfinite(value):
        raise GearshotError(f"{key} must be finite; got {value}")
    if positive and (value < 0 or (value == 0 and not allow_zero)):
        raise GearshotError(f"{key} must be {'>= 0' if allow_zero else '> 0'}; got {value}")
    return value


def _name(value: Any, key: str) -> str:
    if not isinstance(value, str) or not value.strip():
        raise GearshotError(f"{key} must be a non-empty string; got {describe(value)}")
    return value.strip()


def _rate(value: Any, key: str) -> float:
    """A sampling rate: a positive number or an exact fraction written "a/b"."""
    if isinstance(value, str):
        try:
            frac = Fraction(value.replace(" ", ""))
        except (ValueError, ZeroDivisionError):
            raise GearshotError(f"{key} must be a number or a fraction 'a/b' (Hz); got "
                                f"{value!r}") from None
        if frac <= 0:
            raise GearshotError(f"{key} must be > 0 Hz; got {value!r}")
        rate = float(frac) if frac <= MAX_FS else math.inf
    else:
        rate = _float(value, key)
    if rate > MAX_FS:
        raise GearshotError(f"{key} must be <= {MAX_FS:g} Hz; got {value!r}")
    return rate


def parse_sensitivity(text: Any, *, key: str = "sensitivity") -> tuple[float, str]:
    """Parse a sensor sensitivity such as ``"10 mV/g"``.

    Returns
    -------
    (float, str)
        File units (volts for ``V``) per physical unit, and the physical unit
        (``(0.01, "g")`` for ``"10 mV/g"``).
    """
    if not isinstance(text, str):
        raise GearshotError(f"{key} must be a string like '10 mV/g'; got {describe(text)}")
    m = re.fullmatch(r"\s*([0-9.]+(?:[eE][-+]?\d+)?)\s*([munµμk]?)V\s*/\s*(\S+)\s*", text)
    if m is None:
        raise GearshotError(f"{key} must look like '<number> [m|u|n]V/<unit>' (e.g. '10 mV/g'); "
                            f"got {text!r}")
    value = float(m.group(1)) * _PREFIX[m.group(2)]
    if not value > 0:
        raise GearshotError(f"{key} must be > 0; got {text!r}")
    return value, m.group(3)


def _check_keys(table: Mapping[str, Any], allowed: set[str], where: str) -> None:
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise GearshotError(f"unknown key(s) {unknown} in {where}; allowed: {sorted(allowed)}")


def _table(data: Mapping[str, Any], key: str, *, required: bool) -> dict[str, Any] | None:
    value = data.get(key)
    if value is None:
        if required:
            raise GearshotError(f"the machine description needs a [{key}] table")
        return None
    if not isinstance(value, Mapping):
        raise GearshotError(f"[{key}] must be a table; got {describe(value)}")
    return dict(value)


def _tables(data: Mapping[str, Any], key: str) -> list[Mapping[str, Any]]:
    """The non-empty array of tables ``[[key]]``, each checked to be a table."""
    value = data.get(key)
    if not isinstance(value, list) or not value:
        raise GearshotError(f"the machine needs at least one [[{key}]]; got {describe(value)}")
    for i, item in enumerate(value):
        if not isinstance(item, Mapping):
            raise GearshotError(f"{key}[{i}] must be a table; got {describe(item)}")
    return value


# --------------------------------------------------------------------------- parts
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
        rad (0 for spur gears).
    """

    driver: str
    driver_teeth: int
    driven: str
    driven_teeth: int
    module: float | None = None
    face_width: float | None = None
    pressure_angle: float | None = None
    helix_angle: float = 0.0

    def __post_init__(self) -> None:
        _name(self.driver, "stage.driver")
        _name(self.driven, "stage.driven")
        _int(self.driver_teeth, "stage.driver_teeth")
        _int(self.driven_teeth, "stage.driven_teeth")
        if self.driver == self.driven:
            raise GearshotError(f"stage.driver and stage.driven must be different shafts; "
                                f"both are {self.driver!r}")
        for key in ("module", "face_width", "pressure_angle"):
            if getattr(self, key) is not None:
                _float(getattr(self, key), f"stage.{key}")
        _float(self.helix_angle, "stage.helix_angle", allow_zero=True)
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
        _name(self.channel, "tacho.channel")
        _name(self.shaft, "tacho.shaft")
        _int(self.pulses_per_rev, "tacho.pulses_per_rev")
        if self.threshold is not None:
            _float(self.threshold, "tacho.threshold", positive=False)


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
        _name(self.shaft, "speed.shaft")
        if self.speed_range is not None:
            rng = self.speed_range
            if not isinstance(rng, (list, tuple)) or len(rng) != 2:
                raise GearshotError(f"speed.range_hz must be [low, high] (rev/s of the shaft); "
                                    f"got {describe(rng)}")
            lo = _float(rng[0], "speed.range_hz[0]")
            hi = _float(rng[1], "speed.range_hz[1]")
            if not lo < hi:
                raise GearshotError(f"speed.range_hz must be [low, high] with low < high; got "
                                    f"{list(rng)}")
            object.__setattr__(self, "speed_range", (lo, hi))
        if self.track is not None:
            _int(self.track, "speed.track")
        if self.sensor is not None:
            _name(self.sensor, "speed.sensor")


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
        _name(self.name, "sensor.name")
        _name(self.channel, "sensor.channel")
        _float(self.sensitivity, "sensor.sensitivity")
        _name(self.unit, "sensor.unit")


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
        for c in self.columns:
            _name(c, "file.columns[]")
        if len(set(self.columns)) != len(self.columns):
            raise GearshotError(f"file.columns must be unique; got {list(self.columns)}")
        _float(self.fs, "file.fs")
        if self.delimiter not in (None, ",", ";", "\t"):
            raise GearshotError(f"file.delimiter must be one of {sorted(_DELIMITERS)}; got "
                                f"{self.delimiter!r}")
        if not isinstance(self.header, bool):
            raise GearshotError(f"file.header must be true or false; got {describe(self.header)}")
        _int(self.skip_rows, "file.skip_rows", minimum=0)


@dataclass(frozen=True)
class MonitoredGear:
    """The gear whose fault size is estimated: its shaft and tooth count."""

    shaft: str
    teeth: int

    def __post_init__(self) -> None:
        _name(self.shaft, "monitored.shaft")
        _int(self.teeth, "monitored.teeth")


# --------------------------------------------------------------------------- machine
@dataclass(frozen=True)
class Machine:
    """A gearbox: shafts, gear stages, tacho, sensors, file layout and monitored gear.

    Parameters
    ----------
    name : str
        Free text.
    shafts : tuple of str
        Shaft names; the first is the input shaft.
    stages : tuple of GearStage
        Gear meshes; together they must connect every shaft (speed ratios are exact
        fractions of tooth counts).
    tacho : Tacho or None
        ``None``: no tacho; the speed comes from the vibration (``vibration_speed``).
    sensors : tuple of Sensor
        Vibration sensors; the first is the default.
    layout : FileLayout or None
        Layout of text recordings; ``None`` for self-describing files (HDF5, gearshot CSV).
    monitored : MonitoredGear or None
        The gear whose fault size is estimated.
    samples_per_cycle : int
        SA points per shaft revolution.
    cycles_per_segment : int or None
        Shaft revolutions per SA segment; ``None``: all whole revolutions (one SA).
    shaft_orders : tuple of int
        Shaft orders removed by the classical indicators' difference/residual signals.
    n_sidebands : int
        Sidebands removed around every mesh harmonic in the paper's difference signal.
    antialias : bool
        Low-pass the time signal below the angular Nyquist before angular resampling.
    vibration_speed : VibrationSpeed or None
        How to estimate the speed from the vibration when a recording has no tacho
        (``[speed]``); default with no tacho: track the first shaft.
    """

    name: str
    shafts: tuple[str, ...]
    stages: tuple[GearStage, ...]
    tacho: Tacho | None
    sensors: tuple[Sensor, ...]
    layout: FileLayout | None = None
    monitored: MonitoredGear | None = None
    samples_per_cycle: int = 2048
    cycles_per_segment: int | None = None
    shaft_orders: tuple[int, ...] = (1, 2)
    n_sidebands: int = 2
    antialias: bool = True
    vibration_speed: VibrationSpeed | None = None
    _ratios: dict[str, Fraction] = field(default_factory=dict, init=False, repr=False,
                                         compare=False)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "shafts", tuple(self.shafts))
        set_(self, "stages", tuple(self.stages))
        set_(self, "sensors", tuple(self.sensors))
        set_(self, "shaft_orders", tuple(self.shaft_orders))
        if not isinstance(self.name, str):
            raise GearshotError(f"name must be a string; got {describe(self.name)}")
        if not self.shafts:
            raise GearshotError("shafts must name at least one shaft; got []")
        for s in self.shafts:
            _name(s, "shafts[]")
        if len(set(self.shafts)) != len(self.shafts):
            raise GearshotError(f"shafts must be unique; got {list(self.shafts)}")
        known = set(self.shafts)
        for i, st in enumerate(self.stages):
            if not isinstance(st, GearStage):
                raise GearshotError(f"stage[{i}] must be a GearStage; got {describe(st)}")
            for key in ("driver", "driven"):
                if getattr(st, key) not in known:
                    raise GearshotError(f"stage[{i}].{key}={getattr(st, key)!r} is not one of "
                                        f"the shafts {list(self.shafts)}")
        if self.tacho is not None and not isinstance(self.tacho, Tacho):
            raise GearshotError(f"tacho must be a Tacho or None; got {describe(self.tacho)}")
        if self.tacho is not None and self.tacho.shaft not in known:
            raise GearshotError(f"tacho.shaft={self.tacho.shaft!r} is not one of the shafts "
                                f"{list(self.shafts)}")
        if self.vibration_speed is None and self.tacho is None:
            set_(self, "vibration_speed", VibrationSpeed(self.shafts[0]))
        if self.vibration_speed is not None:
            if not isinstance(self.vibration_speed, VibrationSpeed):
                raise GearshotError(f"vibration_speed must be a VibrationSpeed; got "
                                    f"{describe(self.vibration_speed)}")
            if self.vibration_speed.shaft not in known:
                raise GearshotError(f"speed.shaft={self.vibration_speed.shaft!r} is not one of "
                                    f"the shafts {list(self.shafts)}")
        if not self.sensors:
            raise GearshotError("the machine needs at least one [[sensor]]")
        names = [s.name for s in self.sensors]
        if len(set(names)) != len(names):
            raise GearshotError(f"sensor names must be unique; got {names}")
        vs = self.vibration_speed
        if isinstance(vs, VibrationSpeed) and vs.sensor is not None and vs.sensor not in names:
            raise GearshotError(f"speed.sensor={vs.sensor!r} is not a sensor; sensors: {names}")
        if self.layout is not None:
            cols = set(self.layout.columns)
            for sensor in self.sensors:
                if sensor.channel not in cols:
                    raise GearshotError(f"sensor {sensor.name!r}: channel={sensor.channel!r} is "
                                        f"not one of file.columns {list(self.layout.columns)}")
            if self.tacho is not None and self.tacho.channel not in cols:
                raise GearshotError(f"tacho.channel={self.tacho.channel!r} is not one of "
                                    f"file.columns {list(self.layout.columns)}")
        if self.monitored is not None:
            if self.monitored.shaft not in known:
                raise GearshotError(f"monitored.shaft={self.monitored.shaft!r} is not one of "
                                    f"the shafts {list(self.shafts)}")
            if self.monitored.teeth not in self.gear_teeth(self.monitored.shaft):
                raise GearshotError(
                    f"monitored.teeth={self.monitored.teeth}: shaft "
                    f"{self.monitored.shaft!r} carries gears of "
                    f"{list(self.gear_teeth(self.monitored.shaft))} teeth")
        _int(self.samples_per_cycle, "analysis.samples_per_cycle", minimum=16)
        if self.cycles_per_segment is not None:
            _int(self.cycles_per_segment, "analysis.cycles_per_segment")
        for o in self.shaft_orders:
            _int(o, "analysis.shaft_orders[]")
        _int(self.n_sidebands, "analysis.n_sidebands", minimum=0)
        if not isinstance(self.antialias, bool):
            raise GearshotError(f"analysis.antialias must be true or false; got "
                                f"{describe(self.antialias)}")
        set_(self, "_ratios", self._solve_ratios())

    # ------------------------------------------------------------------ train
    @property
    def reference_shaft(self) -> str:
        """The shaft whose speed is measured: the tacho's, else the one tracked in the
        vibration (``[speed]`` shaft). Speed ratios are relative to it."""
        if self.tacho is not None:
            return self.tacho.shaft
        assert self.vibration_speed is not None
        return self.vibration_speed.shaft

    def _solve_ratios(self) -> dict[str, Fraction]:
        """Speed of every shaft relative to the reference (tacho) shaft, exact fractions."""
        ref = self.reference_shaft
        speed = {ref: Fraction(1)}
        todo = [ref]
        while todo:
            shaft = todo.pop()
            for i, st in enumerate(self.stages):
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
        missing = [s for s in self.shafts if s not in speed]
        if missing:
            raise GearshotError(f"shaft(s) {missing} are not connected to the tacho shaft "
                                f"{ref!r} by any stage; their speed is unknown")
        return speed

    def check_shaft(self, shaft: str, key: str = "shaft") -> str:
        """Return ``shaft`` if it is one of the machine's shafts, else raise naming ``key``."""
        if shaft not in self.shafts:
            raise GearshotError(f"{key}={shaft!r} is not a shaft of machine {self.name!r}; "
                                f"shafts: {list(self.shafts)}")
        return shaft

    def speed_ratio(self, shaft: str, relative_to: str | None = None) -> Fraction:
        """Revolutions of ``shaft`` per revolution of ``relative_to`` (default: the tacho
        shaft, or the tracked shaft without a tacho), as an exact fraction of tooth counts."""
        self.check_shaft(shaft)
        ref = self.reference_shaft if relative_to is None else self.check_shaft(relative_to,
                                                                            "relative_to")
        return self._ratios[shaft] / self._ratios[ref]

    def tacho_revs_per_cycle(self, shaft: str) -> Fraction:
        """Tacho-shaft revolutions per revolution of ``shaft`` (exact)."""
        return 1 / self.speed_ratio(shaft)

    def gear_teeth(self, shaft: str) -> tuple[int, ...]:
        """Tooth counts of the gears that ``shaft`` carries (in stage order)."""
        self.check_shaft(shaft)
        teeth: list[int] = []
        for st in self.stages:
            z = st.teeth_on(shaft)
            if z is not None and z not in teeth:
                teeth.append(z)
        return tuple(teeth)

    def mesh_orders(self, shaft: str) -> tuple[int, ...]:
        """Every gear mesh that is synchronous with ``shaft``, in orders of its revolution.

        First the meshes of the gears ``shaft`` carries (their tooth counts), then the
        mesh of every other stage whose frequency is a whole multiple of the shaft's speed:
        a stage's mesh is ``driver_teeth`` times its driver's speed, i.e. order
        ``driver_teeth * speed_ratio(driver, shaft)``. Such a mesh repeats identically
        every revolution of ``shaft`` and so stays in its synchronous average (e.g. the
        PHM09 spur input shaft: its own 32T mesh and the idler 48T → 80T mesh at order
        48 / 3 = 16). Meshes at fractional orders average out and are not listed.
        """
        orders = list(self.gear_teeth(shaft))
        for st in self.stages:
            order = st.driver_teeth * self.speed_ratio(st.driver, relative_to=shaft)
            if order.denominator == 1 and int(order) not in orders:
                orders.append(int(order))
        return tuple(orders)

    def sensor(self, name: str | None = None) -> Sensor:
        """The sensor called ``name`` (default: the first)."""
        if name is None:
            return self.sensors[0]
        for s in self.sensors:
            if s.name == name:
                return s
        raise GearshotError(f"sensor={name!r} is not a sensor of machine {self.name!r}; "
                            f"sensors: {[s.name for s in self.sensors]}")

    def _monitored(self) -> MonitoredGear:
        if self.monitored is None:
            raise GearshotError(f"machine {self.name!r} names no [monitored] gear")
        return self.monitored

    def monitored_stage(self) -> GearStage:
        """The stage of the monitored gear."""
        mon = self._monitored()
        for st in self.stages:
            if st.teeth_on(mon.shaft) == mon.teeth:
                return st
        raise GearshotError("no stage holds the monitored gear")  # pragma: no cover

    def mate(self) -> tuple[str, int]:
        """Shaft and tooth count of the gear that meshes with the monitored gear."""
        st = self.monitored_stage()
        if st.driver == self._monitored().shaft:
            return st.driven, st.driven_teeth
        return st.driver, st.driver_teeth

    def gear_pair(self, **overrides: Any):
        """The monitored pair as a :class:`gearshot.sim.GearPair` for the simulator.

        The simulator puts the fault on its driven gear (``z_gear``), so ``z_gear`` is the
        monitored gear and ``z_pinion`` its mate, whichever drives in the machine. Geometry
        missing from the description takes the paper's values (module 3 mm, face width
        15 mm, 20 deg). ``helix_angle`` is passed only if ``GearPair`` accepts it.
        """
        import dataclasses

        from .sim import GearPair

        st = self.monitored_stage()
        _, mate_teeth = self.mate()
        base = GearPair.paper()
        teeth = self._monitored().teeth
        kwargs: dict[str, Any] = dict(z_pinion=mate_teeth, z_gear=teeth)
        if mate_teeth != base.z_pinion or teeth != base.z_gear:
            kwargs.update(mass_pinion=None, mass_gear=None)  # from density and size
        if st.module is not None:
            kwargs["module"] = st.module
        if st.face_width is not None:
            kwargs["face_width"] = st.face_width
        if st.pressure_angle is not None:
            kwargs["pressure_angle"] = st.pressure_angle
        fields = {f.name for f in dataclasses.fields(GearPair)}
        if "helix_angle" in fields:
            kwargs["helix_angle"] = st.helix_angle
        elif st.helix_angle:
            import warnings

            warnings.warn(f"GearPair has no helix_angle yet; the monitored pair is simulated "
                          f"as a spur pair (helix angle {math.degrees(st.helix_angle):g} deg "
                          f"ignored)", stacklevel=2)
        kwargs.update(overrides)
        return GearPair.paper(**kwargs)

    def sim_speed(self, tacho_speed: float) -> float:
        """Simulator speed (rev/s of the monitored gear's mate) at a tacho-shaft speed."""
        mate_shaft, _ = self.mate()
        return float(tacho_speed) * float(self.speed_ratio(mate_shaft))

    # ------------------------------------------------------------------ constructors
    @classmethod
    def paper(cls) -> Machine:
        """The rig of Matania et al. (2023): 17 -> 38 teeth, tacho once per input
        revolution, one accelerometer in g, 50-cycle segments of the output shaft."""
        stage = GearStage("input", 17, "output", 38, module=3e-3, face_width=15e-3,
                          pressure_angle=math.radians(20.0))
        return cls(name="Matania et al. (2023) rig", shafts=("input", "output"),
                   stages=(stage,), tacho=Tacho("tacho", "input", 1),
                   sensors=(Sensor("acceleration", "acceleration", 1.0, "g"),),
                   layout=None, monitored=MonitoredGear("output", 38),
                   samples_per_cycle=2048, cycles_per_segment=50)

    @classmethod
    def from_toml(cls, path: str | Path) -> Machine:
        """Read a machine description from a TOML file (format: module docstring)."""
        path = Path(path)
        if not path.is_file():
            raise GearshotError(f"machine file {str(path)!r} does not exist")
        try:
            data = tomllib.loads(path.read_text(encoding="utf-8"))
        except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
            raise GearshotError(f"machine file {str(path)!r} is not valid TOML: {exc}") from None
        try:
            return cls.from_dict(data)
        except GearshotError as exc:
            raise GearshotError(f"machine file {str(path)!r}: {exc}") from None

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Machine:
        """Build a machine from the parsed TOML mapping."""
        if not isinstance(data, Mapping):
            raise GearshotError(f"a machine description must be a mapping; got "
                                f"{describe(data)}")
        try:
            return cls._from_dict(data)
        except (TypeError, AttributeError) as exc:   # a list or table where a value belongs
            raise GearshotError(f"a value of the wrong type ({type(exc).__name__}: {exc}); "
                                f"see the machine file format in gearshot.machine") from None

    @classmethod
    def _from_dict(cls, data: Mapping[str, Any]) -> Machine:
        _check_keys(data, {"name", "shafts", "stage", "tacho", "sensor", "file", "monitored",
                           "analysis", "speed"}, "the top level")
        name = data.get("name", "")
        if not isinstance(name, str):
            raise GearshotError(f"name must be a string; got {describe(name)}")
        shafts = data.get("shafts")
        if not isinstance(shafts, list) or not shafts:
            raise GearshotError(f"shafts must be a list of shaft names; got {describe(shafts)}")
        stages = []
        for i, st in enumerate(_tables(data, "stage")):
            _check_keys(st, {"driver", "driver_teeth", "driven", "driven_teeth", "module_mm",
                             "face_width_mm", "pressure_angle_deg", "helix_angle_deg"},
                        f"[[stage]] {i}")
            for key in ("driver", "driver_teeth", "driven", "driven_teeth"):
                if key not in st:
                    raise GearshotError(f"stage[{i}] needs {key!r}")
            opt = {}
            for key, scale, field_name in (("module_mm", 1e-3, "module"),
                                           ("face_width_mm", 1e-3, "face_width"),
                                           ("pressure_angle_deg", math.pi / 180,
                                            "pressure_angle")):
                if key in st:
                    opt[field_name] = _float(st[key], f"stage[{i}].{key}") * scale
            helix = math.radians(_float(st.get("helix_angle_deg", 0.0),
                                        f"stage[{i}].helix_angle_deg", allow_zero=True))
            try:
                stages.append(GearStage(
                    _name(st["driver"], f"stage[{i}].driver"),
                    _int(st["driver_teeth"], f"stage[{i}].driver_teeth"),
                    _name(st["driven"], f"stage[{i}].driven"),
                    _int(st["driven_teeth"], f"stage[{i}].driven_teeth"),
                    helix_angle=helix, **opt))
            except GearshotError as exc:
                raise GearshotError(f"stage[{i}]: {exc}") from None

        tt = _table(data, "tacho", required=False)
        tacho = None
        if tt is not None:
            _check_keys(tt, {"channel", "shaft", "pulses_per_rev", "threshold"}, "[tacho]")
            for key in ("channel", "shaft", "pulses_per_rev"):
                if key not in tt:
                    raise GearshotError(f"[tacho] needs {key!r} (pulses_per_rev is never "
                                        f"guessed)")
            tacho = Tacho(_name(tt["channel"], "tacho.channel"),
                          _name(tt["shaft"], "tacho.shaft"),
                          _int(tt["pulses_per_rev"], "tacho.pulses_per_rev"),
                          None if tt.get("threshold") is None
                          else _float(tt["threshold"], "tacho.threshold", positive=False))
        vibration_speed = None
        st_ = _table(data, "speed", required=False)
        if st_ is not None:
            _check_keys(st_, {"shaft", "range_hz", "track", "sensor"}, "[speed]")
            shafts_ = data.get("shafts") if isinstance(data.get("shafts"), list) else []
            vibration_speed = VibrationSpeed(
                _name(st_.get("shaft", shafts_[0] if shafts_ else None), "speed.shaft"),
                st_.get("range_hz"),
                None if st_.get("track") is None else _int(st_["track"], "speed.track"),
                None if st_.get("sensor") is None else _name(st_["sensor"], "speed.sensor"))

        sensors = []
        for i, s in enumerate(_tables(data, "sensor")):
            _check_keys(s, {"name", "channel", "sensitivity", "unit", "ac_coupled"},
                        f"[[sensor]] {i}")
            ac = s.get("ac_coupled", True)
            if not isinstance(ac, bool):
                raise GearshotError(f"sensor[{i}].ac_coupled must be true or false; got "
                                    f"{describe(ac)}")
            if "name" not in s:
                raise GearshotError(f"sensor[{i}] needs 'name'")
            sname = _name(s["name"], f"sensor[{i}].name")
            channel = _name(s.get("channel", sname), f"sensor[{i}].channel")
            sens = s.get("sensitivity", 1.0)
            if isinstance(sens, str):
                value, unit = parse_sensitivity(sens, key=f"sensor[{i}].sensitivity")
                if "unit" in s and s["unit"] != unit:
                    raise GearshotError(f"sensor[{i}].unit={s['unit']!r} contradicts "
                                        f"sensitivity={sens!r}")
            else:
                value = _float(sens, f"sensor[{i}].sensitivity")
                unit = _name(s.get("unit", "g"), f"sensor[{i}].unit")
            sensors.append(Sensor(sname, channel, value, unit, ac))

        layout = None
        ft = _table(data, "file", required=False)
        if ft is not None:
            _check_keys(ft, {"columns", "delimiter", "header", "fs", "skip_rows"}, "[file]")
            cols = ft.get("columns")
            if not isinstance(cols, list) or not cols:
                raise GearshotError(f"file.columns must list the column names; got "
                                    f"{describe(cols)}")
            if "fs" not in ft:
                raise GearshotError("[file] needs 'fs' (sampling rate, Hz)")
            delim = ft.get("delimiter", "whitespace")
            if not isinstance(delim, str) or delim not in _DELIMITERS:
                raise GearshotError(f"file.delimiter must be one of {sorted(_DELIMITERS)}; got "
                                    f"{delim!r}")
            header = ft.get("header", False)
            if not isinstance(header, bool):
                raise GearshotError(f"file.header must be true or false; got {describe(header)}")
            layout = FileLayout(tuple(_name(c, "file.columns[]") for c in cols),
                                _rate(ft["fs"], "file.fs"), _DELIMITERS[delim], header,
                                _int(ft.get("skip_rows", 0), "file.skip_rows", minimum=0))

        monitored = None
        mt = _table(data, "monitored", required=False)
        if mt is not None:
            _check_keys(mt, {"shaft", "teeth"}, "[monitored]")
            for key in ("shaft", "teeth"):
                if key not in mt:
                    raise GearshotError(f"[monitored] needs {key!r}")
            monitored = MonitoredGear(_name(mt["shaft"], "monitored.shaft"),
                                      _int(mt["teeth"], "monitored.teeth"))

        at = _table(data, "analysis", required=False) or {}
        _check_keys(at, {"samples_per_cycle", "cycles_per_segment", "shaft_orders",
                         "n_sidebands", "antialias"}, "[analysis]")
        cps = at.get("cycles_per_segment", "all")
        if cps == "all":
            cps = None
        elif isinstance(cps, str):
            raise GearshotError(f"analysis.cycles_per_segment must be an integer or 'all'; "
                                f"got {cps!r}")
        else:
            cps = _int(cps, "analysis.cycles_per_segment")
        orders = at.get("shaft_orders", [1, 2])
        if not isinstance(orders, list):
            raise GearshotError(f"analysis.shaft_orders must be a list of integers; got "
                                f"{describe(orders)}")
        return cls(
            name=name, shafts=tuple(_name(s, "shafts[]") for s in shafts),
            stages=tuple(stages), tacho=tacho, sensors=tuple(sensors), layout=layout,
            monitored=monitored,
            samples_per_cycle=_int(at.get("samples_per_cycle", 2048),
                                   "analysis.samples_per_cycle", minimum=16),
            cycles_per_segment=cps,
            shaft_orders=tuple(_int(o, "analysis.shaft_orders[]") for o in orders),
            n_sidebands=_int(at.get("n_sidebands", 2), "analysis.n_sidebands", minimum=0),
            antialias=at.get("antialias", True), vibration_speed=vibration_speed)
