"""Time–frequency ridge of a shaft's mesh harmonics: step 1 of
:mod:`gearshot.signal.tracking` (speed and angle from the vibration).

STFT (:class:`scipy.signal.ShortTimeFFT`, Hann window), every frame's power in dB above the
frame's median over the searched band, a comb over every mesh order of the shaft and its
harmonics for every candidate speed, and the best slowly-varying path by dynamic
programming.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._errors import GearshotError
from .._validation import as_signal_array, check_int, check_positive, describe

__all__ = ["SpeedRidge", "speed_ridge"]

_LINE_DB = 6.0  # a comb line "stands out" at this mean level above the median (noise: ~3)
_CAP_DB = 30.0  # one strong line counts at most this much in the comb score


@dataclass(frozen=True)
class SpeedRidge:
    """The speed ridge of :func:`speed_ridge`.

    Attributes
    ----------
    times : ndarray, shape (n_frames,)
        Frame centres, s from the first sample.
    speed : ndarray, shape (n_frames,)
        Shaft speed along the ridge, rev/s.
    order : int
        The order to demodulate: ``track``, or the harmonic of the shaft's own mesh
        (``orders[0]``) with the highest level along the ridge.
    level_db : float
        Mean level of that harmonic along the ridge, dB above the frames' median.
    n_lines, n_comb : int
        Comb lines (mesh order × harmonic, below Nyquist) whose mean level along the ridge
        is at least 6 dB above the frames' median, and comb lines in all.
    """

    times: np.ndarray
    speed: np.ndarray
    order: int
    level_db: float
    n_lines: int = 0
    n_comb: int = 0




def _orders(orders: Any) -> tuple[int, ...]:
    if isinstance(orders, (int, np.integer)) and not isinstance(orders, bool):
        orders = [orders]
    if not isinstance(orders, (Sequence, np.ndarray)) or len(orders) == 0:
        raise GearshotError(f"orders must be a positive integer or a non-empty sequence of "
                            f"them; got {describe(orders)}")
    out: list[int] = []
    for i, o in enumerate(orders):
        o = check_int(o, f"orders[{i}]", minimum=1, maximum=100_000)
        if o not in out:
            out.append(o)
    return tuple(out)


def _speed_range(speed_range: Any) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in speed_range)
    except (TypeError, ValueError):
        raise GearshotError(f"speed_range must be (low, high) in rev/s; got "
                            f"{describe(speed_range)}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
        raise GearshotError(f"speed_range must be (low, high) with 0 < low < high rev/s; got "
                            f"{describe(speed_range)}")
    return lo, hi


#: Speed ratios a comb of whole orders may lock on (a multi-shaft train's lines fit them).
_RATIOS = (1 / 2, 2 / 3, 3 / 2, 2.0)


def _ratios_in_range(speed_range: tuple[float, float], slow: float, fast: float
                     ) -> tuple[float, ...]:
    """The ratios ``r`` of :data:`_RATIOS` for which speeds from ``slow`` to ``fast``
    times ``r`` also lie inside ``speed_range``: a comb there cannot exclude them."""
    lo, hi = speed_range
    return tuple(r for r in _RATIOS if lo <= r * slow and r * fast <= hi)


def speed_ridge(x: np.ndarray, fs: float, *, orders: Any, speed_range: Any,
                n_harmonics: int = 3, window: float = 0.5, max_rate: float | None = None,
                smooth: float = 0.5, track: int | None = None) -> SpeedRidge:
    """Shaft speed along the time–frequency ridge of its mesh harmonics.

    Parameters
    ----------
    x : array_like, shape (n,)
        Vibration, any unit, sampled at ``fs``.
    fs : float
        Sampling rate, Hz.
    orders : int or sequence of int
        Mesh orders synchronous with the shaft (its gears' tooth counts and every other
        whole-order mesh, :meth:`gearshot.Machine.mesh_orders`), the shaft's own gear
        first: all of them vote for the speed; the harmonic demodulated afterwards is one
        of the first order's (another stage's mesh carries the other shafts' transmission
        errors in its phase).
    speed_range : (float, float)
        Lowest and highest shaft speed searched, rev/s. Keep it within an octave
        (high < 2 low) where the spectrum may hold strong lines at half the mesh orders:
        a comb at half the speed then cannot win.
    n_harmonics : int, default 3
        Harmonics of every mesh order in the comb (those below ``fs / 2``).
    window : float, default 0.5
        STFT window length, s (rounded to a power of two of samples); hop a quarter of it.
        Long enough to resolve the line from sidebands a third of an order away at 10
        rev/s; during a run-up the line's peak stays at the window's centre frequency
        (a chirp smears symmetrically), and the phase step corrects the rest.
    max_rate : float, optional
        Largest speed change, rev/s per second. Default: half the top of ``speed_range``
        per second.
    smooth : float, default 0.5
        Span of the local quadratic (Savitzky–Golay) that smooths the ridge, s.
    track : int, optional
        The order to follow (and demodulate). Default: the harmonic of ``orders[0]`` with
        the highest level along the ridge.

    Returns
    -------
    SpeedRidge

    Examples
    --------
    Two stages' mesh lines of a shaft at a steady 25 rev/s (orders 32 and 16):

    >>> import numpy as np
    >>> from gearshot.signal import speed_ridge
    >>> noise = 0.1 * np.random.default_rng(0).standard_normal(40_000)
    >>> phase = 2 * np.pi * 25.0 * np.arange(noise.size) / 20_000.0
    >>> x = np.sin(32 * phase) + 0.5 * np.sin(16 * phase) + noise
    >>> r = speed_ridge(x, 20_000.0, orders=[32, 16], speed_range=(15, 40))
    >>> bool(abs(np.median(r.speed) - 25.0) < 0.1)
    True
    """
    x = as_signal_array(x, "x", max_ndim=1, min_length=16)
    fs = check_positive(fs, "fs")
    order_list = _orders(orders)
    lo, hi = _speed_range(speed_range)
    n_harmonics = check_int(n_harmonics, "n_harmonics", minimum=1, maximum=100)
    max_rate = 0.5 * hi if max_rate is None else check_positive(max_rate, "max_rate")
    smooth = check_positive(smooth, "smooth")
    pairs, candidates = _comb_lines(order_list, n_harmonics, hi, fs, track)
    args = (x, fs, pairs, candidates, lo, hi, max_rate, smooth)
    return _ridge_pass(*args, check_positive(window, "window"))


def _comb_lines(orders: tuple[int, ...], n_harmonics: int, hi: float, fs: float,
                track: int | None) -> tuple[list[tuple[int, float]], list[int]]:
    """The comb's (order, weight) pairs below Nyquist (fundamentals count most) and the
    orders that may be demodulated."""
    pairs = [(h * o, 1.0 / h) for o in orders for h in range(1, n_harmonics + 1)
             if h * o * hi < 0.5 * fs]
    if not pairs:
        raise GearshotError(f"orders={list(orders)} at speed_range top {hi:g} rev/s lie above "
                            f"the Nyquist frequency {fs / 2:g} Hz")
    if track is None:
        return pairs, [h * orders[0] for h in range(1, n_harmonics + 1)
                       if h * orders[0] * hi < 0.5 * fs] or sorted({c for c, _ in pairs})
    track = check_int(track, "track", minimum=1, maximum=100_000)
    if track * hi >= 0.5 * fs:
        raise GearshotError(f"track={track} at {hi:g} rev/s is above the Nyquist "
                            f"frequency {fs / 2:g} Hz")
    return pairs, [track]


def _levels(x: np.ndarray, fs: float, combos: list[int], lo: float, hi: float,
            window: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, int, int]:
    """STFT power, its level in dB over every frame's median in the searched band (capped
    at 0 and :data:`_CAP_DB`), frame times, bin width, top bin and hop."""
    import scipy.signal  # lazy: a one-record call need not import it
    nper = int(2 ** round(math.log2(max(window * fs, 16.0))))
    if nper > x.size:
        raise GearshotError(f"x holds {x.size} samples, shorter than one STFT window of "
                            f"window={window:g} s ({nper} samples at fs={fs:g} Hz)")
    hop = max(1, nper // 4)
    stft = scipy.signal.ShortTimeFFT(scipy.signal.windows.hann(nper, sym=False), hop, fs)
    p0 = stft.lower_border_end[1]
    p1 = max(stft.upper_border_begin(x.size)[1], p0 + 1)
    power = stft.spectrogram(x, p0=p0, p1=p1)  # (n_freq, n_frames)
    times = stft.t(x.size, p0, p1)
    df = fs / nper
    top = min(power.shape[0] - 1, int(math.ceil(max(combos) * hi * 1.05 / df)) + 2)
    bottom = max(1, int(math.floor(min(combos) * lo * 0.95 / df)) - 1)
    level = 10.0 * np.log10(power[: top + 1] + 1e-30 * (power.max() + 1e-300))
    level -= np.median(level[bottom: top + 1], axis=0, keepdims=True)
    return power, np.clip(level, 0.0, _CAP_DB), times, df, top, hop


def _best_path(score: np.ndarray, jump: int) -> np.ndarray:
    """Indices of the best path through ``score`` (candidates × frames) that moves at
    most ``jump`` candidates per frame (dynamic programming)."""
    import scipy.ndimage  # lazy: a one-record call need not import it
    acc = np.empty_like(score)
    acc[:, 0] = score[:, 0]
    for k in range(1, score.shape[1]):
        acc[:, k] = score[:, k] + scipy.ndimage.maximum_filter1d(acc[:, k - 1], 2 * jump + 1,
                                                                 mode="nearest")
    path = np.empty(score.shape[1], dtype=np.int64)
    path[-1] = int(np.argmax(acc[:, -1]))
    for k in range(score.shape[1] - 1, 0, -1):
        a, b = max(0, path[k] - jump), min(score.shape[0], path[k] + jump + 1)
        path[k - 1] = a + int(np.argmax(acc[a:b, k - 1]))
    return path


def _followed(power: np.ndarray, level: np.ndarray, ridge: np.ndarray, df: float, top: int,
              candidates: list[int]) -> tuple[int, float, np.ndarray]:
    """The harmonic to follow (highest level along the ridge), its level, and the ridge
    moved to that harmonic's peak (parabola through the log power, within ±1 bin)."""
    frames = np.arange(ridge.size)
    best, best_level = candidates[0], -1.0
    for c in candidates:
        i0 = np.clip(np.rint(c * ridge / df).astype(np.int64), 1, top - 1)
        lev = float(np.mean(level[i0, frames]))
        if lev > best_level + 1e-9:
            best, best_level = c, lev
    i0 = np.clip(np.rint(best * ridge / df).astype(np.int64), 2, top - 2)
    nb = np.stack([power[i0 + d, frames] for d in (-1, 0, 1)])
    k = i0 + np.argmax(nb, axis=0) - 1  # local peak within ±1 bin
    a, b, c3 = (np.log(power[k + d, frames] + 1e-300) for d in (-1, 0, 1))
    denom = a - 2 * b + c3
    with np.errstate(divide="ignore", invalid="ignore"):
        delta = np.where(denom < 0, 0.5 * (a - c3) / denom, 0.0)
    refined = (k + np.clip(delta, -0.5, 0.5)) * df / best
    ok = np.abs(refined - ridge) <= 2.0 * df / best
    return int(best), best_level, np.where(ok, refined, ridge)


