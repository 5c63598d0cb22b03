"""The target side of ``fit``: steps 3 and 5–7 on the target machine's SAs."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..signal.alignment import subtract_with_lags
from . import steps
from ._inputs import _FitInputs, _on_grid
from ._shared_work import keep, kept, shared, sharing
from .zero_shot import residue_mean_square

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


def suppressed_target(signals: FloatArray, references: FloatArray, upsample: int,
                      unscaled: tuple[FloatArray, FloatArray] | None = None) -> FloatArray:
    """Step 6 on target SAs (:func:`steps.suppress_harmonics_target`), shared inside a
    :func:`shared_target_work` block.

    ``unscaled``: the same SAs and references before a common scale was divided out
    (``signals == unscaled[0] / s``, ``references == unscaled[1] / s``). The lag search
    does not depend on that scale, so the lags found for the unscaled arrays serve the
    scaled ones (and the other way round); the residual is computed as without them.
    """
    def compute() -> FloatArray:
        if not sharing():
            return steps.suppress_harmonics_target(signals, references, upsample=upsample)
        on = (*(unscaled or (signals, references)), int(upsample))
        lags = kept("lags", on)
        residual, found = subtract_with_lags(signals, references, upsample=upsample,
                                             lags=lags)
        if lags is None:
            keep("lags", on, found)
        return residual

    return shared("suppress", (signals, references, int(upsample)), compute)


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


def fit_target_side(est: Any, inputs: _FitInputs, names: tuple[str, ...],
                    recordings: NDArray[Any] | None = None) -> _TargetSide:
    """Steps 3 and 5–7 on the target: TF, scale, references, healthy features.

    ``recordings`` (the healthy SAs' recording labels, or None): each training SA's
    step-6 reference is then taken from the *other* recordings only (:func:`cross_run`).
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
    if recordings is None:
        sub_h = suppressed_target(train_h, references, upsample, unscaled)
    else:
        sub_h = cross_run(train_h, references, recordings, upsample, unscaled)
    feats_h, mean_h = steps.centred_features(sub_h, mesh_order=est._mesh_orders(),
                                             names=names,
                                             healthy_mask=np.ones(len(sub_h), bool))
    return _TargetSide(tf, scale, scaled, references, mean_h, feats_h,
                       steps.residue_power(sub_h),
                       residue_mean_square(sub_h, est._mesh_orders()))


def cross_run(train: FloatArray, references: FloatArray, recordings: NDArray[Any],
              upsample: int, unscaled: tuple[FloatArray, FloatArray] | None = None
              ) -> FloatArray:
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
        out[rows] = suppressed_target(train[rows], references[other], upsample, part)
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
                    healthy_mean: FloatArray, names: tuple[str, ...]) -> FloatArray:
    """Steps 5–7 on target SAs with the target side's scale, references and mean
    (shared inside a :func:`shared_target_work` block)."""
    x = np.atleast_2d(np.asarray(sa, dtype=float))
    upsample, orders = est._options().upsample, est._mesh_orders()

    def compute() -> FloatArray:
        y, unscaled = x, None
        if est.rms_normalization:
            y = steps.normalize_rms(x, scale=scale)
            raw_refs = kept("unscaled references", (references, float(scale)))
            unscaled = None if raw_refs is None else (x, raw_refs)
        sub = suppressed_target(y, references, upsample, unscaled)
        feats, _ = steps.centred_features(sub, healthy_mean, mesh_order=orders, names=names)
        return feats

    return shared("features", (x, bool(est.rms_normalization), float(scale), references,
                                np.asarray(healthy_mean, dtype=float), tuple(names),
                                orders, int(upsample)), compute)
