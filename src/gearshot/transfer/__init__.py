"""Transfer functions: FRF container, file I/O, hammer-test estimation, modal synthesis, filtering.

(Temporary package init on the ``transfer`` branch; the lead's version re-exports the
estimation functions as well.)
"""

from .bank import TransferFunctionBank
from .filtering import filter_signal, fir_from_transfer_function
from .function import TransferFunction
from .impacts import ImpactFRF, frf_from_impacts, impact_arrays
from .modal import Mode, antiresonances, attenuation_db, modal_frf, synthetic_bank
from .plot import plot_transfer_function, plot_transfer_functions
from .uff import FRF_SUFFIXES, UffRecord, read_frf, read_uff_records, write_frf

__all__ = [
    "TransferFunction", "TransferFunctionBank", "UffRecord", "read_frf", "write_frf",
    "read_uff_records", "FRF_SUFFIXES", "ImpactFRF", "frf_from_impacts", "impact_arrays",
    "Mode", "modal_frf", "synthetic_bank", "attenuation_db", "antiresonances",
    "filter_signal", "fir_from_transfer_function", "plot_transfer_function",
    "plot_transfer_functions",
]
