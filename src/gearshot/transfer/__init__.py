"""Transfer functions: estimation from healthy signals, resampling and propagation."""

from .estimation import (
    estimate_transfer_function,
    propagate,
    resample_transfer_function,
    rms,
    rms_normalize,
)

__all__ = [
    "estimate_transfer_function",
    "resample_transfer_function",
    "propagate",
    "rms",
    "rms_normalize",
]
