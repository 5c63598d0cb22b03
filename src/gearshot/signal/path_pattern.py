"""The transfer path's resonance pattern of a recording, and how far two patterns agree.

A tooth fault changes what the gears excite: the mesh harmonics, their sidebands and, as
it grows, the broadband energy of its impacts. It does not move the resonances of the
path from the gears to the sensor. Moving the sensor (a remount, another accelerometer,
another gearbox) does. The pattern of a recording is its spectrum's background (lines
removed by a running median over frequency), in log10, on a fixed logarithmic frequency
grid, less its own smooth trend (a running mean over the grid): what is left are the
path's resonances and anti-resonances, whatever the source's level and tilt.

:func:`path_pattern` computes it; :func:`pattern_correlation` compares a recording's
pattern with the mean pattern of others (the fit's healthy recordings) over the grid
points both hold.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._errors import GearshotError

__all__ = ["path_pattern", "pattern_correlation", "PATH_GRID_HZ", "MIN_PATTERN_POINTS"]

#: The pattern's frequency grid (Hz): 200 points, logarithmic from 300 Hz (above the
#: shafts' and the lowest meshes' lines of typical gearboxes) to 20 kHz; points at or
#: above 0.45 × the sampling rate are NaN.
PATH_GRID_HZ = np.geomspace(300.0, 20_000.0, 200)

#: Fewest grid points two patterns must share to be compared.
MIN_PATTERN_POINTS = 40

_SEGMENT = 4096        # Welch segment (samples)
_MEDIAN_HZ = 180.0     # running-median width that removes lines (Hz)
_TREND_POINTS = 31     # running-mean width of the trend removed (grid points: ×1.9 in f)


def path_pattern(x: ArrayLike, fs: float) -> NDArray[np.float64]:
    """The resonance pattern of one channel (module docstring).

    Parameters
    ----------
    x : array_like (n,)
        Acceleration samples (any unit: the pattern ignores the level).
    fs : float
        Sampling rate, Hz.

    Returns
    -------
    ndarray (len(PATH_GRID_HZ),)
        NaN at grid points the recording cannot show (above 0.45 fs); all NaN for a
        recording shorter than 2 Welch segments or without any energy.

    Examples
    --------
    Noise through a resonance at 3 kHz: the pattern peaks there.

    >>> import numpy as np
    >>> from scipy import signal
    >>> b, a = signal.iirpeak(3000, 8, fs=50_000)
    >>> x = signal.lfilter(b, a, np.random.default_rng(0).normal(size=200_000))
    >>> pattern = path_pattern(x + 0.05 * np.random.default_rng(1).normal(size=x.size), 50_000)
    >>> round(float(PATH_GRID_HZ[np.nanargmax(pattern)]), -2)
    3000.0
    """
    from scipy import ndimage, signal

    samples = np.asarray(x, dtype=float).reshape(-1)
    if not np.isfinite(fs) or fs <= 0:
        raise GearshotError(f"fs must be a positive sampling rate (Hz); got {fs!r}")
    out = np.full(PATH_GRID_HZ.size, np.nan)
    if samples.size < 2 * _SEGMENT or not np.all(np.isfinite(samples)):
        return out
    f, p = signal.welch(samples, fs=fs, nperseg=_SEGMENT)
    width = max(3, int(round(_MEDIAN_HZ / (f[1] - f[0]))) | 1)
    background = ndimage.median_filter(p, size=width, mode="nearest")
    shown = (PATH_GRID_HZ < 0.45 * fs) & (PATH_GRID_HZ > f[1])
    if not np.any(background > 0) or shown.sum() < _TREND_POINTS:
        return out
    floor = background[background > 0].min()
    level = np.log10(np.maximum(background, floor))
    grid = np.interp(np.log(PATH_GRID_HZ[shown]), np.log(f[1:]), level[1:])
    out[shown] = grid - ndimage.uniform_filter1d(grid, _TREND_POINTS, mode="nearest")
    return out


def pattern_correlation(pattern: ArrayLike, references: Sequence[ArrayLike]) -> float:
    """Pearson correlation of ``pattern`` with the mean of ``references`` over the grid
    points all of them show; NaN with fewer than :data:`MIN_PATTERN_POINTS` of them.

    Examples
    --------
    Two recordings through one path agree; through a path resonating elsewhere, not:

    >>> import numpy as np
    >>> from scipy import signal
    >>> rng = np.random.default_rng(0)
    >>> def heard(f0):
    ...     b, a = signal.iirpeak(f0, 8, fs=50_000)
    ...     x = signal.lfilter(b, a, rng.normal(size=200_000))
    ...     return path_pattern(x + 0.05 * rng.normal(size=x.size), 50_000)
    >>> ref = [heard(3000)]
    >>> bool(pattern_correlation(heard(3000), ref) > 0.9)
    True
    >>> bool(pattern_correlation(heard(7000), ref) < 0.5)
    True
    """
    mine = np.asarray(pattern, dtype=float).reshape(-1)
    refs = np.asarray([np.asarray(r, dtype=float).reshape(-1) for r in references])
    if not refs.size or refs.shape[1] != mine.size:
        raise GearshotError(f"references must hold patterns of {mine.size} points; got "
                            f"shape {refs.shape}")
    shown = np.isfinite(mine) & np.all(np.isfinite(refs), axis=0)
    if shown.sum() < MIN_PATTERN_POINTS:
        return float("nan")
    a, b = mine[shown], refs[:, shown].mean(axis=0)
    if a.std() == 0 or b.std() == 0:
        return float("nan")
    return float(np.corrcoef(a, b)[0, 1])
