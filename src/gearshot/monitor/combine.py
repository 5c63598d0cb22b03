"""One estimate per recording from the estimates of its SA segments."""

from __future__ import annotations

import numpy as np
import pandas as pd

from .trust import recording_trust, row_trust

__all__ = ["combine_segments"]


def combine_segments(frame: pd.DataFrame) -> dict:
    """The combined estimate of one recording's segments.

    The estimate is the median of the trusted segments' estimates (of all segments when
    the recording is not trusted: half of its segments or fewer are); the interval is the
    median of their interval bounds — the segments of one run share its bias, so the
    interval is not narrowed by their number.

    Parameters
    ----------
    frame : pandas.DataFrame
        The recording's rows of :func:`gearshot.app.predict.estimate_segments`.

    Returns
    -------
    dict
        ``predicted``, ``low``, ``high``, ``segments``, ``trusted_segments``, ``trusted``.
    """
    ok = row_trust(frame)
    trusted = recording_trust(frame)
    use = ok if trusted else np.ones(len(frame), dtype=bool)
    part = frame[use]
    return {"predicted": float(np.median(part["predicted"])),
            "low": float(np.median(part["low"])), "high": float(np.median(part["high"])),
            "segments": int(len(frame)), "trusted_segments": int(ok.sum()),
            "trusted": bool(trusted)}
