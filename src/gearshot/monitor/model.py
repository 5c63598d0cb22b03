"""The model file of a monitored machine: everything estimating a new recording needs.

A :class:`MonitorModel` carries the fitted estimator, the machine file's text (or the
gear pair the recordings are segmented for, without one), the database's identity (path
and the SHA-256 of its ``manifest.json``), the fit check, how the fit was calibrated
(``"one_fault_shot"`` with its faulty recording and size, or ``"zero_shot"``) and the
healthy baseline with the alarm threshold it sets. :meth:`MonitorModel.save` writes it in
the skops format (no pickle) and :func:`load_model` reads it back constructing only the
types a fitted estimator is made of (:func:`gearshot.estimator.persistence.read_skops`).
The model's identity in a history is :attr:`MonitorModel.digest`, the SHA-256 of the
file's bytes (first 16 hex digits).
"""

from __future__ import annotations

import hashlib
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import sklearn

from .. import __version__
from .._atomic import atomic_path
from .._errors import GearshotError

__all__ = ["MonitorModel", "load_model", "file_digest", "database_identity", "CALIBRATIONS"]

_FORMAT = "gearshot-monitor-model/1"
CALIBRATIONS = ("one_fault_shot", "zero_shot")


def file_digest(path: str | os.PathLike[str]) -> str:
    """First 16 hex digits of the SHA-256 of a file's bytes."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()[:16]


def database_identity(database: str | os.PathLike[str]) -> dict[str, str]:
    """``path`` (absolute) and ``manifest_sha256`` of a database store."""
    store = Path(database)
    manifest = store / "manifest.json"
    if not manifest.is_file():
        raise GearshotError(f"--database {str(store)!r} holds no manifest.json")
    digest = hashlib.sha256(manifest.read_bytes()).hexdigest()
    return {"path": str(store.resolve()), "manifest_sha256": digest}


@dataclass
class MonitorModel:
    """A fitted estimator and what monitoring with it needs.

    Attributes
    ----------
    estimator : OneFaultShotEstimator
        Fitted.
    calibration : {"one_fault_shot", "zero_shot"}
    condition : dict
        ``speed`` and ``load`` of the database slice (rps, or tacho-shaft Hz with a
        machine file: ``speed_unit`` says which) and how recordings are segmented
        (``gear_teeth``, ``pinion_teeth``, or ``cycles_per_segment``, ``sensor``).
    database : dict
        :func:`database_identity`.
    baseline : list of float
        Estimated sizes of healthy recordings (or segments) the fit did not see.
    threshold : float
        Alarm threshold from the baseline (:func:`gearshot.monitor.alarm.alarm_threshold`).
    false_alarm_rate : float
    sustain : int
    machine_toml : str or None
        The machine file's text (None: recordings segmented without one).
    faulty : dict or None
        ``recording`` and ``size`` of the faulty example (None: zero-shot).
    fit_check : object
        The estimator's ``fit_check_`` when it has one, else None (as plain data).
    coverage : float
        Of the estimates' intervals.
    seed : int
    """

    estimator: Any
    calibration: str
    condition: dict
    database: dict
    baseline: list
    threshold: float
    false_alarm_rate: float
    sustain: int
    machine_toml: str | None = None
    faulty: dict | None = None
    fit_check: Any = None
    coverage: float = 0.9
    seed: int = 0
    extras: dict = field(default_factory=dict)
    path: Path | None = None

    def __post_init__(self) -> None:
        if self.calibration not in CALIBRATIONS:
            raise GearshotError(f"calibration must be one of {CALIBRATIONS}; got "
                                f"{self.calibration!r}")

    @property
    def digest(self) -> str:
        """The model's identity: :func:`file_digest` of its file (saved models only)."""
        if self.path is None:
            raise GearshotError("the model has no file yet: save it first")
        return file_digest(self.path)

    @property
    def machine(self):
        """The :class:`gearshot.Machine` of ``machine_toml`` (None without one)."""
        if self.machine_toml is None:
            return None
        import tomllib

        from ..machine import Machine

        return Machine.from_dict(tomllib.loads(self.machine_toml))

    def describe(self) -> str:
        """One line: calibration, condition and threshold (printed by every command)."""
        how = ("zero-shot (no faulty example: calibration='zero_shot')"
               if self.calibration == "zero_shot" else
               f"one faulty example ({Path(self.faulty['recording']).name}, size "
               f"{self.faulty['size']:g})" if self.faulty else "one faulty example")
        unit = self.condition.get("speed_unit", "rps")
        base = np.asarray(self.baseline, dtype=float)
        base = base[np.isfinite(base)]
        source = (f"; set from {base.size} healthy estimates, mean {base.mean():.3f}, "
                  f"largest {base.max():.3f}" if base.size else "")
        return (f"model fitted {how} at {self.condition['speed']:g} {unit}, "
                f"{self.condition['load']:g} N m; alarm threshold {self.threshold:.3f} "
                f"(false-alarm rate {self.false_alarm_rate:g} per recording, "
                f"{self.sustain} consecutive{source})")

    def _payload(self) -> dict:
        return {"format": _FORMAT, "gearshot_version": __version__,
                "sklearn_version": sklearn.__version__, "estimator": self.estimator,
                "calibration": self.calibration, "condition": dict(self.condition),
                "database": dict(self.database),
                "baseline": [float(v) for v in self.baseline],
                "threshold": float(self.threshold),
                "false_alarm_rate": float(self.false_alarm_rate),
                "sustain": int(self.sustain), "machine_toml": self.machine_toml,
                "faulty": None if self.faulty is None else dict(self.faulty),
                "fit_check": _plain(self.fit_check), "coverage": float(self.coverage),
                "seed": int(self.seed), "extras": dict(self.extras)}

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the model (skops) atomically; returns the path."""
        import skops.io as sio

        if not hasattr(self.estimator, "model_"):
            raise GearshotError("the model's estimator is not fitted")
        path = Path(path)
        with atomic_path(path, make_parents=True) as tmp:
            sio.dump(self._payload(), tmp)
        self.path = path
        return path


def _plain(value: Any) -> Any:
    """A fit check as plain data a skops file holds without new types."""
    if value is None or isinstance(value, (str, int, float, bool)):
        return value
    if hasattr(value, "as_dict"):
        return _plain(value.as_dict())
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return str(value)


def load_model(path: str | os.PathLike[str]) -> MonitorModel:
    """Read a model written by :meth:`MonitorModel.save` (``gearshot fit --model``).

    Raises
    ------
    GearshotError
        A missing, damaged or foreign file, or one that would construct types no fitted
        estimator holds.
    """
    from ..estimator.persistence import read_skops

    path = Path(path)
    if not path.is_file():
        raise GearshotError(f"--model {str(path)!r} does not exist (write it with "
                            f"gearshot fit --model)")
    payload = read_skops(path)
    if not isinstance(payload, dict) or payload.get("format") != _FORMAT:
        raise GearshotError(f"--model {str(path)!r} is not a gearshot model file (gearshot "
                            f"fit --model writes them)")
    keys = ("estimator", "calibration", "condition", "database", "baseline", "threshold",
            "false_alarm_rate", "sustain", "machine_toml", "faulty", "fit_check",
            "coverage", "seed", "extras")
    model = MonitorModel(**{k: payload[k] for k in keys})
    model.path = path
    return model
