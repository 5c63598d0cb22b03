"""The machine file verified against the signal: the mesh orders it declares must stand
where it says in the healthy recordings' order spectrum.

A machine file turns a recording into the angle of every shaft: the tacho's pulses per
revolution and the sampling rate make the reference shaft's speed, the tooth counts every
other shaft's. A mistake in any of them moves every gear mesh away from the order the file
declares for it, and the estimates built on that angle are wrong without looking wrong.
Each stage's mesh is a line at order ``driver_teeth * speed_ratio(driver)`` of the reference
shaft (with harmonics). :func:`check_recording` reads the whole-record order spectrum of
that shaft (along the tacho's angle, or the angle tracked from the vibration) and tests,
in this order:

1. without a tacho, the tracked speed (:func:`speed_check`): the record's whole orders
   must stand best at the tracked speed, not at another within 15 % (a comb locked on a
   mesh sideband or on a ratio of the speed is named with its size and the speed found);
2. the declared comb must stand out (:data:`MIN_COMB_DB`); where it does not, the scale
   ``k`` of the orders that a nameable mistake makes is tried (:data:`MIN_GAIN_DB`):
   ``k = p / P`` with the speed off the declared range: ``pulses_per_rev`` looks like
   ``P``, not ``p``; ``k`` the speed ratio of two shafts: the tacho (or ``[speed]``)
   watches the other shaft; none: a tooth count (one mesh missing, the others standing)
   or another gear train;
3. the odd harmonics of the lowest declared mesh must stand out (:data:`MIN_ODD_DB`;
   tested by :func:`verify_machine` on the mean over its recordings): otherwise that mesh
   is not there and the train found has twice the declared orders (the PHM09 helical
   file on spur records: 16, 8 declared, 32, 16 found);
4. the speed must lie in the declared ``[speed] range_hz`` (or within 10 % of the
   recording's nominal ``speed``): otherwise, with the orders where declared, ``fs`` is
   off (the tacho and the vibration are stretched alike, so the orders cannot show it).

Level of a line: its peak in the Hann-windowed order spectrum of the whole record, in dB
above the median of the spectrum over the surrounding whole order. *Prominence* of a line:
its level minus the median level at the eight neighbouring whole-order offsets
(``±1 … ±4`` shaft orders): a mesh stands above the shaft's own harmonics and sidebands
around it, which every healthy gearbox shows at almost every whole order.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from .._errors import GearshotError
from ._mistakes import (
    _CLIP,
    MIN_COMB_DB,
    MIN_GAIN_DB,
    MIN_ODD_DB,
    MIN_PROMINENCE_DB,
    SPEED_RANGE_MARGIN,
    MeshLine,
    fs_mistake,
    half_mistake,
    name_mistake,
    plausible_speeds,
    tooth_mistake,
)
from ._order_spectrum import (
    HARMONICS,
    MAX_WHOLE_GAIN_DB,
    order_spectrum,
    speed_ratio_found,
    tracked_off,
)

__all__ = ["MeshLine", "MachineCheck", "verify_machine", "check_recording", "speed_check",
           "MIN_COMB_DB", "MIN_ODD_DB", "MIN_GAIN_DB", "MAX_WHOLE_GAIN_DB",
           "MIN_PROMINENCE_DB", "SPEED_RANGE_MARGIN"]

_SAMPLES_PER_REV = 1024
_ODD_TOP = 125.0


@dataclass(frozen=True)
class MachineCheck:
    """What :func:`verify_machine` found for one recording.

    Attributes
    ----------
    recording : str
        The recording's origin.
    passed : bool
    mistake : str
        ``""`` when passed, else the likely mistake in one line.
    scale : float
        Orders found / orders declared (1 when the declared comb stands best).
    speed_hz : float
        Mean reference-shaft speed the file gives, rev/s.
    speed_source : str
        ``"tacho"`` or ``"vibration"``.
    lines : tuple of MeshLine
    score_db, best_score_db : float
        Mean clipped prominence of every declared line at scale 1 and at ``scale``.
    odd_db : float
        Mean prominence of the odd harmonics of the lowest declared mesh.
    whole_db : float
        Median level of the whole orders 1-100 over the half orders, dB (tracked speed
        only; 0 with a tacho).
    speed_ratio : float
        True / used speed at which the whole orders stand best (within 15 %).
    """

    recording: str
    passed: bool
    mistake: str
    scale: float
    speed_hz: float
    speed_source: str
    lines: tuple[MeshLine, ...] = field(default=())
    score_db: float = 0.0
    best_score_db: float = 0.0
    odd_db: float = 0.0
    whole_db: float = 0.0
    speed_ratio: float = 1.0

    def describe(self) -> str:
        """One line: the file, the verdict, the mistake."""
        found = ", ".join(f"{ln.order:g} ({ln.prominence_db:+.1f} dB)" for ln in self.lines)
        if self.passed:
            return (f"{self.recording}: machine file verified (mesh orders {found} of the "
                    f"{self.speed_source} shaft at {self.speed_hz:.4g} Hz)")
        return f"{self.recording}: {self.mistake}"

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready summary."""
        return {"recording": self.recording, "passed": self.passed, "mistake": self.mistake,
                "scale": self.scale, "speed_hz": self.speed_hz,
                "speed_source": self.speed_source,
                "mesh_orders": [ln.order for ln in self.lines],
                "prominence_db": [ln.prominence_db for ln in self.lines]}


