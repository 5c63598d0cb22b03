"""The paper's eight steps (Matania et al. 2023, Fig. 12), one named function each, in order.

1. :func:`select_features`        invariance to what the TF estimate leaves unmitigated
2. :func:`tune_grade`             pick the simulated surface grade from the one example
3. :func:`estimate_tf`            TF from one long healthy target signal
4. :func:`propagate_simulated`    simulated SAs through that TF
5. :func:`normalize_rms`          divide by the mean RMS of the domain's healthy SAs
   (:func:`rms_scale`: that mean, the one computation of step 5's scale)
6. :func:`suppress_harmonics_simulated` / :func:`suppress_harmonics_target`
   (with :func:`split_target_healthy`, which sets the target's references apart; the
   target side blends 3 references where the fit whitens its residue)
7. :func:`centred_features`       features minus the healthy mean of their domain
8. :func:`fit_knn`                K-nearest-neighbour regression, K chosen on a 70/30 split
   (defined with :class:`KnnModel` in :mod:`gearshot.estimator.knn`)

:func:`simulated_features` chains steps 4–7 on one set of simulated SAs; step 1 and the
estimator's grade models both use it. The grade weights and prediction intervals, which
are not steps of the paper, are in :mod:`gearshot.estimator.uncertainty`.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray
from sklearn.utils import check_random_state

from .._errors import GearshotError
from ..features import extract_features
from ..signal import mean_rms, subtract_blend, subtract_healthy
from ..transfer import estimate_transfer_function, propagate
from ._inputs import REFERENCE_FRACTION, reference_count
from ._simulated import difference_features, residue_noise_spectrum, twin_difference_features
from .knn import KnnModel, fit_knn

__all__ = [
    "select_features", "feature_invariance_errors", "tune_grade", "estimate_tf",
    "propagate_simulated", "rms_scale", "normalize_rms", "suppress_harmonics_simulated",
    "residue_power", "residue_noise", "split_target_healthy", "suppress_harmonics_target",
    "centred_features", "simulated_features", "fit_knn", "KnnModel",
]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]
RandomStateLike = int | np.random.RandomState | None


# ---------------------------------------------------------------- step 1
def select_features(sim_sa: ArrayLike, fault_size: ArrayLike, selection_tf: ArrayLike, *,
                    mesh_order: int | Sequence[int], names: Sequence[str],
                    threshold: float = 0.10, fallback: str = "best",
                    twins: ArrayLike | None = None,
                    noise_fraction: float = 0.10, n_long_cycles: int = 128,
                    random_state: RandomStateLike = None, return_features: bool = False,
                    ) -> Any:
    """Step 1: keep features that the TF estimate makes invariant to the transfer path.

    A "test" set is the simulated SAs plus white noise (``noise_fraction`` of the healthy
    RMS) through the held-out ``selection_tf``; a "training" set is the same simulated SAs
    through the TF *estimated* (step 3) from a long healthy signal of the test set. Steps
    5–7 are applied to both (:func:`simulated_features`: both are simulated signals of the
    same gears, so both subtract their first healthy SA) and feature ``i`` is kept when
    ``mean_n |a_in - b_in| / min(std a_i, std b_i) < threshold``.

    Parameters
    ----------
    sim_sa : ndarray (n_signals, n_points)
        Simulated SAs of one grade.
    fault_size : ndarray (n_signals,)
        Their sizes (0 healthy).
    selection_tf : ndarray of complex (n_points,)
        The held-out TF on the SA grid.
    mesh_order : int or sequence of int
    names : sequence of str
        Candidate features.
    threshold : float
    fallback : {"best", "all"}
        When no feature passes: keep the one with the smallest error, or all of them.
    twins : ndarray (n_signals, n_points), optional
        Each signal's healthy twin (a paired database): both sets subtract it in step 6
        instead of their first healthy SA.
    noise_fraction : float
    n_long_cycles : int
        Cycles in the long healthy test signal used for the TF estimate.
    random_state : int, RandomState or None
        Seeds the noise and the choice of the healthy SA the long signal repeats.
    return_features : bool, default False
        Also return the paired feature arrays (what the paper's Fig. 11 plots).

    Returns
    -------
    selected : tuple of str
        At least one name: when no feature passes, the one with the smallest error
        (``fallback="best"``) or every candidate (``fallback="all"``).
    errors : dict name → error
    (train, test) : tuple of ndarray (n_signals - 1, n_features)
        Only with ``return_features``: the features through the estimated and the true TF.
    """
    rng = np.random.default_rng(check_random_state(random_state).randint(2**31 - 1))
    sim_sa = np.asarray(sim_sa, float)
    healthy = np.asarray(fault_size) == 0
    n_points = sim_sa.shape[1]
    noise_rms = noise_fraction * mean_rms(sim_sa[healthy])
    noisy = sim_sa + noise_rms * rng.standard_normal(sim_sa.shape)
    long_cycles = propagate(_long_healthy_signal(sim_sa[healthy], n_long_cycles, noise_rms,
                                                 rng), selection_tf)
    tf_hat = estimate_tf(long_cycles.ravel(), n_points)
    f_train = simulated_features(sim_sa, healthy, tf_hat, mesh_order=mesh_order, names=names,
                                 twins=twins)
    f_test = simulated_features(noisy, healthy, np.asarray(selection_tf),
                                mesh_order=mesh_order, names=names, twins=twins)
    keep = np.ones(len(f_test), bool)
    keep[np.flatnonzero(healthy)[0]] = False  # the subtracted reference itself (unpaired)
    err = feature_invariance_errors(f_train[keep], f_test[keep])
    errors = dict(zip(names, err.tolist()))
    selected = tuple(n for n, e in errors.items() if e < threshold)
    if not selected:
        if fallback not in ("best", "all"):
            raise GearshotError(f"fallback must be 'best' or 'all'; got {fallback!r}")
        selected = (min(errors, key=errors.__getitem__),) if fallback == "best" else tuple(names)
    if return_features:
        return selected, errors, (f_train[keep], f_test[keep])
    return selected, errors


def feature_invariance_errors(a: ArrayLike, b: ArrayLike) -> FloatArray:
    """Per-feature error ``mean_n |a_n - b_n| / min(std a, std b)`` of paired features."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    scale = np.minimum(a.std(axis=0), b.std(axis=0))
    with np.errstate(divide="ignore", invalid="ignore"):
        err = np.mean(np.abs(a - b), axis=0) / scale
    return np.where(scale > 0, err, np.inf)


def _long_healthy_signal(healthy_sa: FloatArray, n_cycles: int, noise_rms: float,
                         rng: np.random.Generator) -> FloatArray:
    """A long cycle-domain healthy signal of one gear: its SA repeated, fresh noise each cycle.

    What a long healthy recording is in the angle domain: the gear's periodic vibration plus
    non-synchronous vibration, here white noise.
    """
    one = healthy_sa[rng.integers(0, healthy_sa.shape[0])]
    return cast(FloatArray, one + noise_rms * rng.standard_normal((n_cycles, one.size)))


# ---------------------------------------------------------------- step 2
def tune_grade(predict_example: Callable[[int], float], grades: Sequence[int],
               faulty_size: float, *, smoothing: str = "isotonic",
               ) -> tuple[int, dict[str, FloatArray]]:
    """Step 2: the grade whose model predicts the one faulty example best.

    The paper keeps the grade whose prediction of the example is nearest its true size.
    With one example that choice is noisy (each grade's KNN prediction scatters), while the
    underlying trend is monotone: a coarser simulated grade puts more tooth-profile energy
    into the training signals, which moves the example's predicted size one way. With
    ``smoothing="isotonic"`` the predictions are first fitted by a monotone (isotonic)
    curve over the grades and the grade nearest on that curve is kept (ties: the one with
    the smaller raw error); ``smoothing="none"`` is the paper's literal rule.

    Parameters
    ----------
    predict_example : callable grade → predicted size of the faulty example
    grades : sequence of int
    faulty_size : float
        The example's true size.
    smoothing : {"isotonic", "none"}

    Returns
    -------
    grade : int
    curve : dict with arrays ``grade``, ``prediction``, ``smoothed``, ``abs_error``
        (``abs_error`` is of the curve used for the choice).
    """
    if smoothing not in ("isotonic", "none"):
        raise GearshotError(f"smoothing must be 'isotonic' or 'none'; got {smoothing!r}")
    grades = [int(g) for g in grades]
    preds = np.array([float(predict_example(g)) for g in grades])
    raw_error = np.abs(preds - faulty_size)
    smoothed = preds
    if smoothing == "isotonic" and len(grades) > 2:
        from scipy.stats import ConstantInputWarning
        from sklearn.isotonic import IsotonicRegression

        with warnings.catch_warnings():  # 'auto' direction on a flat curve: either is fine
            warnings.simplefilter("ignore", UserWarning)
            warnings.simplefilter("ignore", ConstantInputWarning)
            smoothed = IsotonicRegression(increasing="auto").fit_transform(grades, preds)
    errors = np.abs(smoothed - faulty_size)
    candidates = np.flatnonzero(np.isclose(errors, errors.min(), rtol=0, atol=1e-12))
    best = grades[int(candidates[np.argmin(raw_error[candidates])])]
    return best, {"grade": np.array(grades), "prediction": preds, "smoothed": smoothed,
                  "abs_error": errors}


# ---------------------------------------------------------------- step 3
def estimate_tf(healthy_long: ArrayLike, n_points: int, *, nfft: int = 2**15,
                segment_size: int = 200) -> ComplexArray:
    """Step 3: minimum-phase TF estimate from one long healthy angle-domain signal."""
    return estimate_transfer_function(healthy_long, n_points, nfft=nfft,
                                      segment_size=segment_size)


# ---------------------------------------------------------------- step 4
def propagate_simulated(sim_sa: ArrayLike, tf: ArrayLike | None) -> FloatArray:
    """Step 4: simulated SAs through a TF on their DFT grid (``tf=None``: unchanged)."""
    if tf is None:
        return np.asarray(sim_sa, dtype=float)
    return propagate(sim_sa, tf)


# ---------------------------------------------------------------- step 5
def rms_scale(healthy: ArrayLike, *, name: str = "the healthy SAs") -> float:
    """Step 5's scale: the mean RMS of a domain's healthy SAs (``name`` them for the error
    when it is zero)."""
    scale = mean_rms(healthy)
    if not scale > 0:
        raise GearshotError(f"{name} has zero RMS; step 5 cannot normalize by it")
    return scale


def normalize_rms(signals: ArrayLike, healthy: ArrayLike | None = None, *,
                  scale: float | None = None) -> FloatArray:
    """Step 5: divide by the mean RMS of the healthy SAs of the same domain.

    The one home of step 5, for both domains: the simulated SAs by their own healthy SAs,
    the target SAs by the target's healthy SAs (``scale``: :func:`rms_scale` of them,
    measured once at fit).
    """
    if scale is None:
        if healthy is None:
            raise GearshotError("normalize_rms needs the healthy SAs or their scale")
        scale = rms_scale(healthy)
    return np.asarray(signals, dtype=float) / scale


# ---------------------------------------------------------------- step 6
def suppress_harmonics_simulated(sim_sa: ArrayLike, healthy_mask: ArrayLike,
                                 twins: ArrayLike | None = None) -> FloatArray:
    """Step 6, simulated side: subtract the first healthy simulated SA from every SA.

    With ``twins`` (one SA per signal: the healthy SA of the same simulated gear pair,
    :func:`gearshot.sim.build_database` with ``paired=True``), subtract each signal's own
    twin instead; the difference is then the fault's signature alone, as on the target
    side where a gear is compared with itself.
    """
    sim_sa = np.asarray(sim_sa, dtype=float)
    if twins is not None:
        twins = np.asarray(twins, dtype=float)
        if twins.shape != sim_sa.shape:
            raise GearshotError(f"twins must have the shape of the simulated SAs "
                                f"{sim_sa.shape}; got {twins.shape}")
        return cast(FloatArray, sim_sa - twins)
    first = int(np.flatnonzero(healthy_mask)[0])
    return cast(FloatArray, sim_sa - sim_sa[first])


def residue_power(differences: ArrayLike) -> FloatArray:
    """Mean power spectrum ``mean_n |rfft(d_n)|²`` of difference signals (step 6 output).

    On the target's healthy SAs after harmonic suppression this is the spectrum of what a
    gear compared with itself leaves: the SAs' non-synchronous residue.
    """
    d = np.atleast_2d(np.asarray(differences, dtype=float))
    return np.asarray(np.mean(np.abs(np.fft.rfft(d, axis=-1)) ** 2, axis=0), dtype=np.float64)


def residue_noise(power: ArrayLike, n_signals: int, n_points: int,
                  rng: np.random.Generator) -> FloatArray:
    """Gaussian noise signals whose expected power spectrum is ``power``
    (from :func:`residue_power`): white noise shaped in the frequency domain
    (:func:`~gearshot.estimator._simulated.residue_noise_spectrum`, inverted)."""
    shaped = residue_noise_spectrum(power, n_signals, n_points, rng)
    return np.asarray(np.fft.irfft(shaped, n=n_points, axis=-1), dtype=np.float64)


def split_target_healthy(target_healthy: FloatArray, *, ref_fraction: float = REFERENCE_FRACTION
                         ) -> tuple[FloatArray, FloatArray]:
    """Split target healthy SAs into (training part, references): the last fifth are references."""
    n = target_healthy.shape[0]
    n_ref = reference_count(n, ref_fraction)
    if n - n_ref < 1:
        raise GearshotError(f"target_healthy holds {n} SAs; at least 2 are needed to keep "
                            f"references apart from training (5 or more recommended)")
    return target_healthy[: n - n_ref], target_healthy[n - n_ref:]


def suppress_harmonics_target(signals: ArrayLike, references: ArrayLike, *,
                              upsample: int = 100, blend: int = 1) -> FloatArray:
    """Step 6, target side: subtract the best delay-aligned healthy reference (the paper),
    or with ``blend`` > 1 the least-squares blend of that many best-aligned references,
    each at its own delay (:func:`gearshot.signal.subtract_blend`; 3 in fits that whiten
    their residue, ``EstimatorOptions.reference_blend``)."""
    if blend > 1:
        residual = subtract_blend(signals, references, n_blend=blend, upsample=upsample)[0]
        return np.asarray(residual, dtype=np.float64)
    return np.asarray(subtract_healthy(signals, references, upsample=upsample), dtype=np.float64)


# ---------------------------------------------------------------- step 7
def centred_features(sa: ArrayLike, healthy_mean: ArrayLike | None = None, *,
                     mesh_order: int | Sequence[int], names: Sequence[str],
                     healthy_mask: ArrayLike | None = None,
                     ) -> tuple[FloatArray, FloatArray]:
    """Step 7: features of (suppressed) SAs minus a healthy mean.

    Either ``healthy_mean`` (a feature vector: centre on another set's healthy mean) or
    ``healthy_mask`` (centre on the mean of these SAs' own healthy rows) is given.

    Returns
    -------
    features : ndarray (n_signals, n_features)
    mean : ndarray (n_features,)
        The healthy mean used.
    """
    feats = extract_features(sa, mesh_order, names=names)
    if healthy_mean is None:
        if healthy_mask is None or not np.any(healthy_mask):
            raise GearshotError("centred_features needs healthy_mean or a non-empty "
                                "healthy_mask")
        healthy_mean = feats[np.asarray(healthy_mask)].mean(axis=0)
    mean = np.asarray(healthy_mean, dtype=np.float64)
    return np.asarray(feats - mean, dtype=np.float64), mean


def simulated_features(sim_sa: ArrayLike, healthy_mask: ArrayLike, tf: ArrayLike | None, *,
                       mesh_order: int | Sequence[int], names: Sequence[str],
                       rms_normalization: bool = True, twins: ArrayLike | None = None,
                       noise: ArrayLike | None = None,
                       noise_spectrum: ArrayLike | None = None,
                       kept: dict[str, Any] | None = None) -> FloatArray:
    """Steps 4–7 on one set of simulated SAs: propagate, normalize, suppress, centre.

    Steps 4–6 are linear: they run on the one-sided spectra and the features start from
    the result (:func:`gearshot.features.spectrum_features`; the time-domain steps' numbers
    to within rounding, two FFTs per signal fewer).

    Parameters
    ----------
    sim_sa : ndarray (n_signals, n_points)
    healthy_mask : ndarray of bool (n_signals,)
        The healthy SAs (the RMS reference, the subtracted SA and the centring mean).
    tf : ndarray of complex (n_points,) or None
        Transfer function of step 4 (None: no propagation).
    mesh_order : int or sequence of int
    names : sequence of str
    rms_normalization : bool, default True
        Apply step 5.
    twins : ndarray (n_signals, n_points), optional
        Each signal's healthy twin: step 6 subtracts it (propagated and scaled like the
        signals) instead of the first healthy SA.
    noise : ndarray (n_signals, n_points), optional
        Residue added to the difference signals (noise matching: :func:`residue_noise`
        of the target's healthy differences' :func:`residue_power`); with twins the
        simulated differences have no residue of their own.
    noise_spectrum : ndarray of complex (n_signals, n_points // 2 + 1), optional
        The same given by its ``rfft`` (one draw added to many sets is transformed once).
    kept : dict, optional
        With twins and ``noise_spectrum``: where the features of healthy rows equal to
        their twin are kept across sets (:func:`._simulated.twin_difference_features`).

    Returns
    -------
    ndarray (n_signals, n_features)
        Centred features (without twins, the first healthy SA's row is the zero-signal's
        features).
    """
    healthy = np.asarray(healthy_mask, bool)
    sim_sa = np.asarray(sim_sa, dtype=float)
    if twins is None:
        reference = sim_sa[int(np.flatnonzero(healthy)[0])]
    else:
        reference = np.asarray(twins, dtype=float)
        if reference.shape != sim_sa.shape:
            raise GearshotError(f"twins must have the shape of the simulated SAs "
                                f"{sim_sa.shape}; got {reference.shape}")
    scale = (rms_scale(propagate_simulated(sim_sa[healthy], tf)) if rms_normalization
             else 1.0)
    tf = None if tf is None else np.asarray(tf)
    if kept is not None and twins is not None and noise_spectrum is not None and noise is None:
        feats = twin_difference_features(sim_sa, reference, healthy, tf, scale,
                                         mesh_order=mesh_order, names=names,
                                         noise_spectrum=np.asarray(noise_spectrum), kept=kept)
    else:
        feats = difference_features(
            sim_sa, reference, tf, scale, mesh_order=mesh_order, names=names,
            noise=None if noise is None else np.asarray(noise, dtype=float),
            noise_spectrum=None if noise_spectrum is None else np.asarray(noise_spectrum))
    return np.asarray(feats - feats[healthy].mean(axis=0), dtype=np.float64)


# ---------------------------------------------------------------- step 8
# fit_knn and KnnModel (from .knn): K-nearest-neighbour regression, K on one split.
