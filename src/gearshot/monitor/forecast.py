"""When will the fault reach a limit: growth laws fitted to a trusted size history.

Three laws of a fault size ``y`` against time ``t`` (DESIGN 3a: linear, exponential and
Paris-like power laws are what gear prognosis uses), each starting at an onset ``t0``
from a healthy level ``h`` (with ``s = max(t - t0, 0) / S``, ``S`` the span from ``t0`` to
the last point):

* ``linear``: ``y = h + a s``
* ``exponential``: ``y = h + a (exp(k s) - 1)``
* ``power``: ``y = h + a s ** p``

Every law is evaluated on a grid: every onset candidate (the history's own times) and
every shape (``k`` or ``p``, log-spaced), with ``h, a`` the least-squares solution of each
grid point. :func:`fit_growth` returns the best point by the Akaike information criterion,
refined by :func:`scipy.optimize.curve_fit`.

:func:`forecast_crossing` does not bet on that one point. Each grid point is weighted by
its likelihood (normal residuals, spread profiled out: ``rss ** (-n / 2)``) under a prior
that gives each law the same mass, spread evenly over its onsets and shapes; each
point's crossing time carries its own least-squares error (normal, delta method), and
the forecast is the median of that weighted mixture, the interval its quantiles. A
noisy history fits a late onset with a steep law about as well as an early onset with a
gentle one, and the two reach the limit at very different times: a single best fit
hides that, the weighted grid keeps it in the interval. Chosen on synthetic lives and
the development lives of ``benchmarks/monitor_lives.py`` (``benchmarks/RESULTS.md``,
"Monitoring": the single best fit's 90 % intervals held the true crossing in about 40 %
of synthetic lives, the weighted grid's in about 88 %).

The weights know the history's scatter, not the estimator's error on this machine, the
same on every recording: the interval mixes over the limit's true reading
(``reading_spread``, :func:`reading_spread_at`: what a one-fault-shot model's size
intervals carry above its example's size), the point forecast stays the median at the
limit (rig lives: intervals holding the truth 48 → 65 of 77, ``benchmarks/RESULTS.md``).

No forecast is made (and the reason is said) from fewer than :data:`MIN_POINTS` points,
fewer than :data:`MIN_GROWTH_POINTS` after the best fit's onset, a flat trend (the best
fit's growth over the data is under twice its residual spread, or under
:data:`MIN_RISE`), or when most of the weight lies on laws that never reach the limit.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import OptimizeWarning, brentq, curve_fit
from scipy.special import ndtr

from .._errors import GearshotError
from .._validation import check_in_range
from ..estimator.uncertainty import EXTRAPOLATION_SPREAD

__all__ = ["fit_growth", "forecast_crossing", "reading_spread_at", "GrowthFit", "Forecast",
           "LAWS", "MIN_POINTS", "MIN_GROWTH_POINTS", "MIN_RISE", "READING_NODES"]

LAWS = ("linear", "exponential", "power")
MIN_POINTS = 6
MIN_GROWTH_POINTS = 4
MIN_RISE = 0.1
#: Gauss-Hermite nodes of the mixture over the limit's reading (``reading_spread``).
READING_NODES = 7
_SHAPES = {"linear": np.array([1.0]),
           "exponential": np.geomspace(0.2, 12.0, 25),
           "power": np.geomspace(0.4, 6.0, 25)}
_MAX_ONSETS = 40
_REFINED = 3


def _basis(law: str, s: np.ndarray, shape: float | np.ndarray) -> np.ndarray:
    if law == "linear":
        return s
    if law == "exponential":
        return np.expm1(shape * s)
    return s ** shape


def _inverse(law: str, rise: float | np.ndarray,
             shape: float | np.ndarray) -> float | np.ndarray:
    """``s`` where ``basis(s) = rise`` (rise > 0)."""
    if law == "linear":
        return rise
    if law == "exponential":
        return np.log1p(rise) / shape
    return rise ** (1.0 / shape)


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
        return self.onset + self.span * float(_inverse(
            self.law, (limit - self.level) / self.amplitude, self.shape))


@dataclass(frozen=True)
class _Grid:
    """One law's least-squares fits over onsets × shapes (arrays of that shape)."""

    law: str
    onset: np.ndarray
    span: np.ndarray
    shape: np.ndarray
    level: np.ndarray
    amplitude: np.ndarray
    rss: np.ndarray
    basis_mean: np.ndarray
    basis_ss: np.ndarray
    n: int

    def crossing(self, limit: float) -> tuple[np.ndarray, np.ndarray]:
        """Every grid point's time of reaching ``limit`` (as :meth:`GrowthFit.crossing`)
        and its standard error from the point's least-squares level and amplitude (delta
        method: the fitted mean's standard error at that time over the law's slope)."""
        rising = self.amplitude > 0
        ahead = rising & (limit > self.level)
        rise = np.where(ahead, (limit - self.level) / np.where(rising, self.amplitude, 1.0),
                        1.0)
        s = _inverse(self.law, rise, self.shape)
        when = np.where(limit <= self.level, self.onset,
                        np.where(rising, self.onset + self.span * s, np.inf))
        if self.law == "linear":
            slope = np.ones_like(s)
        elif self.law == "exponential":
            slope = self.shape * np.exp(self.shape * s)
        else:
            slope = self.shape * s ** (self.shape - 1.0)
        k = 2 if self.law == "linear" else 3
        var = self.rss / max(self.n - k - 1, 1) * (
            1.0 / self.n + (rise - self.basis_mean) ** 2
            / np.where(self.basis_ss > 0, self.basis_ss, np.inf))
        rate = np.where(ahead, self.amplitude * slope / self.span, np.inf)
        return when, np.sqrt(var) / rate


