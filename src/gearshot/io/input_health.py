"""Input health: is a recorded signal fit to be estimated from at all?

Every check here runs before any estimate (``gearshot predict``, ``gearshot indicators``)
and answers with a small frozen :class:`InputCheck`: ``ok``, the name of the check that
failed (``failed``, one of :data:`CHECKS`) and a one-line ``reason``. A recording used to
fit is refused when it fails (:func:`require_ok`); a recording that is only estimated keeps
its rows, each marked with the failed check (:func:`input_check_column`).

The checks, in the order they are tried (the first failure is the answer):

``non_numeric``
    NaN, inf, or a non-numeric dtype.
``implausible_level``
    A sample beyond :data:`MAX_PEAK_G` (in g). The method is RMS-normalised, so a
    recording scaled by 1e30 would otherwise give an estimate of its own: such a scale is
    no acceleration a gearbox casing can carry, and is refused as unphysical.
``dead``
    No signal: the channel's standard deviation is below :data:`DEAD_FLOOR_G` and its mean
    is too (all zeros, or a disconnected sensor's rounding noise).
``constant``
    The channel does not move (standard deviation below the floor) but sits at a non-zero
    value: a stuck or DC-only channel.
``clipped``
    Flat tops: more than :data:`CLIP_FRACTION` of the samples sit exactly at the channel's
    minimum or maximum (the rails of a saturated sensor or converter). Checked on raw
    samples only: a synchronous average smooths flat tops away.
``damaged_bytes``
    Not computed here: the name under which a file whose stored digest or checksums do not
    match is refused (:mod:`gearshot.io._format_hdf5`).

The thresholds were chosen on the development records (virtual-rig campaigns of seeds 0
and 1, PHM09 run 1 records of ``../shared/data/phm09``) and verified on records they were
not chosen on (virtual-rig seeds 2-5 at another condition, PHM09 run 2 records), all of
which pass: ``benchmarks/input_health.py``, results in ``benchmarks/RESULTS.md``, section
"Trust: input health". On the development records the largest peak is 343 g (a virtual-rig
impact; PHM09: 17.9 g), the smallest standard deviation 0.34 g (raw) and 0.14 g (an SA
segment), and the largest share of samples at a channel's extremes 1.5e-5; each bound sits
more than a decade beyond them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._errors import GearshotError

__all__ = ["InputCheck", "check_input", "check_numeric", "check_segments",
           "input_check_column", "mark_rows", "require_ok", "CHECKS", "OK", "MAX_PEAK_G",
           "DEAD_FLOOR_G", "CLIP_FRACTION", "G_PER_UNIT"]

#: Names of the checks (the values of the ``input_check`` column besides ``"ok"``).
CHECKS = ("non_numeric", "implausible_level", "dead", "constant", "clipped", "damaged_bytes")
#: The ``input_check`` value of a signal that passes every check.
OK = "ok"

#: Largest plausible acceleration magnitude, g: the top of the range of shock
#: accelerometers, two hundred times that of a general-purpose industrial one (+-500 g);
#: the development records peak at 343 g. No gearbox casing carries more: a larger value
#: is a wrong scale or unit (the x1e30 recording), refused rather than normalised away.
MAX_PEAK_G = 1e5
#: Smallest standard deviation of a live channel, g: the order of the broadband noise
#: floor of a piezoelectric accelerometer and its conditioning; the development SA segments
#: (10 cycles averaged) have at least 0.14 g, their raw channels 0.34 g.
DEAD_FLOOR_G = 1e-5
#: Largest share of samples allowed exactly at the channel's minimum or maximum. A live,
#: unclipped signal reaches each extreme once or a few times (development records: at most
#: 1.5e-5 of the samples, PHM09 text and float64 rig files alike). The same records clipped
#: at three standard deviations put 2.7e-3 to 2e-2 there (every channel refused); clipped at
#: half their peak, 4e-5 to 5e-2 (51 of 56 channels refused: the other five are impulsive,
#: and the clip touches a few impacts only); at 90 % of the peak, at most 2.5e-4 (none).
CLIP_FRACTION = 1e-3

#: Unit strings understood as accelerations -> g per unit. Another unit (volts, counts)
#: gets the unit-free checks only (non-numeric, exactly zero, exactly constant, clipped).
G_PER_UNIT = {"g": 1.0, "m/s^2": 1 / 9.80665, "m/s2": 1 / 9.80665, "m/s**2": 1 / 9.80665,
              "mm/s^2": 1e-3 / 9.80665, "mg": 1e-3}


@dataclass(frozen=True)
class InputCheck:
    """The answer of the input checks for one signal.

    Attributes
    ----------
    failed : str or None
        Name of the failed check (one of :data:`CHECKS`); ``None`` when every check passed.
    reason : str
        One line: what was found (the measured value and the bound).
    """

    failed: str | None = None
    reason: str = "every input check passed"

    @property
    def ok(self) -> bool:
        """True when every check passed."""
        return self.failed is None

    @property
    def label(self) -> str:
        """The ``input_check`` value: ``"ok"`` or the failed check's name."""
        return OK if self.failed is None else self.failed


