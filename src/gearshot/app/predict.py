"""Fit from recording files and estimate the fault size of other recordings."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from .._errors import GearshotError
from .._validation import check_in_range

__all__ = ["predict_from_files", "ROLES"]

#: The ``role`` column of every ``gearshot predict`` output: what a row's segment was to
#: the fit. ``healthy_fitted``: a healthy segment the estimator was fitted on (an
#: in-sample estimate); ``example``: the one faulty example (its estimate is near the
#: declared size by construction); ``faulty_rest``: the faulty recording's other segments
#: (same record as the example); ``healthy_holdout``: healthy segments kept out of the fit
#: (``--machine``); ``test``: a recording the fit never saw.
ROLES = ("healthy_fitted", "example", "faulty_rest", "healthy_holdout", "test")


def _recording_files(path: Path):
    """Recording files of a folder (or the file itself); kept for callers of old."""
    from .files import expand_recordings

    return expand_recordings([path], "--recordings")


def predict_from_files(database, healthy, faulty, faulty_size, recordings, *, speed, load=None,
                       coverage=0.9, gear_teeth=38, pinion_teeth=17, seed=0,
                       selection_tf=None):
    """Fit the estimator from files and predict every SA segment of ``recordings``.

    Parameters
    ----------
    recordings : path or sequence of path
        Files and folders (their recording files) to estimate; the fitted files among them
        are estimated too, with their ``role``.
    speed, load : float
        The database condition (``load`` None: the database's only load).
    selection_tf : optional
        Step 1's held-out TF (default :func:`gearshot.estimator.default_selection_tf` of
        ``seed``).

    Returns
    -------
    pandas.DataFrame
        ``recording, role, segment, predicted, low, high, comparability, comparable``
        (roles: :data:`ROLES`; the last two from
        :meth:`~gearshot.estimator.OneFaultShotEstimator.comparability`).
    """
    from ..estimator import OneFaultShotEstimator, default_selection_tf
    from ..io import recording_segments
    from ..sim import load_database
    from .conditions import choose_condition
    from .files import expand_recordings

    for p in [*healthy, faulty]:
        if not Path(p).is_file():
            raise GearshotError(f"recording {str(p)!r} does not exist")
    faulty_size = check_in_range(faulty_size, "faulty_size (--faulty-size)", 0.0, 1.0,
                                 low_inclusive=False)
    coverage = check_in_range(coverage, "coverage (--coverage)", 0.0, 1.0,
                              low_inclusive=False, high_inclusive=False)
    if isinstance(recordings, (str, Path)):
        recordings = [recordings]
    files = expand_recordings(recordings, "--recordings")
    speed, load = choose_condition(database, None, speed=speed, load=load, measured=[])
    kw = dict(gear_teeth=gear_teeth, pinion_teeth=pinion_teeth)
    # every recording is read and segmented before the fit: a file too short for one SA
    # segment (or unreadable) fails now, not after minutes of fitting
    targets = [(path, recording_segments(path, **kw)) for path in files]
    db = load_database(database, speed=speed, load=load)
    healthy_sa, long = [], None
    for i, p in enumerate(healthy):
        if i == 0:
            sa, long = recording_segments(p, long=True, **kw)
        else:
            sa = recording_segments(p, **kw)
        healthy_sa.append(sa)
    example = recording_segments(faulty, **kw)[0]
    if selection_tf is None:
        selection_tf = default_selection_tf(seed)
    est = OneFaultShotEstimator(random_state=seed)
    est.fit(db, np.vstack(healthy_sa), example, faulty_size, long, selection_tf=selection_tf)
    fitted = {_key(p) for p in healthy}
    frames = []
    for path, sa in targets:
        low, high = est.predict_interval(sa, coverage=coverage)
        comp = est.comparability(sa)
        frames.append(pd.DataFrame(dict(recording=str(path),
                                        role=_roles(path, len(sa), fitted, faulty),
                                        segment=np.arange(len(sa)),
                                        predicted=est.predict(sa), low=low, high=high,
                                        comparability=comp.score,
                                        comparable=comp.comparable)))
    frame = pd.concat(frames, ignore_index=True)
    frame.attrs["speed"], frame.attrs["load"] = speed, load
    return frame


def _key(path) -> Path:
    return Path(path).resolve()


def _roles(path, n: int, fitted: set, faulty) -> list[str]:
    if _key(path) in fitted:
        return ["healthy_fitted"] * n
    if _key(path) == _key(faulty):
        return ["example"] + ["faulty_rest"] * (n - 1)
    return ["test"] * n


def summary_table(frame: pd.DataFrame, roles: Sequence[str] = ROLES) -> pd.DataFrame:
    """One row per recording and role: segments, mean estimate and mean interval, headed
    columns (the printed summary of ``gearshot predict``)."""
    order = {r: i for i, r in enumerate(roles)}
    by = ["recording", "role"] if "role" in frame else ["recording"]
    aggs = dict(segments=("predicted", "size"), estimated_size=("predicted", "mean"),
                low=("low", "mean"), high=("high", "mean"))
    if "comparable" in frame:
        aggs["comparable"] = ("comparable", "sum")
    table = frame.groupby(by, sort=False).agg(**aggs).reset_index()
    if "role" in table:
        table = table.sort_values("role", key=lambda r: r.map(order), kind="stable")
    table["recording"] = [Path(r).name for r in table["recording"]]
    return table.rename(columns={"estimated_size": "mean estimated size",
                                 "low": "mean low", "high": "mean high"})
