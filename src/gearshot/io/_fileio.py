"""File plumbing shared by the recording formats: atomic writes, sidecars, channel choice.

Every reader returns a :class:`RawFile` -- an ordered set of named 1-D channels, the sampling
rate the file states (if any) and the metadata it carries -- and :func:`select_channels`
turns that into acceleration/tacho arrays with errors that name the file and the parameter.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .._atomic import atomic_path, write_json_atomic
from .._errors import GearshotError
from .._validation import describe

__all__ = [
    "RawFile",
    "atomic_path",
    "sidecar_path",
    "read_sidecar",
    "write_json_atomic",
    "select_channels",
    "reconcile_fs",
    "machine_channels",
    "time_column_fs",
    "METADATA_KEYS",
    "ACCEL_NAMES",
    "TACHO_NAMES",
    "FS_NAMES",
]

#: Metadata fields of :class:`~gearshot.rig.Recording` stored in every format.
METADATA_KEYS = ("speed", "load", "fault_size", "units", "source",
                 "tacho_pulses_per_rev", "tacho_shaft", "extras")

#: Channel/variable names tried (case-insensitively) when the caller names no channel.
ACCEL_NAMES = ("acceleration", "accel", "acc", "vibration", "vib", "accelerometer")
TACHO_NAMES = ("tacho", "tach", "tachometer", "tacho_signal", "pulse", "pulses",
               "keyphasor", "trigger")
FS_NAMES = ("fs", "sample_rate", "sampling_rate", "samplerate", "sr", "srate")
TIME_NAMES = ("time", "t", "time_s")


@dataclass
class RawFile:
    """What a reader found in a file, before channel selection."""

    path: Path
    channels: dict[str, np.ndarray]          # ordered: name -> 1-D array
    fs: float | None = None
    metadata: dict[str, Any] = field(default_factory=dict)
    positional_defaults: bool = False          # accel = channel 0, tacho = 1 if unnamed
    time_channel: str | None = None            # a time column (never a default channel)


def sidecar_path(path: Path) -> Path:
    """The JSON sidecar of a WAV/CSV file: ``<name>.<ext>.json`` beside it."""
    path = Path(path)
    return path.with_name(path.name + ".json")


def read_sidecar(path: Path) -> dict[str, Any]:
    """Read the sidecar of ``path`` if there is one (``rec.wav.json``, else ``rec.json``)."""
    for cand in (sidecar_path(path), Path(path).with_suffix(".json")):
        if cand.is_file():
            try:
                data = json.loads(cand.read_text(encoding="utf-8"))
            except (OSError, ValueError) as exc:
                raise GearshotError(f"sidecar {str(cand)!r} of {str(path)!r} is not valid "
                                    f"JSON: {exc}") from None
            if not isinstance(data, dict):
                raise GearshotError(f"sidecar {str(cand)!r} must hold a JSON object; got "
                                    f"{type(data).__name__}")
            return data
    return {}


def _lookup(channels: Mapping[str, np.ndarray], names: Sequence[str]) -> str | None:
    lower = {k.lower(): k for k in channels}
    for name in names:
        if name in lower:
            return lower[name]
    return None


def _resolve(raw: RawFile, which: str, spec: Any,
             aliases: Mapping[str, Any]) -> str:
    """Turn a caller's channel spec (name or index) into a channel name of ``raw``."""
    names = list(raw.channels)
    if isinstance(spec, str) and spec in aliases:
        spec = aliases[spec]
    if isinstance(spec, (int, np.integer)) and not isinstance(spec, bool):
        idx = int(spec)
        if not -len(names) <= idx < len(names):
            raise GearshotError(
                f"{str(raw.path)!r}: {which}={idx} is out of range; the file has "
                f"{len(names)} channel(s): {names}")
        return names[idx]
    if isinstance(spec, str):
        if spec in raw.channels:
            return spec
        hit = _lookup(raw.channels, (spec.lower(),))
        if hit is not None:
            return hit
        raise GearshotError(f"{str(raw.path)!r}: {which}={spec!r} is not a channel of the "
                            f"file; available: {names}")
    raise GearshotError(f"{which} must be a channel name (str) or index (int); got "
                        f"{describe(spec)}")


def _channel_aliases(raw: RawFile, channels: Any) -> dict[str, Any]:
    """Names given by the caller's ``channels=``: a list of names or a name -> index mapping."""
    if channels is None:
        return {}
    if isinstance(channels, Mapping):
        out = {}
        for k, v in channels.items():
            if not isinstance(k, str):
                raise GearshotError(f"channels keys must be names (str); got {describe(k)}")
            out[k] = v
        return out
    if isinstance(channels, Sequence) and not isinstance(channels, str):
        names = list(channels)
        if len(names) != len(raw.channels):
            raise GearshotError(
                f"{str(raw.path)!r}: channels={names!r} names {len(names)} channel(s) but the "
                f"file has {len(raw.channels)}")
        return {str(n): i for i, n in enumerate(names)}
    raise GearshotError(f"channels must be a list of names or a mapping name -> index; got "
                        f"{describe(channels)}")


