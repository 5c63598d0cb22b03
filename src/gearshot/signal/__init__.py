"""Pure signal-processing functions for gear vibration.

Batching convention: every function takes signals along the **last axis**; any leading
axes are batch axes and are preserved (``(n_signals, n_points)`` for a stack of
synchronous averages). Options are keyword-only. Bad input raises
:class:`gearshot.GearshotError` naming the parameter.
"""

from .alignment import fractional_shift, subtract_healthy
from .angle import check_pulse_train
from .angular import angle_to_time, angular_resample, pulse_times
from .antialias import antialias_filter
from .averaging import nonsynchronous_signal, synchronous_average
from .cepstrum import minimum_phase, real_cepstrum
from .envelope import envelope
from .level import mean_rms, rms
from .orders import (
    difference_signal,
    harmonic_signal,
    mesh_band_orders,
    order_mask,
    regular_signal,
    residual_signal,
)
from .reference_blend import subtract_blend
from .ridge import speed_ridge
from .spectra import acs_background, amplitude_spectrum
from .tracking import angle_pulse_times, demodulate_angle, estimate_shaft_angle
from .trains import shaft_cycle_times

__all__ = [
    "pulse_times",
    "angle_to_time",
    "angular_resample",
    "antialias_filter",
    "shaft_cycle_times",
    "check_pulse_train",
    "synchronous_average",
    "harmonic_signal",
    "difference_signal",
    "regular_signal",
    "residual_signal",
    "nonsynchronous_signal",
    "order_mask",
    "mesh_band_orders",
    "rms",
    "mean_rms",
    "envelope",
    "amplitude_spectrum",
    "acs_background",
    "real_cepstrum",
    "minimum_phase",
    "fractional_shift",
    "subtract_healthy",
    "subtract_blend",
    "speed_ridge",
    "demodulate_angle",
    "angle_pulse_times",
    "estimate_shaft_angle",
]
