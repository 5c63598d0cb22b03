"""The information limit: a template-likelihood oracle on the difference signal's spectrum.

A paired database gives every simulated faulty SA its healthy twin, so the fault component
``Δ = faulty − twin`` of each signal is known exactly. An estimator that knows the fault
family (the simulator that made the templates) and the target's noise can do no better than
the Bayes posterior of the size given the target's difference spectrum:

* **templates**: on a grid of sizes ``y_j`` the mean fault component ``T(y_j)`` (kernel
  smoothing of the training Δ spectra over ``y``) and its scatter ``V(y_j)`` (what the
  profile errors and the fault draw leave around the mean), per one-sided spectral bin;
* **likelihood**: each bin of the target's difference spectrum ``X`` is circular complex
  Gaussian around ``T(y_j)`` with variance ``P + V(y_j)``, ``P`` the noise power per bin
  (the mean ``|rfft|²`` of the healthy differences, :func:`gearshot.estimator.steps.residue_power`);
* **prior**: the training sizes' histogram on the grid (healthy signals at ``y = 0``);
* **estimate**: the posterior median (the minimiser of the expected absolute error).

With ``phase=False`` only the magnitudes ``|X|`` count (a Rice likelihood per bin around
``|T(y_j)|``): the limit of an estimator that does not know where in the revolution the
fault sits or how the path turns its phase.

The bins are those the difference signal keeps (the paper's step 7 removes the mesh
harmonics and their ±2 sidebands, and DC): what no estimator of the difference signal sees
is not counted. Used by ``benchmarks/info_limit.py`` to measure the lowest error reachable in
the simulated domain.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._errors import GearshotError
from .._validation import check_int, check_positive
from ..signal.orders import order_mask

__all__ = ["TemplateOracle", "fault_bins", "fit_template_oracle"]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

#: Rows × grid points × bins per block of the likelihood (about 16 MB of complex128).
_BLOCK = 1 << 20


def fault_bins(n_points: int, mesh_order: int | Sequence[int], *,
               n_sidebands: int = 2) -> NDArray[np.intp]:
    """One-sided bins the difference signal keeps: every order in ``1 … n_points // 2``
    except the mesh harmonics and their ``n_sidebands`` sidebands.

    Parameters
    ----------
    n_points : int
        Points per SA cycle.
    mesh_order : int or sequence of int
        Mesh order(s) in the cycle.
    n_sidebands : int, default 2
        Sidebands removed on each side of every mesh harmonic (the paper's 2).

    Returns
    -------
    ndarray of int
        Bin (order) indices, increasing.

    Examples
    --------
    >>> from gearshot.estimator.oracle import fault_bins
    >>> bins = fault_bins(64, 10, n_sidebands=1)
    >>> [int(b) for b in bins[:10]]
    [1, 2, 3, 4, 5, 6, 7, 8, 12, 13]
    """
    mask = order_mask(n_points, mesh_order, n_sidebands=n_sidebands)
    mask[0] = True
    return np.asarray(np.flatnonzero(~mask), dtype=np.intp)


@dataclass(frozen=True)
class TemplateOracle:
    """Fault-component templates on a size grid and the likelihood of spectra under them.

    Attributes
    ----------
    grid : ndarray (n_grid,)
        Sizes of the templates, increasing, in [0, 1].
    bins : ndarray of int (n_bins,)
        One-sided spectral bins used.
    templates : ndarray of complex (n_grid, n_bins)
        Mean fault component ``T(y)`` per grid size.
    variance : ndarray (n_grid, n_bins)
        Variance per bin of the fault components around ``T(y)`` plus the noise power.
    log_prior : ndarray (n_grid,)
        Log prior weight of each grid size.
    phase : bool
        Whether the likelihood uses the spectra's phases (else magnitudes only).
    """

    grid: FloatArray
    bins: NDArray[np.intp]
    templates: ComplexArray
    variance: FloatArray
    log_prior: FloatArray
    phase: bool = True

    def log_posterior(self, spectra: ArrayLike) -> FloatArray:
        """Unnormalised log posterior of every grid size for every spectrum.

        Parameters
        ----------
        spectra : array_like of complex (n_signals, n_points // 2 + 1)
            One-sided spectra (``rfft``) of difference signals.

        Returns
        -------
        ndarray (n_signals, n_grid)
        """
        spec = np.atleast_2d(np.asarray(spectra))
        if not np.iscomplexobj(spec) or spec.ndim != 2 or spec.shape[1] <= self.bins[-1]:
            raise GearshotError(f"spectra must be complex one-sided spectra with more than "
                                f"{int(self.bins[-1])} bins per row; got dtype {spec.dtype} "
                                f"and shape {spec.shape}")
        x = spec[:, self.bins]
        log_norm = np.sum(np.log(self.variance), axis=1)
        out = np.empty((x.shape[0], self.grid.size))
        rows = max(1, _BLOCK // (self.grid.size * self.bins.size))
        inv = 1.0 / self.variance
        if not self.phase:
            return np.asarray(self._log_rice(np.abs(x), inv, rows) + self.log_prior,
                              dtype=np.float64)
        for i in range(0, x.shape[0], rows):
            d = x[i:i + rows, None, :] - self.templates[None, :, :]
            out[i:i + rows] = -np.einsum("rgb,gb->rg", d.real ** 2 + d.imag ** 2, inv)
        return np.asarray(out - log_norm + self.log_prior, dtype=np.float64)

    def _log_rice(self, r: FloatArray, inv: FloatArray, rows: int) -> FloatArray:
        """Sum over bins of the Rice log-density of magnitudes ``r`` (n, n_bins) around
        ``|T|`` with ``E|noise|² = variance`` (terms free of the grid dropped)."""
        from scipy.special import i0e

        amp = np.abs(self.templates)
        out = np.empty((r.shape[0], self.grid.size))
        base = -np.sum(np.log(self.variance), axis=1) - np.sum(amp ** 2 * inv, axis=1)
        for i in range(0, r.shape[0], rows):
            z = 2.0 * r[i:i + rows, None, :] * amp[None, :, :] * inv[None, :, :]
            out[i:i + rows] = (np.sum(np.log(i0e(z)) + z, axis=2)
                               - np.einsum("rb,gb->rg", r[i:i + rows] ** 2, inv) + base)
        return out

    def posterior(self, spectra: ArrayLike) -> FloatArray:
        """Posterior probabilities of the grid sizes (rows sum to 1), (n_signals, n_grid)."""
        logp = self.log_posterior(spectra)
        logp -= logp.max(axis=1, keepdims=True)
        p = np.exp(logp)
        return np.asarray(p / p.sum(axis=1, keepdims=True), dtype=np.float64)

    def predict(self, spectra: ArrayLike) -> FloatArray:
        """Posterior-median sizes of difference spectra, (n_signals,)."""
        cdf = np.cumsum(self.posterior(spectra), axis=1)
        idx = np.argmax(cdf >= 0.5, axis=1)
        return np.asarray(self.grid[idx], dtype=np.float64)


def fit_template_oracle(differences: ArrayLike, fault_size: ArrayLike,
                        noise_power: ArrayLike, *, mesh_order: int | Sequence[int],
                        n_points: int, n_grid: int = 101,
                        bandwidth: float = 0.02, phase: bool = True) -> TemplateOracle:
    """Templates of the fault component from noise-free difference spectra.

    Parameters
    ----------
    differences : array_like of complex (n_signals, n_points // 2 + 1)
        ``rfft`` of the training fault components (faulty SA − its healthy twin, through
        the path and the scale the target sees); healthy signals are zero rows.
    fault_size : array_like (n_signals,)
        Their sizes in [0, 1].
    noise_power : array_like (n_points // 2 + 1,)
        Expected ``|rfft|²`` of the target's noise per bin (> 0 on the bins used).
    mesh_order : int or sequence of int
        Mesh order(s) whose bands are left out (:func:`fault_bins`).
    n_points : int
        Points per SA cycle.
    n_grid : int >= 2, default 101
        Grid sizes, evenly spaced over [0, 1].
    bandwidth : float > 0, default 0.02
        Standard deviation in size units of the Gaussian kernel that smooths the
        templates over ``y``.
    phase : bool, default True
        Use the complex spectra (False: their magnitudes only, a Rice likelihood).

    Returns
    -------
    TemplateOracle

    Raises
    ------
    GearshotError
        On shapes that do not match, sizes outside [0, 1] or a noise power not positive on
        the bins used (the message names the argument and the value).
    """
    n_points = check_int(n_points, "n_points", minimum=4)
    n_grid = check_int(n_grid, "n_grid", minimum=2)
    bandwidth = check_positive(bandwidth, "bandwidth")
    spec = np.atleast_2d(np.asarray(differences))
    y = np.asarray(fault_size, dtype=float)
    power = np.asarray(noise_power, dtype=float)
    n_bins = n_points // 2 + 1
    if not np.iscomplexobj(spec) or spec.shape[1:] != (n_bins,):
        raise GearshotError(f"differences must be complex spectra with n_points // 2 + 1 = "
                            f"{n_bins} bins; got dtype {spec.dtype} and shape {spec.shape}")
    if y.shape != spec.shape[:1] or not np.all((y >= 0) & (y <= 1)):
        raise GearshotError(f"fault_size must hold one size in [0, 1] per row of differences "
                            f"({spec.shape[0]}); got shape {y.shape}, range "
                            f"[{np.nanmin(y) if y.size else 'empty'}, "
                            f"{np.nanmax(y) if y.size else 'empty'}]")
    bins = fault_bins(n_points, mesh_order)
    if power.shape != (n_bins,) or not np.all(np.isfinite(power[bins])) \
            or np.any(power[bins] <= 0):
        raise GearshotError(f"noise_power must hold {n_bins} finite values, positive outside "
                            f"the mesh bands; got shape {power.shape}, minimum "
                            f"{float(np.min(power)) if power.size else 'empty'}")
    grid = np.linspace(0.0, 1.0, n_grid)
    weights = np.exp(-0.5 * ((grid[:, None] - y[None, :]) / bandwidth) ** 2)
    weights[:, y == 0] = 0.0            # the healthy rows define y = 0 alone
    weights[0] = (y == 0).astype(float)
    if not weights[0].any():            # no healthy rows: the zero component
        weights[0] = 0.0
    total = weights.sum(axis=1, keepdims=True)
    empty = total[:, 0] == 0
    weights = np.divide(weights, total, out=np.zeros_like(weights), where=total > 0)
    x = spec[:, bins]
    templates = weights @ x
    second = weights @ (x.real ** 2 + x.imag ** 2)
    scatter = np.maximum(second - (templates.real ** 2 + templates.imag ** 2), 0.0)
    if empty.any():                     # grid points no training size reaches
        templates[empty] = 0.0
        scatter[empty] = 0.0
    counts = np.bincount(np.rint(y * (n_grid - 1)).astype(int), minlength=n_grid)
    prior = (counts + 0.5) / (counts.sum() + 0.5 * n_grid)
    return TemplateOracle(grid, bins, np.asarray(templates, np.complex128),
                          np.asarray(scatter + power[bins][None, :], np.float64),
                          np.log(prior), bool(phase))
