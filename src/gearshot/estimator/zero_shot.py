"""Zero-fault-shot grade choice: match healthy-signal statistics (the paper's future work).

Without a faulty example, the surface grade is chosen from healthy data alone: the
tooth-profile errors a grade implies set how much of a healthy SA's energy lies *off* the
mesh harmonics. The signature of a set of healthy SAs is the distribution of
``log(RMS(difference signal) / RMS(harmonic signal))``; the grade whose simulated healthy SAs
(through the same TF estimate) have the nearest median signature is chosen.

The signature only means something if some grade's simulation resembles the target. When
the target's median lies further from every grade's median than ``consistency`` times the
simulated within-grade spread, the healthy data carry content the simulator does not
produce (other machine parts, a structure of its own), and :func:`signature_weights`
falls back to the uniform prior over grades: the prediction is then the average of the
grade models, not a guess driven by that foreign content.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..signal import difference_signal, harmonic_signal
from .uncertainty import prune_weights

__all__ = ["healthy_signature", "residue_mean_square", "match_grade", "signature_weights"]


def healthy_signature(sa: ArrayLike, mesh_order: int | Sequence[int], *, n_sidebands: int = 2,
                      residue_ms: float = 0.0) -> NDArray[np.float64]:
    """``log(RMS(diff) / RMS(harmonic))`` of each SA (scale-free).

    ``residue_ms`` (mean square, in the SAs' units) is the part of ``RMS(diff)²`` that is
    not the gear's: the SA's non-synchronous residue (see :func:`residue_mean_square`).
    It is taken off ``RMS(diff)²`` (floored at 1 % of it) before the ratio, so that a
    noisy target is compared with noise-free simulations on its gear content alone.
    """
    diff = difference_signal(sa, mesh_order, n_sidebands=n_sidebands)
    harm = harmonic_signal(sa, mesh_order, n_sidebands=n_sidebands)
    d2 = np.mean(diff ** 2, axis=-1)
    d = np.sqrt(np.maximum(d2 - float(residue_ms), 0.01 * d2))
    h = np.sqrt(np.mean(harm ** 2, axis=-1))
    return cast(NDArray[np.float64], np.log(np.maximum(d, 1e-300) / np.maximum(h, 1e-300)))


def residue_mean_square(healthy_differences: ArrayLike, mesh_order: int | Sequence[int], *,
                        n_sidebands: int = 2) -> float:
    """Mean square of one SA's non-synchronous residue off the mesh harmonics, from the
    target's healthy difference signals (each SA minus an aligned healthy reference: two
    independent residues, hence half their mean square)."""
    diff = difference_signal(healthy_differences, mesh_order, n_sidebands=n_sidebands)
    return 0.5 * float(np.mean(diff ** 2))


def match_grade(target_signature: ArrayLike,
                simulated_signatures: Mapping[int, ArrayLike],
                ) -> tuple[int, dict[str, NDArray[np.float64]]]:
    """Grade whose simulated signature median is nearest the target's.

    Parameters
    ----------
    target_signature : ndarray
    simulated_signatures : dict grade → ndarray

    Returns
    -------
    grade : int
    curve : dict with arrays ``grade``, ``prediction`` (simulated median signature),
        ``abs_error`` (distance to the target median)
    """
    target = float(np.median(np.asarray(target_signature, float)))
    grades = np.array(sorted(simulated_signatures))
    sims = {g: np.asarray(simulated_signatures[g], float) for g in grades}
    medians = np.array([float(np.median(sims[g])) for g in grades])
    dist = np.abs(medians - target)
    return int(grades[int(np.argmin(dist))]), {"grade": grades, "prediction": medians,
                                                "abs_error": dist}


def signature_weights(target_signature: ArrayLike,
                      simulated_signatures: Mapping[int, ArrayLike], *,
                      consistency: float = 2.0, min_weight: float = 1e-3,
                      ) -> tuple[dict[int, float], bool]:
    """Weights of the grades from healthy data alone.

    ``w_g ∝ exp(-½ ((m_g - t) / s)²)`` with ``m_g`` each grade's median simulated signature,
    ``t`` the target's median and ``s`` the median within-grade standard deviation of the
    simulated signatures. If no grade lies within ``consistency · s`` of the target, the
    signature is not trusted and every grade gets the same weight.

    Parameters
    ----------
    target_signature : ndarray
    simulated_signatures : dict grade → ndarray
    consistency : float > 0
    min_weight : float
        Grades below this share are dropped and the rest renormalized.

    Returns
    -------
    weights : dict grade → weight (sums to 1, largest first)
    consistent : bool
        Whether some grade matched (False: the uniform fallback was used).
    """
    target = float(np.median(np.asarray(target_signature, float)))
    grades = np.array(sorted(simulated_signatures))
    sims = {g: np.asarray(simulated_signatures[g], float) for g in grades}
    medians = np.array([float(np.median(sims[g])) for g in grades])
    spread = float(np.median([np.std(sims[g]) for g in grades]))
    spread = max(spread, 1e-12)
    dist = np.abs(medians - target)
    consistent = bool(dist.min() <= consistency * spread)
    if consistent:
        logw = -0.5 * (dist / spread) ** 2
        w = np.exp(logw - logw.max())
    else:
        w = np.ones(grades.size)
    return prune_weights(grades, w, min_weight), consistent