def _scale(units: str | None) -> float | None:
    if units is None:
        return 1.0
    return G_PER_UNIT.get(units.strip().lower().replace(" ", ""))


def _check_row(x: np.ndarray, g_per_unit: float | None, clipping: bool) -> InputCheck:
    """The checks of one 1-D signal (already numeric)."""
    finite = np.isfinite(x)
    if not finite.all():
        bad = int(x.size - np.count_nonzero(finite))
        return InputCheck("non_numeric", f"{bad} of {x.size} samples are NaN or inf")
    lo, hi = float(x.min()), float(x.max())
    peak = max(abs(lo), abs(hi))
    if g_per_unit is not None and peak * g_per_unit > MAX_PEAK_G:
        return InputCheck("implausible_level",
                          f"a sample of magnitude {peak * g_per_unit:.3g} g; no gearbox "
                          f"vibration exceeds {MAX_PEAK_G:g} g (wrong scale or units?)")
    if hi == lo:
        if hi == 0.0:
            return InputCheck("dead", "every sample is 0")
        return InputCheck("constant", f"every sample is {hi:.6g}")
    if g_per_unit is not None:
        mean = float(np.mean(x))
        std = float(np.std(x)) * g_per_unit
        if std < DEAD_FLOOR_G:
            if abs(mean) * g_per_unit < DEAD_FLOOR_G:
                return InputCheck("dead", f"standard deviation {std:.3g} g, below the "
                                          f"{DEAD_FLOOR_G:g} g of a live sensor")
            return InputCheck("constant", f"standard deviation {std:.3g} g around "
                                          f"{mean * g_per_unit:.6g} g: the channel does not "
                                          f"move")
    if clipping:
        at_edges = int(np.count_nonzero(x == lo) + np.count_nonzero(x == hi))
        share = at_edges / x.size
        if share > CLIP_FRACTION:
            return InputCheck("clipped", f"{at_edges} of {x.size} samples ({share:.2%}) sit "
                                         f"at the extremes {lo:.6g} / {hi:.6g} (flat tops: "
                                         f"a saturated sensor)")
    return InputCheck()


def _as_rows(x: Any, name: str) -> np.ndarray | InputCheck:
    try:
        arr = np.asarray(x)
    except Exception:  # ragged sequences and the like
        return InputCheck("non_numeric", f"{name} is not an array of numbers")
    if arr.dtype == object or not (np.issubdtype(arr.dtype, np.number)
                                   or np.issubdtype(arr.dtype, np.bool_)) or \
            np.iscomplexobj(arr):
        return InputCheck("non_numeric", f"{name} has dtype {arr.dtype}, not real numbers")
    if arr.ndim not in (1, 2) or arr.size == 0:
        raise GearshotError(f"{name} must be a non-empty 1-D or 2-D array; got shape "
                            f"{arr.shape}")
    return np.atleast_2d(arr.astype(np.float64, copy=False))


