"""Fit from recording files and estimate the fault size of other recordings."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from .._errors import GearshotError
from .._validation import check_in_range
from ..paper import GEAR_TEETH, PINION_TEETH

__all__ = ["predict_from_files", "fit_from_files", "estimate_segments", "FittedFiles",
           "predict_recordings", "write_predictions",
           "format_predictions", "comparable_summary", "summary_table", "ROLES"]

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
                       coverage=0.9, gear_teeth=None, pinion_teeth=None, seed=0,
                       selection_tf=None):
    """Fit the estimator from files and predict every SA segment of ``recordings``.

    The recordings are segmented for ``gear_teeth`` / ``pinion_teeth`` (default: the
    database's gear pair); the estimator takes its mesh order from the database and
    refuses tooth counts other than its pair's.

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
    from .files import expand_recordings

    _check_files(healthy, faulty)        # before the recordings: the fit's files first
    if isinstance(recordings, (str, Path)):
        recordings = [recordings]
    files = expand_recordings(recordings, "--recordings")
    est, fitted_files = fit_from_files(database, healthy, faulty, faulty_size, speed=speed,
                                       load=load, coverage=coverage, gear_teeth=gear_teeth,
                                       pinion_teeth=pinion_teeth, seed=seed,
                                       selection_tf=selection_tf, recordings=files)
    fitted = {_key(p) for p in healthy}
    frames = []
    for path, sa in fitted_files.targets:
        rows = estimate_segments(est, sa, coverage=coverage)
        rows.insert(0, "recording", str(path))
        rows.insert(1, "role", _roles(path, len(sa), fitted, faulty))
        frames.append(rows)
    frame = pd.concat(frames, ignore_index=True)
    frame.attrs["speed"], frame.attrs["load"] = fitted_files.speed, fitted_files.load
    return frame


@dataclass
class FittedFiles:
    """What :func:`fit_from_files` found besides the estimator: the database condition
    (``speed`` rps, ``load`` N m), the gear pair the recordings were segmented for
    (``teeth``: ``gear_teeth``, ``pinion_teeth``) and the SA segments of ``recordings``
    (``targets``: (path, SAs) pairs)."""

    speed: float
    load: float
    teeth: dict
    targets: list = field(default_factory=list)


def fit_from_files(database, healthy, faulty, faulty_size, *, speed, load=None,
                   coverage=0.9, gear_teeth=None, pinion_teeth=None, seed=0,
                   selection_tf=None, recordings=()):
    """Fit the estimator from recording files (the fit of ``gearshot predict`` and
    ``gearshot fit`` without ``--machine``).

    ``faulty`` None fits zero-shot (``calibration="zero_shot"``, ``faulty_size`` ignored).
    Every recording (``recordings`` too, segmented into ``FittedFiles.targets``) is read
    and segmented before the fit: a bad file fails now, not after minutes of fitting.

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
    db = load_database(database, speed=speed, load=load)
    # the pair is the database's unless declared (a declared other pair is refused by fit)
    teeth = dict(gear_teeth=gear_teeth, pinion_teeth=pinion_teeth)
    kw = {k: db.attrs.get(k, default) if teeth[k] is None else teeth[k]
          for k, default in (("gear_teeth", GEAR_TEETH), ("pinion_teeth", PINION_TEETH))}
    targets, healthy_sa, long, example = _segments(recordings, healthy, faulty, kw)
    if selection_tf is None:
        selection_tf = default_selection_tf(seed)
    if faulty is None:
        est = OneFaultShotEstimator(random_state=seed, calibration="zero_shot")
        est.fit(db, healthy_sa, None, None, long, selection_tf=selection_tf, **kw)
    else:
        est = OneFaultShotEstimator(random_state=seed)
        est.fit(db, healthy_sa, example, faulty_size, long, selection_tf=selection_tf, **kw)
    return est, FittedFiles(float(speed), float(load), kw, targets)


def _check_files(healthy, faulty) -> None:
    """Every healthy recording and the faulty one (when given) exist."""
    for p in [*healthy, *([] if faulty is None else [faulty])]:
        if not Path(p).is_file():
            raise GearshotError(f"recording {str(p)!r} does not exist")


def estimate_segments(est, sa, *, coverage=0.9) -> pd.DataFrame:
    """Estimate SA segments with a fitted estimator: one row per segment with
    ``segment, predicted, low, high, comparability, comparable`` (the estimate columns of
    every ``gearshot predict`` row; ``gearshot monitor`` estimates through it too)."""
    low, high = est.predict_interval(sa, coverage=coverage)
    comp = est.comparability(sa)
    return pd.DataFrame(dict(segment=np.arange(len(sa)), predicted=est.predict(sa),
                             low=low, high=high, comparability=comp.score,
                             comparable=comp.comparable))


def _segments(files, healthy, faulty, kw):
    """SA segments of the targets, the healthy recordings (stacked; the first one's long
    angle-domain signal too) and the faulty example (the faulty recording's first segment).

    Every recording is read and segmented before the fit: a file too short for one SA
    segment (or unreadable) fails now, not after minutes of fitting.
    """
    from ..io import recording_segments

    targets = [(path, recording_segments(path, **kw)) for path in files]
    healthy_sa, long = [], None
    for i, p in enumerate(healthy):
        if i == 0:
            sa, long = recording_segments(p, long=True, **kw)
        else:
            sa = recording_segments(p, **kw)
        healthy_sa.append(sa)
    example = None if faulty is None else recording_segments(faulty, **kw)[0]
    return targets, np.vstack(healthy_sa), long, example


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


def predict_recordings(database, healthy, faulty, faulty_size, recordings, *, machine=None,
                       speed=None, load=None, coverage=0.9, gear_teeth=None, pinion_teeth=None,
                       seed=0, cycles_per_segment=None, sensor=None, holdout=0.25,
                       speed_tolerance=0.05) -> tuple[pd.DataFrame, str]:
    """``gearshot predict``: fit and estimate, through a machine file or without one.

    With ``machine`` (a TOML path): :func:`gearshot.app.predict_machine.predict_from_machine`
    (speeds in tacho-shaft Hz, ``speed`` None: from the healthy recordings' tacho).
    Without: :func:`predict_from_files` (``speed`` required, in rps; at least one
    recording).

    Returns
    -------
    frame : pandas.DataFrame
        One row per SA segment (see the two functions).
    where : str
        One line naming the database condition the estimates were made at.
    """
    from .files import expand_recordings

    if machine is not None:
        from ..machine import Machine
        from .predict_machine import predict_from_machine

        frame = predict_from_machine(Machine.from_toml(machine), database, healthy, faulty,
                                     faulty_size, expand_recordings(recordings, "--recordings"),
                                     speed=speed, load=load,
                                     cycles_per_segment=cycles_per_segment, sensor=sensor,
                                     holdout=holdout, coverage=coverage, seed=seed,
                                     speed_tolerance=speed_tolerance)
        return frame, (f"database condition: tacho shaft {frame.attrs['speed_hz']:.4g} Hz, "
                       f"load {frame.attrs['load']:g} N m{frame.attrs.get('load_note', '')}")
    if speed is None:
        raise GearshotError("--speed is required without --machine (the database's "
                            "speed, rps)")
    if not recordings:
        raise GearshotError("--recordings: give at least one file or folder to estimate")
    frame = predict_from_files(database, healthy, faulty, faulty_size, recordings,
                               speed=speed, load=load, coverage=coverage,
                               gear_teeth=gear_teeth, pinion_teeth=pinion_teeth, seed=seed)
    return frame, (f"database condition: {frame.attrs['speed']:g} rps, load "
                   f"{frame.attrs['load']:g} N m")


def write_predictions(frame: pd.DataFrame, out: str | Path) -> Path:
    """Write a predict table to ``out``: JSON records when it ends in ``.json``, else CSV
    (through :func:`gearshot._atomic.atomic_path`)."""
    from .._atomic import atomic_path

    out = Path(out)
    with atomic_path(out, make_parents=True) as tmp:
        if out.suffix.lower() == ".json":
            tmp.write_text(frame.to_json(orient="records", indent=2))
        else:
            frame.to_csv(tmp, index=False)
    return out


def comparable_summary(frame: pd.DataFrame) -> str:
    """One line counting the comparable segments of a predict table (issue #19)."""
    if "comparable" not in frame or not len(frame):
        return "comparable: no segment estimated"
    n_yes = int(frame["comparable"].sum())
    n_no = len(frame) - n_yes
    line = f"comparable: {n_yes} segment(s), not comparable: {n_no}"
    if n_no:
        line += (" (they do not look like the fitted machine — another build, speed, load "
                 "or sensor? — do not act on their estimates)")
    return line


def format_predictions(frame: pd.DataFrame, where: str) -> str:
    """What ``gearshot predict`` prints: the condition, the summary per recording and
    role (:func:`summary_table`) and the comparability count."""
    table = summary_table(frame).to_string(index=False, float_format=lambda v: f"{v:.3f}")
    return "\n".join([where, table, comparable_summary(frame)])
