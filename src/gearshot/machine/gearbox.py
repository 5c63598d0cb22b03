"""The :class:`Machine`: a gearbox's parts checked together, the exact speed ratios of its
gear train, the monitored pair for the simulator, and its constructors (the paper's rig, a
TOML file, a parsed mapping)."""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .._errors import GearshotError
from .._validation import describe
from ._consistency import (
    check_analysis,
    check_layout,
    check_monitored,
    check_sensors,
    check_shafts,
    check_stages,
    check_tacho,
    check_vibration_speed,
    gear_teeth,
    solve_ratios,
)
from ._tables import machine_fields
from .parts import FileLayout, GearStage, MonitoredGear, Sensor, Tacho, VibrationSpeed

if TYPE_CHECKING:
    from ..sim import GearPair

__all__ = ["Machine"]


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
        for key in ("shafts", "stages", "sensors", "shaft_orders"):
            set_(self, key, tuple(getattr(self, key)))
        check_shafts(self.name, self.shafts)
        check_stages(self.stages, self.shafts)
        check_tacho(self.tacho, self.shafts)
        if self.vibration_speed is None and self.tacho is None:
            set_(self, "vibration_speed", VibrationSpeed(self.shafts[0]))
        check_vibration_speed(self.vibration_speed, self.shafts)
        check_sensors(self.sensors, self.vibration_speed)
        check_layout(self.layout, self.sensors, self.tacho)
        check_monitored(self.monitored, self.shafts, self.stages)
        check_analysis(self.samples_per_cycle, self.cycles_per_segment, self.shaft_orders,
                       self.n_sidebands, self.antialias)
        set_(self, "_ratios", solve_ratios(self.shafts, self.stages, self.reference_shaft))

    # ------------------------------------------------------------------ train
    @property
    def reference_shaft(self) -> str:
        """The shaft whose speed is measured: the tacho's, else the one tracked in the
        vibration (``[speed]`` shaft). Speed ratios are relative to it."""
        if self.tacho is not None:
            return self.tacho.shaft
        assert self.vibration_speed is not None
        return self.vibration_speed.shaft

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
        return gear_teeth(self.stages, shaft)

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

    def gear_pair(self, **overrides: Any) -> GearPair:
        """The monitored pair as a :class:`gearshot.sim.GearPair` for the simulator.

        The simulator puts the fault on its driven gear (``z_gear``), so ``z_gear`` is the
        monitored gear and ``z_pinion`` its mate, whichever drives in the machine. Geometry
        missing from the description takes the paper's values (module 3 mm, face width
        15 mm, 20 deg); the helix angle is the stage's (0: a spur pair).

        Raises
        ------
        GearshotError
            The monitored stage is helical (``helical = true``) but states no
            ``helix_angle_deg``: simulated as a spur pair it would not be this machine's.
        """
        from ..sim import GearPair

        st = self.monitored_stage()
        _, mate_teeth = self.mate()
        if st.helical and st.helix_angle == 0.0:
            raise GearshotError(
                f"machine {self.name!r}: the monitored stage {st.driver} {st.driver_teeth}T "
                f"-> {st.driven} {st.driven_teeth}T is helical but states no "
                f"helix_angle_deg; the simulator would build a spur pair, not this "
                f"machine's: state the helix angle in its [[stage]]")
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
        kwargs["helix_angle"] = st.helix_angle
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
        from .. import paper

        stage = GearStage("input", paper.PINION_TEETH, "output", paper.GEAR_TEETH,
                          module=paper.MODULE, face_width=paper.FACE_WIDTH,
                          pressure_angle=math.radians(paper.PRESSURE_ANGLE_DEG))
        return cls(name="Matania et al. (2023) rig", shafts=("input", "output"),
                   stages=(stage,), tacho=Tacho("tacho", "input", 1),
                   sensors=(Sensor("acceleration", "acceleration", 1.0, "g"),),
                   layout=None, monitored=MonitoredGear("output", paper.GEAR_TEETH),
                   samples_per_cycle=paper.SAMPLES_PER_CYCLE,
                   cycles_per_segment=paper.CYCLES_PER_SEGMENT)

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
            return cls(**machine_fields(data))
        except (TypeError, AttributeError) as exc:   # a list or table where a value belongs
            raise GearshotError(f"a value of the wrong type ({type(exc).__name__}: {exc}); "
                                f"see the machine file format in gearshot.machine") from None
