"""The delay search of :mod:`gearshot.signal.alignment`: coarse-to-fine argmax of circular
cross-correlations, and the bound that drops references which cannot leave the least
residual energy before their fine search."""

from __future__ import annotations

import functools
from typing import cast

import numpy as np

from .._typing import BoolArray, ComplexArray, FloatArray, IntArray

__all__ = ["_LagSearch", "contenders", "roots"]


class _LagSearch:
    """Argmax of a circular cross-correlation on a grid of ``1/upsample`` sample.

    The correlation is band-limited, so its maximum on the fine grid lies next to the
    maximum of a ×4 over-sampled version: that coarse curve (a short inverse FFT) picks a few
    candidate peaks, and the fine grid is evaluated only around them (a small matrix
    product), instead of one inverse FFT of ``n * upsample`` points per pair. The values are
    those of frequency-domain ×``upsample`` interpolation with the Nyquist bin split evenly
    (MATLAB ``interpft``), whose first maximum the reference implementation takes.
    """

    n_candidates = 3

    def __init__(self, n: int, upsample: int):
        self.n, self.upsample = n, upsample
        self.coarse = 4 if upsample % 4 == 0 else (2 if upsample % 2 == 0 else 1)
        self.step = upsample // self.coarse  # fine points per coarse point
        self.k = np.arange(n // 2 + 1)
        weights = np.full(self.k.size, 2.0)
        weights[0] = 1.0
        if n % 2 == 0:
            weights[-1] = 0.5  # the two split Nyquist halves multiply to 1/4, twice
        self.weights = weights
        offsets = np.arange(-self.step, self.step + 1)
        # Re(b · exp(iθko)) = Re b · cos θko − Im b · sin θko: cosines are even in the
        # offset o, sines odd, so the products over o ≥ 0 give every offset
        phase = np.exp(2j * np.pi * np.outer(self.k, offsets[self.step:]) / (n * upsample))
        self.cos, self.sin = phase.real.copy(), phase.imag[:, 1:].copy()
        self.offsets = offsets
        self._padded = np.zeros((0, n * self.coarse // 2 + 1), dtype=complex)

    def best(self, cross: ComplexArray) -> IntArray:
        """Fine-grid index (0 … n·upsample−1) of the first maximum for each row of ``cross``."""
        curve = self.coarse_curve(cross)
        return self.fine(cross, curve, np.argmax(curve, axis=-1))

    def coarse_curve(self, cross: ComplexArray) -> FloatArray:
        """The correlations of the rows of ``cross`` (≥ n//2+1 columns) on the coarse grid
        (``n·coarse`` points; ``n·coarse`` times the values of :meth:`fine`'s curve)."""
        n, m = self.n, self.n // 2 + 1
        width = n * self.coarse // 2 + 1
        if len(self._padded) < len(cross):  # zero beyond column m, kept between calls
            self._padded = np.zeros((len(cross), width), dtype=complex)
        padded = self._padded[: len(cross)]
        np.multiply(cross[:, :m], self.weights, out=padded[:, :m])
        padded[:, 1:m] *= 0.5  # irfft doubles these bins itself
        return np.fft.irfft(padded, n=n * self.coarse, axis=-1)

    def fine(self, cross: ComplexArray, curve: FloatArray, first: IntArray) -> IntArray:
        """:meth:`best` from :meth:`coarse_curve`'s ``curve`` of the same rows of ``cross``
        (overwritten) and its row-wise argmax ``first``."""
        n, n_fine = self.n, self.n * self.upsample
        n_cand = min(self.n_candidates, curve.shape[-1])
        cand = _top_indices(curve, n_cand, first)
        centres = cand * self.step  # (rows, n_candidates) on the fine grid
        # exp(2πi·centre·k/n_fine) = w^(cand·k mod n·coarse), w = exp(2πi/(n·coarse))
        turns = (cand[:, :, None] * self.k) % (n * self.coarse)
        half = cross[:, : n // 2 + 1] * self.weights
        base = roots(n * self.coarse)[turns] * half[:, None, :]
        even = base.real @ self.cos  # (rows, n_candidates, step + 1): offsets 0 … step
        odd = base.imag @ self.sin  # offsets 1 … step
        values = np.concatenate([(even[..., 1:] + odd)[..., ::-1], even[..., :1],
                                 even[..., 1:] - odd], axis=-1)
        fine = (centres[:, :, None] + self.offsets) % n_fine
        values = values.reshape(len(values), -1)
        fine = fine.reshape(len(fine), -1)
        top = values == values.max(axis=-1, keepdims=True)
        return cast(IntArray, np.where(top, fine, n_fine).min(axis=-1))  # first max., as argmax


def _top_indices(work: FloatArray, count: int, first: IntArray) -> IntArray:
    """Column indices of the ``count`` largest values of each row, ascending, given the
    row-wise argmax ``first``: ``count − 1`` more argmax passes (each found maximum masked
    in place: ``work`` is overwritten), cheaper than ``argpartition``."""
    rows = np.arange(len(work))
    found = np.empty((len(work), count), dtype=np.intp)
    found[:, 0] = first
    work[rows, first] = -np.inf
    for i in range(1, count):
        found[:, i] = np.argmax(work, axis=-1)
        work[rows, found[:, i]] = -np.inf
    return cast(IntArray, np.sort(found, axis=-1))


@functools.lru_cache(maxsize=8)
def roots(m: int) -> ComplexArray:
    """The ``m`` roots of unity ``exp(2πi·j/m)``, j = 0 … m−1 (a lookup table; read-only)."""
    table = np.exp(2j * np.pi * np.arange(m) / m)
    table.flags.writeable = False
    return cast(ComplexArray, table)


def contenders(sx: ComplexArray, spec_r: ComplexArray, peak: FloatArray,
               search: _LagSearch, among: int = 1) -> BoolArray:
    """Which references (c, n_refs) may be among the ``among`` leaving the least residual
    energy for each signal (``among=1``: the one leaving the least).

    The residual energy of signal spectrum ``X`` and reference ``H`` at delay ``τ`` is
    ``Σ|X|² + Σ|H|² − 2·C(τ) + ν(τ)``, with ``C`` the correlation curve the search
    maximizes and ``ν`` the Nyquist bin's part (``|ν| ≤ X²_N + |C_N|``, zero for odd n).
    The fine maximum ``C(τ*)`` is at least the coarse maximum ``C_c`` (a fine point) and at
    most ``C_c + D₂h²/2``: at the continuous maximum ``C' = 0``, the nearest coarse point is
    at most ``h`` (half a coarse step) away and ``|C''| ≤ D₂ = Σ_k w_k|X_k||H_k|ω_k²``.
    A reference whose least possible energy exceeds the greatest of ``among`` others (with a
    margin for rounding, 1e-9 of the energies' scale) cannot be chosen, and needs no fine
    search.

    Parameters
    ----------
    sx : complex ndarray (c, n)
        Signal spectra.
    spec_r : complex ndarray (n_refs, n)
        Reference spectra.
    peak : ndarray (c, n_refs)
        The maximum of :meth:`_LagSearch.coarse_curve` for each signal × reference.
    search : _LagSearch
    among : int >= 1
    """
    n, m = search.n, search.n // 2 + 1
    abs_x, abs_r = np.abs(sx[:, :m]), np.abs(spec_r[:, :m])
    omega2 = (2 * np.pi * search.k / n) ** 2
    d2 = abs_x @ (abs_r * (search.weights * omega2)).T
    scale = abs_x @ (abs_r * search.weights).T  # ≥ max |C|
    energy = (np.sum(sx.real ** 2 + sx.imag ** 2, axis=-1)[:, None]
              + np.sum(spec_r.real ** 2 + spec_r.imag ** 2, axis=-1)[None])
    nyquist = np.zeros_like(energy)
    if n % 2 == 0:
        nyquist = abs_x[:, -1:] ** 2 + abs_x[:, -1:] * abs_r[:, -1]
    coarse_max = peak * (n * search.coarse)
    h = 0.5 / search.coarse
    least = energy - 2 * (coarse_max + d2 * h * h / 2) - nyquist
    most = energy - 2 * coarse_max + nyquist
    margin = 1e-9 * np.max(energy + 2 * scale, axis=-1, keepdims=True)
    among = min(max(int(among), 1), most.shape[-1])
    bound = np.partition(most, among - 1, axis=-1)[:, among - 1:among]
    return cast(BoolArray, least <= bound + margin)
