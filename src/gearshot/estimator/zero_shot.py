"""Zero-fault-shot grade choice: match healthy-signal statistics (the paper's future work).

Without a faulty example, the surface grade is chosen from healthy data alone: the
tooth-profile errors a grade implies set how much of a healthy SA's energy lies *off* the
mesh harmonics. The signature of a set of healthy SAs is the distribution of
``log(RMS(difference signal) / RMS(harmonic signal))``; the grade whose simulated healthy SAs
(through the same TF estimate) have the nearest median signature is chosen.
"""

from __future__ import annotations

import numpy as np

from ..signal import difference_signal, harmonic_signal

__all__ = ["healthy_signature", "match_grade"]


def healthy_signature(sa, mesh_order, *, n_sidebands=2):
    """``log(RMS(diff) / RMS(harmonic))`` of each SA (scale-free)."""
    diff = difference_signal(sa, mesh_order, n_sidebands=n_sidebands)
    harm = harmonic_signal(sa, mesh_order, n_sidebands=n_sidebands)
    d = np.sqrt(np.mean(diff ** 2, axis=-1))
    h = np.sqrt(np.mean(harm ** 2, axis=-1))
    return np.log(np.maximum(d, 1e-300) / np.maximum(h, 1e-300))


def match_grade(target_signature, simulated_signatures):
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
    target = float(np.median(target_signature))
    grades = np.array(sorted(simulated_signatures))
    medians = np.array([float(np.median(simulated_signatures[g])) for g in grades])
    dist = np.abs(medians - target)
    return int(grades[int(np.argmin(dist))]), {"grade": grades, "prediction": medians,
                                                "abs_error": dist}
