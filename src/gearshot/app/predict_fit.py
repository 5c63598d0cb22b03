"""The fit of ``gearshot predict``, ``gearshot fit`` and ``gearshot monitor`` from
recording files (no machine file), and the estimate of SA segments with a fitted
estimator."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from .._errors import GearshotError
from .._validation import check_in_range
from ..estimator.holdouts import HOLDOUT
from ..io.input_health import require_ok
from ..paper import CYCLES_PER_SEGMENT, GEAR_TEETH, PINION_TEETH, SAMPLES_PER_CYCLE

__all__ = ["FittedFiles", "fit_from_files", "estimate_segments", "recording_labels"]


@dataclass
class FittedFiles:
    """What :func:`fit_from_files` found besides the estimator: the database condition
    (``speed`` rps, ``load`` N m), the gear pair the recordings were segmented for
    (``teeth``: ``gear_teeth``, ``pinion_teeth``), the SA segments of ``recordings``
    (``targets``: (path, SAs) pairs), each healthy recording's hold-outs (``held``:
    (path, SAs, n_fitted)), the faulty record's other segments (``rest``) and every
    recording's input checks (``health``: resolved path -> checks)."""

    speed: float
    load: float
    teeth: dict
    targets: list = field(default_factory=list)
    held: list = field(default_factory=list)
    rest: np.ndarray | None = None
    health: dict = field(default_factory=dict)


def fit_from_files(database, healthy, faulty, faulty_size, *, speed, load=None,
                   coverage=0.9, gear_teeth=None, pinion_teeth=None, seed=0,
                   selection_tf=None, recordings=(), holdout=HOLDOUT, holdout_files=(),
                   reads=None, params=None):
    """Fit the estimator from recording files (the fit of ``gearshot predict`` and
    ``gearshot fit`` without ``--machine``), its hold-outs checking it.

    ``faulty`` None fits zero-shot (``calibration="zero_shot"``, ``faulty_size`` ignored).
    ``holdout`` keeps the last segments of each healthy recording out of the fit;
    ``holdout_files`` (healthy recordings among ``recordings``) are kept out whole: both
    are the healthy hold-outs that check the fit.
    Every recording (``recordings`` too, segmented into ``FittedFiles.targets``) is read,
    checked (:mod:`gearshot.io.input_health`: a fit recording that fails is refused) and
    segmented before the fit: a bad file fails now, not after minutes of fitting.
    ``reads``, a dict kept by the caller across fits on the same files, holds the database
    slice and every file's segments, so that each is read once (``gearshot fit``'s
    cross-fits). ``params``: other :class:`~gearshot.estimator.OneFaultShotEstimator`
    parameters (the library defaults when None).

    Returns
    -------
    estimator : OneFaultShotEstimator
    fitted : FittedFiles
    """
    from ..estimator import OneFaultShotEstimator, default_selection_tf
    from ..sim import load_database
    from .conditions import choose_condition

    _check_files(healthy, faulty)
    if faulty is not None:
        faulty_size = check_in_range(faulty_size, "faulty_size (--faulty-size)", 0.0, 1.0,
                                     low_inclusive=False)
    check_in_range(coverage, "coverage (--coverage)", 0.0, 1.0, low_inclusive=False,
                   high_inclusive=False)
    speed, load = choose_condition(database, None, speed=speed, load=load, measured=[])
    key = ("database", str(database), speed, load)
    db = (reads or {}).get(key)
    if db is None:
        db = load_database(database, speed=speed, load=load)
        if reads is not None:
            reads[key] = db
    # the pair is the database's unless declared (a declared other pair is refused by fit)
    teeth = dict(gear_teeth=gear_teeth, pinion_teeth=pinion_teeth)
    kw = {k: db.attrs.get(k, default) if teeth[k] is None else teeth[k]
          for k, default in (("gear_teeth", GEAR_TEETH), ("pinion_teeth", PINION_TEETH))}
    targets, healthy_sa, long, example, rest, held, health = _segments(
        recordings, healthy, faulty, kw, holdout, reads)
    if selection_tf is None:
        selection_tf = default_selection_tf(seed)
    whole = {_key(p) for p in holdout_files}
    labels, healthy_sa = recording_labels(healthy_sa), np.vstack(healthy_sa)
    checks = dict(holdout=holdout, healthy_recordings=labels, healthy_holdout=np.vstack(
        [sa for _, sa, _ in held] + [sa for p, sa in targets if _key(p) in whole]))
    if faulty is None:
        est = OneFaultShotEstimator(**{**(params or {}), "random_state": seed,
                                       "calibration": "zero_shot"})
        est.fit(db, healthy_sa, None, None, long, selection_tf=selection_tf, **checks, **kw)
    else:
        est = OneFaultShotEstimator(**{**(params or {}), "random_state": seed})
        est.fit(db, healthy_sa, example, faulty_size, long, selection_tf=selection_tf,
                example_record=rest, **checks, **kw)
    return est, FittedFiles(float(speed), float(load), kw, targets, held, rest, health)


