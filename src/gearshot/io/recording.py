"""`Recording`: one accelerometer channel plus a tacho, with metadata; file I/O; SA segments."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .._errors import GearshotError
from .._validation import as_signal_array, check_int, check_positive, describe
from ..signal.angle import TACHO_SHAFTS, check_pulse_train, gear_cycle_times, uniform_cycle_times
from ._fileio import METADATA_KEYS, RawFile, reconcile_fs, select_channels
from ._format_csv import read_csv, write_csv
from ._format_hdf5 import read_hdf5, write_hdf5
from ._format_matlab import read_mat, write_mat
from ._format_wav import read_wav, write_wav

__all__ = ["Recording", "FORMATS"]

#: file suffix -> format name understood by :meth:`Recording.read` / :meth:`Recording.write`.
FORMATS = {".h5": "hdf5", ".hdf5": "hdf5", ".hdf": "hdf5", ".mat": "mat",
           ".wav": "wav", ".csv": "csv"}

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
    """An accelerometer recording with a shaft tacho.

    Parameters
    ----------
    acceleration : ndarray, shape (n,)
        Acceleration samples, in ``units``.
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
    tacho_pulses_per_rev : int
        Tacho pulses per revolution of the shaft it watches (default 1).
    tacho_shaft : {"input", "output"}
        The shaft the tacho watches: the input (pinion) shaft (default) or the output
        (driven gear) shaft.
    extras : mapping
        Free-form JSON-serializable metadata (stored in every format).
    origin : str or None
        The file the recording was read from (not stored; used in error messages).
    """

    acceleration: np.ndarray
    tacho: np.ndarray | None
    fs: float
    speed: float | None = None
    load: float | None = None
    fault_size: float | None = None
    units: str = "g"
    source: str = ""
    tacho_pulses_per_rev: int = 1
    tacho_shaft: str = "input"
    extras: Mapping[str, Any] = field(default_factory=dict)
    origin: str | None = field(default=None, compare=False)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        acc = as_signal_array(self.acceleration, "acceleration", max_ndim=1, min_length=2,
                              max_abs=None)
        set_(self, "acceleration", acc)
        if self.tacho is not None:
            tac = as_signal_array(self.tacho, "tacho", max_ndim=1, max_abs=None)
            if tac.shape != acc.shape:
                raise GearshotError(f"tacho must have as many samples as acceleration "
                                    f"({acc.size}); got {tac.size}")
            set_(self, "tacho", tac)
        set_(self, "fs", check_positive(self.fs, "fs"))
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
        set_(self, "tacho_pulses_per_rev",
             check_int(self.tacho_pulses_per_rev, "tacho_pulses_per_rev", minimum=1))
        if self.tacho_shaft not in TACHO_SHAFTS:
            raise GearshotError(f"tacho_shaft must be one of {TACHO_SHAFTS}; got "
                                f"{self.tacho_shaft!r}")
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
        return (f"Recording(n={self.acceleration.size}, fs={self.fs:g} Hz, "
                f"{self.duration:.3g} s, {tach}, speed={self.speed}, load={self.load}, "
                f"fault_size={self.fault_size}{where})")

    @property
    def duration(self) -> float:
        """Length in s."""
        return self.acceleration.size / self.fs

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
             channels: Any = None, metadata: Mapping[str, Any] | None = None) -> Recording:
        """Read a recording; the format follows the suffix.

        Supported: ``.h5``/``.hdf5`` (native, see :mod:`gearshot.rig._format_hdf5`),
        ``.mat`` (MATLAB v5 and v7.3), ``.wav`` (float32/int16/int32, multi-channel) and
        ``.csv`` (header row of channel names).

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
        reader = {"hdf5": read_hdf5, "mat": read_mat, "wav": read_wav, "csv": read_csv}[fmt]
        try:
            raw: RawFile = reader(path)
        except GearshotError:
            raise
        except Exception as exc:  # corrupt / truncated / not this format
            raise GearshotError(f"cannot read {str(path)!r} as {fmt}: "
                                f"{type(exc).__name__}: {exc}") from None
        acc, tac = select_channels(raw, accel=accel, tacho=tacho, channels=channels)
        rate = reconcile_fs(raw, fs)
        meta = dict(raw.metadata)
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
            return cls(acc, tac, rate, extras=extras, origin=str(path), **meta)
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
        if format is None:
            fmt = FORMATS.get(path.suffix.lower())
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

    # ------------------------------------------------------------------ angle domain
    def pulse_times(self, *, threshold: float | None = None) -> np.ndarray:
        """Validated tacho pulse times in s (raises on a missing/flat tacho or a dropout)."""
        from ..signal import pulse_times

        if self.tacho is None:
            raise GearshotError(f"{self._label()} has no tacho; SA segments need one")
        if float(np.ptp(self.tacho)) == 0.0:
            raise GearshotError(f"{self._label()}: the tacho is flat (no pulses)")
        try:
            pulses = np.asarray(pulse_times(self.tacho, self.fs, threshold=threshold))
        except GearshotError as exc:
            raise GearshotError(f"{self._label()}: {exc}") from None
        return check_pulse_train(pulses, pulses_per_rev=self.tacho_pulses_per_rev,
                                 label=self._label())

    def _cycle_times(self, gear_teeth: int, pinion_teeth: int) -> np.ndarray:
        pulses = self.pulse_times()
        ratio = gear_teeth / pinion_teeth if self.tacho_shaft == "output" else 1.0
        shaft_rate = 1.0 / (float(np.median(np.diff(pulses))) * self.tacho_pulses_per_rev)
        measured = ratio * shaft_rate  # input-shaft speed, rev/s
        if self.speed is not None and abs(measured / self.speed - 1.0) > SPEED_TOLERANCE:
            raise GearshotError(
                f"{self._label()}: the tacho gives an input speed of {measured:.4g} rev/s at "
                f"fs={self.fs:g} Hz but the metadata say speed={self.speed:g} rev/s; is fs "
                f"wrong (or tacho_pulses_per_rev/tacho_shaft)?")
        return gear_cycle_times(pulses, gear_teeth=gear_teeth, pinion_teeth=pinion_teeth,
                                pulses_per_rev=self.tacho_pulses_per_rev,
                                tacho_shaft=self.tacho_shaft)

    def angle_domain(self, *, gear_teeth: int, pinion_teeth: int,
                     samples_per_cycle: int = 2048, upsample: int = 2,
                     resample: bool = True) -> np.ndarray:
        """The acceleration re-sampled on the driven gear's angle.

        Parameters
        ----------
        gear_teeth, pinion_teeth : int
            Tooth counts (38 and 17 for the paper's pair).
        samples_per_cycle : int
            Samples per gear revolution.
        upsample : int
            Up-sampling factor of the angular re-sampler (cubic interpolation).
        resample : bool
            ``False`` skips angular re-sampling: the signal is cut at the *mean* gear period
            (constant-speed assumption), as a plain time-domain average would. For
            comparison only.

        Returns
        -------
        ndarray, shape (n_cycles * samples_per_cycle,)
            Whole gear revolutions from the first tacho pulse on (see
            :mod:`gearshot.rig.angle` for the construction).
        """
        from ..signal import angular_resample

        gear_teeth = check_int(gear_teeth, "gear_teeth", minimum=1)
        pinion_teeth = check_int(pinion_teeth, "pinion_teeth", minimum=1)
        samples_per_cycle = check_int(samples_per_cycle, "samples_per_cycle", minimum=2)
        upsample = check_int(upsample, "upsample", minimum=1)
        cycles = self._cycle_times(gear_teeth, pinion_teeth)
        if cycles.size < 2:
            raise GearshotError(f"{self._label()} holds less than one gear revolution")
        if not resample:
            cycles = uniform_cycle_times(cycles)
        x = angular_resample(self.acceleration, self.fs, cycles,
                             samples_per_rev=samples_per_cycle, pulses_per_rev=1,
                             upsample=upsample)
        n_cycles = cycles.size - 1
        return np.asarray(x)[: n_cycles * samples_per_cycle]

    def to_sa_segments(self, *, gear_teeth: int, pinion_teeth: int,
                       cycles_per_segment: int = 50, samples_per_cycle: int = 2048,
                       upsample: int = 2, resample: bool = True) -> np.ndarray:
        """Synchronous averages of consecutive ``cycles_per_segment``-cycle segments.

        Parameters
        ----------
        gear_teeth, pinion_teeth : int
            Tooth counts (38 and 17 for the paper's pair); the SA cycle is one revolution
            of the driven gear.
        cycles_per_segment : int
            Gear revolutions averaged per segment (50 in the paper).
        samples_per_cycle : int
            SA length (2048 in the paper).
        upsample, resample
            See :meth:`angle_domain`.

        Returns
        -------
        ndarray, shape (n_segments, samples_per_cycle)
            One SA per segment, in ``units``; segments do not overlap, the incomplete tail
            is dropped.

        Raises
        ------
        GearshotError
            No tacho, flat tacho, a tacho dropout, a tacho speed that contradicts ``speed``
            (wrong ``fs``), or fewer than ``cycles_per_segment`` gear revolutions.
        """
        from ..signal import synchronous_average

        cycles_per_segment = check_int(cycles_per_segment, "cycles_per_segment", minimum=1)
        samples_per_cycle = check_int(samples_per_cycle, "samples_per_cycle", minimum=2)
        x = self.angle_domain(gear_teeth=gear_teeth, pinion_teeth=pinion_teeth,
                              samples_per_cycle=samples_per_cycle, upsample=upsample,
                              resample=resample)
        n_cycles = x.size // samples_per_cycle
        n_seg = n_cycles // cycles_per_segment
        if n_seg < 1:
            raise GearshotError(
                f"{self._label()} ({self.duration:.3g} s) holds {n_cycles} whole gear "
                f"revolution(s); one segment needs cycles_per_segment={cycles_per_segment}")
        seg_len = cycles_per_segment * samples_per_cycle
        blocks = x[: n_seg * seg_len].reshape(n_seg, seg_len)
        return np.asarray(synchronous_average(blocks, samples_per_cycle,
                                              n_cycles=cycles_per_segment))
