"""Does the healthy baseline drift while it is recorded? (part of the fit check)

A fit that holds the healthy segments of one or two recordings learns the machine's
healthy signal from a few seconds of it, and its hold-outs (the last segments of the same
recordings) lie next to step 6's references in time. When the signal moves steadily
during the recording (a brake's torque settling, a machine warming up), a later run of the
same healthy gear lies beyond everything the fit saw, and its difference signal reads as a
fault that the hold-outs never show.

:func:`healthy_drift` tests for that trend inside each recording: the residual energy
left by step 6's aligned subtraction between two segments of the recording
(:func:`gearshot.signal.subtract_healthy`) is ranked against how far apart in time they
are (Spearman's ρ over the pairs, pooled over the recordings with each recording's
energies divided by their median), and the ranks' association is tested by permuting
the segments' order inside each recording (a Mantel test, ``n_permutations`` seeded
draws). The baseline **drifts** when the p-value is at most :data:`DRIFT_P` and the
energy's straight-line fit on the separation reads at least :data:`DRIFT_RATIO` times
higher at the largest separation than at neighbouring segments.

Chosen on the development records of the PHM09 spur subset (30 Hz, run 1 and run 2 of
every spur case, both sensors, 10-revolution segments; ``benchmarks/healthy_drift.py``):
every Low-load record drifts by this test (p 0.001–0.016, trend ratio 1.37–2.17) and no
High-load record does (p ≥ 0.145, trend ratio 0.85–1.12). There the healthy gear's run 2
read 0.21 at Low load (its run-1 hold-outs 0.08) and 0.09 at High load.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._errors import GearshotError
from .._validation import as_signal_array, check_int

__all__ = ["Drift", "healthy_drift", "fit_drift", "DRIFT_P", "DRIFT_RATIO", "MIN_DRIFT_SEGMENTS"]

#: Largest p-value of a drifting baseline.
DRIFT_P = 0.05
#: Smallest trend ratio of a drifting baseline: the straight line of the pairs' residual
#: energy on their separation, at the largest separation over at neighbours.
DRIFT_RATIO = 1.25
#: Fewest segments a recording needs to be tested (fewer cannot show a trend).
MIN_DRIFT_SEGMENTS = 6
#: Delay resolution of the pairs' aligned subtraction (samples / ``_UPSAMPLE``).
_UPSAMPLE = 10


@dataclass(frozen=True)
class Drift:
    """The outcome of :func:`healthy_drift`.

    Attributes
    ----------
    p_value : float or None
        Of the time trend (None: no recording had enough segments).
    ratio : float or None
        The trend's size: the straight line of the pairs' residual energy on their
        separation, at the largest separation over at neighbouring segments.
    n_recordings : int
        Recordings tested (those with at least :data:`MIN_DRIFT_SEGMENTS` segments).
    drifting : bool
    """

    p_value: float | None
    ratio: float | None
    n_recordings: int
    drifting: bool

    def reason(self) -> str | None:
        """The fit-check reason for a drifting baseline, else None."""
        if not self.drifting:
            return None
        return (f"the healthy recording drifts while it is recorded (segments far apart "
                f"differ {self.ratio:.2f}× more than neighbours, p = {self.p_value:.3f}): "
                f"a later run may read as a fault that the hold-outs do not show; fit on "
                f"healthy recordings of 3 or more runs")


def _pair_energy(sa: NDArray[np.float64]) -> NDArray[np.float64]:
    """Symmetric mean-square residual of every pair's aligned subtraction."""
    from ..signal import subtract_healthy

    n = len(sa)
    energy = np.empty((n, n))
    for j in range(n):
        energy[:, j] = np.mean(subtract_healthy(sa, sa[j], upsample=_UPSAMPLE) ** 2, axis=1)
    return (energy + energy.T) / 2