def select_channels(raw: RawFile, *, accel: Any, tacho: Any, channels: Any
                    ) -> tuple[np.ndarray, np.ndarray | None]:
    """Pick the acceleration and tacho channels from ``raw``.

    ``accel``/``tacho`` are a channel name, an index, or ``None`` (try the usual names,
    e.g. ``"acceleration"``/``"tacho"``; for WAV and CSV without recognizable names, channel
    0 and 1). ``tacho=False`` means "no tacho". A channel named explicitly but absent raises.
    """
    aliases = _channel_aliases(raw, channels)
    names = [n for n in raw.channels if n != raw.time_channel]
    if not names:
        raise GearshotError(f"{str(raw.path)!r} holds no signal channel")

    if accel is None:
        accel_name = _lookup(raw.channels, ACCEL_NAMES)
        alias = _lookup(aliases, ACCEL_NAMES)  # names given by the caller's channels=
        if accel_name is None and alias is not None:
            accel_name = _resolve(raw, "accel", alias, aliases)
        if accel_name is None:
            if raw.positional_defaults or len(names) == 1:
                accel_name = names[0]
            else:
                raise GearshotError(
                    f"{str(raw.path)!r}: cannot tell which channel is the acceleration; name it "
                    f"'acceleration' in the file (API: Recording.read(path, accel=<name or "
                    f"index>)); available: {names}")
    else:
        accel_name = _resolve(raw, "accel", accel, aliases)

    tacho_name: str | None
    if tacho is False:
        tacho_name = None
    elif tacho is None:
        tacho_name = _lookup(raw.channels, TACHO_NAMES)
        alias = _lookup(aliases, TACHO_NAMES)
        if tacho_name is None and alias is not None:
            tacho_name = _resolve(raw, "tacho", alias, aliases)
        if tacho_name is None and raw.positional_defaults:
            rest = [n for n in names if n != accel_name]
            tacho_name = rest[0] if rest else None
    else:
        tacho_name = _resolve(raw, "tacho", tacho, aliases)
    if tacho_name is not None and tacho_name == accel_name:
        raise GearshotError(f"{str(raw.path)!r}: accel and tacho both select channel "
                            f"{accel_name!r}")

    acc = np.asarray(raw.channels[accel_name], dtype=np.float64).ravel()
    tac = None
    if tacho_name is not None:
        tac = np.asarray(raw.channels[tacho_name], dtype=np.float64).ravel()
        if tac.size == 0:
            raise GearshotError(f"{str(raw.path)!r}: tacho channel {tacho_name!r} is empty")
    if acc.size == 0:
        raise GearshotError(f"{str(raw.path)!r}: acceleration channel {accel_name!r} is empty")
    return acc, tac


def reconcile_fs(raw: RawFile, fs: Any) -> float:
    """The sampling rate: the caller's ``fs`` must agree with the file's if both exist."""
    file_fs = raw.fs
    if file_fs is not None:
        if not (isinstance(file_fs, (int, float, np.number)) and math.isfinite(file_fs)
                and file_fs > 0):
            raise GearshotError(f"{str(raw.path)!r} states an invalid sampling rate fs="
                                f"{describe(file_fs)}")
        file_fs = float(file_fs)
    if fs is None:
        if file_fs is None:
            side = sidecar_path(raw.path).name
            raise GearshotError(f"{str(raw.path)!r} does not state its sampling rate: add a "
                                f"'time' column, or a sidecar {side!r} holding "
                                f"{{\"fs\": <Hz>}} (API: Recording.read(path, fs=<Hz>))")
        return file_fs
    if isinstance(fs, bool) or not isinstance(fs, (int, float, np.number)) or not (
            math.isfinite(fs) and fs > 0):
        raise GearshotError(f"fs must be a finite positive number (Hz); got {describe(fs)}")
    rate = float(fs)
    if file_fs is not None and abs(rate - file_fs) > 1e-9 * file_fs:
        raise GearshotError(f"fs={rate!r} conflicts with the sampling rate {file_fs!r} Hz "
                            f"stated in {str(raw.path)!r}")
    return rate


def time_column_fs(path: Path, t: np.ndarray) -> float:
    """Sampling rate from a uniformly spaced time column (raises if not uniform)."""
    t = np.asarray(t, dtype=np.float64)
    if t.size < 2:
        raise GearshotError(f"{str(path)!r}: the time column has fewer than 2 values")
    dt = np.diff(t)
    step = float(np.median(dt))
    if not (step > 0 and np.all(np.abs(dt - step) <= 1e-6 * step + 1e-12)):
        raise GearshotError(f"{str(path)!r}: the time column is not uniformly spaced "
                            f"(steps {dt.min()!r} .. {dt.max()!r} s)")
    return float(f"{1.0 / step:.9g}")  # time columns carry rounding noise


def machine_channels(raw: RawFile, machine: Any
                     ) -> tuple[np.ndarray, np.ndarray | None, tuple[str, ...]]:
    """Sensor channels (scaled to physical units) and the tacho of a file, by the machine."""
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
