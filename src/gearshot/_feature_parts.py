"""The decompositions of a batch of SAs that the condition indicators share
(:mod:`gearshot.features`): spectrum, difference signal, envelope, Zakrajsek difference,
residual and regular meshing signal, each computed once, on first use.

A batch is given either as SAs or as their one-sided spectra (``rfft``): the simulated
side of the estimator builds its signals in the frequency domain (propagation, scaling,
twin subtraction and the matched noise are linear), and the features then start from
that spectrum instead of an inverse and a forward FFT more.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import cached_property
from typing import cast

import numpy as np

from ._typing import ComplexArray, FloatArray, IntArray
from .signal.orders import mesh_band_orders

_TINY_RMS = 1e-10
_SHAFT_ORDERS = (1, 2)


class _Parts:
    """Lazily computed decompositions of a batch of SAs, shared between features.

    ``sa`` (n_signals, n) or, with ``sa=None``, ``spectrum`` (n_signals, n // 2 + 1) and
    ``n_points``.
    """

    def __init__(self, sa: FloatArray | None, mesh_order: int | tuple[int, ...],
                 n_sidebands: int, baseline_variance: float | None,
                 shaft_orders: Sequence[int] = _SHAFT_ORDERS, *,
                 spectrum: ComplexArray | None = None, n_points: int | None = None) -> None:
        if sa is not None:
            self.__dict__["sa"] = sa
            self.n = sa.shape[-1]
        elif spectrum is not None and n_points is not None:
            self.n = n_points
        else:
            raise ValueError("_Parts needs the SAs or their spectrum and length")
        if spectrum is not None:
            self.__dict__["spectrum"] = spectrum
        self.mesh_orders = tuple(mesh_order) if isinstance(mesh_order, tuple) else (mesh_order,)
        self.mesh_order: int | tuple[int, ...] = (self.mesh_orders if len(self.mesh_orders) > 1
                                                  else self.mesh_orders[0])
        self.n_sidebands = n_sidebands
        self.baseline_variance = baseline_variance
        self.shaft_orders = tuple(shaft_orders)

    @cached_property
    def sa(self) -> FloatArray:
        return np.fft.irfft(self.spectrum, n=self.n, axis=-1)

    @cached_property
    def spectrum(self) -> ComplexArray:
        return np.fft.rfft(self.sa, axis=-1)

    def _keep(self, orders: IntArray, *, invert: bool = False) -> FloatArray:
        mask = np.zeros(self.n // 2 + 1, dtype=bool)
        mask[orders] = True
        if invert:
            mask = ~mask
        return np.fft.irfft(self.spectrum * mask, n=self.n, axis=-1)

    def _mesh(self, n_sidebands: int) -> IntArray:
        return mesh_band_orders(self.n, self.mesh_order, n_sidebands)

    @cached_property
    def diff_spectrum(self) -> ComplexArray:
        out = self.spectrum.copy()
        out[..., self._mesh(self.n_sidebands)] = 0.0
        return out

    @cached_property
    def diff(self) -> FloatArray:
        return np.fft.irfft(self.diff_spectrum, n=self.n, axis=-1)

    @cached_property
    def rms_diff(self) -> FloatArray:
        return cast(FloatArray, np.sqrt(np.mean(self.diff ** 2, axis=-1)))

    @cached_property
    def envelope(self) -> FloatArray:
        # |analytic signal| (as scipy.signal.hilbert): its real part is the difference
        # signal, its imaginary part the Hilbert transform, the real inverse FFT of
        # -i X_k over 0 < k < n/2 (DC and Nyquist give no imaginary part)
        n, half = self.n, self.diff_spectrum
        quad = -1j * half
        quad[..., 0] = 0.0
        if n % 2 == 0:
            quad[..., n // 2] = 0.0
        hilb = np.fft.irfft(quad, n=n, axis=-1)
        return _centred_modulus(self.diff, hilb)

    @cached_property
    def regular_mesh(self) -> FloatArray:
        return self._keep(self._mesh(1))

    @cached_property
    def zakrajsek_diff(self) -> FloatArray:
        orders = np.union1d(self._mesh(1), [0, *self.shaft_orders])
        return self._keep(orders, invert=True)

    @cached_property
    def residual(self) -> FloatArray:
        orders = np.union1d(self._mesh(0), [0, *self.shaft_orders])
        return self._keep(orders, invert=True)


def _centred_modulus(re: FloatArray, im: FloatArray) -> FloatArray:
    """``|re + i·im|`` minus its mean along the last axis.

    ``sqrt(re² + im²)`` in place (within an ulp of ``np.hypot``, five times faster);
    ``np.hypot`` for rows whose squares could overflow or underflow.
    """
    env = re * re
    env += im * im
    peak = env.max(axis=-1, initial=0.0)
    odd = ~((peak < 1e300) & ((peak > 1e-280) | (peak == 0.0)))
    np.sqrt(env, out=env)
    if np.any(odd):
        env[odd] = np.hypot(re[odd], im[odd])
    env -= env.mean(axis=-1, keepdims=True)
    return env


def _moment_ratio(x: FloatArray, order: int, *,
                  variance: float | FloatArray | None = None) -> FloatArray:
    """Biased normalized central moment ``mean(m^order) / var^(order/2)``; 0 if RMS tiny."""
    centred = x - x.mean(axis=-1, keepdims=True)
    square = centred * centred
    own_var = np.mean(square, axis=-1)
    var = own_var if variance is None else np.broadcast_to(variance, own_var.shape)
    power = centred if order % 2 else square  # integer powers by multiplication: fast
    for _ in range(order // 2 - (0 if order % 2 else 1)):
        power = power * square
    num = np.mean(power, axis=-1)
    small = np.sqrt(own_var) < _TINY_RMS
    with np.errstate(divide="ignore", invalid="ignore"):
        out = num / var ** (order / 2)
    return cast(FloatArray, np.where(small, 0.0, out))