def _grid(law: str, t: np.ndarray, y: np.ndarray, onsets: np.ndarray) -> _Grid:
    """Least squares of ``h, a`` for every onset in ``onsets`` and every shape of ``law``."""
    onsets = onsets[onsets < t[-1]]
    shapes = _SHAPES[law]
    span = t[-1] - onsets
    s = np.maximum(t[None, :] - onsets[:, None], 0.0) / span[:, None]
    b = _basis(law, s[:, None, :], shapes[None, :, None])          # (onsets, shapes, n)
    b_mean = b.mean(axis=-1)
    bc = b - b_mean[..., None]
    yc = y - y.mean()
    sbb = np.einsum("osn,osn->os", bc, bc)
    amp = np.einsum("osn,n->os", bc, yc) / np.where(sbb > 0, sbb, 1.0)
    level = y.mean() - amp * b_mean
    rss = np.sum((yc - amp[..., None] * bc) ** 2, axis=-1)
    full = np.broadcast_to
    return _Grid(law, full(onsets[:, None], amp.shape), full(span[:, None], amp.shape),
                 full(shapes[None, :], amp.shape), level, amp, rss, b_mean, sbb, t.size)


def _refine(law: str, t: np.ndarray, y: np.ndarray, t0: float, span: float,
            start: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    """``start`` (rss, level, amplitude, shape) refined by curve_fit."""
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


def _checked(times: ArrayLike, sizes: ArrayLike, laws) -> tuple[np.ndarray, np.ndarray]:
    t = np.asarray(times, float)
    y = np.asarray(sizes, float)
    if t.shape != y.shape or t.ndim != 1 or t.size < MIN_GROWTH_POINTS:
        raise GearshotError(f"fit_growth needs two 1-D arrays of the same length ≥ "
                            f"{MIN_GROWTH_POINTS}; got shapes {t.shape} and {y.shape}")
    unknown = [law for law in laws if law not in LAWS]
    if unknown:
        raise GearshotError(f"laws must be among {LAWS}; got {unknown}")
    return t, y


def _best(grids: list[_Grid], t: np.ndarray, y: np.ndarray, n_free_onset: int) -> GrowthFit:
    """The AIC-best law of ``grids``, each law's best few grid points refined."""
    n = t.size
    best: GrowthFit | None = None
    for g in grids:
        k = (2 if g.law == "linear" else 3) + n_free_onset
        flat = g.rss.ravel()
        for i in np.argsort(flat, kind="stable")[:_REFINED]:
            start = (float(flat[i]), float(g.level.flat[i]), float(g.amplitude.flat[i]),
                     float(g.shape.flat[i]))
            t0, span = float(g.onset.flat[i]), float(g.span.flat[i])
            rss, level, amp, shape = _refine(g.law, t, y, t0, span, start)
            aic = n * np.log(max(rss, 1e-12) / n) + 2 * k
            if best is None or aic < best.aic:
                sigma = float(np.sqrt(rss / max(n - k, 1)))
                best = GrowthFit(g.law, t0, span, level, amp, shape, sigma, float(aic))
    if best is None:
        raise GearshotError("fit_growth: the history spans no time")
    return best


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
    t, y = _checked(times, sizes, laws)
    onsets = _onsets(t) if onset is None else np.array([float(onset)])
    grids = [_grid(law, t, y, onsets) for law in laws]
    return _best([g for g in grids if g.rss.size], t, y, int(onset is None))


@dataclass(frozen=True)
class Forecast:
    """The time a size history reaches ``limit`` (times in the caller's unit).

    ``time``, ``low`` and ``high`` are None (and ``reason`` says why) when no forecast is
    made; ``high`` is inf when more than its share of the weight never reaches the
    limit. ``law`` is the law holding the most weight, ``fit`` its best fit and
    ``law_weights`` each law's share of the weight (None when no forecast is made).
    """

    limit: float
    time: float | None
    low: float | None
    high: float | None
    law: str | None
    reason: str | None
    fit: GrowthFit | None = None
    law_weights: dict[str, float] | None = field(default=None)


def _mixture_quantiles(mean: np.ndarray, spread: np.ndarray, weight: np.ndarray,
                       qs) -> list[float]:
    """Quantiles of a weighted mixture of normal laws (inf means: weight that never
    reaches; inf where a quantile lies in that weight)."""
    keep = weight > 1e-12 * weight.max()
    mean, spread, weight = mean[keep], spread[keep], weight[keep] / weight[keep].sum()
    ok = np.isfinite(mean)
    m, w = mean[ok], weight[ok]
    sd = np.maximum(np.nan_to_num(spread[ok], nan=0.0, posinf=0.0), 1e-9 * (1 + np.abs(m)))

    def cdf(x: float) -> float:
        return float(np.sum(w * ndtr((x - m) / sd)))

    lo, hi = float(np.min(m - 10 * sd)), float(np.max(m + 10 * sd))
    return [brentq(lambda x, q=q: cdf(x) - q, lo, hi, xtol=1e-9 * (1 + abs(hi)))
            if q < w.sum() else np.inf for q in qs] if m.size else [np.inf for _ in qs]


def _crossings(grids: list[_Grid], limit: float) -> tuple[np.ndarray, np.ndarray]:
    """Every grid point's crossing time of ``limit`` and its standard error, flattened in
    the order of the grids' weights."""
    crossings = [g.crossing(limit) for g in grids]
    return (np.concatenate([c[0].ravel() for c in crossings]),
            np.concatenate([c[1].ravel() for c in crossings]))


def reading_spread_at(limit: float, example_size: float | None,
                      extrapolation_spread: float = EXTRAPOLATION_SPREAD) -> float:
    """Standard deviation of a one-fault-shot estimate's systematic error at ``limit``:
    ``extrapolation_spread · (limit − example_size)`` above the example's size (the
    error the size intervals carry there,
    :func:`gearshot.estimator.uncertainty.holdout_interval`), 0 at or below it or
    without an example.

    >>> round(reading_spread_at(0.6, 0.42), 4), reading_spread_at(0.3, 0.42)
    (0.0594, 0.0)
    """
    if example_size is None or not np.isfinite(example_size):
        return 0.0
    return float(extrapolation_spread * max(float(limit) - float(example_size), 0.0))


def forecast_crossing(times: ArrayLike, sizes: ArrayLike, limit: float, *,
                      coverage: float = 0.9, reading_spread: float = 0.0) -> Forecast:
    """Weigh the growth laws' fits and forecast when the size reaches ``limit``.

    Parameters
    ----------
    times, sizes : array_like, shape (n,)
        The trusted history in time order (e.g. days since the first recording).
    limit : float in (0, 1]
    coverage : float in (0, 1)
        Of the interval (weighted quantiles of the grid's crossing times).
    reading_spread : float >= 0
        Standard deviation of the estimator's systematic error at ``limit``: the interval
        mixes over the reading ``limit + reading_spread · x``, ``x`` standard normal
        (:data:`READING_NODES` Gauss-Hermite nodes); :func:`reading_spread_at`.
    """
    limit = check_in_range(limit, "limit (--limit)", 0.0, 1.0, low_inclusive=False)
    coverage = check_in_range(coverage, "coverage", 0.0, 1.0, low_inclusive=False,
                              high_inclusive=False)
    reading_spread = check_in_range(reading_spread, "reading_spread", 0.0, np.inf)
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
    grids = [g for g in (_grid(law, t, y, _onsets(t)) for law in LAWS) if g.rss.size]
    if not grids:
        return none("the trusted recordings span no time")
    best = _best(grids, t, y, 1)
    after = int(np.sum(t > best.onset))
    rise = float(best(t[-1]) - best(best.onset))
    if after < MIN_GROWTH_POINTS - 1:
        return none(f"too few trusted recordings since the growth began: {after}")
    if rise < max(2.0 * best.sigma, MIN_RISE):
        return none(f"flat trend: the fitted growth over the history is {rise:.3f}, under "
                    f"max(2 × residual spread {best.sigma:.3f}, {MIN_RISE})")
    # each law the same prior mass, spread evenly over its grid points
    log_w = [-0.5 * t.size * np.log(np.maximum(g.rss.ravel(), 1e-12)) - np.log(g.rss.size)
             for g in grids]
    top = max(float(lw.max()) for lw in log_w)
    law_w = [np.exp(lw - top) for lw in log_w]
    w = np.concatenate(law_w)
    weights = {g.law: float(wl.sum() / w.sum()) for g, wl in zip(grids, law_w, strict=True)}
    q = (1.0 - coverage) / 2.0
    when, spread = _crossings(grids, limit)
    low, mid, high = _mixture_quantiles(when, spread, w, [q, 0.5, 1.0 - q])
    if reading_spread > 0 and np.isfinite(mid):
        nodes, node_w = np.polynomial.hermite_e.hermegauss(READING_NODES)
        at = [_crossings(grids, float(np.clip(limit + reading_spread * x, 1e-6, 1.0)))
              if x else (when, spread) for x in nodes]   # the middle node: the limit's
        low, high = _mixture_quantiles(
            np.concatenate([a[0] for a in at]), np.concatenate([a[1] for a in at]),
            np.concatenate([w * v for v in node_w]), [q, 1.0 - q])
    if not np.isfinite(mid):
        reached = float(w[np.isfinite(when)].sum() / w.sum())
        return none(f"the growth laws fitted to the history do not reach {limit:g} "
                    f"(those that do hold {reached:.0%} of the weight)")
    law = max(weights, key=weights.__getitem__)
    fit = best if best.law == law else _best([g for g in grids if g.law == law], t, y, 1)
    return Forecast(limit, mid, low, high, law, None, fit, weights)
