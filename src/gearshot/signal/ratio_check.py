"""Which multiple of a tracked speed the whole-record order spectrum favours.

A comb of mesh orders can lock on a ratio of the true speed: on a two-stage train whose
second stage meshes at 8 input orders, a comb at 1.5 times the speed puts its orders 16
and 32 on the true orders 24 and 48 (``3 × 8``, ``6 × 8``), real lines. Every shaft of the
train turns a whole number of times per some number of revolutions of the tracked shaft,
so at the *true* speed every whole order is a harmonic of the tracked shaft (and of the
others): the record's order spectrum along the tracked angle has a line at every whole
order. At 1.5 times the speed only every second whole order (the even ones, which are
whole orders of the truth) finds a line, at twice the speed the same, at half the speed
every second.

:func:`whole_order_scores` resamples the record at equal steps of the tracked angle
(the same order spectrum a synchronous average integrates) and scores a ratio ``r`` by
the mean level, over the local floor, of the whole orders of ``r`` times the tracked
speed, up to the same frequency for every ratio. The tracker
(:func:`gearshot.signal.tracking.estimate_shaft_angle`) compares the tracked speed with
each ratio 1/2, 2/3, 3/2, 2 of it that also lies in the searched range.
"""

from __future__ import annotations

import numpy as np

from .ridge import _RATIOS
from .speed_profile import _decimated, _gain, _levels

__all__ = ["RATIOS", "whole_order_scores"]

#: Speed ratios a comb of whole orders may lock on.
RATIOS = _RATIOS


def whole_order_scores(x: np.ndarray, fs: float, times: np.ndarray, angle: np.ndarray, *,
                       ratios: tuple[float, ...], top_order: float) -> dict[float, float]:
    """Mean level of the whole orders of ``r`` times a tracked speed, for every ratio.

    Parameters
    ----------
    x : ndarray, shape (n,)
        One sensor's vibration sampled at ``fs`` Hz.
    fs : float
        Sampling rate, Hz.
    times, angle : ndarray, shape (m,)
        The tracked shaft angle (revolutions) at increasing times (s).
    ratios : tuple of float
        Ratios ``r`` of the tracked speed to score (1 included where wanted).
    top_order : float
        Highest order of the tracked speed read (the same frequency band for every
        ratio): whole orders ``j`` of ``r`` times the speed with ``j r <= top_order``.

    Returns
    -------
    dict
        Ratio -> mean over those orders of the level above the local floor in excess of
        10 dB, capped at 30 dB (noise: near 0; a line at every order: 10 or more).

    Examples
    --------
    A shaft at 20 rev/s with a line at every whole order: its own speed scores high,
    1.5 times it (every second of its orders on a line) half as much.

    >>> import numpy as np
    >>> from gearshot.signal.ratio_check import whole_order_scores
    >>> fs = 4000.0
    >>> t = np.arange(int(4 * fs)) / fs
    >>> x = sum(np.cos(2 * np.pi * j * 20.0 * t + j) for j in range(1, 40))
    >>> x = x + np.random.default_rng(0).standard_normal(t.size)
    >>> s = whole_order_scores(x, fs, t, 20.0 * t, ratios=(1.0, 1.5), top_order=30)
    >>> bool(s[1.0] > 10 and 0.3 < s[1.5] / s[1.0] < 0.7)
    True
    """
    speed = np.gradient(angle, times)
    y, fs_d = _decimated(x, fs, top_order * float(speed.max()) * 1.1)
    t = np.arange(y.size) / fs_d
    sel = (t >= times[0]) & (t <= times[-1])
    theta = np.interp(t[sel], times, angle)
    step = float(speed.min()) / fs_d  # revolutions per sample at the slowest speed
    grid = np.arange(theta[0], theta[-1], step)
    z = np.interp(grid, theta, y[sel]) * np.hanning(grid.size)
    n = 1 << int(np.ceil(np.log2(2 * grid.size)))
    level = _levels(np.abs(np.fft.rfft(z, n)) ** 2)
    d_order = 1.0 / (n * step)  # bin width, orders of the tracked speed
    gain = _gain(level)
    out = {}
    for r in ratios:
        j = np.arange(1, int(top_order / r) + 1)
        i = np.clip(np.rint(r * j / d_order).astype(np.int64), 1, gain.size - 2)
        out[r] = float(np.mean(np.max(np.stack([gain[i - 1], gain[i], gain[i + 1]]), axis=0)))
    return out