def check_input(x: Any, *, units: str | None = "g", clipping: bool = True,
                name: str = "acceleration") -> InputCheck:
    """Check one recorded signal (every channel of it) before any estimate.

    Parameters
    ----------
    x : array_like, shape (n,) or (n_channels, n)
        The samples, in ``units``.
    units : str or None
        Their unit: one of :data:`G_PER_UNIT` (``"g"``, ``"m/s^2"``, ...) enables the level
        checks (:data:`MAX_PEAK_G`, :data:`DEAD_FLOOR_G`); any other string (volts, counts)
        keeps the unit-free ones only; ``None`` is read as g.
    clipping : bool
        Look for flat tops (raw samples; ``False`` for averaged signals).
    name : str
        Used in messages.

    Returns
    -------
    InputCheck
        The first failed check over the channels (the reason names the channel of a
        multi-channel signal), or an ``ok`` result.

    Raises
    ------
    GearshotError
        ``x`` is empty or has more than two dimensions.
    """
    rows = _as_rows(x, name)
    if isinstance(rows, InputCheck):
        return rows
    scale = _scale(units)
    for i, row in enumerate(rows):
        res = _check_row(row, scale, clipping)
        if not res.ok:
            where = f"channel {i}: " if rows.shape[0] > 1 else ""
            return InputCheck(res.failed, where + res.reason)
    return InputCheck()


def check_numeric(x: Any, *, name: str = "acceleration") -> InputCheck:
    """Only the ``non_numeric`` check (the one every reader applies: a recording holding
    NaN or inf is refused when it is read)."""
    rows = _as_rows(x, name)
    if isinstance(rows, InputCheck):
        return rows
    bad = int(rows.size - np.count_nonzero(np.isfinite(rows)))
    if bad:
        return InputCheck("non_numeric", f"{bad} of {rows.size} samples are NaN or inf")
    return InputCheck()


def check_segments(segments: Any, *, units: str | None = "g", kind: str = "sa"
                   ) -> tuple[InputCheck, ...]:
    """Check every segment of a recording: one :class:`InputCheck` per row.

    Parameters
    ----------
    segments : array_like, shape (n_segments, n)
        SA segments (``kind="sa"``: averaged, so no flat-top check) or raw stretches of
        samples (``kind="raw"``: every check).
    units, kind
        See :func:`check_input`; ``kind`` is ``"sa"`` or ``"raw"``.

    Returns
    -------
    tuple of InputCheck
        In the order of the rows.
    """
    if kind not in ("sa", "raw"):
        raise GearshotError(f"kind must be 'sa' or 'raw'; got {kind!r}")
    rows = _as_rows(segments, "segments")
    if isinstance(rows, InputCheck):
        n = int(np.shape(segments)[0]) if np.ndim(segments) >= 1 else 1
        return (rows,) * n
    scale = _scale(units)
    return tuple(_check_row(row, scale, kind == "raw") for row in rows)


def input_check_column(recording: InputCheck, segments: Sequence[InputCheck],
                       rows: Sequence[int] | None = None) -> list[str]:
    """The ``input_check`` column of one recording's rows in a predict table.

    A failure of the whole recording marks every row with it; otherwise each row carries
    its own segment's answer (``"ok"`` or the failed check's name).

    Parameters
    ----------
    recording : InputCheck
        The recording's own answer (:func:`check_input` of its raw samples).
    segments : sequence of InputCheck
        One per segment (:func:`check_segments`).
    rows : sequence of int, optional
        The segment index of each row (default: every segment, in order).
    """
    picks = range(len(segments)) if rows is None else rows
    if not recording.ok:
        return [recording.label] * len(picks)
    return [segments[int(k)].label for k in picks]


def mark_rows(frame: Any, column: Sequence[str]) -> Any:
    """Add the ``input_check`` column to a predict table and withdraw the estimates of the
    rows that failed it: their ``predicted``, ``low`` and ``high`` become NaN (written as
    empty/null), so no failed row reads as a number. Returns ``frame``."""
    frame["input_check"] = list(column)
    failed = np.asarray([c != OK for c in column], dtype=bool)
    if failed.any():
        for col in ("predicted", "low", "high"):
            if col in frame:
                frame[col] = frame[col].astype(float)
                frame.loc[failed, col] = np.nan
    return frame


def require_ok(check: InputCheck, path: Any, role: str | None = None) -> None:
    """Refuse a recording (e.g. one that fits the estimator, its ``role``) unless it
    passed every check.

    Raises
    ------
    GearshotError
        One line naming the file, its role and the failed check.
    """
    if not check.ok:
        where = "" if role is None else f" ({role})"
        raise GearshotError(f"{str(path)!r}{where} fails the input check {check.failed!r}: "
                            f"{check.reason}")
