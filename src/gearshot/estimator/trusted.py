"""The ``trusted`` column of a predict table (issue #29): every check of a segment passed,
in a recording most of whose segments pass them too.

The fit's own verdict comes from :mod:`gearshot.estimator.fit_check`; the segment checks
are the input health, the tracked speed and comparability.
"""

from __future__ import annotations

from typing import Any

__all__ = ["trusted_column", "recording_majority", "comparable_at_speed", "TRUST_COLUMNS",
           "LABEL_CHECKS", "MIN_TRUSTED_SHARE", "PASSED"]

#: The verdict of a fit that passed.
PASSED = "passed"
#: Share of a recording's segments that must pass every check for any of them (and the
#: recording) to be trusted: more than this (a strict majority; a 2-segment recording
#: needs both). Chosen on the development lives (``benchmarks/monitor_lives.py``, seeds
#: 1-4): at "at least half", a remounted recording with one of its two segments
#: comparable was trusted and alarmed.
MIN_TRUSTED_SHARE = 0.5


#: The columns of :meth:`OneFaultShotEstimator.trust`, in order.
TRUST_COLUMNS = ("predicted", "low", "high", "comparability", "comparable", "input_check",
                 "fit_check", "trusted")


#: The predict-table columns that hold "ok" or the failed check's label (besides
#: ``comparable`` and ``fit_check``): what :func:`trusted_column` requires to be "ok".
LABEL_CHECKS = ("input_check", "speed_check", "path_check")


def comparable_at_speed(frame: Any) -> Any:
    """The ``comparable`` column of a predict table: the SA's comparability, false where
    ``speed_check`` failed (the recording ran at a speed the fit's recordings did not
    show: another operating condition) or ``path_check`` did (it was heard through
    another transfer path); a table without either column is left as it is."""
    comparable = frame["comparable"].astype(bool)
    for check in ("speed_check", "path_check"):
        if check in frame:
            comparable &= frame[check].astype(str) == "ok"
    return comparable


def trusted_column(frame: Any) -> Any:
    """The ``trusted`` column of a predict table: ``input_check``, ``speed_check`` and
    ``path_check`` "ok" (a table without such a column counts as "ok"),
    ``comparable`` and ``fit_check == "passed"`` (a table without ``fit_check`` is not
    trusted)."""
    import pandas as pd

    ok = pd.Series(True, index=frame.index)
    for check in LABEL_CHECKS:
        if check in frame:
            ok &= frame[check].astype(str) == "ok"
    ok &= frame["comparable"].astype(bool) if "comparable" in frame else False
    ok &= (frame["fit_check"].astype(str) == PASSED) if "fit_check" in frame else False
    return ok.astype(bool)


def recording_majority(recording: Any, trusted: Any) -> Any:
    """Per row: whether more than :data:`MIN_TRUSTED_SHARE` of its recording's segments
    pass every check (the rule by which ``gearshot monitor`` trusts a recording). A
    segment that passes in a recording most of whose segments do not look like the fitted
    machine is luck, not evidence: under the README journey's High-load fit on the output
    sensor, the healthy spur3 Low record had 1 comparable segment of 11, and it read 0.57.

    Parameters
    ----------
    recording, trusted : pandas.Series
        Each row's recording and whether it passes every check.

    Returns
    -------
    pandas.Series of bool
    """
    share = trusted.astype(float).groupby(recording).transform("mean")
    return share > MIN_TRUSTED_SHARE
