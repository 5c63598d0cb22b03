"""The transfer path from the gearbox to the accelerometer: a TF applied in physical time.

The TF comes from a bank -- a folder of measured FRFs (UFF58/CSV, read with
:class:`gearshot.transfer.TransferFunctionBank`), a bank, any sequence of
:class:`~gearshot.transfer.TransferFunction`, or :func:`synthetic_path_tfs`. As in the
paper's propagation (where a TF's measured band is laid over the SA's band), the TF's
frequency axis is **stretched** so that its last line lands on ``fs / 2``: measured hammer
FRFs (0-1000 Hz) then shape the whole 0-25 kHz band of a 50 kHz recording. The TF is scaled
to the wanted overall attenuation (:func:`gearshot.transfer.attenuation_db`) and applied as a
causal FIR by overlap-add convolution (linear, no wrap-around).
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Sequence
from typing import Any

import numpy as np
import scipy.signal

from .._errors import GearshotError
from .._validation import check_int, check_positive
from ..transfer import (
    Mode,
    TransferFunction,
    TransferFunctionBank,
    fir_from_transfer_function,
    modal_frf,
)
from ..transfer import attenuation_db as tf_attenuation_db

__all__ = ["synthetic_path_tfs", "as_tf_list", "path_fir", "apply_path"]


def synthetic_path_tfs(n: int, *, rng: np.random.Generator, band: float = 25_000.0,
                       n_lines: int = 4097) -> list[TransferFunction]:
    """``n`` seeded modal accelerance TFs over 0 ... ``band`` Hz (the rig's default paths).

    Each has 4-10 modes (log-uniform 0.5-20 kHz, damping 1-5 %, log-normal residues with
    random signs, so antiresonances appear), a mass line and a pure delay of 0.05-0.5 ms
    (non-minimum phase): :func:`gearshot.transfer.modal_frf` of those modes.
    """
    n = check_int(n, "n", minimum=1)
    f = np.linspace(0.0, band, n_lines)
    out = []
    for i in range(n):
        k = int(rng.integers(4, 11))
        fk = np.exp(rng.uniform(np.log(500.0), np.log(20_000.0), k))
        zk = rng.uniform(0.01, 0.05, k)
        rk = rng.lognormal(0.0, 0.7, k) * rng.choice([-1.0, 1.0], k)
        modes = [Mode(float(a), float(b), float(c)) for a, b, c in zip(fk, zk, rk)]
        delay = float(rng.uniform(5e-5, 5e-4))
        out.append(modal_frf(f, modes, rigid_body=0.3, delay=delay, name=f"synthetic_{i}"))
    return out


def as_tf_list(bank: Any) -> list[TransferFunction]:
    """Normalize a TF bank argument: a folder path, a bank, or a sequence of TFs."""
    if isinstance(bank, (str, os.PathLike)):
        bank = TransferFunctionBank.from_folder(bank)
    if isinstance(bank, TransferFunctionBank):
        return [dataclasses.replace(tf, name=str(name)) for name, tf in bank.items()]
    if isinstance(bank, TransferFunction):
        return [bank]
    if not isinstance(bank, Sequence) and hasattr(bank, "__iter__"):
        bank = list(bank)
    if not isinstance(bank, Sequence) or not bank:
        raise GearshotError(f"tf_bank must be a folder, a TransferFunctionBank or a non-empty "
                            f"sequence of TransferFunction; got {type(bank).__name__}")
    for i, tf in enumerate(bank):
        if not isinstance(tf, TransferFunction):
            raise GearshotError(f"tf_bank[{i}] must be a gearshot.transfer.TransferFunction; "
                                f"got {type(tf).__name__}")
    return list(bank)


def path_fir(tf: TransferFunction, fs: float, *, attenuation_db: float,
             n_taps: int | None = None) -> np.ndarray:
    """Causal FIR (impulse response per sample) of ``tf`` stretched onto 0 ... fs/2 and
    scaled to ``attenuation_db`` of overall attenuation.

    ``n_taps`` defaults to twice the TF's number of lines (its full impulse response).
    """
    fs = check_positive(fs, "fs")
    n_taps = 2 * (tf.n_lines - 1) if n_taps is None else check_int(n_taps, "n_taps",
                                                                    minimum=4)
    n_taps += n_taps % 2
    stretched = dataclasses.replace(tf, freqs=tf.freqs * ((fs / 2) / tf.freqs[-1]))
    gain = 10.0 ** ((tf_attenuation_db(tf) - attenuation_db) / 20.0)
    return gain * fir_from_transfer_function(stretched, fs, n_taps=n_taps, outside="edge")


def apply_path(x: np.ndarray, fir: np.ndarray) -> np.ndarray:
    """Filter ``x`` through ``fir`` (first ``len(x)`` samples of the linear convolution)."""
    return scipy.signal.oaconvolve(x, fir, mode="full")[: np.shape(x)[-1]]
