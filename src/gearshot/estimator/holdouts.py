"""The segments a fit keeps out to check itself (:mod:`gearshot.estimator.fit_check`):
how many of a recording's segments are held out, and the split of the target's healthy
SAs into those the fit uses and the hold-outs."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._errors import GearshotError
from .._validation import as_signal_array, check_in_range

__all__ = ["Holdouts", "HOLDOUT", "holdout_count", "recording_holdouts", "split_holdouts"]

#: Share of each healthy recording's segments (the last ones) that a checked fit holds out
#: by default (``gearshot predict --holdout``, :func:`gearshot.app.predict.predict_from_files`
#: and the rig family's ``--checked`` fits).
HOLDOUT = 0.25


def holdout_count(n_segments: int, holdout: float) -> int:
    """Hold-outs of a recording of ``n_segments`` segments: ``floor(holdout · n)`` (the
    last ones), so that at least one segment stays for the fit whenever ``holdout < 1``.

    Raises
    ------
    GearshotError
        When ``holdout`` is outside [0, 1).
    """
    holdout = check_in_range(holdout, "holdout", 0.0, 1.0, high_inclusive=False)
    return int(np.floor(holdout * int(n_segments)))


def recording_holdouts(labels: ArrayLike, holdout: float = HOLDOUT,
                       ) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Indices of the healthy SAs a fit keeps and of those it holds out: the last
    :func:`holdout_count` segments of each recording (``labels``: one per SA, in
    recording order within each label).

    >>> keep, hold = recording_holdouts(["a"] * 4 + ["b"] * 8)
    >>> hold.tolist()
    [3, 10, 11]
    """
    names = np.asarray(labels)
    keep: list[int] = []
    hold: list[int] = []
    for name in dict.fromkeys(names.tolist()):
        idx = np.flatnonzero(names == name)
        n_out = holdout_count(idx.size, holdout)
        keep += idx[: idx.size - n_out].tolist()
        hold += idx[idx.size - n_out:].tolist()
    return np.asarray(keep, dtype=np.intp), np.asarray(hold, dtype=np.intp)


@dataclass(frozen=True)
class Holdouts:
    """The SAs a fit keeps out to check itself.

    Attributes
    ----------
    healthy : ndarray (n, n_points) or None
    example : ndarray (n, n_points) or None
        The example record's other segments.
    fraction : float or None
        The ``holdout`` fraction that cut ``healthy`` from the target's healthy SAs (None
        when the hold-outs were given).
    """

    healthy: NDArray[np.float64] | None
    example: NDArray[np.float64] | None
    fraction: float | None


def split_holdouts(target_healthy: ArrayLike, holdout: float = 0.0,
                   healthy_holdout: ArrayLike | None = None,
                   example_record: ArrayLike | None = None,
                   ) -> tuple[NDArray[np.float64], Holdouts]:
    """The healthy SAs the fit uses and the hold-outs it checks itself on.

    Parameters
    ----------
    target_healthy : array_like (n, n_points)
    holdout : float in [0, 1)
        With ``healthy_holdout`` None: the last ``floor(holdout · n)`` healthy SAs are
        held out (:func:`holdout_count`). Otherwise the fraction the caller cut
        ``healthy_holdout`` with (said in an "unchecked" verdict; 0: not said).
    healthy_holdout, example_record : array_like (m, n_points) or (n_points,), optional

    Returns
    -------
    fit_healthy : ndarray (n - n_holdout, n_points)
    holdouts : Holdouts

    Raises
    ------
    GearshotError
        For a bad ``holdout`` or hold-outs whose length differs from the healthy SAs'.
    """
    healthy = as_signal_array(target_healthy, "target_healthy", min_ndim=2, max_ndim=2)
    n_points = healthy.shape[1]

    def checked(sa: ArrayLike | None, name: str) -> NDArray[np.float64] | None:
        if sa is None:
            return None
        arr = np.asarray(sa, dtype=float)
        if arr.size == 0:
            return np.empty((0, n_points))
        arr = as_signal_array(arr, name, max_ndim=2)
        arr = arr.reshape(-1, arr.shape[-1])
        if arr.shape[1] != n_points:
            raise GearshotError(f"{name} has {arr.shape[1]} points per cycle; "
                                f"target_healthy has {n_points}")
        return arr

    example = checked(example_record, "example_record")
    if healthy_holdout is not None:  # cut by the caller (``holdout`` only said)
        holdout = check_in_range(holdout, "holdout", 0.0, 1.0, high_inclusive=False)
        return healthy, Holdouts(checked(healthy_holdout, "healthy_holdout"), example,
                                 float(holdout) if holdout else None)
    n_out = holdout_count(healthy.shape[0], holdout)
    if n_out == 0:
        return healthy, Holdouts(None, example, float(holdout) if holdout else None)
    return (healthy[: healthy.shape[0] - n_out],
            Holdouts(healthy[healthy.shape[0] - n_out:], example, float(holdout)))
