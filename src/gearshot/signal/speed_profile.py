"""A whole-record speed profile fitted to the coherent order spectrum of the mesh lines.

Where a run-up smears the mesh lines over many bins of any short-time spectrum (and the
ridge of :mod:`gearshot.signal.ridge` then sees them only a few dB above the floor), the
record as a whole still holds them coherently — the synchronous average integrates over
every revolution. :func:`fit_speed_profile` looks for the speed profile

``s(t) = c + a (t - t_m) + q (t - t_m)^2``  (rev/s; ``t_m`` the record's middle)

whose angle ``θ(t) = ∫ s dt`` makes the mesh orders of the shaft stand out most in the
spectrum of the signal resampled at equal steps of ``θ`` (an order spectrum over the whole
record). For one *shape* ``a / c`` the resampling is done once and the spectrum read at
``h o c`` for every candidate ``c`` (orders ``o`` of the shaft, harmonics ``h``); the rate
``a`` is searched coarse to fine on the middle quarter, half and whole record (the grid
step ``1 / (2 O h^2)`` keeps the quadratic phase error of a wrong rate below a quarter
cycle at the highest order ``O`` over a half-span ``h``); ``c``, ``a`` and ``q`` are then
refined together by maximizing the coherent power of the lines that stand out
(Nelder–Mead, :func:`scipy.optimize.minimize`).

A line's level is its power over the local floor (a running median of the spectrum,
:func:`scipy.ndimage.median_filter`) in dB; the comb's score sums their :func:`_gain`.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from .._errors import GearshotError
from .._validation import as_signal_array, check_int, check_positive
from .ridge import _orders, _ratios_in_range, _speed_range

__all__ = ["SpeedProfile", "fit_speed_profile"]

_FLOOR_DB = 10.0  # a comb line scores only above this level over the floor (noise: rarely)
_CAP_DB = 30.0  # one line counts at most this much
_LINE_DB = 15.0  # a line "stands out" in the whole-record order spectrum (noise: < 14)
_SHAFT_WEIGHT = 0.5  # a whole order that is no mesh line counts half (f / j fits any line)
_RATES = 160  # rates searched on the first span at most
_KEEP = 6  # rate candidates carried from one stage to the next
_KEEP_LAST = 3  # ... into the whole record's stage (the half record has sorted them)
_CELL = 16  # neighbouring candidate speeds bounded together by the comb's search
_MEDIAN_BINS = 129  # local floor: running median over this many spectrum bins


@dataclass(frozen=True)
class SpeedProfile:
    """A speed profile fitted by :func:`fit_speed_profile`.

    Attributes
    ----------
    mid : float
        Time of the record's middle ``t_m``, s.
    coef : tuple of float
        ``(c, a, q)``: the speed is ``c + a (t - t_m) + q (t - t_m)^2`` rev/s.
    lines : tuple of (int, float)
        Every comb line (order, level in dB over the local floor of the whole-record order
        spectrum), strongest first.
    n_lines : int
        Whole orders of the shaft up to the top mesh line (mesh lines, the shafts'
        harmonics and sidebands) at least 15 dB over the floor; 0 where no mesh line is.
    """

    mid: float
    coef: tuple[float, float, float]
    lines: tuple[tuple[int, float], ...]
    n_lines: int

    def ambiguous(self, speed_range: tuple[float, float], duration: float) -> float | None:
        """A ratio ``r`` (1/2, 2/3, 3/2, 2) for which ``r`` times this profile over the
        record (0 to ``duration`` s) also lies inside ``speed_range``, else None: there
        the whole orders of a multi-shaft train (other shafts' harmonics at fractional
        orders) may fit ``r`` times the true speed as well, and the fit cannot tell."""
        s = self.speed(np.linspace(0.0, duration, 65))
        found = _ratios_in_range(speed_range, float(s.min()), float(s.max()))
        return float(found[0]) if found else None

    def speed(self, t: np.ndarray) -> np.ndarray:
        """Shaft speed at times ``t`` (s from the first sample), rev/s."""
        c, a, q = self.coef
        u = np.asarray(t, dtype=np.float64) - self.mid
        return np.asarray(c + a * u + q * u * u)

    def angle(self, t: np.ndarray) -> np.ndarray:
        """Shaft angle at times ``t``, revolutions (0 at the record's middle)."""
        return _angle(np.asarray(t, dtype=np.float64) - self.mid, self.coef)


def _angle(u: np.ndarray, coef: tuple[float, float, float]) -> np.ndarray:
    c, a, q = coef
    return np.asarray(u * (c + u * (a / 2.0 + u * q / 3.0)))


def _decimated(x: np.ndarray, fs: float, top: float) -> tuple[np.ndarray, float]:
    """``x`` low-passed and decimated to about 3 samples per period of ``top`` Hz."""
    import scipy.signal
    down = max(1, int(fs // (3.0 * top)))
    if down == 1:
        return x - x.mean(), fs
    return scipy.signal.resample_poly(x - x.mean(), 1, down), fs / down


@functools.lru_cache(maxsize=8)
def _hann(n: int) -> np.ndarray:
    """``numpy.hanning(n)``, kept: the rate search reads hundreds of spectra of one length."""
    w = np.hanning(n)
    w.flags.writeable = False
    return w


def _spectrum(y: np.ndarray, dt: float, u: np.ndarray, shape: tuple[float, float],
              search: bool = False) -> tuple[np.ndarray, float]:
    """Power spectrum of ``y`` (sampled at ``u``) resampled at equal steps of the angle of
    the unit-speed profile ``1 + r u + p u^2``; returns (power, bin width in orders × c).
    ``search``: single precision and a fast FFT length about twice the samples (the rate
    search reads hundreds of these; the final line levels use a power of two)."""
    import scipy.fft
    r, p = shape
    phi = _angle(u, (1.0, r, p))
    rel = 1.0 + r * u + p * u * u
    step = dt * float(rel.min())
    grid = np.arange(phi[0], phi[-1], step)
    z = np.interp(grid, phi, y) * _hann(grid.size)
    if search:
        n = scipy.fft.next_fast_len(2 * grid.size, real=True)
        spec = scipy.fft.rfft(z.astype(np.float32), n)
        return np.asarray(spec.real ** 2 + spec.imag ** 2), 1.0 / (n * step)
    n = 1 << int(math.ceil(math.log2(2 * grid.size)))
    return np.abs(np.fft.rfft(z, n)) ** 2, 1.0 / (n * step)


def _gain(level: np.ndarray) -> np.ndarray:
    """A line's share of a comb score: dB over :data:`_FLOOR_DB`, at most :data:`_CAP_DB`."""
    return np.asarray(np.clip(level - _FLOOR_DB, 0.0, _CAP_DB))


def _levels(power: np.ndarray) -> np.ndarray:
    """Level over the local floor, dB: the floor is the median of blocks of
    :data:`_MEDIAN_BINS` bins, interpolated between the blocks' centres."""
    nb = max(1, power.size // _MEDIAN_BINS)
    blocks = power[: nb * _MEDIAN_BINS].reshape(nb, -1)
    centres = (np.arange(nb) + 0.5) * blocks.shape[1]
    floor = np.interp(np.arange(power.size), centres, np.median(blocks, axis=1))
    if power.dtype == np.float32:
        tiny = np.float32(1e-30)
        return np.asarray(10.0 * np.log10(power / (floor.astype(np.float32) + tiny) + tiny))
    return np.asarray(10.0 * np.log10(power / (floor + 1e-300) + 1e-30))


def _comb_rows(gain: np.ndarray, rows: np.ndarray, per_bin: np.ndarray, mesh: np.ndarray,
               n_kept: np.ndarray) -> np.ndarray:
    """The comb score of the speeds ``rows`` (float32) as :func:`_comb` defines it."""
    g = gain[np.minimum(np.outer(rows, per_bin).astype(np.int32), gain.size - 1)]
    shaft = np.cumsum(np.where(mesh, np.float32(0.0), g), axis=1, dtype=np.float32)
    kept = shaft[np.arange(rows.size), np.maximum(n_kept - 1, 0)]
    return np.asarray(g[:, mesh].sum(axis=1) + _SHAFT_WEIGHT * np.where(n_kept > 0, kept, 0.0))


def _comb(level: np.ndarray, df: float, lines: np.ndarray, speeds: np.ndarray,
          top_hz: float) -> tuple[float, int]:
    """Best comb score over the candidate speeds and its index (the first of equals). The
    score sums the levels above the floor over the mesh ``lines`` and, at half weight,
    every other whole order below ``top_hz`` (Hz, the same for every candidate, so that
    twice the speed, which meets only the even orders, loses; half weight, since some
    whole order ``j`` meets any line at the speed ``f / j``).

    Branch and bound: for cells of :data:`_CELL` neighbouring speeds an upper bound (each
    order's largest gain over the bins the cell's speeds reach, every order the cell's
    slowest speed keeps) orders the cells; exact scores are computed cell by cell until
    no bound is above the best — the same maximum as scoring every speed."""
    import scipy.ndimage
    gain = _gain(level).astype(np.float32)
    gain = np.maximum(gain[:-1], gain[1:])  # the line between two bins: the larger
    orders = np.arange(1.0, max(float(lines.max()), top_hz / float(speeds.min())) + 1.0)
    mesh = np.isin(orders, lines)
    per_bin = (orders / df).astype(np.float32)
    n_kept = np.minimum(np.floor(top_hz / speeds).astype(np.int64), orders.size)
    sf = speeds.astype(np.float32)
    starts = np.arange(0, speeds.size, _CELL)
    ends = np.minimum(starts + _CELL, speeds.size) - 1
    width = int(float(np.max(sf[ends] - sf[starts])) * float(per_bin[-1])) + 3
    pooled = scipy.ndimage.maximum_filter1d(gain, width, mode="nearest")
    first = np.minimum(np.outer(sf[starts], per_bin).astype(np.int64) + width // 2,
                       gain.size - 1)
    g = pooled[first]
    shaft = np.cumsum(np.where(mesh, np.float32(0.0), g), axis=1, dtype=np.float32)
    kept = shaft[np.arange(starts.size), np.maximum(n_kept[starts] - 1, 0)]
    bound = (g[:, mesh].sum(axis=1) + _SHAFT_WEIGHT * np.where(n_kept[starts] > 0, kept, 0.0))
    bound = bound * (1.0 + 1e-5) + 1e-3  # float32 sums in another order
    best, best_k = -np.inf, 0
    order = np.argsort(-bound, kind="stable")
    for g0 in range(0, order.size, 8):
        cells = order[g0: g0 + 8]
        if bound[cells[0]] < best:
            break
        idx = np.concatenate([np.arange(starts[c], ends[c] + 1) for c in cells])
        score = _comb_rows(gain, sf[idx], per_bin, mesh, n_kept[idx])
        top = float(score.max())
        k = int(idx[score == top].min())
        if top > best or (top == best and k < best_k):
            best, best_k = top, k
    return best, best_k


def _stage(y: np.ndarray, dt: float, u: np.ndarray, lines: np.ndarray, lo: float, hi: float,
           rates: np.ndarray) -> list[tuple[float, float, float]]:
    """Best (score, c, a) for every candidate rate ``a`` on the samples at ``u``.

    A comb over the mesh lines alone also fits at ``c m / o`` (its lines then fall on
    other whole orders: the shafts' harmonics and sidebands); only the true speed puts
    every whole order on a line, so the comb holds them all (:func:`_comb`).
    """
    c_mid = 0.5 * (lo + hi)
    out = []
    for a in rates:
        power, df = _spectrum(y, dt, u, (a / c_mid, 0.0), search=True)
        # the comb reads no bin above the top line at the top speed
        level = _levels(power[: int(float(lines.max()) * hi / df) + _MEDIAN_BINS])
        speeds = np.arange(lo, hi, df / float(lines.max()))
        score, k = _comb(level, df, lines, speeds, float(lines.max()) * lo)
        out.append((score, float(speeds[k]), float(a)))  # a: the shape a / c_mid
    return out


def _search(y: np.ndarray, fs: float, lines: np.ndarray, lo: float, hi: float,
            max_rate: float) -> tuple[float, float]:
    """Coarse-to-fine (c, a) on the middle quarter (twice: the capped grid of rates, then
    the step the quarter resolves), half and whole record."""
    n = y.size
    t = np.arange(n) / fs
    mid = 0.5 * t[-1]
    top = float(lines.max())
    best: list[tuple[float, float, float]] = []
    prev = 0.0
    for frac in (0.25, 0.25, 0.5, 1.0):  # the quarter twice: coarse rates, then its own
        half = 0.5 * frac * t[-1]
        sel = np.abs(t - mid) <= half
        step = 0.5 / (top * half * half)
        if not best:  # at most _RATES rates on the first span (the later ones refine)
            step = max(step, 2.0 * max_rate / _RATES)
            rates = np.arange(-max_rate, max_rate + 0.5 * step, step)
        elif prev <= step:
            continue  # the first grid was already as fine as this span resolves
        else:
            k = max(1, int(math.ceil(prev / step)))
            rates = np.unique(np.concatenate([a + step * np.arange(-k, k + 1)
                                              for _, _, a in best]))
        found = _stage(y[sel], 1.0 / fs, t[sel] - mid, lines, lo, hi, rates)
        best = sorted(found, reverse=True)[:_KEEP if frac < 0.5 else _KEEP_LAST]
        prev = step
    c = best[0][1]
    return c, best[0][2] * c / (0.5 * (lo + hi))  # the grid's rate is for the shape a / c_mid


def _line_levels(y: np.ndarray, fs: float, coef: tuple[float, float, float],
                 orders: np.ndarray) -> np.ndarray:
    """Level (dB over the local floor) of every order in the whole record's order
    spectrum along the profile ``coef``."""
    u = np.arange(y.size) / fs - 0.5 * (y.size - 1) / fs
    c = coef[0]
    power, df = _spectrum(y, 1.0 / fs, u, (coef[1] / c, coef[2] / c))
    level = _levels(power)
    i0 = np.clip(np.rint(orders * c / df).astype(np.int64), 1, level.size - 2)
    return np.asarray(np.max(np.stack([level[i0 + d] for d in (-1, 0, 1)]), axis=0))


def _refine(y: np.ndarray, fs: float, coef: tuple[float, float, float],
            strong: np.ndarray) -> tuple[float, float, float]:
    """(c, a, q) maximizing the coherent power of the ``strong`` lines (Nelder–Mead on
    each line mixed to 0 Hz with the grid's profile and decimated: the correction's phase
    changes by a fraction of a cycle over the record)."""
    import scipy.optimize
    import scipy.signal
    u = np.arange(y.size) / fs - 0.5 * (y.size - 1) / fs
    theta = _angle(u, coef)
    down = max(1, int(fs // 200.0))
    base = np.stack([scipy.signal.resample_poly(y * np.exp(-2j * np.pi * o * theta), 1, down)
                     for o in strong]) * np.hanning(-(-y.size // down))
    ud = u[::down][: base.shape[1]]
    half = float(u[-1])
    scale = np.array([1.0, 1.0 / half, 1.0 / half ** 2]) / (4.0 * half * float(strong.max()))
    powers = np.array([ud, ud * ud / 2.0, ud ** 3 / 3.0])

    def cost(z: np.ndarray) -> float:
        dtheta = (z * scale) @ powers
        return -float(np.sum(np.abs(np.sum(base * np.exp(-2j * np.pi * np.outer(strong, dtheta)),
                                           axis=1)) ** 2))

    res = scipy.optimize.minimize(cost, np.zeros(3), method="Nelder-Mead",
                                  options={"xatol": 1e-3, "fatol": 1e-12, "maxiter": 600})
    c, a, q = (float(v) for v in np.asarray(coef) + res.x * scale)
    return c, a, q


def fit_speed_profile(x: np.ndarray, fs: float, *, orders: object,
                      speed_range: object, n_harmonics: int = 5,
                      max_rate: float | None = None) -> SpeedProfile:
    """Speed profile of a shaft from the whole record's order spectrum of its mesh lines.

    Parameters
    ----------
    x : array_like, shape (n,)
        One sensor's vibration.
    fs : float
        Its sampling rate, Hz.
    orders : int or sequence of int
        Mesh orders synchronous with the shaft (its own gear first).
    speed_range : (float, float)
        Speeds searched, rev/s (the profile's middle speed ``c`` lies in it).
    n_harmonics : int, default 5
        Harmonics of every order in the comb (those below 0.4 ``fs``).
    max_rate : float, optional
        Largest speed change searched, rev/s per second. Default: the rate that takes the
        speed across the whole range in the record.

    Returns
    -------
    SpeedProfile

    Examples
    --------
    A 17-tooth pinion's mesh and its 2nd harmonic during a run-up from 12 to 16 rev/s,
    buried in noise of twice their amplitude:

    >>> import numpy as np
    >>> from gearshot.signal.speed_profile import fit_speed_profile
    >>> fs = 5000.0
    >>> t = np.arange(int(4 * fs)) / fs
    >>> revs = 12.0 * t + 0.5 * t ** 2
    >>> rng = np.random.default_rng(0)
    >>> x = np.cos(2 * np.pi * 17 * revs) + np.cos(2 * np.pi * 34 * revs)
    >>> x += 2.0 * rng.standard_normal(t.size)
    >>> p = fit_speed_profile(x, fs, orders=[17], speed_range=(10, 19))
    >>> c, a, q = p.coef
    >>> print(f"{c:.2f} rev/s at mid-record, {a:.2f} rev/s per s;", p.n_lines, "lines")
    14.00 rev/s at mid-record, 1.00 rev/s per s; 2 lines
    """
    return _fit(x, fs, orders, speed_range, n_harmonics, max_rate)


def _fit(x: np.ndarray, fs: float, orders: object, speed_range: object, n_harmonics: int,
         max_rate: float | None, guard: bool = False) -> SpeedProfile:
    """:func:`fit_speed_profile`; ``guard``: return the unrefined profile of the rate
    search where a ratio of it (1/2 … 2) lies well inside ``speed_range`` (1 % from its
    ends): the tracker refuses such a profile, and the refinement (Nelder–Mead) moves
    the speed by far less than that."""
    x = as_signal_array(x, "x", max_ndim=1, min_length=64)
    fs = check_positive(fs, "fs")
    order_list = _orders(orders)
    lo, hi = _speed_range(speed_range)
    n_harmonics = check_int(n_harmonics, "n_harmonics", minimum=1, maximum=100)
    duration = x.size / fs
    if max_rate is None:
        max_rate = (hi - lo) / duration
    max_rate = check_positive(max_rate, "max_rate")
    lines = np.array(sorted({h * o for o in order_list for h in range(1, n_harmonics + 1)
                             if h * o * hi * (1.0 + max_rate * duration / (2 * lo))
                             < 0.4 * fs}), dtype=np.float64)
    if lines.size == 0:
        raise GearshotError(f"orders={list(order_list)} at speed_range top {hi:g} rev/s lie "
                            f"above 0.4 fs = {0.4 * fs:g} Hz")
    top_hz = float(lines.max()) * (hi + max_rate * duration / 2)
    y, fs_d = _decimated(x, fs, top_hz)
    c, a = _search(y, fs_d, lines, lo, hi, max_rate)
    if guard:
        coarse = _profile(y, fs_d, lines, (c, a, 0.0))
        if coarse.ambiguous((1.01 * lo, 0.99 * hi), duration) is not None:
            return coarse
    level = _line_levels(y, fs_d, (c, a, 0.0), lines)
    strong = lines[np.argsort(-level)[:3]]
    chain = (c, a, 0.0)
    for frac in (0.25, 0.5, 1.0):  # continuation: a curvature is local on a short span
        m0 = int(0.5 * (1.0 - frac) * y.size)
        chain = _refine(y[m0: y.size - m0], fs_d, chain, strong)
    direct = _refine(y, fs_d, (c, a, 0.0), strong)  # a short span may mislead the chain
    coef = max((direct, chain), key=lambda k: float(_line_levels(y, fs_d, k, strong).sum()))
    return _profile(y, fs_d, lines, coef)


def _profile(y: np.ndarray, fs_d: float, lines: np.ndarray,
             coef: tuple[float, float, float]) -> SpeedProfile:
    """The :class:`SpeedProfile` of ``coef``: its lines' levels and whole orders counted."""
    level = _line_levels(y, fs_d, coef, lines)
    whole = np.arange(1.0, float(lines.max()) + 1.0)
    n_lines = int(np.sum(_line_levels(y, fs_d, coef, whole) >= _LINE_DB))
    if level.max() < _LINE_DB:
        n_lines = 0  # the whole orders alone: no mesh line stands out
    rank = np.argsort(-level)
    mid = 0.5 * (y.size - 1) / fs_d
    return SpeedProfile(mid=mid, coef=coef,
                        lines=tuple((int(lines[i]), float(level[i])) for i in rank),
                        n_lines=n_lines)