def _stage_lines(machine: Any) -> list[tuple[str, Fraction]]:
    ref = machine.reference_shaft
    return [(f"{st.driver} {st.driver_teeth}T -> {st.driven} {st.driven_teeth}T",
             st.driver_teeth * machine.speed_ratio(st.driver, relative_to=ref))
            for st in machine.stages]


def check_recording(machine: Any, rec: Any, *, sensors: Sequence[str] | None = None,
                    odd_test: bool = True, comb_test: bool = True) -> MachineCheck:
    """Verify ``machine`` against one recording read with it (no exception).

    Parameters
    ----------
    machine : gearshot.Machine
    rec : gearshot.io.Recording
        Read with ``machine`` (healthy, steady speed).
    sensors : sequence of str, optional
        Sensors whose spectra are averaged; default: every sensor of the machine.
    odd_test : bool, default True
        Test the odd harmonics of the lowest mesh here (:data:`MIN_ODD_DB`);
        :func:`verify_machine` tests their mean over the recordings instead.
    comb_test : bool, default True
        Test the declared comb, its odd harmonics and the speed range; ``False``: only
        the tracked speed (the whole orders, :func:`speed_check`).

    Returns
    -------
    MachineCheck
    """
    label = str(rec.origin or "recording")
    names = [machine.sensor(s).name for s in (sensors or [s.name for s in machine.sensors])]
    ref = machine.reference_shaft
    speed = float(rec.shaft_speed())
    source = rec.speed_source
    x = np.stack([rec.angle_domain(shaft=ref, sensor=n, samples_per_cycle=_SAMPLES_PER_REV,
                                   antialias=machine.antialias) for n in names])
    spec = order_spectrum(x, _SAMPLES_PER_REV)
    stages = _stage_lines(machine)
    declared = np.array([float(o) for _, o in stages])
    h = np.arange(1, HARMONICS + 1)
    prom = spec.prominence(declared[:, None] * h)
    lines = [MeshLine(name, float(o), float(np.mean(p)))
             for (name, o), p in zip(stages, prom)]
    s1 = float(np.mean(np.clip(prom, *_CLIP)))
    low = float(declared.min())
    odd = float(np.mean(spec.prominence(low * np.arange(1, max(2, int(_ODD_TOP / low) + 1), 2))))
    # the whole-order scan only where the speed was tracked (a tacho's speed is exact)
    whole, whole_best, ratio = (speed_ratio_found(spec) if source == "vibration"
                                else (0.0, 0.0, 1.0))
    k, best = 1.0, s1
    plausible = plausible_speeds(machine, rec)
    moved = ""
    if source == "vibration":
        moved = tracked_off(spec, speed, whole, whole_best, ratio)
    if moved:
        mistake = moved
    elif not comb_test:
        mistake = ""
    elif s1 < MIN_COMB_DB:
        k, best, mistake = name_mistake(machine, spec, speed, source, plausible, lines,
                                         declared, s1)
    elif odd_test and odd < MIN_ODD_DB:
        mistake = (tooth_mistake(lines, half=True)
                   or half_mistake(machine, declared, low, odd))
    elif plausible is not None and not plausible[0] <= speed <= plausible[1]:
        # a wrong pulse count or tacho shaft moves the orders too; fs does not
        k, best, mistake = name_mistake(machine, spec, speed, source, plausible, lines,
                                         declared, s1)
        if k == 1.0:
            k, best, mistake = 1.0, s1, fs_mistake(rec, speed, plausible)
    else:
        mistake = ""
    return MachineCheck(label, not mistake, mistake, k, speed, source, tuple(lines), s1,
                        best, odd, whole, ratio)


