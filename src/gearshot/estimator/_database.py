"""A simulated database split for the estimator: one fault type, per grade, with twins."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._errors import GearshotError
from .._validation import as_signal_array

FloatArray = NDArray[np.float64]


def _select_fault_type(database: Any, fault_type: str | None) -> Any:
    """The signals of one fault type (healthy ones included) of a database whose
    ``fault_type`` coordinate names each signal's type; databases without it hold FTFFs."""
    try:
        types = np.asarray(database["fault_type"]).astype(str)
    except (KeyError, TypeError):
        types = None
    if types is None or types.ndim == 0:
        have = ["ftff"] if types is None else [str(types)]
        if fault_type is not None and fault_type not in have:
            raise GearshotError(f"fault_type {fault_type!r} is not in the database "
                                f"(it has {have})")
        return database
    have = list(dict.fromkeys(types))
    if fault_type is None:
        if len(have) > 1:
            raise GearshotError(f"the database holds several fault types {have}; choose "
                                f"one with fault_type=...")
        return database
    if fault_type not in have:
        raise GearshotError(f"fault_type {fault_type!r} is not in the database "
                            f"(it has {have})")
    return database.isel(signal=np.flatnonzero(types == fault_type))


def _database_by_grade(database: Any,
                       n_points: int | None = None) -> dict[int, tuple[FloatArray, FloatArray]]:
    """Split a simulated database (xarray.Dataset or mapping) into {grade: (sa, y)}."""
    try:
        sa = np.asarray(database["sa"], dtype=float)
        sizes = np.asarray(database["fault_size"], dtype=float)
        grades = np.asarray(database["grade"]).astype(int)
    except (KeyError, TypeError, ValueError) as exc:
        raise GearshotError(
            "database must be a simulated database (xarray.Dataset with 'sa', "
            f"'fault_size' and 'grade', e.g. from gearshot.sim.load_database); {exc}") from None
    sa = as_signal_array(sa, "database['sa']", min_ndim=2, max_ndim=2, min_length=16)
    if grades.ndim == 0:
        grades = np.full(sa.shape[0], int(grades))
    if sizes.shape != (sa.shape[0],) or grades.shape != (sa.shape[0],):
        raise GearshotError(
            f"database coords fault_size {sizes.shape} and grade {grades.shape} must have "
            f"one value per signal ({sa.shape[0]})")
    if n_points is not None and sa.shape[1] != n_points:
        raise GearshotError(f"database SAs have {sa.shape[1]} points but target SAs have "
                            f"{n_points}")
    out = {}
    for g in np.unique(grades):
        m = grades == g
        if not np.any(sizes[m] == 0):
            raise GearshotError(f"database holds no healthy signal (fault_size == 0) for "
                                f"grade {g}; the simulated side needs healthy references")
        out[int(g)] = (_rows(sa, m), sizes[m])
    return out


def _rows(arr: FloatArray, mask: NDArray[np.bool_]) -> FloatArray:
    """``arr[mask]``; a view (no copy of the signals) when the rows are one block, as the
    grades of a database built grade by grade are."""
    rows = np.flatnonzero(mask)
    if rows.size and rows[-1] - rows[0] + 1 == rows.size:
        return arr[rows[0]:rows[-1] + 1]
    return arr[mask]


def _has_twins(database: Any) -> bool:
    """Whether a database holds healthy twins (``sa_twin``, a paired store)."""
    try:
        return "sa_twin" in database
    except TypeError:
        return False


def _database_twins(database: Any, by_grade: Mapping[int, tuple[FloatArray, FloatArray]]
                    ) -> dict[int, FloatArray]:
    """The healthy twins ``sa_twin`` of a paired database, split by grade like the SAs."""
    try:
        twins = np.asarray(database["sa_twin"], dtype=float)
    except (KeyError, TypeError, ValueError):
        raise GearshotError("simulated_reference='twin' needs a paired database (with "
                            "'sa_twin': gearshot.sim.build_database(..., paired=True) or "
                            "`gearshot simulate --paired`); this one has none") from None
    grades = np.asarray(database["grade"]).astype(int)
    if grades.ndim == 0:
        grades = np.full(twins.shape[0], int(grades))
    out = {}
    for g, (sa, _) in by_grade.items():
        tw = _rows(twins, grades == g)
        if tw.shape != sa.shape:
            raise GearshotError(f"database['sa_twin'] of grade {g} has shape {tw.shape}; "
                                f"the SAs have {sa.shape}")
        out[g] = tw
    return out
