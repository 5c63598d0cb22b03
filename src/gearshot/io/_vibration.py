"""A :class:`~gearshot.io.Recording` without a tacho: the speed and angle of a shaft from the
vibration (:func:`gearshot.signal.tracking.estimate_shaft_angle`), and the mean speed of any
shaft from either source."""

from __future__ import annotations

from typing import Any

import numpy as np

from .._errors import GearshotError
from .._validation import check_speed
from ._tacho import SPEED_TOLERANCE, TachoRecording

__all__ = ["VibrationRecording", "SPEED_HINT_KEY"]

#: Metadata key of a recording's speed hint: the nominal speed (Hz) of the shaft tracked in
#: the vibration, for a record without a tacho (``Recording.read(..., metadata={
#: "speed_hint_hz": 30})``, ``gearshot indicators FILE@30`` or ``--speed-hint 30``). The
#: speed is searched within ±10 % of it, before the machine file's ``[speed] range_hz``.
SPEED_HINT_KEY = "speed_hint_hz"


class VibrationRecording(TachoRecording):
    """Speed and angle from the vibration where there is no tacho."""

    @property
    def speed_source(self) -> str:
        """Where the speed and angle come from: ``"tacho"``, or ``"vibration"`` (no tacho:
        estimated from a mesh harmonic, :meth:`vibration_angle`)."""
        return "tacho" if self.tacho is not None else "vibration"

    @property
    def speed_uncertainty(self) -> float | None:
        """Standard uncertainty (rev/s) of the speed of the tracked shaft estimated from the
        vibration (phase noise and a model term validated against a tacho,
        :attr:`gearshot.signal.tracking.ShaftAngle.speed_uncertainty`); ``None`` with a
        tacho."""
        if self.tacho is not None:
            return None
        return float(self.vibration_angle().speed_uncertainty)

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
            ``range_hz``, else the nominal ``speed`` ±10 % (converted to that shaft). A
            speed hint in the metadata (:data:`SPEED_HINT_KEY`) comes first: ±10 % of it.
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
        hint = self.extras.get(SPEED_HINT_KEY) if speed_range is None else None
        if hint is not None:   # the record's own nominal speed of this shaft, Hz
            hint = check_speed(hint, SPEED_HINT_KEY)
            speed_range = (hint * (1 - SPEED_TOLERANCE), hint * (1 + SPEED_TOLERANCE))
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
        tacho_rate: float
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