def _check_files(healthy, faulty) -> None:
    """Every healthy recording and the faulty one (when given) exist."""
    for p in [*healthy, *([] if faulty is None else [faulty])]:
        if not Path(p).is_file():
            raise GearshotError(f"recording {str(p)!r} does not exist")


def estimate_segments(est, sa, *, coverage=0.9, input_check=None) -> pd.DataFrame:
    """Estimate SA segments with a fitted estimator: one row per segment with ``segment``,
    the columns of :meth:`~gearshot.estimator.OneFaultShotEstimator.trust` (``predicted,
    low, high, comparability, comparable, input_check, fit_check, trusted``) and
    ``below_detection_limit`` (``gearshot monitor`` estimates through it; ``input_check``:
    one per segment or for all, None: each segment's own
    :func:`gearshot.io.input_health.check_segments`)."""
    from ..estimator import below_detection_limit
    from ..io.input_health import check_segments

    if input_check is None:
        input_check = [c.label for c in check_segments(np.asarray(sa), units="g")]
    frame = est.trust(sa, input_check=input_check, coverage=coverage)
    frame.insert(0, "segment", np.arange(len(frame)))
    frame["below_detection_limit"] = below_detection_limit(est, frame["predicted"])
    return frame


def _segments(files, healthy, faulty, kw, holdout=0.0, reads=None):
    """SA segments of the targets; the healthy recordings' fitted segments (one array per
    recording; the first one's long angle-domain signal too, without its hold-outs); the
    faulty example (the faulty recording's most typical segment,
    :func:`~gearshot.estimator.example.typical_segment`) and its record's other segments;
    each healthy recording's hold-outs (its last ``floor(holdout · n)`` segments) as
    (path, SAs).

    Every recording is read and segmented before the fit: a file too short for one SA
    segment (or unreadable) fails now, not after minutes of fitting; ``reads`` (a dict,
    optional) keeps each file's segments and checks for the next fit on the same files.
    """
    from ..estimator.example import typical_segment
    from ..estimator.fit_check import holdout_count
    from ..io import recording_segments

    health: dict = {}   # resolved path -> its input checks (gearshot.io.input_health)

    def cut(path, role=None, **more):
        key = (_key(path), bool(more.get("long")), tuple(sorted(kw.items())))
        if reads is not None and key in reads:
            out, found = reads[key]
        else:
            found = {}
            out = recording_segments(path, health=found, **more, **kw)
            if reads is not None:
                reads[key] = (out, found)
        health[_key(path)] = found
        if role is not None:   # a recording the fit uses: refused unless every check passes
            for check in (found["recording"], *found["segments"]):
                require_ok(check, path, role)
        return out

    targets = [(path, cut(path)) for path in files]
    healthy_sa, long, held = [], None, []
    for i, p in enumerate(healthy):
        if i == 0:
            sa, long = cut(p, "healthy", long=True)
        else:
            sa = cut(p, "healthy")
        n_fit = len(sa) - holdout_count(len(sa), holdout)
        if i == 0 and n_fit < len(sa):  # held-out segments stay out of the TF estimate
            long = long[: n_fit * CYCLES_PER_SEGMENT * SAMPLES_PER_CYCLE]
        healthy_sa.append(sa[:n_fit])
        held.append((p, sa[n_fit:], n_fit))
    if faulty is None:   # zero-shot
        return targets, healthy_sa, long, None, None, held, health
    faulty_sa = cut(faulty, "faulty")
    k = typical_segment(faulty_sa)
    rest = np.delete(faulty_sa, k, axis=0)
    return targets, healthy_sa, long, faulty_sa[k], rest, held, health


def recording_labels(per_recording) -> np.ndarray:
    """The recording index of every SA of per-recording SA arrays, stacked in order (the
    fit's ``healthy_recordings``: comparability calibrated on whole recordings left out)."""
    return np.repeat(np.arange(len(per_recording)), [len(sa) for sa in per_recording])


def _key(path) -> Path:
    return Path(path).resolve()
