"""Simulated datasets of the paper's Sec. 4.1: simulated test signals through a measured TF."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from .._errors import GearshotError
from .._validation import check_attenuation, check_in_range, check_int
from ..transfer import mean_rms, propagate

__all__ = ["SimulatedDataset", "simulated_dataset"]


@dataclass(frozen=True)
class SimulatedDataset:
    """One Sec. 4.1 dataset: what the estimator is fitted on and what it is tested on.

    Attributes
    ----------
    database : xarray.Dataset
        Training simulated SAs (``sa``, ``fault_size``, ``grade``).
    target_healthy : ndarray (n, n_points)
        The test-domain healthy SAs moved to training.
    faulty_example, faulty_size
        One test-domain faulty SA and its size.
    healthy_long : ndarray
        Long healthy test-domain signal (cycle domain) for the TF estimate.
    test_sa, test_size : ndarray
        The test set.
    """

    database: xr.Dataset
    target_healthy: np.ndarray
    faulty_example: np.ndarray
    faulty_size: float
    healthy_long: np.ndarray
    test_sa: np.ndarray
    test_size: np.ndarray

    def fit_args(self):
        """Positional arguments for :meth:`OneFaultShotEstimator.fit`."""
        return (self.database, self.target_healthy, self.faulty_example, self.faulty_size,
                self.healthy_long)


def simulated_dataset(sa, fault_size, tf, *, grade=7, attenuation_db=10.0,
                      noise_fraction=0.1, target_fraction=0.25, n_long_cycles=128,
                      cycles_per_sa=50, random_state=None, attrs=None):
    """Build a Sec. 4.1 dataset from one grade's simulated SAs and a measured TF.

    Healthy SAs are split half/half and faulty ones 70/30 between training (simulated
    domain) and test. Test signals get white noise (``noise_fraction`` of the healthy RMS per
    cycle, averaged over ``cycles_per_sa`` cycles as an SA would), are attenuated by
    ``attenuation_db`` and pass through ``tf``. ``target_fraction`` of the test healthy SAs
    move to training as target healthy; one random test faulty SA becomes the example.
    The long healthy signal is one target healthy gear's SA repeated for ``n_long_cycles``
    cycles, each with fresh noise (the non-synchronous vibration), through the same path.

    Parameters
    ----------
    sa : ndarray (n_signals, n_points)
    fault_size : ndarray (n_signals,)
    tf : ndarray of complex (n_points,) or TransferFunction
    grade : int, default 7
        DIN grade of ``sa``, stored in the training database.
    attenuation_db : float, >= 0
    noise_fraction : float, >= 0
    target_fraction : float in (0, 1)
    n_long_cycles, cycles_per_sa : int
    random_state : int or Generator
    attrs : mapping, optional
        Attributes of the training database: pass the loaded database's (its gear pair,
        from which the estimator takes its mesh order).

    Returns
    -------
    SimulatedDataset
    """
    rng = np.random.default_rng(random_state)
    sa = np.asarray(sa, float)
    y = np.asarray(fault_size, float)
    n_points = sa.shape[1]
    grade = check_int(grade, "grade", minimum=1, maximum=12)
    attenuation_db = check_attenuation(attenuation_db, "attenuation_db")
    noise_fraction = check_in_range(noise_fraction, "noise_fraction", 0, 10)
    target_fraction = check_in_range(target_fraction, "target_fraction", 0, 1,
                                     low_inclusive=False, high_inclusive=False)
    if hasattr(tf, "to_signal_grid"):
        tf = tf.to_signal_grid(n_points)
    tf = np.asarray(tf)
    healthy = np.flatnonzero(y == 0)
    faulty = np.flatnonzero(y > 0)
    if healthy.size < 8 or faulty.size < 4:
        raise GearshotError(f"sa must hold at least 8 healthy and 4 faulty signals; got "
                            f"{healthy.size} and {faulty.size}")
    healthy, faulty = rng.permutation(healthy), rng.permutation(faulty)
    h_train, h_test = np.array_split(healthy, 2)
    n_f_train = int(round(0.7 * faulty.size))
    f_train, f_test = faulty[:n_f_train], faulty[n_f_train:]
    n_target = max(5, int(round(target_fraction * h_test.size)))
    h_target, h_test = h_test[:n_target], h_test[n_target:]

    alpha = 10 ** (-attenuation_db / 20)
    noise_rms = noise_fraction * mean_rms(sa[healthy])

    def to_target(x, n_avg):
        noisy = x + noise_rms / np.sqrt(n_avg) * rng.standard_normal(x.shape)
        return propagate(alpha * noisy, tf)

    example = rng.choice(f_test)
    test = np.setdiff1d(np.r_[h_test, f_test], [example])
    long_idx = np.full(n_long_cycles, rng.choice(h_target))  # one gear, many cycles
    train_idx = np.r_[h_train, f_train]
    database = xr.Dataset(
        {"sa": (("signal", "angle"), sa[train_idx])},
        coords={"fault_size": ("signal", y[train_idx]),
                "grade": ("signal", np.full(train_idx.size, int(grade)))},
        attrs=dict(attrs or {}))
    return SimulatedDataset(
        database=database,
        target_healthy=to_target(sa[h_target], cycles_per_sa),
        faulty_example=to_target(sa[example], cycles_per_sa),
        faulty_size=float(y[example]),
        healthy_long=to_target(sa[long_idx], 1).ravel(),
        test_sa=to_target(sa[test], cycles_per_sa),
        test_size=y[test],
    )
