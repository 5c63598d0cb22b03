"""The bottom layer of a :class:`~gearshot.io.Recording`: what it holds (declared here, set
by the dataclass) and its tacho: pulse times, pulses per revolution, and the tacho
revolutions of one SA cycle of a shaft or a gear pair."""

from __future__ import annotations

from collections.abc import Mapping
from fractions import Fraction
from typing import TYPE_CHECKING, Any

import numpy as np

from .._errors import GearshotError
from .._validation import check_int
from ..signal.angle import check_pulse_train

if TYPE_CHECKING:
    from ..machine import Machine

__all__ = ["TachoRecording", "SPEED_TOLERANCE"]

#: Relative disagreement between the tacho's speed and the ``speed`` metadata that is taken
#: as a wrong sampling rate.
SPEED_TOLERANCE = 0.10


class TachoRecording:
    """A recording's samples, tacho and metadata (the fields of
    :class:`~gearshot.io.Recording`) and what its tacho says."""

    acceleration: np.ndarray
    tacho: np.ndarray | None
    fs: float
    speed: float | None
    tacho_pulses_per_rev: int | None
    tacho_shaft: str
    origin: str | None
    channel_names: tuple[str, ...]
    machine: Machine | None
    extras: Mapping[str, Any]

    @property
    def duration(self) -> float:
        """Length in s."""
        n: int = self.acceleration.shape[-1]
        return n / self.fs

    def _label(self) -> str:
        return f"recording {self.origin!r}" if self.origin else "recording"

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

    def _raw_pulses(self, threshold: float | None) -> np.ndarray:
        from ..signal import pulse_times

        if self.tacho is None:
            raise GearshotError(f"{self._label()} has no tacho; SA segments need one")
        if float(np.ptp(self.tacho)) == 0.0:
            raise GearshotError(f"{self._label()}: the tacho is flat (no pulses)")
        if threshold is None and self.machine is not None and self.machine.tacho is not None:
            threshold = self.machine.tacho.threshold
        cache: dict[float | None, np.ndarray] = self.__dict__.setdefault("_pulse_cache", {})
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