def _ridge_pass(x: np.ndarray, fs: float, pairs: list[tuple[int, float]],
                candidates: list[int], lo: float, hi: float, max_rate: float, smooth: float,
                window: float) -> SpeedRidge:
    """One STFT + comb + dynamic-programming pass of :func:`speed_ridge`."""
    import scipy.signal  # lazy: a one-record call need not import it
    combos = sorted({c for c, _ in pairs})
    power, level, times, df, top, hop = _levels(x, fs, combos, lo, hi, window)
    step = df / (2.0 * max(combos))
    speeds = np.arange(lo, hi + 0.5 * step, step)
    score = np.zeros((speeds.size, times.size))
    for c, w in pairs:
        pos = c * speeds / df
        i0 = np.clip(np.floor(pos).astype(np.int64), 0, top - 1)
        score += w * np.maximum(level[i0], level[i0 + 1])
    score /= sum(w for _, w in pairs)
    jump = max(1, int(math.ceil(max_rate * hop / fs / step)))
    ridge = speeds[_best_path(score, jump)]
    best, best_level, ridge = _followed(power, level, ridge, df, top, candidates)
    # the speed changes slowly: a local quadratic over ``smooth`` s takes out the beating of
    # the line with its sidebands inside one window, and keeps a ramp unbiased
    span = int(round(smooth * fs / hop)) | 1
    if span >= 5 and times.size >= 5:
        ridge = scipy.signal.savgol_filter(ridge, min(span, times.size - 1 + times.size % 2),
                                           2, mode="interp")
    # how many comb lines (order x harmonic) stand out along the final ridge
    frames = np.arange(times.size)
    lines = 0
    for c in combos:
        i0 = np.clip(np.rint(c * ridge / df).astype(np.int64), 0, top - 1)
        lev = np.maximum(level[i0, frames], level[np.minimum(i0 + 1, top), frames])
        lines += int(float(np.mean(lev)) >= _LINE_DB)
    return SpeedRidge(times=times, speed=ridge, order=best, level_db=best_level,
                      n_lines=lines, n_comb=len(combos))
