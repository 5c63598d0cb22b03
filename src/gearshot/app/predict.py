"""Fit from recording files and estimate the fault size of other recordings."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from .._errors import GearshotError
from .._validation import check_in_range
from ..paper import GEAR_TEETH, PINION_TEETH

__all__ = ["predict_from_files"]


def _recording_files(path: Path):
    from ..io import FORMATS, INDEX_NAME

    path = Path(path)
    if path.is_file():
        return [path]
    if not path.is_dir():
        raise GearshotError(f"--recordings {str(path)!r} does not exist")
    suffixes = {s if s.startswith(".") else f".{s}" for s in FORMATS}
    files = sorted(p for p in path.iterdir()
                   if p.suffix.lower() in suffixes and p.name != INDEX_NAME)
    if not files:
        raise GearshotError(f"{str(path)!r} holds no recording ({sorted(suffixes)})")
    return files


def predict_from_files(database, healthy, faulty, faulty_size, recordings, *, speed, load,
                       coverage=0.9, gear_teeth=None, pinion_teeth=None, seed=0,
                       selection_tf=None):
    """Fit the estimator from files and predict every SA segment of ``recordings``.

    The recordings are segmented for ``gear_teeth`` / ``pinion_teeth`` (default: the
    database's gear pair); the estimator takes its mesh order from the database and
    refuses tooth counts other than its pair's.

    Returns
    -------
    pandas.DataFrame
        ``recording, segment, predicted, low, high, comparability, comparable``
        (:meth:`~gearshot.estimator.OneFaultShotEstimator.comparability`).
    """
    from ..estimator import OneFaultShotEstimator
    from ..io import recording_segments
    from ..sim import load_database
    from ..transfer import TransferFunctionBank

    for p in [*healthy, faulty]:
        if not Path(p).is_file():
            raise GearshotError(f"recording {str(p)!r} does not exist")
    faulty_size = check_in_range(faulty_size, "faulty_size (--faulty-size)", 0.0, 1.0,
                                 low_inclusive=False)
    coverage = check_in_range(coverage, "coverage (--coverage)", 0.0, 1.0,
                              low_inclusive=False, high_inclusive=False)
    db = load_database(database, speed=speed, load=load)
    # the pair is the database's unless declared (a declared other pair is refused by fit)
    teeth = dict(gear_teeth=gear_teeth, pinion_teeth=pinion_teeth)
    kw = {k: db.attrs.get(k, default) if teeth[k] is None else teeth[k]
          for k, default in (("gear_teeth", GEAR_TEETH), ("pinion_teeth", PINION_TEETH))}
    # every recording is read and segmented before the fit: a file too short for one SA
    # segment (or unreadable) fails now, not after minutes of fitting
    targets = [(path, recording_segments(path, **kw))
               for path in _recording_files(Path(recordings))]
    healthy_sa, long = [], None
    for i, p in enumerate(healthy):
        if i == 0:
            sa, long = recording_segments(p, long=True, **kw)
        else:
            sa = recording_segments(p, **kw)
        healthy_sa.append(sa)
    example = recording_segments(faulty, **kw)[0]
    if selection_tf is None:
        selection_tf = TransferFunctionBank.synthetic(1, rng=[seed, 99])[0]
    est = OneFaultShotEstimator(random_state=seed)
    est.fit(db, np.vstack(healthy_sa), example, faulty_size, long, selection_tf=selection_tf,
            **kw)
    frames = []
    for path, sa in targets:
        low, high = est.predict_interval(sa, coverage=coverage)
        comp = est.comparability(sa)
        frames.append(pd.DataFrame(dict(recording=str(path), segment=np.arange(len(sa)),
                                        predicted=est.predict(sa), low=low, high=high,
                                        comparability=comp.score,
                                        comparable=comp.comparable)))
    return pd.concat(frames, ignore_index=True)
