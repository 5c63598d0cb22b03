"""One recording through a machine description: the monitored gear's SA segments, the
whole angle-domain signal, the speed and what the read checks."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._errors import GearshotError
from ..io.input_health import check_input, check_segments
from ..machine.signal_check import speed_check
from ..signal.path_pattern import path_pattern

__all__ = ["machine_segments"]


def machine_segments(path: str | Path, machine, *, cycles_per_segment: int,
                     sensor: str | None = None, info: dict | None = None, rec=None
                     ) -> tuple[np.ndarray, np.ndarray, float]:
    """SA segments of the monitored gear's shaft for one recording file (``rec``: the file
    already read with ``machine``; default: read now).

    ``info``, when given, receives ``speed_source`` (``"tacho"`` or ``"vibration"``),
    ``speed_uncertainty_hz`` (rev/s; ``None`` with a tacho), ``speed_check``
    (:func:`gearshot.machine.signal_check.speed_check`), the sensor's input checks
    ``recording`` and ``segments`` and its resonance pattern ``path``.

    Returns ``sa`` (n_segments, samples_per_cycle), ``x`` (the whole angle-domain signal,
    n_cycles * samples_per_cycle) and ``speed`` (the tacho shaft's, rev/s).
    """
    from ..io import Recording

    if machine.monitored is None:
        raise GearshotError(f"machine {machine.name!r} names no [monitored] gear")
    rec = Recording.read(path, machine=machine) if rec is None else rec
    name = machine.sensor(sensor).name
    spc = machine.samples_per_cycle
    x = rec.angle_domain(shaft=machine.monitored.shaft, sensor=name, samples_per_cycle=spc,
                         antialias=machine.antialias)
    n_cycles = x.size // spc
    n_seg = n_cycles // cycles_per_segment
    if n_seg < 1:
        raise GearshotError(f"{str(path)!r} holds {n_cycles} revolution(s) of shaft "
                            f"{machine.monitored.shaft!r}; --cycles-per-segment="
                            f"{cycles_per_segment} is too many")
    blocks = x[: n_seg * cycles_per_segment * spc].reshape(n_seg, cycles_per_segment, spc)
    if info is not None:
        info.update(speed_source=rec.speed_source, speed_uncertainty_hz=rec.speed_uncertainty,
                    speed_check=speed_check(machine, rec))
        info.update(_input_health(rec.channel(name), blocks.mean(axis=1),
                                  machine.sensor(name).unit))
    return blocks.mean(axis=1), x, rec.shaft_speed()


def _input_health(channel, sas, unit) -> dict:
    """The input checks of one sensor of a recording (``channel``: its one-channel
    :class:`~gearshot.io.Recording`): its raw samples and its SA segments
    (:mod:`gearshot.io.input_health`), and its resonance pattern ``path``
    (:func:`gearshot.signal.path_pattern.path_pattern`)."""
    raw = channel.acceleration
    return dict(recording=check_input(raw, units=unit), segments=check_segments(sas, units=unit),
                path=path_pattern(raw, channel.fs))
