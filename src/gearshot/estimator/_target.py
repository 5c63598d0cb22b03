"""The target side of ``fit``: steps 3 and 5–7 on the target machine's SAs."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..signal.alignment import subtract_with_lags
from ..signal.orders import mesh_band_orders
from ..signal.reference_blend import subtract_blend
from . import steps
from ._inputs import _FitInputs, _on_grid
from ._shared_work import keep, kept, shared, sharing
from .calibration import resolve_calibration
from .whitening import MIN_RUNS, filter_orders, residue_weights, two_sided
from .zero_shot import residue_mean_square

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

#: References blended by step 6 on the target under ``reference_blend="auto"`` (chosen on
#: the rig family's development range: 1 → 8.09 %, 2 → 8.07, 3 → 7.75, 5 → 7.74;
#: benchmarks/RESULTS.md, "Estimator").
BLEND = 3


def suppressed_target(signals: FloatArray, references: FloatArray, upsample: int,
                      unscaled: tuple[FloatArray, FloatArray] | None = None,
                      blend: int = 1) -> FloatArray:
    """Step 6 on target SAs (:func:`steps.suppress_harmonics_target`), shared inside a
    :func:`shared_target_work` block.

    ``blend`` > 1: the least-squares blend of that many best-aligned references is
    subtracted instead of the best one (:func:`~gearshot.signal.reference_blend.subtract_blend`).

    ``unscaled``: the same SAs and references before a common scale was divided out
    (``signals == unscaled[0] / s``, ``references == unscaled[1] / s``). The lag search
    does not depend on that scale, so the lags found for the unscaled arrays serve the
    scaled ones (and the other way round); the residual is computed as without them.
    """
    def compute() -> FloatArray:
        if not sharing():
            return steps.suppress_harmonics_target(signals, references, upsample=upsample,
                                                   blend=blend)
        on = (*(unscaled or (signals, references)), int(upsample), int(blend))
        lags = kept("lags", on)
        if blend > 1:
            residual, found = subtract_blend(signals, references, n_blend=blend,
                                             upsample=upsample, lags=lags)
        else:
            residual, found = subtract_with_lags(signals, references, upsample=upsample,
                                                 lags=lags)
        if lags is None:
            keep("lags", on, found)
        return residual

    return shared("suppress", (signals, references, int(upsample), int(blend)), compute)


def reference_blend(est: Any, whitening: bool) -> int:
    """How many healthy references step 6 blends on the target
    (:attr:`~gearshot.estimator.EstimatorOptions.reference_blend` resolved: ``"auto"`` is
    :data:`BLEND` in a fit that ``whitening`` says whitens its residue (healthy runs of
    ``MIN_RUNS`` recordings or more, not the paper's estimator), else 1. Blended within
    one recording, the references follow that run's segments closer than a later run's,
    and the fit then reads its own healthy hold-outs as a fault: PHM09 30 Hz High, one
    healthy recording, hold-outs 0.09 → 0.26 with 3 references)."""
    value = est._options().reference_blend
    if value == "auto":
        return BLEND if whitening else 1
    return int(value)


@dataclass(frozen=True)
class _TargetSide:
    """What steps 3 and 5–7 learn from the target's healthy SAs."""

    transfer_function: ComplexArray | None
    scale: float
    scaled_healthy: FloatArray
    references: FloatArray
    healthy_mean: FloatArray
    healthy_features: FloatArray
    residue_power: FloatArray
    residue_ms: float
    weights: FloatArray | None = None          # residue whitening of the differences
    simulated_tf: ComplexArray | None = None   # what the simulated side goes through
    residues: FloatArray | None = None         # the matched noise's draws, when recorded
    blend: int = 1                             # healthy references step 6 blends


def fit_target_side(est: Any, inputs: _FitInputs, names: tuple[str, ...],
                    recordings: NDArray[Any] | None = None,
                    matched: bool = False) -> _TargetSide:
    """Steps 3 and 5–7 on the target: TF, scale, references, healthy features.

    ``recordings`` (the healthy SAs' recording labels, or None): each training SA's
    step-6 reference is then taken from the *other* recordings only (:func:`cross_run`).
    ``matched``: the simulated side subtracts twins and adds the target's residue. The
    residue whitening needs it (without it the weighted residue has no counterpart) and
    healthy recordings of ``MIN_RUNS`` runs or more (weights learned within one run
    meet another run's residue where that run was quiet). The residue added is drawn from
    the healthy differences themselves when ``residue_draws`` says so (``"auto"``: when
    the fit whitens), else Gaussian with their mean power.
    """
    tf = target_tf(est, inputs.healthy_long, inputs.n_points)
    scale = steps.rms_scale(inputs.target_healthy, name="target_healthy")
    scaled = steps.normalize_rms(inputs.target_healthy, scale=scale) \
        if est.rms_normalization else inputs.target_healthy
    train_h, references = steps.split_target_healthy(scaled)
    unscaled = None
    if est.rms_normalization:  # the unscaled arrays' lags serve (shared_target_work)
        unscaled = steps.split_target_healthy(inputs.target_healthy)
        keep("unscaled references", (references, float(scale)), unscaled[1])
    upsample = est._options().upsample
    whitening = whitens(est, recordings, matched)
    blend = reference_blend(est, whitening)

    def step6(train: FloatArray, refs: FloatArray,
              raw: tuple[FloatArray, FloatArray] | None = None) -> FloatArray:
        if recordings is None:
            return suppressed_target(train, refs, upsample, raw, blend)
        return cross_run(train, refs, recordings, upsample, raw, blend)

    sub_h = step6(train_h, references, unscaled)
    weights, sim_tf = fit_whitening(est, inputs, sub_h, scale, tf, whitening)
    sub_w = sub_h
    if weights is not None:   # step 6 again on the filtered SAs (their own lags)
        sub_w = step6(filter_orders(train_h, weights), filter_orders(references, weights))
    feats_h, mean_h = steps.centred_features(sub_w, mesh_order=est._mesh_orders(),
                                             names=names,
                                             healthy_mask=np.ones(len(sub_h), bool))
    draws = est._options().residue_draws
    recorded = matched and (draws == "recorded" or (draws == "auto" and weights is not None))
    return _TargetSide(tf, scale, scaled, references, mean_h, feats_h,
                       steps.residue_power(sub_w),
                       residue_mean_square(sub_h, est._mesh_orders()), weights, sim_tf,
                       sub_w if recorded else None, blend)


def whitens(est: Any, recordings: NDArray[Any] | None, matched: bool) -> bool:
    """Whether the fit whitens its residue (:func:`fit_whitening`): the option is on
    (``"auto"``: but for the paper's estimator), the calibration is not joint, the
    simulated side is ``matched`` and the healthy SAs come from ``MIN_RUNS`` or more
    ``recordings``."""
    mode = est._options().residue_whitening
    runs = 0 if recordings is None else np.unique(np.asarray(recordings)).size
    return not (mode == "off" or (mode == "auto" and getattr(est, "estimator", "paper")
                                  == "paper")
                or resolve_calibration(est.calibration) is not None or not matched
                or runs < MIN_RUNS)


def fit_whitening(est: Any, inputs: _FitInputs, differences: FloatArray, scale: float,
                  tf: ComplexArray | None, whitening: bool
                  ) -> tuple[FloatArray | None, ComplexArray | None]:
    """The target differences' weights and the simulated side's transfer function
    (:mod:`.whitening`), or ``(None, tf)`` when the fit does not whiten (``whitening``,
    :func:`whitens`: the option is off — ``"auto"``: for the paper's estimator —, the
    calibration is joint, the simulated side is not matched or the healthy SAs come from
    fewer than ``MIN_RUNS`` recordings).

    Step 5 then divides each side by its own healthy RMS *after* the weights: the target's
    weights carry the ratio of the raw to the filtered scale (its differences are formed
    on the raw scale), the simulated side filters before its scale is taken."""
    if not whitening:
        return None, tf
    healthy, n = inputs.target_healthy, inputs.n_points
    base = residue_weights(differences)
    base[mesh_band_orders(n, est._mesh_orders(), 2)] = 0.0   # what the features drop
    weights = base
    if est.rms_normalization:
        weights = base * (scale / steps.rms_scale(filter_orders(healthy, base),
                                                  name="target_healthy"))
    sim_tf = two_sided(base, n).astype(np.complex128)
    return weights, sim_tf if tf is None else sim_tf * np.asarray(tf)


def cross_run(train: FloatArray, references: FloatArray, recordings: NDArray[Any],
              upsample: int, unscaled: tuple[FloatArray, FloatArray] | None = None,
              blend: int = 1) -> FloatArray:
    """Step 6 on the training SAs with references of other recordings only.

    A recording estimated later is another run: none of step 6's references comes from
    it. The target's healthy differences that centre the features and set the noise
    matched on the simulated side are formed the same way, so that they carry the
    run-to-run change a new recording brings (a training SA whose recording holds every
    reference keeps them all). ``recordings`` labels ``train`` then ``references``.
    """
    labels = np.asarray(recordings)
    own, ref_labels = labels[: len(train)], labels[len(train):]
    out = np.empty_like(train)
    for group in dict.fromkeys(own.tolist()):
        rows = np.nonzero(own == group)[0]
        other = ref_labels != group
        if not other.any():
            other = np.ones(len(references), bool)
        part = None if unscaled is None else (unscaled[0][rows], unscaled[1][other])
        out[rows] = suppressed_target(train[rows], references[other], upsample, part, blend)
    return out


def target_tf(est: Any, healthy_long: FloatArray | None,
              n_points: int) -> ComplexArray | None:
    """Step 3, or the given TF on the SA grid, or None."""
    tf = est.transfer_function
    if isinstance(tf, str):
        if tf == "none" or healthy_long is None:  # checked: "estimate" has it
            return None
        return steps.estimate_tf(healthy_long, n_points)
    return _on_grid(tf, n_points, "transfer_function")


def target_features(est: Any, sa: ArrayLike | None, scale: float, references: FloatArray,
                    healthy_mean: FloatArray, names: tuple[str, ...],
                    weights: FloatArray | None = None, blend: int = 1) -> FloatArray:
    """Steps 5–7 on target SAs with the target side's scale, references, mean, residue
    weights and reference blend (shared inside a :func:`shared_target_work` block)."""
    x = np.atleast_2d(np.asarray(sa, dtype=float))
    upsample, orders = est._options().upsample, est._mesh_orders()

    def compute() -> FloatArray:
        y, unscaled = x, None
        if est.rms_normalization:
            y = steps.normalize_rms(x, scale=scale)
            raw_refs = kept("unscaled references", (references, float(scale)))
            unscaled = None if raw_refs is None else (x, raw_refs)
        if weights is None:
            sub = suppressed_target(y, references, upsample, unscaled, blend)
        else:   # filtered SAs and references, their own lags
            sub = suppressed_target(filter_orders(y, weights),
                                    filter_orders(references, weights), upsample,
                                    blend=blend)
        feats, _ = steps.centred_features(sub, healthy_mean, mesh_order=orders, names=names)
        return feats

    return shared("features", (x, bool(est.rms_normalization), float(scale), references,
                                np.asarray(healthy_mean, dtype=float), tuple(names),
                                orders, int(upsample), blend,
                                None if weights is None else np.asarray(weights)), compute)
