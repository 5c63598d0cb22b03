"""``fit``'s arguments checked, the per-step seeds and step 1's default held-out TF."""

from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._errors import GearshotError
from .._validation import as_signal_array
from ..transfer import resample_transfer_function
from .comparability_states import _recording_labels

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

#: The steps that draw random numbers, each from its own child seed of ``random_state``
#: (in this order of :meth:`numpy.random.SeedSequence.spawn`).
STEP_SEEDS = ("select_features", "fit_knn", "match_noise")


def _step_seeds(random_state: Any) -> dict[str, int]:
    """One independent seed per random step, derived from ``random_state``.

    The root entropy is ``random_state`` itself (an int), one draw from it (a RandomState
    or Generator) or fresh OS entropy (None); :class:`numpy.random.SeedSequence` spawns
    one child per name of :data:`STEP_SEEDS`. Switching a step off therefore does not move
    any other step's random numbers.
    """
    if random_state is None:
        root = np.random.SeedSequence()
    elif isinstance(random_state, np.random.RandomState):
        root = np.random.SeedSequence(int(random_state.randint(np.iinfo(np.int32).max)))
    elif isinstance(random_state, np.random.Generator):
        root = np.random.SeedSequence(int(random_state.integers(2**63)))
    else:
        root = np.random.SeedSequence(int(random_state))
    children = root.spawn(len(STEP_SEEDS))
    return {name: int(child.generate_state(1)[0]) for name, child in zip(STEP_SEEDS, children)}


def default_selection_tf(random_state: Any = 0) -> Any:
    """Step 1's held-out TF when none is given: one TF of
    :meth:`gearshot.transfer.TransferFunctionBank.synthetic`, drawn with
    ``numpy.random.default_rng([random_state, 99])`` for an int ``random_state`` (the TF
    ``gearshot predict`` and ``gearshot experiment rig`` use with ``--seed``), else from
    the ``select_features`` step seed of ``random_state``."""
    from ..transfer import TransferFunctionBank

    if isinstance(random_state, numbers.Integral) and not isinstance(random_state, bool):
        rng = np.random.default_rng([int(random_state), 99])
    else:
        rng = np.random.default_rng(_step_seeds(random_state)["select_features"])
    return TransferFunctionBank.synthetic(1, rng=rng)[0]


def _on_grid(tf: Any, n_points: int, name: str) -> ComplexArray:
    """A TF on the n-point DFT grid from an array (grid or one-sided) or a TransferFunction."""
    if hasattr(tf, "to_signal_grid"):
        return np.asarray(tf.to_signal_grid(n_points), dtype=complex)
    arr = as_signal_array(tf, name, max_ndim=1, allow_complex=True)
    if arr.size == n_points:
        return arr.astype(complex)
    return np.asarray(resample_transfer_function(arr, n_points), dtype=complex)


@dataclass(frozen=True)
class _FitInputs:
    """The checked arguments of :meth:`OneFaultShotEstimator.fit`."""

    target_healthy: FloatArray
    faulty_example: FloatArray | None
    faulty_size: float | None
    healthy_long: FloatArray | None
    selection_tf: Any
    n_points: int


def check_fit_inputs(est: Any, target_healthy: ArrayLike, faulty_example: ArrayLike | None,
                      faulty_size: float | None, healthy_long: ArrayLike | None,
                      selection_tf: Any) -> _FitInputs:
    """Check ``fit``'s arguments against each other and the parameters."""
    healthy = as_signal_array(target_healthy, "target_healthy", min_ndim=2, max_ndim=2,
                              min_length=16)
    n_points = healthy.shape[1]
    if healthy.shape[0] < 2:
        raise GearshotError(f"target_healthy holds {healthy.shape[0]} SA(s); at "
                            f"least 2 are needed (5 or more recommended)")
    example, size = None, None
    if est._strategy_name() != "zero_shot":
        if faulty_example is None or faulty_size is None:
            raise GearshotError("faulty_example and faulty_size are required unless "
                                "calibration='zero_shot'")
        example = as_signal_array(faulty_example, "faulty_example",
                                  max_ndim=2).reshape(-1)
        if example.size != n_points:
            raise GearshotError(f"faulty_example has {example.size} points but "
                                f"target_healthy SAs have {n_points}")
        if (isinstance(faulty_size, bool) or not isinstance(faulty_size, numbers.Real)
                or not 0 < float(faulty_size) <= 1):
            raise GearshotError(f"faulty_size must lie in (0, 1]; got {faulty_size!r}")
        size = float(faulty_size)
    long = None if healthy_long is None else as_signal_array(
        healthy_long, "healthy_long", max_ndim=1)
    if isinstance(est.transfer_function, str) and est.transfer_function == "estimate" \
            and long is None:
        raise GearshotError("healthy_long is required with transfer_function='estimate'")
    sel_tf = None
    if est.feature_selection:
        if selection_tf is None:
            selection_tf = default_selection_tf(est.random_state)
        sel_tf = _on_grid(selection_tf, n_points, "selection_tf")
    return _FitInputs(healthy, example, size, long, sel_tf, n_points)


#: Share of the target's healthy SAs that are step 6's references (the last ones).
REFERENCE_FRACTION = 0.2


def reference_count(n_healthy: int, ref_fraction: float = REFERENCE_FRACTION) -> int:
    """How many of ``n_healthy`` target healthy SAs are step 6's references (at least one;
    :func:`gearshot.estimator.steps.split_target_healthy`)."""
    return max(1, int(round(n_healthy * ref_fraction)))


def spread_references(target_healthy: FloatArray, recordings: ArrayLike | None
                      ) -> tuple[FloatArray, NDArray[Any] | None]:
    """The fit's healthy SAs ordered so that the references of step 6 (the last
    :func:`reference_count`) come from as many recordings as possible, and their recording
    labels (None below :data:`~gearshot.estimator.comparability.MIN_GROUPS` recordings).

    ``recordings`` labels the SAs (it may be longer: the hold-outs cut from the end are not
    labelled here); with fewer than ``MIN_GROUPS`` recordings (or None) the order is kept
    (the references are the last SAs). Otherwise the references are taken round-robin,
    the last SA of each recording first: the target side subtracts the reference that
    leaves the least, and a reference of every run lets a segment of a later run (another
    speed within tolerance, another day) find the run it resembles most.
    """
    n = len(target_healthy)
    labels = _recording_labels(None if recordings is None else
                               np.asarray(recordings).reshape(-1)[:n], n, "healthy_recordings")
    if labels is None:
        return target_healthy, None
    names = list(dict.fromkeys(labels.tolist()))
    n_ref = reference_count(len(labels))
    queues = [list(np.nonzero(labels == g)[0][::-1]) for g in names]
    refs: list[int] = []
    while len(refs) < n_ref:
        for q in queues:
            if q and len(refs) < n_ref:
                refs.append(int(q.pop(0)))
    chosen = set(refs)
    order = np.array([i for i in range(len(labels)) if i not in chosen] + refs[::-1])
    return target_healthy[order], labels[order]
