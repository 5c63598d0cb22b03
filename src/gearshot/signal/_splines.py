"""Cubic splines on a uniform grid, in NumPy (no SciPy import on the one-record path).

Both splines come down to the same linear system: the symmetric tridiagonal ``[1, 4, 1]``
(slopes of an interpolating cubic spline; B-spline coefficients of samples). Its inverse is
the two-sided geometric filter ``z^|k| / (2√3)`` with ``z = √3 − 2`` (the root of
``z² + 4z + 1 = 0`` inside the unit circle); the taps beyond 32 each side sum to less than
1e-18: 32 taps give it to rounding.

* :func:`bspline_read`: the cubic B-spline through equally spaced samples with mirror
  boundaries, read at fractional sample positions -- what
  ``scipy.ndimage.map_coordinates(spline_filter1d(x, 3, mode="mirror"), ..., order=3,
  mode="mirror", prefilter=False)`` gives (the coefficients are the exact mirror-extended
  convolution, as SciPy's exact boundary start gives).
* :class:`NotAKnotSpline`: the not-a-knot interpolating cubic spline on a uniform grid --
  what ``scipy.interpolate.CubicSpline(x, y)`` gives: interior slope equations
  ``s[i-1] + 4 s[i] + s[i+1] = 3 (m[i-1] + m[i])`` solved by the filter above, the two
  not-a-knot end rows by adding the decaying homogeneous solutions ``z^i`` and
  ``z^(n-1-i)`` (a 2 × 2 solve).
"""

from __future__ import annotations

import math

import numpy as np

from .._typing import FloatArray

__all__ = ["NotAKnotSpline", "bspline_read"]

_Z = math.sqrt(3.0) - 2.0
_K = 32  # taps each side of the [1, 4, 1] inverse: |z|^33 / (1 - |z|) < 1e-18
_INV141 = _Z ** np.abs(np.arange(-_K, _K + 1)) / (2.0 * math.sqrt(3.0))


def _solve141(r: FloatArray, mode: str) -> FloatArray:
    """``[1, 4, 1]``-inverse filter of ``r`` with its ends extended by ``mode``
    (``"reflect"``: mirror without repeating the end sample; ``"constant"``: zeros)."""
    padded: FloatArray = np.pad(r, _K, mode=mode)  # type: ignore[call-overload]
    return np.convolve(padded, _INV141, mode="valid")


def bspline_read(x: FloatArray, position: FloatArray) -> FloatArray:
    """Cubic B-spline interpolant of the samples ``x`` (1-D, at least 3, mirror boundaries)
    at the fractional sample indices ``position``."""
    n = x.size
    coeffs = _solve141(6.0 * x, "reflect")
    # one mirrored coefficient before, two after: indices -1 … n+1 -> 0 … n+2
    coeffs = np.concatenate([coeffs[1:2], coeffs, coeffs[n - 2:n - 4 if n > 3 else None:-1]])
    p = position
    if p.size and (p.min() < 0 or p.max() > n - 1):  # fold back into 0 … n-1
        period = 2.0 * (n - 1)
        p = np.abs(p) % period
        p = np.where(p > n - 1, period - p, p)
    base = np.floor(p)
    t = p - base
    i = base.astype(np.int64)
    u = 1.0 - t
    t2 = t * t
    out = u * u * u * coeffs[i]
    out += ((3.0 * t - 6.0) * t2 + 4.0) * coeffs[i + 1]
    out += (((3.0 - 3.0 * t) * t + 3.0) * t + 1.0) * coeffs[i + 2]
    out += t2 * t * coeffs[i + 3]
    return out / 6.0


class NotAKnotSpline:
    """Not-a-knot interpolating cubic spline through ``values`` at the uniform ``knots``
    (at least 4); as :class:`scipy.interpolate.CubicSpline` with its default end
    conditions, extrapolating the end pieces.

    Examples
    --------
    Four points of a cubic give that cubic:

    >>> import numpy as np
    >>> from gearshot.signal._splines import NotAKnotSpline
    >>> knots = np.arange(4.0)
    >>> curve = NotAKnotSpline(knots, knots ** 3)
    >>> print(curve(np.array([0.5, 2.5])), curve(np.array([1.5]), 1))
    [ 0.125 15.625] [6.75]
    """

    def __init__(self, knots: FloatArray, values: FloatArray) -> None:
        n = values.size
        self.knots = knots
        dx = np.diff(knots)
        m = np.diff(values) / dx
        r = np.zeros(n)
        r[1:-1] = 3.0 * (m[:-1] + m[1:])
        s = _solve141(r, "constant")
        zi = _Z ** np.arange(n)  # homogeneous solutions: zi and zi[::-1]
        a11, a12 = 1.0 + 2.0 * _Z, zi[-1] + 2.0 * zi[-2]
        b1 = 0.5 * (5.0 * m[0] + m[1]) - s[0] - 2.0 * s[1]
        b2 = 0.5 * (m[-2] + 5.0 * m[-1]) - 2.0 * s[-2] - s[-1]
        det = a11 * a11 - a12 * a12
        alpha, beta = (a11 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det
        s += alpha * zi + beta * zi[::-1]
        t = (s[:-1] + s[1:] - 2.0 * m) / dx
        self._c = (t / dx, (m - s[:-1]) / dx - t, s[:-1], values[:-1])

    def __call__(self, x: FloatArray, nu: int = 0) -> FloatArray:
        """Values (``nu=0``) or first derivatives (``nu=1``) at ``x``."""
        i = np.clip(np.searchsorted(self.knots, x, side="right") - 1, 0,
                    self.knots.size - 2)
        d = x - self.knots[i]
        c0, c1, c2, c3 = (c[i] for c in self._c)
        if nu == 1:
            return (3.0 * c0 * d + 2.0 * c1) * d + c2
        return ((c0 * d + c1) * d + c2) * d + c3
