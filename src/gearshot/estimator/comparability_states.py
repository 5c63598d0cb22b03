"""The fitted machine's states and a segment's distance from them (what
:mod:`gearshot.estimator.comparability` tests and calibrates; see its docstring)."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._errors import GearshotError

FloatArray = NDArray[np.float64]

#: Fewest healthy recordings whose leave-one-recording-out scores calibrate the test (with
#: fewer, each SA is left out alone): two recordings give one between-run difference each,
#: too few to tell a run-to-run spread from one odd run (chosen on the development lives of
#: ``benchmarks/monitor_lives.py``).
MIN_GROUPS = 3

#: Smallest standard deviation of a feature (log10 units; kurtosis units for kurtosis):
#: identical healthy SAs would otherwise make every other segment infinitely far.
MIN_STD = 1e-3

#: Relative uncertainty of the example's effect on each feature: a fault of another size
#: moves every feature toward the example's value, but not in exact proportion (measured
#: on virtual rigs: a size-0.3 fault moves the level 18 % and the background 43 % of the
#: way to a size-0.6 example). Chosen on the development part of the matrix (0, 0.05,
#: 0.1, 0.25, 0.5, 1 tried: the smallest value that keeps a smaller fault of the
#: development rig comparable).
FAULT_SHAPE_UNCERTAINTY = 0.25

#: Largest step of the level along the fault, in multiples of the step of the signal's
#: shape (every other group's features projected together on their part of the fault
#: direction): a fault that raises the level changes the signal's shape too (its
#: sidebands, shaft orders, kurtosis), while another gain or a louder path moves the level
#: alone. Chosen on the development part of the matrix and the development lives.
LEVEL_STEP_RATIO = 2.0


def _group_masks(groups: tuple[str, ...]) -> list[NDArray[np.bool_]]:
    labels = np.asarray(groups)
    return [labels == g for g in dict.fromkeys(groups)]


def _local_spread(features: FloatArray) -> FloatArray:
    """RMS difference of each row from its nearest other row (in pooled standard
    deviations) over ``sqrt(2)``, per column, at least :data:`MIN_STD`."""
    pooled = np.sqrt(features.var(axis=0, ddof=1) + MIN_STD ** 2)
    z = features / pooled
    gap = np.sum((z[:, None, :] - z[None, :, :]) ** 2, axis=-1)
    np.fill_diagonal(gap, np.inf)
    nearest = features[np.argmin(gap, axis=1)]
    return np.asarray(np.sqrt(np.mean((features - nearest) ** 2, axis=0) / 2
                              + MIN_STD ** 2), dtype=float)


def _distance(z: FloatArray, anchors: FloatArray, direction: FloatArray,
              max_step: float, masks: list[NDArray[np.bool_]]
              ) -> tuple[FloatArray, FloatArray]:
    """Distance of standardised rows ``z`` from the nearest state ``anchor + t_g v_g``
    (the first mask is the level's: its step at most :data:`LEVEL_STEP_RATIO` times the
    step of the other groups taken together), and the level's residual at that state in
    its standard deviations.

    The other groups are taken together, not by the farthest-moved one: a group that the
    fault barely moves has a short direction, so its step is set by noise alone and may be
    anything up to ``max_step`` at no cost; it freed the level of every segment, and a
    healthy record through a sensor of twice the gain passed as a fault state."""
    offset = z[:, None, :] - anchors[None, :, :]        # (m, n_anchors, d)
    total = np.zeros(offset.shape[:2])

    def step(mask: NDArray[np.bool_]) -> FloatArray:
        v = direction[mask]
        vv = float(v @ v)
        return (np.clip(offset[..., mask] @ v / vv, 0.0, max_step) if vv > 0
                else np.zeros(total.shape))

    steps = [step(mask) for mask in masks]
    if len(steps) > 1:   # the shape's step: every other group at once
        shape = np.logical_or.reduce(masks[1:])
        steps[0] = np.minimum(steps[0], LEVEL_STEP_RATIO * step(shape))
    level = np.zeros(total.shape)
    for i, (mask, t) in enumerate(zip(masks, steps, strict=True)):
        v = direction[mask]
        resid = offset[..., mask] - t[..., None] * v
        var = 1.0 + t[..., None] ** 2 * (1.0 + (FAULT_SHAPE_UNCERTAINTY * v) ** 2)
        part = np.sum(resid ** 2 / var, axis=-1)
        total += part
        if i == 0:
            level = np.sqrt(part)
    best = np.argmin(total, axis=1)
    rows = np.arange(len(z))
    return (np.asarray(np.sqrt(total[rows, best] / z.shape[1]), dtype=float),
            np.asarray(level[rows, best], dtype=float))


def _states(features: FloatArray, example: FloatArray | None
            ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Mean, local spread, anchors and fault direction of healthy feature rows."""
    mean = features.mean(axis=0)
    std = _local_spread(features)
    anchors = (features - mean) / std
    direction = np.zeros_like(mean)
    if example is not None:
        ez = (example - mean) / std
        gap = np.sum((anchors - ez) ** 2, axis=1)
        direction = ez - anchors[gap <= np.median(gap)].mean(axis=0)
    return mean, std, anchors, direction


def _leave_one_out_scores(features: FloatArray, example: FloatArray | None,
                          max_step: float, masks: list[NDArray[np.bool_]],
                          recordings: NDArray[Any] | None = None
                          ) -> tuple[FloatArray, FloatArray]:
    """Each healthy row scored by the states fitted on the others (on the other
    recordings' rows when ``recordings`` labels the rows): scores and level residuals."""
    labels = np.arange(len(features)) if recordings is None else recordings
    scores, levels = np.empty(len(features)), np.empty(len(features))
    for label in dict.fromkeys(labels.tolist()):
        out = labels == label
        mean, std, anchors, direction = _states(features[~out], example)
        scores[out], levels[out] = _distance((features[out] - mean) / std, anchors,
                                             direction, max_step, masks)
    return scores, levels


def _recording_labels(recordings: ArrayLike | None, n: int, name: str = "recordings"
                      ) -> NDArray[Any] | None:
    """The recording labels (argument ``name``) of ``n`` healthy SAs when they name at
    least :data:`MIN_GROUPS` recordings (else None: leave one SA out; the references of
    step 6 are the last SAs)."""
    if recordings is None:
        return None
    labels = np.asarray(recordings).reshape(-1)
    if labels.size != n:
        raise GearshotError(f"{name} has {labels.size} labels for {n} healthy SAs")
    return labels if len(set(labels.tolist())) >= MIN_GROUPS else None
