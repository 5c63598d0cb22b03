"""When will the fault reach a limit: growth laws fitted to a trusted size history.

Three laws of a fault size ``y`` against time ``t`` (DESIGN 3a: linear, exponential and
Paris-like power laws are what gear prognosis uses), each starting at an onset ``t0``
from a healthy level ``h`` (with ``s = max(t - t0, 0) / S``, ``S`` the span from ``t0`` to
the last point):

* ``linear``: ``y = h + a s``
* ``exponential``: ``y = h + a (exp(k s) - 1)``
* ``power``: ``y = h + a s ** p``

For every onset candidate (the history's own times) and every shape (``k`` or ``p`` on
a grid) the linear parameters ``h, a`` are the least-squares solution; each law's best
grid point is then refined by :func:`scipy.optimize.curve_fit`. The law and onset with the smallest
Akaike information criterion win. The time the fitted law reaches ``limit`` comes with
an interval from a parametric bootstrap (the fitted law plus normal residuals of the
fit's spread, refitted with the law and onset kept; fixed seed).

No forecast is made (and the reason is said) from fewer than :data:`MIN_POINTS` points,
fewer than :data:`MIN_GROWTH_POINTS` after the onset, or a flat trend (the fitted growth
over the data is under twice the residual spread, or under :data:`MIN_RISE`).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import OptimizeWarning, curve_fit

from .._errors import GearshotError
from .._validation import check_in_range, check_int

__all__ = ["fit_growth", "forecast_crossing", "GrowthFit", "Forecast", "LAWS", "MIN_POINTS",
           "MIN_GROWTH_POINTS", "MIN_RISE"]

LAWS = ("linear", "exponential", "power")
MIN_POINTS = 6
MIN_GROWTH_POINTS = 4
MIN_RISE = 0.1
_SHAPES = {"linear": np.array([1.0]),
           "exponential": np.geomspace(0.2, 12.0, 25),
           "power": np.geomspace(0.4, 6.0, 25)}
_MAX_ONSETS = 40
_REFINED = 3


def _basis(law: str, s: np.ndarray, shape: float) -> np.ndarray:
    if law == "linear":
        return s
    if law == "exponential":
        return np.expm1(shape * s)
    return s ** shape


def _inverse(law: str, rise: float, shape: float) -> float:
    """``s`` where ``basis(s) = rise`` (rise > 0)."""
    if law == "linear":
        return rise
    if law == "exponential":
        return float(np.log1p(rise) / shape)
    return float(rise ** (1.0 / shape))


@dataclass(frozen=True)
class GrowthFit:
    """One growth law fitted to a history (times in the caller's unit).

    Attributes
    ----------
    law : str
    onset : float
        ``t0``.
    span : float
        ``S``: last time minus ``t0``.
    level, amplitude, shape : float
        ``h``, ``a`` and ``k`` or ``p`` (1 for the linear law).
    sigma : float
        Residual standard deviation.
    aic : float
    """

    law: str
    onset: float
    span: float
    level: float
    amplitude: float
    shape: float
    sigma: float
    aic: float

    def __call__(self, t: ArrayLike) -> np.ndarray:
        s = np.maximum(np.asarray(t, float) - self.onset, 0.0) / self.span
        return self.level + self.amplitude * _basis(self.law, s, self.shape)

    def crossing(self, limit: float) -> float:
        """Time the law reaches ``limit`` (inf when it never does, ``onset`` when the
        level is already there)."""
        if limit <= self.level:
            return self.onset
        if self.amplitude <= 0:
            return np.inf
        return self.onset + self.span * _inverse(self.law, (limit - self.level)
                                                 / self.amplitude, self.shape)


def _solve(law: str, t: np.ndarray, y: np.ndarray, t0: float, span: float,
           shapes: np.ndarray) -> tuple[float, float, float, float]:
    """Best (rss, level, amplitude, shape) of ``law`` with onset ``t0`` over ``shapes``."""
    s = np.maximum(t - t0, 0.0) / span
    best = (np.inf, 0.0, 0.0, 1.0)
    for shape in shapes:
        design = np.column_stack([np.ones_like(s), _basis(law, s, shape)])
        coef, *_ = np.linalg.lstsq(design, y, rcond=None)
        rss = float(np.sum((design @ coef - y) ** 2))
        if rss < best[0]:
            best = (rss, float(coef[0]), float(coef[1]), float(shape))
    return best


def _refine(law: str, t: np.ndarray, y: np.ndarray, t0: float, span: float,
            start: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    """``start`` refined by curve_fit over (level, amplitude, shape)."""
    if law == "linear":
        return start
    s = np.maximum(t - t0, 0.0) / span
    lo, hi = _SHAPES[law][0], _SHAPES[law][-1]

    def f(x, h, a, shape):
        return h + a * _basis(law, x, shape)

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", OptimizeWarning)
            popt, _ = curve_fit(f, s, y, p0=start[1:], maxfev=200,
                                bounds=([-np.inf, -np.inf, lo], [np.inf, np.inf, hi]))
    except (RuntimeError, ValueError):
        return start
    rss = float(np.sum((f(s, *popt) - y) ** 2))
    return (rss, *map(float, popt)) if rss < start[0] else start  # type: ignore[return-value]


def _onsets(t: np.ndarray) -> np.ndarray:
    """Onset candidates: the times with at least MIN_GROWTH_POINTS points after them."""
    cands = t[: t.size - MIN_GROWTH_POINTS + 1]
    if cands.size > _MAX_ONSETS:
        cands = cands[np.linspace(0, cands.size - 1, _MAX_ONSETS).round().astype(int)]
    return cands


def fit_growth(times: ArrayLike, sizes: ArrayLike, *, laws=LAWS,
               onset: float | None = None) -> GrowthFit:
    """The growth law (and onset) with the smallest AIC.

    Parameters
    ----------
    times, sizes : array_like, shape (n,)
        Time-ordered trusted history (n ≥ :data:`MIN_GROWTH_POINTS`).
    laws : sequence of str
        Laws to try (:data:`LAWS`).
    onset : float, optional
        Keep this onset instead of searching one.
    """
    t = np.asarray(times, float)
    y = np.asarray(sizes, float)
    if t.shape != y.shape or t.ndim != 1 or t.size < MIN_GROWTH_POINTS:
        raise GearshotError(f"fit_growth needs two 1-D arrays of the same length ≥ "
                            f"{MIN_GROWTH_POINTS}; got shapes {t.shape} and {y.shape}")
    unknown = [law for law in laws if law not in LAWS]
    if unknown:
        raise GearshotError(f"laws must be among {LAWS}; got {unknown}")
    n = t.size
    best: GrowthFit | None = None
    for law in laws:
        # the grid over onsets and shapes first, then curve_fit from the law's best
        # grid points (the best few onsets)
        cands = []
        for t0 in (_onsets(t) if onset is None else [float(onset)]):
            span = float(t[-1] - t0)
            if span > 0:
                cands.append((_solve(law, t, y, t0, span, _SHAPES[law]), float(t0), span))
        cands.sort(key=lambda c: c[0][0])
        k = (2 if law == "linear" else 3) + (1 if onset is None else 0)
        for found, t0, span in cands[:_REFINED]:
            rss, level, amp, shape = _refine(law, t, y, t0, span, found)
            aic = n * np.log(max(rss, 1e-12) / n) + 2 * k
            if best is None or aic < best.aic:
                sigma = float(np.sqrt(rss / max(n - k, 1)))
                best = GrowthFit(law, t0, span, level, amp, shape, sigma, float(aic))
    if best is None:
        raise GearshotError("fit_growth: the history spans no time")
    return best


@dataclass(frozen=True)
class Forecast:
    """The time a size history reaches ``limit`` (times in the caller's unit).

    ``time``, ``low`` and ``high`` are None (and ``reason`` says why) when no forecast is
    made; ``fit`` is the chosen :class:`GrowthFit` (None then).
    """

    limit: float
    time: float | None
    low: float | None
    high: float | None
    law: str | None
    reason: str | None
    fit: GrowthFit | None = None


def forecast_crossing(times: ArrayLike, sizes: ArrayLike, limit: float, *,
                      coverage: float = 0.9, n_boot: int = 200, seed: int = 0) -> Forecast:
    """Fit the growth laws and forecast when the size reaches ``limit``.

    Parameters
    ----------
    times, sizes : array_like, shape (n,)
        The trusted history in time order (e.g. days since the first recording).
    limit : float in (0, 1]
    coverage : float in (0, 1)
        Of the interval (bootstrap quantiles).
    n_boot : int
        Bootstrap refits.
    seed : int
        Of the bootstrap's residual draws.
    """
    limit = check_in_range(limit, "limit (--limit)", 0.0, 1.0, low_inclusive=False)
    coverage = check_in_range(coverage, "coverage", 0.0, 1.0, low_inclusive=False,
                              high_inclusive=False)
    n_boot = check_int(n_boot, "n_boot", minimum=10)
    t = np.asarray(times, float)
    y = np.asarray(sizes, float)
    keep = np.isfinite(t) & np.isfinite(y)
    t, y = t[keep], y[keep]
    order = np.argsort(t, kind="stable")
    t, y = t[order], y[order]

    def none(reason: str) -> Forecast:
        return Forecast(limit, None, None, None, None, reason)

    if t.size < MIN_POINTS:
        return none(f"too few trusted recordings: {t.size} (a forecast needs {MIN_POINTS})")
    fit = fit_growth(t, y)
    after = int(np.sum(t > fit.onset))
    rise = float(fit(t[-1]) - fit(fit.onset))
    if after < MIN_GROWTH_POINTS - 1:
        return none(f"too few trusted recordings since the growth began: {after}")
    if rise < max(2.0 * fit.sigma, MIN_RISE):
        return none(f"flat trend: the fitted growth over the history is {rise:.3f}, under "
                    f"max(2 × residual spread {fit.sigma:.3f}, {MIN_RISE})")
    when = fit.crossing(limit)
    if not np.isfinite(when):
        return none(f"the fitted {fit.law} law does not reach {limit:g}")
    rng = np.random.default_rng(seed)
    mean = fit(t)
    draws = []
    for _ in range(n_boot):
        yb = mean + fit.sigma * rng.standard_normal(t.size)
        span = fit.span
        found = _solve(fit.law, t, yb, fit.onset, span, _SHAPES[fit.law])
        _, level, amp, shape = found
        g = GrowthFit(fit.law, fit.onset, span, level, amp, shape, fit.sigma, 0.0)
        draws.append(g.crossing(limit))
    q = (1.0 - coverage) / 2.0
    draws_arr = np.asarray(draws)
    low, high = np.quantile(draws_arr, [q, 1.0 - q])  # inf draws give an open upper end
    return Forecast(limit, float(when), float(low), float(high), fit.law, None, fit)
