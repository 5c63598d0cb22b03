"""`Recording`: accelerometer channel(s) plus a tacho, with metadata; file I/O; SA segments."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from .._errors import GearshotError
from .._validation import MAX_FS, as_signal_array, check_int, check_positive, describe
from ..signal.angle import TACHO_SHAFTS, check_pulse_train, uniform_cycle_times
from ._fileio import METADATA_KEYS, RawFile, reconcile_fs, select_channels
from ._format_csv import read_csv, write_csv
from ._format_hdf5 import read_hdf5, write_hdf5
from ._format_matlab import read_mat, write_mat
from ._format_text import TEXT_SUFFIXES, read_text
from ._format_wav import read_wav, write_wav

__all__ = ["Recording", "FORMATS"]

#: file suffix -> format name understood by :meth:`Recording.read` / :meth:`Recording.write`.
FORMATS = {".h5": "hdf5", ".hdf5": "hdf5", ".hdf": "hdf5", ".mat": "mat",
           ".wav": "wav", ".csv": "csv", ".tdms": "tdms",
           **{suffix: "text" for suffix in TEXT_SUFFIXES}}

#: Relative disagreement between the tacho's speed and the ``speed`` metadata that is taken
#: as a wrong sampling rate.
SPEED_TOLERANCE = 0.10


def _opt_float(value: Any, name: str) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float, np.number)):
        raise GearshotError(f"{name} must be a real number or None; got {describe(value)}")
    value = float(value)
    if not math.isfinite(value):
        raise GearshotError(f"{name} must be finite; got {value}")
    return value


@dataclass(frozen=True, eq=False)
class Recording:
    """An accelerometer recording (one or several channels) with a shaft tacho.

    Parameters
    ----------
    acceleration : ndarray, shape (n,) or (n_channels, n)
        Acceleration samples, in ``units``; several sensors along the first axis.
    tacho : ndarray, shape (n,) or None
        Tacho signal sampled with the acceleration (pulses, any amplitude); ``None`` if the
        recording has none (then no SA segments can be made).
    fs : float
        Sampling rate in Hz.
    speed : float or None
        Nominal input-shaft (pinion) speed in rev/s.
    load : float or None
        Nominal load torque in N m.
    fault_size : float or None
        Fault size y in [0, 1] (0 = healthy) when known.
    units : str
        Units of ``acceleration`` (e.g. ``"g"``, ``"m/s^2"``).
    source : str
        Free text: where the data come from.
    tacho_pulses_per_rev : int or None
        Tacho pulses per revolution of the shaft it watches. ``None`` (not stated): inferred
        from ``speed`` when that is known; SA segments raise otherwise (a 10-pulse tacho
        taken for a 1-pulse one would give cycles of a tenth of a revolution).
    tacho_shaft : str
        The shaft the tacho watches: ``"input"`` (pinion, default) or ``"output"``
        (driven gear); with a ``machine``, any of its shafts.
    extras : mapping
        Free-form JSON-serializable metadata (stored in every format).
    origin : str or None
        The file the recording was read from (not stored; used in error messages).
    channel_names : tuple of str
        Names of the acceleration channels (sensor names); default ``("acceleration",)``
        or ``("0", "1", ...)``.
    machine : gearshot.Machine or None
        The machine the recording comes from (gear train, tacho, sensors); enables SA
        segments of any shaft (``shaft=``). Not stored in files.
    """

    acceleration: np.ndarray
    tacho: np.ndarray | None
    fs: float
    speed: float | None = None
    load: float | None = None
    fault_size: float | None = None
    units: str = "g"
    source: str = ""
    tacho_pulses_per_rev: int | None = None
    tacho_shaft: str = "input"
    extras: Mapping[str, Any] = field(default_factory=dict)
    origin: str | None = field(default=None, compare=False)
    channel_names: tuple[str, ...] = ()
    machine: Any = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        acc = as_signal_array(self.acceleration, "acceleration", max_ndim=2, min_length=2,
                              max_abs=None)
        set_(self, "acceleration", acc)
        names = tuple(self.channel_names)
        if not names:
            names = ("acceleration",) if acc.ndim == 1 else tuple(str(i) for i in
                                                                  range(acc.shape[0]))
        n_ch = 1 if acc.ndim == 1 else acc.shape[0]
        if len(names) != n_ch or not all(isinstance(n, str) and n for n in names) or \
                len(set(names)) != len(names):
            raise GearshotError(f"channel_names must be {n_ch} distinct non-empty str; got "
                                f"{describe(self.channel_names)}")
        set_(self, "channel_names", names)
        if self.tacho is not None:
            tac = as_signal_array(self.tacho, "tacho", max_ndim=1, max_abs=None)
            if tac.shape[-1] != acc.shape[-1]:
                raise GearshotError(f"tacho must have as many samples as acceleration "
                                    f"({acc.shape[-1]}); got {tac.size}")
            set_(self, "tacho", tac)
        set_(self, "fs", check_positive(self.fs, "fs"))
        if self.fs > MAX_FS:
            raise GearshotError(f"fs must be <= {MAX_FS:g} Hz; got {self.fs:g}")
        set_(self, "speed", _opt_float(self.speed, "speed"))
        if self.speed is not None and self.speed <= 0:
            raise GearshotError(f"speed must be > 0 rev/s; got {self.speed}")
        set_(self, "load", _opt_float(self.load, "load"))
        set_(self, "fault_size", _opt_float(self.fault_size, "fault_size"))
        if self.fault_size is not None and not 0.0 <= self.fault_size <= 1.0:
            raise GearshotError(f"fault_size must lie in [0, 1]; got {self.fault_size}")
        for name in ("units", "source"):
            if not isinstance(getattr(self, name), str):
                raise GearshotError(f"{name} must be a str; got {describe(getattr(self, name))}")
        if self.tacho_pulses_per_rev is not None:
            set_(self, "tacho_pulses_per_rev",
                 check_int(self.tacho_pulses_per_rev, "tacho_pulses_per_rev", minimum=1))
        shafts = TACHO_SHAFTS if self.machine is None else self.machine.shafts
        if self.tacho_shaft not in shafts:
            raise GearshotError(f"tacho_shaft must be one of {tuple(shafts)}; got "
                                f"{self.tacho_shaft!r}")
        if self.machine is not None:
            from ..machine import Machine

            if not isinstance(self.machine, Machine):
                raise GearshotError(f"machine must be a gearshot.Machine; got "
                                    f"{describe(self.machine)}")
        if not isinstance(self.extras, Mapping) or not all(isinstance(k, str)
                                                           for k in self.extras):
            raise GearshotError(f"extras must be a mapping with str keys; got "
                                f"{describe(self.extras)}")
        try:
            extras = json.loads(json.dumps(dict(self.extras)))
        except (TypeError, ValueError) as exc:
            raise GearshotError(f"extras must be JSON-serializable: {exc}") from None
        set_(self, "extras", extras)

    # ------------------------------------------------------------------ basics
    def __repr__(self) -> str:
        tach = "no tacho" if self.tacho is None else "tacho"
        where = f", origin={self.origin!r}" if self.origin else ""
        chans = "" if self.acceleration.ndim == 1 else f"channels={list(self.channel_names)}, "
        return (f"Recording({chans}n={self.acceleration.shape[-1]}, fs={self.fs:g} Hz, "
                f"{self.duration:.3g} s, {tach}, speed={self.speed}, load={self.load}, "
                f"fault_size={self.fault_size}{where})")

    @property
    def duration(self) -> float:
        """Length in s."""
        return self.acceleration.shape[-1] / self.fs

    @property
    def metadata(self) -> dict[str, Any]:
        """The metadata fields as a JSON-serializable dict (``extras`` nested)."""
        return {k: getattr(self, k) for k in METADATA_KEYS}

    def _label(self) -> str:
        return f"recording {self.origin!r}" if self.origin else "recording"

    # ------------------------------------------------------------------ I/O
    @classmethod
    def read(cls, path: str | Path, *, accel: str | int | None = None,
             tacho: str | int | bool | None = None, fs: float | None = None,
             channels: Any = None, metadata: Mapping[str, Any] | None = None,
             machine: Any = None) -> Recording:
        """Read a recording; the format follows the suffix.

        Supported: ``.h5``/``.hdf5`` (native, see :mod:`gearshot.io._format_hdf5`),
        ``.mat`` (MATLAB v5 and v7.3), ``.wav`` (float32/int16/int32, multi-channel),
        ``.csv`` (header row of channel names; a header-less CSV needs ``channels=`` or a
        machine), delimited text ``.txt``/``.dat``/``.asc``/``.tsv`` -- also zipped
        (``.zip``) or gzipped (``.gz``) -- and ``.tdms`` (needs the optional ``npTDMS``).

        Parameters
        ----------
        path : str or Path
            The file.
        accel, tacho : str or int, optional
            Channel of the acceleration / tacho, by name or index. By default the usual
            names are tried (``acceleration``, ``accel``, ``acc``, ... / ``tacho``, ``tach``,
            ...); for WAV/CSV without such names, channel 0 and 1. ``tacho=False``: no tacho.
        fs : float, optional
            Sampling rate in Hz; needed when the file does not state one, and must agree
            with the file when it does.
        channels : list of str or mapping str -> int, optional
            Names for the file's channels (e.g. ``["acc", "tacho"]`` for a 2-channel WAV or
            ``{"acc": 3, "tacho": 0}``); ``accel``/``tacho`` may then use these names.
        metadata : mapping, optional
            Metadata to set or override (``speed``, ``load``, ``fault_size``, ``units``,
            ``source``, ``tacho_pulses_per_rev``, ``tacho_shaft``; other keys go to
            ``extras``).
        machine : gearshot.Machine or path of a machine TOML, optional
            The machine the file comes from: its ``[file]`` layout names the columns (and
            sets delimiter, header and ``fs``), its sensors become the acceleration channels
            (each divided by its sensitivity: volts -> g), its tacho sets the tacho channel,
            pulses per revolution and shaft. ``accel``/``tacho``/``channels`` are then not
            used.

        Raises
        ------
        GearshotError
            Unknown suffix, missing/corrupt/truncated file, unknown channel, missing or
            conflicting ``fs``, bad metadata -- the message names the file.
        """
        path = Path(path)
        fmt = FORMATS.get(path.suffix.lower())
        if fmt is None:
            raise GearshotError(f"{str(path)!r}: unknown recording format {path.suffix!r}; "
                                f"supported suffixes: {sorted(FORMATS)}")
        if not path.is_file():
            raise GearshotError(f"recording file {str(path)!r} does not exist")
        if machine is not None:
            from ..machine import Machine

            if not isinstance(machine, Machine):
                machine = Machine.from_toml(machine)
        layout = None if machine is None else machine.layout
        if layout is not None and fmt in ("text", "csv"):
            def reader(p):
                return read_text(p, delimiter=layout.delimiter, header=layout.header,
                                 columns=layout.columns, skip_rows=layout.skip_rows)
        else:
            reader = {"hdf5": read_hdf5, "mat": read_mat, "wav": read_wav, "csv": read_csv,
                      "text": read_text, "tdms": read_tdms}[fmt]
        try:
            raw: RawFile = _bounded_read(reader, path)
        except GearshotError:
            raise
        except Exception as exc:  # corrupt / truncated / not this format
            raise GearshotError(f"cannot read {str(path)!r} as {fmt}: "
                                f"{type(exc).__name__}: {exc}") from None
        names: tuple[str, ...] = ()
        if machine is None:
            acc, tac = select_channels(raw, accel=accel, tacho=tacho, channels=channels)
            rate = reconcile_fs(raw, fs)
        else:
            acc, tac, names = _machine_channels(raw, machine)
            given = fs if fs is not None else (
                layout.fs if layout is not None and raw.fs is None else None)
            rate = reconcile_fs(raw, given)
        meta = dict(raw.metadata)
        if machine is not None:
            units = [s.unit for s in machine.sensors]
            meta.update(units=units[0] if len(set(units)) == 1 else ",".join(units),
                        tacho_pulses_per_rev=(None if machine.tacho is None
                                              else machine.tacho.pulses_per_rev),
                        tacho_shaft=machine.reference_shaft)
            meta.setdefault("source", machine.name)
        extras = dict(meta.pop("extras", None) or {})
        for key, value in (metadata or {}).items():
            if key in METADATA_KEYS and key != "extras":
                meta[key] = value
            elif key == "extras":
                extras.update(value)
            else:
                extras[key] = value
        unknown = set(meta) - set(METADATA_KEYS)
        for key in unknown:
            extras[key] = meta.pop(key)
        try:
            return cls(acc, tac, rate, extras=extras, origin=str(path), channel_names=names,
                       machine=machine, **meta)
        except GearshotError as exc:
            raise GearshotError(f"{str(path)!r}: {exc}") from None

    def write(self, path: str | Path, *, format: str | None = None,
              dtype: Any = None) -> Path:
        """Write the recording; the format follows the suffix unless ``format`` is given.

        Parameters
        ----------
        path : str or Path
            Target file. Written through a temporary file in the same folder and
            ``os.replace``, so a failure never leaves a half-written file.
        format : {"hdf5", "mat5", "mat73", "wav", "csv"}, optional
            Default: from the suffix (``.mat`` -> v5).
        dtype : str, optional
            Storage type: HDF5 "float64" (default) or "float32"; WAV "float32" (default),
            "int16" or "int32". Ignored by MAT (float64) and CSV (17 digits).

        Returns
        -------
        Path
            ``path``.
        """
        path = Path(path)
        if self.acceleration.ndim != 1:
            raise GearshotError(f"writing a {self.acceleration.shape[0]}-channel recording is "
                                f"not supported; write one channel at a time "
                                f"(rec.channel(name).write(...))")
        if format is None:
            fmt = FORMATS.get(path.suffix.lower())
            if fmt in ("text", "tdms"):
                fmt = None
            if fmt is None:
                raise GearshotError(f"{str(path)!r}: unknown recording format "
                                    f"{path.suffix!r}; supported: {sorted(FORMATS)}")
            format = "mat5" if fmt == "mat" else fmt
        if format == "hdf5":
            write_hdf5(self, path, dtype=np.float64 if dtype is None else dtype)
        elif format in ("mat5", "mat73"):
            write_mat(self, path, version="5" if format == "mat5" else "7.3")
        elif format == "wav":
            write_wav(self, path, dtype="float32" if dtype is None else dtype)
        elif format == "csv":
            write_csv(self, path)
        else:
            raise GearshotError(f"format must be one of 'hdf5', 'mat5', 'mat73', 'wav', "
                                f"'csv'; got {format!r}")
        return path

    # ------------------------------------------------------------------ channels
    def channel(self, name: str | int) -> Recording:
        """A one-channel recording of sensor ``name`` (or index), same tacho and metadata."""
        import dataclasses

        if self.acceleration.ndim == 1:
            if name in (0, self.channel_names[0]):
                return self
            raise GearshotError(f"{self._label()}: sensor={name!r} is not a channel; channels: "
                                f"{list(self.channel_names)}")
        i = self._channel_index(name)
        units = self.units.split(",")[i] if "," in self.units else self.units
        return dataclasses.replace(self, acceleration=self.acceleration[i], units=units,
                                   channel_names=(self.channel_names[i],))

    def _channel_index(self, name: str | int) -> int:
        if isinstance(name, (int, np.integer)) and not isinstance(name, bool):
            n = len(self.channel_names)
            if not -n <= int(name) < n:
                raise GearshotError(f"{self._label()}: sensor={int(name)} is out of range; the "
                                    f"recording has {n} channel(s)")
            return int(name) % n
        if name in self.channel_names:
            return self.channel_names.index(name)
        raise GearshotError(f"{self._label()}: sensor={name!r} is not a channel; channels: "
                            f"{list(self.channel_names)}")

    # ------------------------------------------------------------------ angle domain
    def _raw_pulses(self, threshold: float | None) -> np.ndarray:
        from ..signal import pulse_times

        if self.tacho is None:
            raise GearshotError(f"{self._label()} has no tacho; SA segments need one")
        if float(np.ptp(self.tacho)) == 0.0:
            raise GearshotError(f"{self._label()}: the tacho is flat (no pulses)")
        if threshold is None and self.machine is not None:
            threshold = self.machine.tacho.threshold
        cache = self.__dict__.setdefault("_pulse_cache", {})
        if threshold not in cache:
            try:
                cache[threshold] = np.asarray(pulse_times(self.tacho, self.fs,
                                                          threshold=threshold))
            except GearshotError as exc:
                raise GearshotError(f"{self._label()}: {exc}") from None
        return cache[threshold]

    def _tacho_over_input(self, pinion_teeth: int | None = None,
                          gear_teeth: int | None = None) -> Fraction | None:
        """Tacho-shaft speed / input-shaft speed (None where unknown)."""
        if self.machine is not None:
            return self.machine.speed_ratio(self.tacho_shaft, self.machine.shafts[0])
        if self.tacho_shaft == "input":
            return Fraction(1)
        if pinion_teeth and gear_teeth:
            return Fraction(pinion_teeth, gear_teeth)
        return None

    def resolved_pulses_per_rev(self, *, threshold: float | None = None,
                                tacho_over_input: Fraction | None = None) -> int:
        """``tacho_pulses_per_rev``, or, when not stated, inferred from ``speed``.

        Raises
        ------
        GearshotError
            Not stated and no ``speed`` to infer it from, or the tacho's pulse rate is not
            close to a whole multiple of the stated speed.
        """
        if self.tacho_pulses_per_rev is not None:
            return self.tacho_pulses_per_rev
        if tacho_over_input is None:
            tacho_over_input = self._tacho_over_input()
        if self.speed is None or tacho_over_input is None:
            raise GearshotError(
                f"{self._label()}: tacho_pulses_per_rev is not stated and there is no speed to "
                f"infer it from; pass tacho_pulses_per_rev=<pulses per revolution of the "
                f"tacho shaft> (e.g. metadata={{'tacho_pulses_per_rev': 10}}) or read the "
                f"file with a machine description")
        pulses = self._raw_pulses(threshold)
        if pulses.size < 3:
            raise GearshotError(f"{self._label()}: the tacho shows {pulses.size} pulse(s)")
        rate = 1.0 / float(np.median(np.diff(pulses)))
        estimate = rate / (self.speed * float(tacho_over_input))
        k = max(1, int(round(estimate)))  # < 1: a wrong fs, reported by the speed check
        if estimate > 0.75 and abs(estimate / k - 1.0) > SPEED_TOLERANCE:
            raise GearshotError(
                f"{self._label()}: tacho_pulses_per_rev is not stated and the pulse rate "
                f"{rate:.4g} Hz is {estimate:.3g} x the stated speed={self.speed:g} rev/s "
                f"(not a whole number); pass tacho_pulses_per_rev or check fs/speed")
        return k

    def pulse_times(self, *, threshold: float | None = None) -> np.ndarray:
        """Validated tacho pulse times in s (raises on a missing/flat tacho or a dropout)."""
        pulses = self._raw_pulses(threshold)
        if pulses.size < 3:  # nothing to infer from: report the empty tacho first
            check_pulse_train(pulses, pulses_per_rev=self.tacho_pulses_per_rev or 1,
                              label=self._label())
        ppr = self.resolved_pulses_per_rev(threshold=threshold)
        return check_pulse_train(pulses, pulses_per_rev=ppr, label=self._label())

    def _target(self, gear_teeth: int | None, pinion_teeth: int | None,
                shaft: str | None) -> tuple[Fraction, Fraction | None]:
        """(tacho revolutions per SA cycle, tacho speed / input speed) of the request."""
        m = self.machine
        if shaft is not None:
            if gear_teeth is not None or pinion_teeth is not None:
                raise GearshotError(f"pass either shaft={shaft!r} or gear_teeth/pinion_teeth, "
                                    f"not both")
            if m is None:
                raise GearshotError(
                    f"{self._label()}: shaft={shaft!r} needs the gear train; read the file "
                    f"with Recording.read(..., machine=<Machine or TOML file>)")
            m.check_shaft(shaft)
            return m.tacho_revs_per_cycle(shaft), self._tacho_over_input()
        if gear_teeth is None or pinion_teeth is None:
            if m is not None and m.monitored is not None:
                return self._target(None, None, m.monitored.shaft)
            raise GearshotError("pass gear_teeth= and pinion_teeth= (or shaft= with a machine)"
                                f"; got gear_teeth={gear_teeth!r}, pinion_teeth={pinion_teeth!r}")
        gear_teeth = check_int(gear_teeth, "gear_teeth", minimum=1)
        pinion_teeth = check_int(pinion_teeth, "pinion_teeth", minimum=1)
        if m is None:
            ratio = Fraction(gear_teeth, pinion_teeth) if self.tacho_shaft == "input" \
                else Fraction(1)
            return ratio, self._tacho_over_input(pinion_teeth, gear_teeth)
        stages = [st for st in m.stages
                  if st.driver_teeth == pinion_teeth and st.driven_teeth == gear_teeth]
        if not stages:
            raise GearshotError(
                f"gear_teeth={gear_teeth}, pinion_teeth={pinion_teeth}: machine {m.name!r} has "
                f"no stage where a {pinion_teeth}-tooth gear drives a {gear_teeth}-tooth gear "
                f"(stages: {[(st.driver_teeth, st.driven_teeth) for st in m.stages]}); pass "
                f"shaft=<one of {list(m.shafts)}>")
        st = stages[0]
        old = Fraction(gear_teeth, pinion_teeth) if self.tacho_shaft != st.driven else 1
        true = m.tacho_revs_per_cycle(st.driven)
        if old != true:
            raise GearshotError(
                f"gear_teeth={gear_teeth}, pinion_teeth={pinion_teeth}: the tacho watches shaft "
                f"{self.tacho_shaft!r}, not the {pinion_teeth}-tooth gear's shaft {st.driver!r}; "
                f"one revolution of {st.driven!r} is {true} tacho revolutions, not {old}; pass "
                f"shaft={st.driven!r}")
        return true, self._tacho_over_input()

    @property
    def speed_source(self) -> str:
        """Where the speed and angle come from: ``"tacho"``, or ``"vibration"`` (no tacho:
        estimated from a mesh harmonic, :meth:`vibration_angle`)."""
        return "tacho" if self.tacho is not None else "vibration"

    @property
    def speed_uncertainty(self) -> float | None:
        """Standard uncertainty (rev/s) of the instantaneous speed of the tracked shaft
        estimated from the vibration (phase noise only); ``None`` with a tacho."""
        if self.tacho is not None:
            return None
        return float(self.vibration_angle().speed_std)

    def vibration_angle(self, *, orders: Any = None, speed_range: Any = None,
                        bandwidth: float | None = None):
        """Angle and speed of the tacho shaft estimated from the vibration (no tacho needed).

        With a machine: the shaft is the machine's ``[speed]`` shaft (the reference shaft,
        ``tacho_shaft``), its mesh orders come from the gear train
        (:meth:`gearshot.Machine.mesh_orders`), the sensor, searched range and tracked
        order from ``[speed]``. Without one, ``orders`` must be given (e.g. the pinion's
        teeth for the input shaft).

        Parameters
        ----------
        orders : int or sequence of int, optional
            Mesh orders of the tracked shaft, its own gear first.
        speed_range : (float, float), optional
            Speeds of the tracked shaft searched, rev/s. Default: the machine's
            ``range_hz``, else the nominal ``speed`` ±10 % (converted to that shaft).
        bandwidth : float, optional
            Band kept around the tracked harmonic, shaft orders (see
            :func:`gearshot.signal.demodulate_angle`). Default: half the rate of the
            slowest shaft of the machine (every shaft's runout modulates the meshes), at
            most 0.25.

        Returns
        -------
        gearshot.signal.tracking.ShaftAngle
            Cached per argument set.

        Raises
        ------
        GearshotError
            No orders or speed range to go by, or no mesh harmonic stands out (the message
            states the SNR found).
        """
        from ..signal.tracking import estimate_shaft_angle

        m = self.machine
        vs = None if m is None else m.vibration_speed
        shaft = self.tacho_shaft
        track = None if vs is None or vs.shaft != shaft else vs.track
        cache = self.__dict__.setdefault("_angle_cache", {})
        if orders is None and m is None and cache and speed_range is None:
            return next(reversed(cache.values()))  # the last estimate (its orders known)
        if orders is None:
            if m is None:
                raise GearshotError(f"{self._label()} has no tacho; estimating the speed from "
                                    f"the vibration needs the mesh orders of the "
                                    f"{shaft!r} shaft (orders=, or gear_teeth/pinion_teeth, "
                                    f"or a machine)")
            orders = m.mesh_orders(shaft)
        # keep the band below half the slowest shaft's rate: every shaft modulates the meshes
        # (its runout), and a mesh harmonic of this shaft may also be one of another stage
        if bandwidth is None:
            slowest = 1.0 if m is None else min(float(m.speed_ratio(s, shaft))
                                                for s in m.shafts)
            bandwidth = min(0.25, 0.5 * slowest)
        if speed_range is None and vs is not None and vs.shaft == shaft:
            speed_range = vs.speed_range
        if speed_range is None:
            ratio = self._tacho_over_input()
            if self.speed is None or ratio is None:
                raise GearshotError(
                    f"{self._label()} has no tacho and no nominal speed: give the speeds of "
                    f"shaft {shaft!r} to search (machine file [speed] range_hz = [low, high], "
                    f"or speed_range=) or the nominal speed (metadata speed=)")
            nominal = self.speed * float(ratio)
            speed_range = (nominal * (1 - SPEED_TOLERANCE), nominal * (1 + SPEED_TOLERANCE))
        acc = self.acceleration
        if acc.ndim == 2:
            name = vs.sensor if vs is not None and vs.sensor is not None else 0
            acc = acc[self._channel_index(name)]
        key = (tuple(np.atleast_1d(orders).tolist()), tuple(float(v) for v in speed_range),
               track, bandwidth)
        if key not in cache:
            try:
                cache[key] = estimate_shaft_angle(acc, self.fs, orders=orders,
                                                  speed_range=speed_range, track=track,
                                                  bandwidth=bandwidth, label=self._label())
            except GearshotError as exc:
                raise GearshotError(f"{exc} [shaft {shaft!r}]") from None
        return cache[key]

    def shaft_speed(self, shaft: str | None = None) -> float:
        """Mean speed (rev/s) over the record: of the tacho shaft, or of ``shaft`` (machine).

        Without a tacho: from the vibration (:meth:`vibration_angle`; the tracked shaft
        stands for the tacho shaft)."""
        if self.tacho is None:
            tacho_rate = self.vibration_angle().mean_speed
        else:
            pulses = self.pulse_times()
            ppr = self.resolved_pulses_per_rev()
            tacho_rate = (pulses.size - 1) / ppr / float(pulses[-1] - pulses[0])
        if shaft is None:
            return tacho_rate
        if self.machine is None:
            raise GearshotError(f"shaft={shaft!r} needs a machine description")
        return tacho_rate / float(self.machine.tacho_revs_per_cycle(shaft))

    def _cycle_times(self, gear_teeth: int | None = None, pinion_teeth: int | None = None,
                     shaft: str | None = None) -> np.ndarray:
        from ..signal.trains import shaft_cycle_times

        revs_per_cycle, tacho_over_input = self._target(gear_teeth, pinion_teeth, shaft)
        if self.tacho is None:  # no tacho: virtual pulses from the vibration
            orders, band = None, None
            if self.machine is None and pinion_teeth is not None and gear_teeth is not None:
                if self.tacho_shaft == "input":
                    orders = (int(pinion_teeth),)
                    band = min(0.25, 0.5 * int(pinion_teeth) / int(gear_teeth))
                else:
                    orders = (int(gear_teeth),)
            est = self.vibration_angle(orders=orders, bandwidth=band)
            return shaft_cycle_times(est.pulse_times, revs_per_cycle=revs_per_cycle,
                                     pulses_per_rev=est.pulses_per_rev)
        pulses = self.pulse_times()
        ppr = self.resolved_pulses_per_rev()
        if tacho_over_input is not None:
            shaft_rate = 1.0 / (float(np.median(np.diff(pulses))) * ppr)
            measured = shaft_rate / float(tacho_over_input)  # input-shaft speed, rev/s
            if self.speed is not None and abs(measured / self.speed - 1.0) > SPEED_TOLERANCE:
                raise GearshotError(
                    f"{self._label()}: the tacho gives an input speed of {measured:.4g} rev/s "
                    f"at fs={self.fs:g} Hz but the metadata say speed={self.speed:g} rev/s; is "
                    f"fs wrong (or tacho_pulses_per_rev/tacho_shaft)?")
        return shaft_cycle_times(pulses, revs_per_cycle=revs_per_cycle, pulses_per_rev=ppr)

    def angle_domain(self, *, gear_teeth: int | None = None, pinion_teeth: int | None = None,
                     shaft: str | None = None, sensor: str | int | None = None,
                     samples_per_cycle: int = 2048, upsample: int = 2, resample: bool = True,
                     antialias: bool = True) -> np.ndarray:
        """The acceleration re-sampled on the angle of a shaft.

        Parameters
        ----------
        gear_teeth, pinion_teeth : int, optional
            Tooth counts (38 and 17 for the paper's pair): the cycle is one revolution of
            the driven gear, with the tacho on the pinion's (``tacho_shaft="input"``) or the
            gear's (``"output"``) shaft. With a ``machine`` the pair must be one of its
            stages and agree with the tacho's shaft.
        shaft : str, optional
            With a ``machine``: the shaft whose revolution is the cycle (ratio from the
            tooth counts of the train, exact). Default with a machine: the monitored shaft.
        sensor : str or int, optional
            One channel by name or index; default all channels.
        samples_per_cycle : int
            Samples per cycle.
        upsample : int
            Over-sampling factor of the angular re-sampler.
        resample : bool
            ``False`` skips angular re-sampling: the signal is cut at the *mean* cycle period
            (constant-speed assumption), as a plain time-domain average would. For
            comparison only.
        antialias : bool
            Low-pass below the angular Nyquist before re-sampling (see
            :func:`gearshot.signal.angular_resample`).

        Returns
        -------
        ndarray, shape (..., n_cycles * samples_per_cycle)
            Whole cycles from the first tacho pulse on; a leading channel axis for a
            multi-channel recording without ``sensor``.
        """
        from ..signal import angular_resample

        samples_per_cycle = check_int(samples_per_cycle, "samples_per_cycle", minimum=2)
        upsample = check_int(upsample, "upsample", minimum=1)
        cycles = self._cycle_times(gear_teeth, pinion_teeth, shaft)
        if cycles.size < 2:
            raise GearshotError(f"{self._label()} holds less than one revolution of the "
                                f"cycle shaft")
        if not resample:
            cycles = uniform_cycle_times(cycles)
        acc = self.acceleration
        if sensor is not None and acc.ndim == 2:
            acc = acc[self._channel_index(sensor)]
        elif sensor is not None:
            self._channel_index(sensor)
        x = angular_resample(acc, self.fs, cycles, samples_per_rev=samples_per_cycle,
                             pulses_per_rev=1, upsample=upsample, antialias=antialias)
        n_cycles = cycles.size - 1
        return np.asarray(x)[..., : n_cycles * samples_per_cycle]

    def to_sa_segments(self, *, gear_teeth: int | None = None,
                       pinion_teeth: int | None = None, shaft: str | None = None,
                       sensor: str | int | None = None,
                       cycles_per_segment: int | None = 50, samples_per_cycle: int = 2048,
                       upsample: int = 2, resample: bool = True,
                       antialias: bool = True) -> np.ndarray:
        """Synchronous averages of consecutive ``cycles_per_segment``-cycle segments.

        Parameters
        ----------
        gear_teeth, pinion_teeth, shaft, sensor
            The cycle and channel(s); see :meth:`angle_domain`.
        cycles_per_segment : int or None
            Cycles averaged per segment (50 in the paper); ``None``: one segment of all
            whole cycles of the record.
        samples_per_cycle : int
            SA length (2048 in the paper).
        upsample, resample, antialias
            See :meth:`angle_domain`.

        Returns
        -------
        ndarray, shape (..., n_segments, samples_per_cycle)
            One SA per segment, in ``units``; segments do not overlap, the incomplete tail
            is dropped; a leading channel axis for a multi-channel recording without
            ``sensor``.

        Raises
        ------
        GearshotError
            No tacho, flat tacho, a tacho dropout, a tacho speed that contradicts ``speed``
            (wrong ``fs``), no stated or inferable ``tacho_pulses_per_rev``, or fewer than
            ``cycles_per_segment`` cycles.
        """
        from ..signal import synchronous_average

        if cycles_per_segment is not None:
            cycles_per_segment = check_int(cycles_per_segment, "cycles_per_segment", minimum=1)
        samples_per_cycle = check_int(samples_per_cycle, "samples_per_cycle", minimum=2)
        x = self.angle_domain(gear_teeth=gear_teeth, pinion_teeth=pinion_teeth, shaft=shaft,
                              sensor=sensor, samples_per_cycle=samples_per_cycle,
                              upsample=upsample, resample=resample, antialias=antialias)
        n_cycles = x.shape[-1] // samples_per_cycle
        per = n_cycles if cycles_per_segment is None else cycles_per_segment
        n_seg = n_cycles // per if per else 0
        if n_seg < 1:
            what = "gear revolution(s)" if shaft is None else f"revolution(s) of {shaft!r}"
            raise GearshotError(
                f"{self._label()} ({self.duration:.3g} s) holds {n_cycles} whole {what}; one "
                f"segment needs cycles_per_segment={cycles_per_segment}")
        seg_len = per * samples_per_cycle
        blocks = x[..., : n_seg * seg_len].reshape(*x.shape[:-1], n_seg, seg_len)
        return np.asarray(synchronous_average(blocks, samples_per_cycle, n_cycles=per))


#: Seconds a file read may take: this plus one per MB of file (a damaged file fails within
#: it; a healthy one reads at far more than 1 MB/s).
READ_BUDGET_S = 20.0


def _bounded_read(reader: Any, path: Path) -> RawFile:
    """Run ``reader(path)`` in a worker thread; the caller waits in short, interruptible
    steps (Ctrl-C is honoured at once) and gives up with a :class:`GearshotError` after
    :data:`READ_BUDGET_S` + 1 s per MB (a library caught in a damaged file)."""
    import threading
    import time

    budget = READ_BUDGET_S + path.stat().st_size / 1e6
    box: dict[str, Any] = {}

    def work() -> None:
        try:
            box["raw"] = reader(path)
        except BaseException as exc:  # handed to the caller
            box["exc"] = exc

    worker = threading.Thread(target=work, name=f"gearshot-read-{path.name}", daemon=True)
    worker.start()
    deadline = time.monotonic() + budget
    while worker.is_alive() and time.monotonic() < deadline:
        worker.join(0.1)
    if worker.is_alive():
        raise GearshotError(f"reading {str(path)!r} did not finish within {budget:.0f} s: "
                            f"a damaged file (or a stalled disk)")
    if "exc" in box:
        raise box["exc"]
    return box["raw"]


def _machine_channels(raw: RawFile, machine: Any
                      ) -> tuple[np.ndarray, np.ndarray | None, tuple[str, ...]]:
    """Sensor channels (scaled to physical units) and the tacho of a file, by the machine."""
    from ._fileio import _resolve

    rows = []
    for s in machine.sensors:
        name = _resolve(raw, f"sensor {s.name!r} channel", s.channel, {})
        row = np.asarray(raw.channels[name], dtype=np.float64).ravel() / s.sensitivity
        rows.append(row - row.mean() if s.ac_coupled else row)
    tac = None
    if machine.tacho is not None:  # no [tacho]: the speed comes from the vibration
        tname = _resolve(raw, "tacho.channel", machine.tacho.channel, {})
        tac = np.asarray(raw.channels[tname], dtype=np.float64).ravel()
    acc = rows[0] if len(rows) == 1 else np.stack(rows)
    return acc, tac, tuple(s.name for s in machine.sensors)


def read_tdms(path: Path) -> RawFile:
    """Read a National Instruments TDMS file (optional dependency ``npTDMS``).

    Every channel of every group becomes a channel named ``"group/channel"`` (and, when
    unique, by its bare channel name); ``fs`` from the channels' ``wf_increment``.
    """
    try:
        from nptdms import TdmsFile
    except ImportError:
        raise GearshotError(f"reading {str(path)!r} needs the optional package npTDMS: "
                            f"pip install 'gearshot[tdms]'") from None
    tdms = TdmsFile.read(path)
    chans: dict[str, np.ndarray] = {}
    rates = set()
    bare: dict[str, int] = {}
    for group in tdms.groups():
        for ch in group.channels():
            bare[ch.name] = bare.get(ch.name, 0) + 1
    for group in tdms.groups():
        for ch in group.channels():
            data = np.asarray(ch[:], dtype=np.float64)
            name = ch.name if bare[ch.name] == 1 else f"{group.name}/{ch.name}"
            chans[name] = data
            inc = ch.properties.get("wf_increment")
            if inc:
                rates.add(round(1.0 / float(inc), 6))
    if not chans:
        raise GearshotError(f"{str(path)!r} holds no TDMS channel")
    if len(rates) > 1:
        raise GearshotError(f"{str(path)!r}: channels have different sampling rates "
                            f"{sorted(rates)} Hz")
    return RawFile(path, chans, rates.pop() if rates else None, {},
                   positional_defaults=False)
