"""`Recording`: accelerometer channel(s) plus a tacho, with metadata; file I/O.

The angle-domain methods come in layers, each a module: the tacho's pulses
(:mod:`._tacho`), the speed from the vibration without one (:mod:`._vibration`), angular
resampling and SA segments (:mod:`._angle_domain`).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._errors import GearshotError
from .._validation import MAX_FS, as_signal_array, check_int, check_positive, describe
from ..signal.angle import TACHO_SHAFTS
from ._angle_domain import AngleDomainRecording
from ._fileio import METADATA_KEYS, RawFile, machine_channels, reconcile_fs, select_channels
from ._format_csv import read_csv, write_csv
from ._format_hdf5 import read_hdf5, write_hdf5
from ._format_matlab import read_mat, write_mat
from ._format_tdms import read_tdms
from ._format_text import TEXT_SUFFIXES, read_text
from ._format_wav import read_wav, write_wav
from ._read_isolated import can_isolate, read_isolated
from ._tacho import SPEED_TOLERANCE as SPEED_TOLERANCE  # its old home
from .input_health import check_numeric, require_ok

if TYPE_CHECKING:
    from ..machine import FileLayout, Machine

__all__ = ["Recording", "FORMATS"]

#: file suffix -> format name understood by :meth:`Recording.read` / :meth:`Recording.write`.
FORMATS = {".h5": "hdf5", ".hdf5": "hdf5", ".hdf": "hdf5", ".mat": "mat",
           ".wav": "wav", ".csv": "csv", ".tdms": "tdms",
           **{suffix: "text" for suffix in TEXT_SUFFIXES}}


def _opt_float(value: Any, name: str) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float, np.number)):
        raise GearshotError(f"{name} must be a real number or None; got {describe(value)}")
    number = float(value)
    if not math.isfinite(number):
        raise GearshotError(f"{name} must be finite; got {number}")
    return number


@dataclass(frozen=True, eq=False)
class Recording(AngleDomainRecording):
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
    machine: Machine | None = field(default=None, compare=False, repr=False)

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
    def metadata(self) -> dict[str, Any]:
        """The metadata fields as a JSON-serializable dict (``extras`` nested)."""
        return {k: getattr(self, k) for k in METADATA_KEYS}

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
        try:
            raw = _bounded_read(_reader(fmt, layout), path, isolate=fmt in ("hdf5", "mat"))
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
            acc, tac, names = machine_channels(raw, machine)
            given = fs if fs is not None else (
                layout.fs if layout is not None and raw.fs is None else None)
            rate = reconcile_fs(raw, given)
        require_ok(check_numeric(acc), path)   # NaN or inf: refused, naming the check
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

#: it; a healthy one reads at far more than 1 MB/s).
READ_BUDGET_S = 20.0


def _reader(fmt: str, layout: FileLayout | None) -> Callable[[Path], RawFile]:
    """The reader of format ``fmt``; text and CSV files laid out by a machine's ``[file]``
    table when ``layout`` is given."""
    if layout is not None and fmt in ("text", "csv"):
        def read_laid_out(p: Path) -> RawFile:
            return read_text(p, delimiter=layout.delimiter, header=layout.header,
                             columns=layout.columns, skip_rows=layout.skip_rows)
        return read_laid_out
    readers: dict[str, Callable[[Path], RawFile]] = {
        "hdf5": read_hdf5, "mat": read_mat, "wav": read_wav, "csv": read_csv,
        "text": read_text, "tdms": read_tdms}
    return readers[fmt]


def _bounded_read(reader: Callable[[Path], RawFile], path: Path, *,
                  isolate: bool = False) -> RawFile:
    """Run ``reader(path)`` in a worker thread (``isolate``: in a child process when
    :func:`._read_isolated.can_isolate`, for libhdf5, which holds Python's global lock
    through a call); the caller waits in short, interruptible steps (Ctrl-C is honoured at
    once) and gives up with a :class:`GearshotError` after :data:`READ_BUDGET_S` + 1 s per
    MB (a library caught in a damaged file)."""
    import threading
    import time

    budget = READ_BUDGET_S + path.stat().st_size / 1e6
    if isolate and can_isolate():
        return read_isolated(reader, path, budget)
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
    raw: RawFile = box["raw"]
    return raw
