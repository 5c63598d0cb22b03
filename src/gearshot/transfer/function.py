"""The :class:`TransferFunction` container: a measured or modelled FRF on a frequency axis in Hz."""

from __future__ import annotations

import dataclasses
import types
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._errors import GearshotError
from .._validation import as_signal_array, check_increasing, check_int, describe

__all__ = ["TransferFunction"]

_OUTSIDE = ("error", "edge", "zero")
_METHODS = ("linear", "magphase")


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.array(a, copy=True)
    a.flags.writeable = False
    return a


@dataclass(frozen=True, eq=False)
class TransferFunction:
    """A frequency response function (FRF) sampled on an increasing frequency axis.

    Parameters
    ----------
    freqs : array_like, shape (n_lines,)
        Frequency lines in Hz, finite, >= 0 and strictly increasing. The axis need not start
        at 0 Hz (measured FRFs often start one line above DC).
    values : array_like, shape (n_lines,)
        Complex FRF values at ``freqs`` (e.g. accelerance in (m/s²)/N).
    name : str
        Free-text identifier (UFF58 ``id1``; the file stem for files without one).
    response_node, response_direction, reference_node, reference_direction : int
        Degrees of freedom of the measurement (UFF58 convention: direction 1..3 = +X, +Y, +Z,
        negative for the opposite sense, 0 = scalar).
    response_quantity, reference_quantity : str
        Physical quantities of the numerator and denominator, e.g. ``"acceleration"`` and
        ``"force"`` for an accelerance.
    units : str
        Units of ``values`` as free text (``""`` when unknown).
    metadata : Mapping
        Further key/value pairs (e.g. the raw UFF58 header fields) kept for round trips.

    Notes
    -----
    Instances are immutable: ``freqs`` and ``values`` are read-only copies. Use
    :func:`dataclasses.replace` to derive a modified function.
    """

    freqs: np.ndarray
    values: np.ndarray
    name: str = ""
    response_node: int = 0
    response_direction: int = 0
    reference_node: int = 0
    reference_direction: int = 0
    response_quantity: str = "acceleration"
    reference_quantity: str = "force"
    units: str = ""
    metadata: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        freqs = as_signal_array(self.freqs, "freqs", min_ndim=1, max_ndim=1, min_length=2)
        values = as_signal_array(self.values, "values", min_ndim=1, max_ndim=1,
                                 min_length=2, allow_complex=True).astype(np.complex128)
        if values.shape != freqs.shape:
            raise GearshotError(f"values must have the shape of freqs {freqs.shape}; "
                                f"got {values.shape}")
        if freqs[0] < 0:
            raise GearshotError(f"freqs must be >= 0 Hz; got first line {float(freqs[0])!r}")
        check_increasing(freqs, "freqs", unit=" Hz")
        for key in ("response_node", "response_direction", "reference_node",
                    "reference_direction"):
            object.__setattr__(self, key, check_int(getattr(self, key), key))
        for key in ("name", "response_quantity", "reference_quantity", "units"):
            if not isinstance(getattr(self, key), str):
                raise GearshotError(f"{key} must be a str; got {describe(getattr(self, key))}")
        if not isinstance(self.metadata, Mapping):
            raise GearshotError(f"metadata must be a mapping; got {describe(self.metadata)}")
        object.__setattr__(self, "freqs", _readonly(freqs))
        object.__setattr__(self, "values", _readonly(values))
        object.__setattr__(self, "metadata", types.MappingProxyType(dict(self.metadata)))

    # ------------------------------------------------------------------ basic views
    @property
    def n_lines(self) -> int:
        """Number of frequency lines."""
        return int(self.freqs.size)

    @property
    def band(self) -> tuple[float, float]:
        """First and last frequency line in Hz."""
        return float(self.freqs[0]), float(self.freqs[-1])

    @property
    def df(self) -> float:
        """Median line spacing in Hz."""
        return float(np.median(np.diff(self.freqs)))

    @property
    def magnitude(self) -> np.ndarray:
        """``|values|``, shape (n_lines,)."""
        return np.abs(self.values)

    @property
    def phase(self) -> np.ndarray:
        """Unwrapped phase of ``values`` in rad, shape (n_lines,)."""
        return np.unwrap(np.angle(self.values))

    def __repr__(self) -> str:
        lo, hi = self.band
        return (f"TransferFunction(name={self.name!r}, n_lines={self.n_lines}, "
                f"band=({lo:g}, {hi:g}) Hz, {self.response_quantity}/{self.reference_quantity}"
                f"{', units=' + repr(self.units) if self.units else ''})")

    def __eq__(self, other: object) -> bool:
        """Same lines, values, name, DOFs, quantities and units (``metadata`` is ignored)."""
        if not isinstance(other, TransferFunction):
            return NotImplemented
        same_meta = all(getattr(self, f.name) == getattr(other, f.name)
                        for f in dataclasses.fields(self)
                        if f.name not in ("freqs", "values", "metadata"))
        return (same_meta and np.array_equal(self.freqs, other.freqs)
                and np.array_equal(self.values, other.values))

    __hash__ = None  # type: ignore[assignment]

    # ------------------------------------------------------------------ operations
    def to_signal_grid(self, n: int) -> np.ndarray:
        """Resample to an ``n``-point two-sided DFT grid on a normalized frequency axis.

        The measured lines are treated as the one-sided half of the grid (first line ↔ DC,
        last line ↔ Nyquist); this is the reference implementation's way of propagating
        synchronous averages through a TF, identical to
        :func:`gearshot.transfer.resample_transfer_function` applied to ``values``.

        Parameters
        ----------
        n : int
            Length of the output grid (e.g. 2048 points per SA cycle).

        Returns
        -------
        numpy.ndarray of complex, shape (n,)
            Hermitian-symmetric TF, ready for ``real(ifft(tf * fft(x)))``.
        """
        from .estimation import resample_transfer_function  # lazy: lead's module

        n = check_int(n, "n", minimum=2)
        return resample_transfer_function(np.array(self.values), n)

    def at(self, freqs: Any, *, method: str = "linear", outside: str = "error") -> np.ndarray:
        """Interpolate the FRF at physical frequencies.

        Parameters
        ----------
        freqs : array_like
            Frequencies in Hz (any shape).
        method : {"linear", "magphase"}
            ``"linear"``: linear interpolation of the real and imaginary parts (exact at the
            lines, never overshoots). ``"magphase"``: linear interpolation of the magnitude
            and of the unwrapped phase (keeps the magnitude between neighbouring lines).
        outside : {"error", "edge", "zero"}
            What to do with frequencies outside ``band``. Frequencies within one line spacing
            of either end are always clamped to the end value (so a measurement that starts
            one line above DC still answers at 0 Hz). Beyond that: ``"error"`` raises,
            ``"edge"`` holds the end values, ``"zero"`` returns 0.

        Returns
        -------
        numpy.ndarray of complex, shape of ``freqs``
        """
        f = as_signal_array(freqs, "freqs", min_ndim=0)
        if method not in _METHODS:
            raise GearshotError(f"method must be one of {_METHODS}; got {method!r}")
        if outside not in _OUTSIDE:
            raise GearshotError(f"outside must be one of {_OUTSIDE}; got {outside!r}")
        lo, hi = self.band
        slack = self.df * (1 + 1e-9)
        far = (f < lo - slack) | (f > hi + slack)
        if outside == "error" and np.any(far):
            bad = float(f[far].ravel()[0])
            raise GearshotError(
                f"freqs reach {bad!r} Hz, outside the band of TF {self.name!r} "
                f"[{lo:g}, {hi:g}] Hz; pass outside='edge' or outside='zero'")
        if method == "linear":
            out = (np.interp(f, self.freqs, self.values.real)
                   + 1j * np.interp(f, self.freqs, self.values.imag))
        else:
            out = np.interp(f, self.freqs, self.magnitude) * np.exp(
                1j * np.interp(f, self.freqs, self.phase))
        if outside == "zero":
            out = np.where(far, 0.0, out)
        return np.asarray(out, dtype=np.complex128)

    def normalized(self) -> TransferFunction:
        """Return a copy scaled to unit RMS magnitude.

        The scale is chosen so that ``sqrt(mean(|values|**2)) == 1`` over the measured
        one-sided lines (each line weighted equally, DC and the last line included once).
        Because :meth:`to_signal_grid` resamples on a normalized axis, this is also, to
        interpolation accuracy, the RMS gain of the TF applied to white noise — so propagating
        a signal through a normalized TF keeps its RMS level. The phase is untouched.
        """
        rms = float(np.sqrt(np.mean(np.abs(self.values) ** 2)))
        if rms == 0.0:
            raise GearshotError(f"TF {self.name!r} is identically zero; it cannot be normalized")
        return dataclasses.replace(self, values=self.values / rms)