def healthy_drift(healthy: ArrayLike, recordings: ArrayLike | None = None, *,
                  n_permutations: int = 999, random_state: int = 0) -> Drift:
    """Test the healthy segments of each recording for a steady change in time.

    Parameters
    ----------
    healthy : array_like (n, n_points)
        Healthy SAs, each recording's segments in time order.
    recordings : array_like (n,), optional
        Each SA's recording (None: one recording).
    n_permutations : int >= 99
    random_state : int

    Returns
    -------
    Drift
    """
    sa = as_signal_array(healthy, "healthy", min_ndim=2, max_ndim=2)
    n_permutations = check_int(n_permutations, "n_permutations", minimum=99)
    labels = (np.zeros(len(sa), int) if recordings is None
              else np.asarray(recordings).reshape(-1))
    if len(labels) != len(sa):
        raise GearshotError(f"recordings holds {len(labels)} labels for {len(sa)} SAs")
    groups: list[NDArray[np.float64]] = []   # each recording's energies ÷ their median
    for name in dict.fromkeys(labels.tolist()):
        rows = np.flatnonzero(labels == name)
        if len(rows) >= MIN_DRIFT_SEGMENTS:
            energy = _pair_energy(sa[rows])
            groups.append(energy / np.median(energy[np.triu_indices(len(rows), 1)]))
    if not groups:
        return Drift(None, None, 0, False)
    return _trend(groups, n_permutations, random_state)


def _trend(groups: Sequence[NDArray[np.float64]], n_permutations: int, seed: int) -> Drift:
    """Pooled Spearman ρ of energy against separation, permuted inside each recording."""
    from scipy.stats import rankdata

    rng = np.random.default_rng(seed)
    pairs = [np.triu_indices(len(e), 1) for e in groups]
    seps = np.concatenate([(j - i).astype(float) for i, j in pairs])
    sep = rankdata(seps)
    sep = (sep - sep.mean()) / np.linalg.norm(sep - sep.mean())

    def pooled(orders: Sequence[NDArray[np.intp]]) -> NDArray[np.float64]:
        return np.concatenate([e[np.ix_(o, o)][i, j]
                               for e, o, (i, j) in zip(groups, orders, pairs, strict=True)])

    def rho(values: NDArray[np.float64]) -> float:
        r = rankdata(values)
        r = r - r.mean()
        return float(sep @ r / np.linalg.norm(r))

    energies = pooled([np.arange(len(e)) for e in groups])
    observed = rho(energies)
    beaten = sum(rho(pooled([rng.permutation(len(e)) for e in groups])) >= observed
                 for _ in range(n_permutations))
    p_value = (1 + beaten) / (1 + n_permutations)
    # the trend's size: a straight line of energy on separation, at the largest
    # separation against at neighbours (robust to a periodic pattern, e.g. another
    # shaft's leakage into segments that do not span its period)
    slope, intercept = np.polyfit(seps, energies, 1)
    near = intercept + slope
    ratio = float((intercept + slope * seps.max()) / near) if near > 0 else float("inf")
    return Drift(p_value, ratio, len(groups), p_value <= DRIFT_P and ratio >= DRIFT_RATIO)


def fit_drift(healthy: ArrayLike, holdout_healthy: ArrayLike | None,
              recordings: ArrayLike | None) -> Drift | None:
    """The drift test of a fit's healthy baseline, or None when it is not tested.

    It belongs to the check on hold-outs: a fit without healthy hold-outs is unchecked
    anyway, and is not tested. A fit on healthy recordings of
    :data:`~.comparability_states.MIN_GROUPS` or more recordings sees how a run differs
    from another (its comparability and references leave whole recordings out): not
    tested either. With one recording (``recordings`` None or one label), its hold-outs
    (cut from its end) are its last segments and are tested with it; with two, each
    recording's fitted segments.
    """
    from .comparability_states import MIN_GROUPS

    sa = np.asarray(healthy, dtype=float)
    labels = None if recordings is None else np.asarray(recordings).reshape(-1)[:len(sa)]
    names = set() if labels is None else set(labels.tolist())
    held = None if holdout_healthy is None else np.asarray(holdout_healthy, dtype=float)
    if held is None or not held.size or len(names) >= MIN_GROUPS:
        return None
    if len(names) <= 1:
        sa, labels = np.vstack([sa, held.reshape(-1, sa.shape[-1])]), None
    return healthy_drift(sa, labels)
