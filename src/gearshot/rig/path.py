"""The transfer path from the gearbox to the accelerometer: a TF applied in physical time.

The TF comes from a bank -- a folder of measured FRFs (UFF58/CSV, read with
:class:`gearshot.transfer.TransferFunctionBank`), any sequence of objects with ``freqs``
(Hz) and complex ``values``, or :func:`synthetic_path_tfs`. As in the paper's propagation
(where a TF's measured band is laid over the SA's band), the TF's frequency axis is
**stretched** so that its last line lands on ``fs / 2``: measured hammer FRFs
(0-1000 Hz) then shape the whole 0-25 kHz band of a 50 kHz recording. The TF is scaled to
the wanted overall attenuation (-20 log10 of its RMS magnitude over the lines) and applied
as a causal FIR by overlap-add convolution (linear, no wrap-around).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import scipy.signal

from .._errors import GearshotError
from .._validation import as_signal_array, check_int, check_positive

__all__ = ["PathTF", "synthetic_path_tfs", "as_tf_list", "path_fir", "apply_path"]


@dataclass(frozen=True, eq=False)
class PathTF:
    """A TF sampled at increasing frequencies (Hz) with complex values."""

    freqs: np.ndarray
    values: np.ndarray
    name: str = ""

    def __post_init__(self) -> None:
        f = as_signal_array(self.freqs, "freqs", max_ndim=1, min_length=4)
        v = as_signal_array(self.values, "values", max_ndim=1, allow_complex=True)
        if v.shape != f.shape:
            raise GearshotError(f"values must match freqs ({f.size} lines); got {v.size}")
        if np.any(np.diff(f) <= 0) or f[0] < 0:
            raise GearshotError(f"freqs of TF {self.name!r} must be >= 0 and increasing")
        object.__setattr__(self, "freqs", f)
        object.__setattr__(self, "values", v.astype(np.complex128))

    @property
    def attenuation_db(self) -> float:
        """-20 log10 of the RMS magnitude over the lines."""
        return float(-20 * np.log10(np.sqrt(np.mean(np.abs(self.values) ** 2))))


def synthetic_path_tfs(n: int, *, rng: np.random.Generator, band: float = 25_000.0,
                       n_lines: int = 4097) -> list[PathTF]:
    """``n`` seeded modal accelerance-like TFs over 0 ... ``band`` Hz.

    Each has 4-10 modes (log-uniform 0.5-20 kHz, damping 1-5 %, log-normal residues with
    random signs, so antiresonances appear), a mass line and a pure delay of 0.05-0.5 ms
    (non-minimum phase).
    """
    n = check_int(n, "n", minimum=1)
    f = np.linspace(0.0, band, n_lines)
    s = 2j * np.pi * f
    out = []
    for i in range(n):
        k = int(rng.integers(4, 11))
        fk = np.exp(rng.uniform(np.log(500.0), np.log(20_000.0), k))
        zk = rng.uniform(0.01, 0.05, k)
        rk = rng.lognormal(0.0, 0.7, k) * rng.choice([-1.0, 1.0], k)
        wk = 2 * np.pi * fk
        h = 0.3 + sum(r * s ** 2 / (s ** 2 + 2 * z * w * s + w ** 2)
                      for r, z, w in zip(rk, zk, wk))
        h = h * np.exp(-s * rng.uniform(5e-5, 5e-4))
        out.append(PathTF(f, h, name=f"synthetic_{i}"))
    return out


def as_tf_list(bank: Any) -> list[PathTF]:
    """Normalize a TF bank argument: a folder path, a sequence of TF-like objects."""
    if isinstance(bank, (str, os.PathLike)):
        folder = Path(bank)
        try:
            from ..transfer import TransferFunctionBank
        except ImportError as exc:  # pragma: no cover - depends on the transfer module
            raise GearshotError(f"reading a TF folder needs gearshot.transfer: {exc}") from None
        bank = TransferFunctionBank.from_folder(folder)
    if hasattr(bank, "items") and hasattr(bank, "names"):  # a TransferFunctionBank
        return [PathTF(np.asarray(tf.freqs), np.asarray(tf.values), name=str(name))
                for name, tf in bank.items()]
    if isinstance(bank, PathTF):
        return [bank]
    if not isinstance(bank, Sequence) and hasattr(bank, "__iter__"):
        bank = list(bank)
    if not isinstance(bank, Sequence) or not bank:
        raise GearshotError(f"tf_bank must be a folder, or a non-empty sequence of TFs; got "
                            f"{type(bank).__name__}")
    out = []
    for i, tf in enumerate(bank):
        if isinstance(tf, PathTF):
            out.append(tf)
        elif hasattr(tf, "freqs") and hasattr(tf, "values"):
            out.append(PathTF(np.asarray(tf.freqs), np.asarray(tf.values),
                              name=str(getattr(tf, "name", f"tf_{i}"))))
        else:
            raise GearshotError(f"tf_bank[{i}] has no freqs/values; got {type(tf).__name__}")
    return out


def path_fir(tf: PathTF, fs: float, *, attenuation_db: float,
             n_taps: int | None = None) -> np.ndarray:
    """Causal FIR (impulse response per sample) of ``tf`` stretched onto 0 ... fs/2 and
    scaled to ``attenuation_db`` of overall attenuation.

    ``n_taps`` defaults to twice the TF's number of lines (its full impulse response).
    """
    fs = check_positive(fs, "fs")
    n_taps = 2 * (tf.freqs.size - 1) if n_taps is None else check_int(n_taps, "n_taps",
                                                                       minimum=4)
    n_taps += n_taps % 2
    stretch = (fs / 2) / tf.freqs[-1]
    grid = np.fft.rfftfreq(n_taps, 1.0 / fs) / stretch
    h = np.interp(grid, tf.freqs, tf.values.real) + 1j * np.interp(grid, tf.freqs,
                                                                   tf.values.imag)
    h[-1] = h[-1].real
    gain = 10.0 ** (-attenuation_db / 20.0) / np.sqrt(np.mean(np.abs(tf.values) ** 2))
    return gain * np.fft.irfft(h, n_taps)


def apply_path(x: np.ndarray, fir: np.ndarray) -> np.ndarray:
    """Filter ``x`` through ``fir`` (first ``len(x)`` samples of the linear convolution)."""
    return scipy.signal.oaconvolve(x, fir, mode="full")[: np.shape(x)[-1]]
