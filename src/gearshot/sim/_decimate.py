"""Streaming decimation of a fine-rate signal block by block (no edge effects).

:class:`StreamingDecimator` low-pass filters with a centred Kaiser-windowed FIR (as
:func:`scipy.signal.resample_poly`) and keeps every ``up``-th sample, fed with
consecutive blocks of a batch of signals; it carries the filter's history between blocks,
so the output equals filtering the whole signal at once with real samples on both sides.
"""

from __future__ import annotations

import numpy as np

__all__ = ["StreamingDecimator", "fir_half_length"]


def fir_half_length(up: int) -> int:
    """Half length (taps each side of the centre) of the anti-aliasing FIR for factor
    ``up`` (0 when there is nothing to decimate)."""
    return 10 * up if up > 1 else 0


class StreamingDecimator:
    """Decimate by ``up`` into ``out`` (n_signals, n_out), fed block by block.

    Output sample k is the filtered fine sample of index ``k * up``. Feed
    :meth:`start` with the ``half + 1`` fine samples of indices ``-half ... 0`` (the
    filter's history and the first output), then :meth:`push` the following fine samples
    (indices 1, 2, ...) in consecutive blocks, ``half`` beyond the last output in all.

    Parameters
    ----------
    out : ndarray (n_signals, n_out)
        Written in place.
    up : int
        Decimation factor (1: copy).
    """

    def __init__(self, out: np.ndarray, up: int):
        from scipy.signal import firwin

        self.out = out
        self.up = int(up)
        self.half = fir_half_length(self.up)
        self.h = (firwin(2 * self.half + 1, 1.0 / self.up, window=("kaiser", 5.0))
                  if self.up > 1 else np.ones(1))
        self._tail: np.ndarray | None = None
        self._g0 = -self.half        # fine index of the tail's first sample
        self._k_next = 0

    def start(self, history: np.ndarray) -> None:
        """The fine samples of indices ``-half ... 0``, shape (n_signals, half + 1)."""
        self._tail = history
        self._g0 = -self.half
        self._k_next = 0

    def push(self, block: np.ndarray) -> None:
        """The next fine samples, shape (n_signals, n)."""
        from scipy.signal import oaconvolve

        if self._tail is None:
            raise RuntimeError("push() before start()")
        n_out, up, half = self.out.shape[1], self.up, self.half
        zz = np.concatenate([self._tail, block], axis=1)
        if up == 1:
            idx = np.arange(zz.shape[1]) + self._g0
            keep = (idx >= 0) & (idx < n_out)
            self.out[:, idx[keep]] = zz[:, keep]
            self._tail = zz[:, :0]
            self._g0 += zz.shape[1]
            return
        conv = oaconvolve(zz, self.h[None, :], mode="valid", axes=-1)
        centre = self._g0 + half + np.arange(conv.shape[1])  # fine index of each output
        pick = ((centre % up == 0) & (centre // up >= self._k_next)
                & (centre // up < n_out))
        ks = centre[pick] // up
        self.out[:, ks] = conv[:, pick]
        if ks.size:
            self._k_next = int(ks[-1]) + 1
        self._tail = zz[:, -(2 * half):]
        self._g0 += zz.shape[1] - 2 * half