def speed_check(machine: Any, rec: Any) -> str:
    """``"ok"``, or why a speed tracked in the vibration is not to be trusted.

    With a tacho: ``"ok"`` (the pulses are the speed). Without: the whole orders of the
    shaft in the record's order spectrum along the tracked angle must stand best at the
    tracked speed, not at another within 15 % (:data:`MAX_WHOLE_GAIN_DB`): a comb locked
    on a sideband of a mesh (e.g. 2 idler orders beside the PHM09 spur input mesh: 2.08 %
    off) or a run-up locked on another line fails here. The tracker's own refusal (no
    line stands out, an ambiguous ratio 1/2 ... 2) is returned as the reason too. The
    machine file itself is :func:`verify_machine`'s.

    Parameters
    ----------
    machine : gearshot.Machine
    rec : gearshot.io.Recording
        Read with ``machine``.

    Returns
    -------
    str
    """
    if rec.speed_source != "vibration":
        return "ok"
    try:
        check = check_recording(machine, rec, odd_test=False, comb_test=False)
    except GearshotError as exc:
        return str(exc)
    return "ok" if check.passed else check.mistake


def verify_machine(machine: Any, recordings: Any, *, sensors: Sequence[str] | None = None,
                   raise_on_failure: bool = True) -> list[MachineCheck]:
    """Verify a machine file against healthy recordings: its mesh orders where it says.

    Parameters
    ----------
    machine : gearshot.Machine or path
        The machine description (a TOML path is read).
    recordings : Recording, path, or sequence of them
        Healthy recordings of the machine, steady speed (paths are read with
        ``machine``).
    sensors : sequence of str, optional
        Sensors whose order spectra are averaged (default: all of the machine's).
    raise_on_failure : bool, default True
        Raise on the first recording that fails, naming it and the likely mistake.

    Returns
    -------
    list of MachineCheck
        One per recording.

    Raises
    ------
    GearshotError
        A recording's declared mesh orders do not stand where declared, or its speed is
        off the declared range by a constant factor: one line naming the file, the orders
        found and the likely mistake (``pulses_per_rev``, ``fs``, a tooth count, the
        tacho's shaft, another gear train, a tracked speed that is off).
    """
    from ..io import Recording
    from .gearbox import Machine

    if isinstance(machine, (str, Path)):
        machine = Machine.from_toml(machine)
    if isinstance(recordings, (str, Path, Recording)):
        recordings = [recordings]
    out = []
    for item in recordings:
        rec = item if isinstance(item, Recording) else Recording.read(item, machine=machine)
        # a tracker's refusal names the file itself
        check = check_recording(machine, rec, sensors=sensors, odd_test=False)
        if raise_on_failure and not check.passed:
            raise GearshotError(f"machine file {machine.name!r} does not match "
                                f"{check.describe()}")
        out.append(check)
    odd = float(np.mean([c.odd_db for c in out])) if out else MIN_ODD_DB
    if out and odd < MIN_ODD_DB:
        declared = np.array([ln.order for ln in out[0].lines])
        mistake = (tooth_mistake(list(out[0].lines), half=True)
                   or half_mistake(machine, declared, float(declared.min()), odd))
        out = [dataclasses.replace(c, passed=False, mistake=c.mistake or mistake)
               for c in out]
        if raise_on_failure:
            names = ", ".join(Path(c.recording).name for c in out)
            raise GearshotError(f"machine file {machine.name!r} does not match {names}: "
                                f"{mistake}")
    return out
