"""Transfer functions: estimation from healthy signals, resampling and propagation; FRF
container, UFF58/CSV I/O, hammer-test estimation, modal synthesis, physical-time filtering.
"""

from .bank import TransferFunctionBank, synthetic_bank
from .estimation import (
    estimate_transfer_function,
    mean_rms,
    propagate,
    resample_transfer_function,
    rms,
    rms_normalize,
)
from .filtering import filter_signal, fir_from_transfer_function
from .function import TransferFunction
from .impacts import ImpactFRF, frf_from_impacts, impact_arrays
from .modal import Mode, antiresonances, attenuation_db, modal_frf, synthetic_tfs
from .uff import FRF_SUFFIXES, UffRecord, read_frf, read_uff_records, write_frf

__all__ = [
    "estimate_transfer_function",
    "resample_transfer_function",
    "propagate",
    "rms",
    "mean_rms",
    "rms_normalize",
    "TransferFunction", "TransferFunctionBank", "UffRecord", "read_frf", "write_frf",
    "read_uff_records", "FRF_SUFFIXES", "ImpactFRF", "frf_from_impacts", "impact_arrays",
    "Mode", "modal_frf", "synthetic_bank", "synthetic_tfs", "attenuation_db", "antiresonances",
    "filter_signal", "fir_from_transfer_function",
]
