"""A :class:`~gearshot.io.Recording` in the angle domain: the cycle times of a shaft (from the
tacho or the vibration), angular resampling and the synchronous averages of segments."""

from __future__ import annotations

import numpy as np

from .._errors import GearshotError
from .._validation import check_int
from ..signal.angle import uniform_cycle_times
from ._tacho import SPEED_TOLERANCE
from ._vibration import VibrationRecording

__all__ = ["AngleDomainRecording"]


class AngleDomainRecording(VibrationRecording):
    """Angular resampling and SA segments of any shaft."""

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
