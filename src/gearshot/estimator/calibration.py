"""Calibration beyond the grade: fault gain, fault width and TF mode from the one example.

On a paired database every simulated signal is its healthy twin plus a fault component
``Δ = sa - sa_twin``. Two of the quantities by which the lab's later model (PHM-BGU,
arXiv 2410.05073) calibrates its simulation act on ``Δ`` alone, so they need no new
simulation:

* the **fault gain** ``a`` (the fault-to-harmonics ratio): ``Δ → a·Δ``;
* the **fault width** ``w`` (the angular extent of the fault's signature): ``Δ`` stretched
  (``w > 1``) or compressed (``w < 1``) in angle about the fault's centre.

Two more come from the target itself: the **noise level** (the non-synchronous residue of
its healthy recordings, added to every simulated difference: noise matching) and the
**TF mode** (the simulated signals through the transfer function in effect, or RMS
normalization alone, which wins where the blind TF estimate misleads).

A *setting* is one (grade, gain, width, TF mode). :func:`setting_log_likelihoods` scores
every setting of a grid by how well it explains the faulty example: its whole centred
feature vector (all candidate features, not only the size a model predicts for it) is
compared with the simulated feature vectors of the same size under that setting (a
diagonal Gaussian whose spread is the simulated scatter plus the target's healthy
scatter). The weights are the normalized likelihoods (a posterior under a flat prior on
the grid); the estimator fits one model per setting that carries weight and averages
their predictions, as the soft grade weights do.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from typing import Any, cast

import numpy as np
from numpy.typing import NDArray

from .._errors import GearshotError
from . import steps

__all__ = ["CalibrationOptions", "resolve_calibration", "fault_centre", "stretch_about",
           "setting_differences", "setting_log_likelihoods", "CALIBRATION_STRATEGIES"]

FloatArray = NDArray[np.float64]

#: What ``OneFaultShotEstimator(calibration=...)`` accepts as a string: the grade-choice
#: strategies (see the estimator's ``calibration`` parameter).
CALIBRATION_STRATEGIES = ("grade", "tuned", "joint", "nominal", "zero_shot")

TF_MODES = ("tf", "none")


@dataclass(frozen=True)
class CalibrationOptions:
    """The grid and rules of the joint calibration (research knobs; defaults = ``"joint"``).

    Attributes
    ----------
    gains : tuple of float > 0
        Fault gains tried (multiply the fault component ``Δ``).
    widths : tuple of float > 0
        Angular stretch factors of ``Δ`` about the fault centre (1 = as simulated).
    tf_modes : tuple of {"tf", "none"}
        "tf": simulated signals through the estimator's transfer function (estimated or
        given); "none": RMS normalization alone. Only "none" is possible when the
        estimator has no TF (``transfer_function="none"``).
    noise_scales : tuple of float >= 0
        Factors on the matched noise power (1 = the target's measured residue).
    n_near : int >= 2
        The simulated faulty signals of each grade nearest the example's size that
        describe that size under a setting.
    max_settings : int >= 1
        Settings that get their own model (the largest weights; the rest are dropped and
        the kept weights renormalized).
    features : {"candidates", "selected"}
        Feature vector compared: every candidate feature or step 1's selection.
    temperature : float > 0
        Log-likelihoods are divided by it before normalizing (1: the plain posterior;
        larger spreads the weights).
    """

    gains: tuple[float, ...] = (0.7, 1.0, 1.4)
    widths: tuple[float, ...] = (0.75, 1.0, 1.33)
    tf_modes: tuple[str, ...] = TF_MODES
    noise_scales: tuple[float, ...] = (1.0,)
    n_near: int = 24
    max_settings: int = 6
    features: str = "candidates"
    temperature: float = 1.0

    def __post_init__(self) -> None:
        for name in ("gains", "widths", "noise_scales"):
            values = tuple(float(v) for v in getattr(self, name))
            zero_ok = name == "noise_scales"
            if not values or not all(np.isfinite(v) and (v >= 0 if zero_ok else v > 0)
                                     for v in values):
                raise GearshotError(f"calibration {name} must be a non-empty list of "
                                    f"{'non-negative' if name == 'noise_scales' else 'positive'}"
                                    f" numbers; got {getattr(self, name)!r}")
            object.__setattr__(self, name, values)
        modes = tuple(str(m) for m in self.tf_modes)
        if not modes or any(m not in TF_MODES for m in modes):
            raise GearshotError(f"calibration tf_modes must hold 'tf' and/or 'none'; got "
                                f"{self.tf_modes!r}")
        object.__setattr__(self, "tf_modes", modes)
        if int(self.n_near) < 2:
            raise GearshotError(f"calibration n_near must be >= 2; got {self.n_near!r}")
        if int(self.max_settings) < 1:
            raise GearshotError(f"calibration max_settings must be >= 1; got "
                                f"{self.max_settings!r}")
        if self.features not in ("candidates", "selected"):
            raise GearshotError(f"calibration features must be 'candidates' or 'selected'; "
                                f"got {self.features!r}")
        if not float(self.temperature) > 0:
            raise GearshotError(f"calibration temperature must be > 0; got "
                                f"{self.temperature!r}")

    def as_dict(self) -> dict[str, Any]:
        out = asdict(self)
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in out.items()}


def resolve_calibration(value: Any) -> CalibrationOptions | None:
    """The joint grid of ``calibration=``: ``"joint"`` → the default grid, a mapping or
    :class:`CalibrationOptions` → that grid, the other strategies (``"grade"``,
    ``"tuned"``, ``"nominal"``, ``"zero_shot"``: no joint grid) → None."""
    if isinstance(value, CalibrationOptions):
        return value
    if isinstance(value, str):
        if value == "joint":
            return CalibrationOptions()
        if value in CALIBRATION_STRATEGIES:
            return None
    elif isinstance(value, Mapping):
        known = set(CalibrationOptions.__dataclass_fields__)
        unknown = sorted(set(value) - known)
        if unknown:
            raise GearshotError(f"calibration has unknown option(s) {unknown}; known: "
                                f"{sorted(known)}")
        return CalibrationOptions(**dict(value))
    raise GearshotError(f"calibration must be one of {list(CALIBRATION_STRATEGIES)}, a "
                        f"mapping of CalibrationOptions fields or a CalibrationOptions; got "
                        f"{value!r}")


def fault_centre(delta: FloatArray) -> int:
    """Sample of the fault's centre in the cycle: the peak of the mean smoothed |Δ|.

    ``delta`` holds fault components (n_signals, n_points) of one gear position (the
    simulator puts the fault on one tooth); the envelope is smoothed over 1/64 cycle.
    """
    delta = np.atleast_2d(np.asarray(delta, float))
    n = delta.shape[1]
    energy = np.mean(delta**2, axis=0)
    width = max(1, n // 64)
    kernel = np.ones(width) / width
    smooth = np.convolve(np.concatenate([energy[-width:], energy, energy[:width]]), kernel,
                         mode="same")[width:-width]
    return int(np.argmax(smooth))


def stretch_about(delta: FloatArray, width: float, centre: int) -> FloatArray:
    """``Δ`` stretched by ``width`` in angle about ``centre`` (linear interpolation).

    ``out[n] = Δ(c + (n - c)/width)`` with ``n - c`` taken on the circle; where the
    source lies more than half a cycle from the centre (compression), ``out`` is 0.
    ``width = 1`` returns ``delta`` unchanged.
    """
    delta = np.atleast_2d(np.asarray(delta, float))
    if width == 1.0:
        return delta
    n = delta.shape[1]
    offset = (np.arange(n) - centre + n // 2) % n - n // 2
    source = offset / width
    inside = np.abs(source) <= n // 2
    pos = (centre + source) % n
    lo = np.floor(pos).astype(int) % n
    hi = (lo + 1) % n
    frac = pos - np.floor(pos)
    out = delta[:, lo] * (1 - frac) + delta[:, hi] * frac
    out[:, ~inside] = 0.0
    return cast(FloatArray, out)


def setting_differences(delta: FloatArray, tf: Any, scale: float, *, gain: float,
                        width: float, centre: int) -> FloatArray:
    """Step 6's simulated difference signals under one setting (before the noise).

    ``delta`` are raw fault components (simulator output, before the path); they are
    stretched, propagated through ``tf`` (None: not), divided by ``scale`` (the mean RMS
    of the same grade's healthy SAs through the same TF: step 5) and multiplied by
    ``gain``.
    """
    d = steps.propagate_simulated(stretch_about(delta, width, centre), tf)
    return (gain / scale) * d


def setting_log_likelihoods(example: FloatArray, simulated: Sequence[FloatArray],
                            target_spread: FloatArray) -> FloatArray:
    """Log-likelihood of the example's feature vector under each setting.

    Parameters
    ----------
    example : ndarray (n_features,)
        The example's centred features.
    simulated : sequence of ndarray (n_near, n_features)
        Each setting's centred simulated features at the example's size.
    target_spread : ndarray (n_features,)
        Standard deviation of the target's healthy centred features (the measurement
        scatter of one SA).

    Returns
    -------
    ndarray (n_settings,)
        ``Σ_j log N(x_j; μ_j, σ_j² + s_j²)`` with ``μ, σ`` the setting's mean and std.
    """
    example = np.asarray(example, float)
    out = np.empty(len(simulated))
    floor = np.asarray(target_spread, float) ** 2 + 1e-12
    for i, feats in enumerate(simulated):
        feats = np.asarray(feats, float)
        if feats.shape[0] < 2:
            raise GearshotError("a calibration setting has fewer than 2 simulated signals "
                                "near the example's size; raise n_near")
        var = feats.var(axis=0, ddof=1) + floor
        out[i] = float(np.sum(-0.5 * (example - feats.mean(axis=0)) ** 2 / var
                              - 0.5 * np.log(2 * np.pi * var)))
    return out
