"""Fit from recording files and estimate the fault size of other recordings."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from .._errors import GearshotError
from ..estimator.holdouts import HOLDOUT
from ..io.input_health import input_check_column, mark_rows
from .fit_summary import fit_attrs
from .predict_fit import FittedFiles, _check_files, _key, estimate_segments, fit_from_files
from .trust import add_trust_columns, fit_check_line, trust_summary

__all__ = ["predict_from_files", "fit_from_files", "estimate_segments", "FittedFiles",
           "predict_recordings", "write_predictions",
           "predictions_payload", "FIT_KEYS",
           "format_predictions", "comparable_summary", "input_check_summary",
           "trust_summary", "fit_check_line", "add_trust_columns", "summary_table", "ROLES"]

#: The ``role`` column of every ``gearshot predict`` output: what a row's segment was to
#: the fit. ``healthy_fitted``: a healthy segment the estimator was fitted on (an
#: in-sample estimate); ``example``: the one faulty example (its estimate is near the
#: declared size by construction); ``faulty_rest``: the faulty recording's other segments
#: (same record as the example; they check the fit); ``healthy_holdout``: healthy segments
#: kept out of the fit (they check it too); ``test``: a recording the fit never saw.
ROLES = ("healthy_fitted", "example", "faulty_rest", "healthy_holdout", "test")


def _recording_files(path: Path):
    """Recording files of a folder (or the file itself); kept for callers of old."""
    from .files import expand_recordings

    return expand_recordings([path], "--recordings")


def predict_from_files(database, healthy, faulty, faulty_size, recordings, *, speed, load=None,
                       coverage=0.9, gear_teeth=None, pinion_teeth=None, seed=0,
                       selection_tf=None, holdout=HOLDOUT):
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
    holdout : float in [0, 1), default :data:`~gearshot.estimator.holdouts.HOLDOUT` (0.25)
        Fraction of each healthy recording's segments (the last ``floor(holdout · n)``)
        kept out of the fit (and of the TF estimate) and estimated
        (``role="healthy_holdout"``); with the faulty recording's other segments
        (``role="faulty_rest"``, always estimated) they check the fit
        (:attr:`~gearshot.estimator.OneFaultShotEstimator.fit_check_`) and calibrate the
        intervals.

    Returns
    -------
    pandas.DataFrame
        ``recording, role, segment, predicted, low, high, comparability, comparable,
        input_check, fit_check, trusted`` (roles: :data:`ROLES`;
        ``comparability``/``comparable`` from
        :meth:`~gearshot.estimator.OneFaultShotEstimator.comparability`: its p-value and
        whether it is at least the stated false-alarm rate; ``input_check``:
        ``"ok"`` or the failed check of :mod:`gearshot.io.input_health`, per recording and
        segment, with ``predicted``/``low``/``high`` withdrawn (NaN) on a failed row;
        ``fit_check`` the fit's verdict, the same in every row; ``trusted``:
        :func:`gearshot.estimator.trusted_column`). ``attrs["fit_check"]``:
        :meth:`~gearshot.estimator.fit_check.FitCheck.as_dict`. A healthy or faulty
        recording that fails an input check is refused.
    """
    from .files import expand_recordings

    _check_files(healthy, faulty)        # before the recordings: the fit's files first
    if isinstance(recordings, (str, Path)):
        recordings = [recordings]
    files = expand_recordings(recordings, "--recordings")
    est, fit = fit_from_files(database, healthy, faulty, faulty_size, speed=speed, load=load,
                              coverage=coverage, gear_teeth=gear_teeth,
                              pinion_teeth=pinion_teeth, seed=seed,
                              selection_tf=selection_tf, recordings=files, holdout=holdout)
    fitted = {_key(p) for p in healthy}
    estimated = {_key(p) for p in files}
    frames = []
    for path, sa in fit.targets:
        roles = _roles(path, len(sa), fitted, faulty)
        n_held = sum(len(h) for p, h, _ in fit.held if _key(p) == _key(path))
        if n_held:
            roles[len(sa) - n_held:] = ["healthy_holdout"] * n_held
        frames.append(_rows(est, path, roles, sa, coverage, fit.health))
    # the hold-outs that check the fit are estimated even when not asked for
    for path, sa, n_fit in fit.held:
        if len(sa) and _key(path) not in estimated:
            frames.append(_rows(est, path, ["healthy_holdout"] * len(sa), sa, coverage,
                                fit.health, start=n_fit))
    if _key(faulty) not in estimated and len(fit.rest):
        frames.append(_rows(est, faulty, ["faulty_rest"] * len(fit.rest), fit.rest, coverage,
                            fit.health, start=1))
    frame = pd.concat(frames, ignore_index=True)
    frame.attrs["speed"], frame.attrs["load"] = fit.speed, fit.load
    frame["speed_check"] = _fit_speed_checks(frame["recording"], fit.health, healthy, faulty)
    frame["path_check"] = fit_path_checks(frame["recording"], fit.health, healthy)
    add_trust_columns(frame, est.fit_check_)
    frame.attrs.update(fit_attrs(est, _speeds(fit.health, healthy)))
    return frame


def _rows(est, path, roles, sa, coverage, health, start: int = 0) -> pd.DataFrame:
    """One row per SA segment of one recording: estimate, interval, comparability and the
    input checks of its segments (``health``: resolved path -> checks)."""
    from ..estimator import below_detection_limit

    low, high = est.predict_interval(sa, coverage=coverage)
    comp = est.comparability(sa)
    predicted = est.predict(sa)
    rows = pd.DataFrame(dict(recording=str(path), role=roles,
                             segment=start + np.arange(len(sa)), predicted=predicted,
                             low=low, high=high,
                             below_detection_limit=below_detection_limit(est, predicted),
                             comparability=comp.p_value, comparable=comp.comparable))
    checks = health[_key(path)]
    return mark_rows(rows, input_check_column(checks["recording"], checks["segments"],
                                              rows=rows["segment"]))


def _fit_speed_checks(recordings: pd.Series, health: dict, healthy, faulty=None
                      ) -> list[str]:
    """Per row: :func:`gearshot.app.conditions.fit_speed_check` of its recording's
    measured speed (rev/s) against the fit's recordings' (the healthy recordings and the
    faulty one; unknown speeds pass)."""
    from .conditions import fit_speed_check

    fitted = _speeds(health, healthy)
    example = None if faulty is None else _speeds(health, [faulty])[0]
    checks = {r: fit_speed_check(_speeds(health, [r])[0], fitted, example_speed=example,
                                 unit="rev/s")
              for r in set(recordings)}
    return [checks[r] for r in recordings]


def fit_path_checks(recordings: pd.Series, health: dict, healthy) -> list[str]:
    """Per row: :func:`gearshot.app.conditions.fit_path_check` of its recording's
    resonance pattern against the fit's healthy recordings' (``health``: resolved path ->
    what the read kept; unknown patterns pass)."""
    from .conditions import fit_path_check

    refs = [health.get(_key(p), {}).get("path") for p in healthy]
    checks = {r: fit_path_check(health.get(_key(r), {}).get("path"), refs)
              for r in set(recordings)}
    return [checks[r] for r in recordings]


def _speeds(health: dict, paths) -> list[float]:
    """The measured speed (rev/s) the fit's read kept for each of ``paths`` (NaN where
    none was measured or the file was not read)."""
    return [float(health.get(_key(p), {}).get("speed", np.nan)) for p in paths]


def _roles(path, n: int, fitted: set, faulty) -> list[str]:
    if _key(path) in fitted:
        return ["healthy_fitted"] * n
    if _key(path) == _key(faulty):
        return ["example"] + ["faulty_rest"] * (n - 1)
    return ["test"] * n


def summary_table(frame: pd.DataFrame, roles: Sequence[str] = ROLES) -> pd.DataFrame:
    """One row per recording and role: segments, mean estimate and mean interval, the
    comparable and the trusted segments' counts, headed columns (the printed summary of
    ``gearshot predict``)."""
    order = {r: i for i, r in enumerate(roles)}
    by = ["recording", "role"] if "role" in frame else ["recording"]
    aggs = dict(segments=("predicted", "size"), estimated_size=("predicted", "mean"),
                low=("low", "mean"), high=("high", "mean"))
    if "comparable" in frame:
        aggs["comparable"] = ("comparable", "sum")
    if "trusted" in frame:
        aggs["trusted"] = ("trusted", "sum")
    table = frame.groupby(by, sort=False).agg(**aggs).reset_index()
    if "role" in table:
        table = table.sort_values("role", key=lambda r: r.map(order), kind="stable")
    table["recording"] = [Path(r).name for r in table["recording"]]
    return table.rename(columns={"estimated_size": "mean estimated size",
                                 "low": "mean low", "high": "mean high"})


def predict_recordings(database, healthy, faulty, faulty_size, recordings, *, machine=None,
                       speed=None, load=None, coverage=0.9, gear_teeth=None, pinion_teeth=None,
                       seed=0, cycles_per_segment=None, sensor=None, holdout=HOLDOUT,
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

    ignored = (["gear_teeth", "pinion_teeth"] if machine is not None
               else ["cycles_per_segment", "sensor"])
    for name in ignored:   # an option the chosen path would silently ignore
        if locals()[name] is not None:
            raise GearshotError(f"{name}={locals()[name]!r} does not apply "
                                f"{'with' if machine is not None else 'without'} machine")
    if machine is not None:
        from ..machine import Machine
        from .predict_machine import predict_from_machine

        frame = predict_from_machine(Machine.from_toml(machine), database, healthy, faulty,
                                     faulty_size, expand_recordings(recordings, "--recordings"),
                                     speed=speed, load=load,
                                     cycles_per_segment=cycles_per_segment, sensor=sensor,
                                     holdout=holdout, coverage=coverage, seed=seed,
                                     speed_tolerance=speed_tolerance)
        frame.attrs["inputs"] = _inputs(database, healthy, faulty, faulty_size, frame,
                                        machine=machine, speed=frame.attrs.get("speed_hz"),
                                        seed=seed, coverage=coverage,
                                        speed_unit="Hz (tacho shaft)")
        note = frame.attrs.get("sensor_note") or "the machine's first"
        return frame, (f"database condition: tacho shaft {frame.attrs['speed_hz']:.4g} Hz, "
                       f"load {frame.attrs['load']:g} N m{frame.attrs.get('load_note', '')}\n"
                       f"sensor: {frame.attrs['sensor']} ({note})")
    if speed is None:
        raise GearshotError("--speed is required without --machine (the database's "
                            "speed, rps)")
    if not recordings:
        raise GearshotError("--recordings: give at least one file or folder to estimate")
    frame = predict_from_files(database, healthy, faulty, faulty_size, recordings,
                               speed=speed, load=load, coverage=coverage,
                               gear_teeth=gear_teeth, pinion_teeth=pinion_teeth, seed=seed,
                               holdout=holdout)
    frame.attrs["inputs"] = _inputs(database, healthy, faulty, faulty_size, frame,
                                    machine=None, speed=frame.attrs.get("speed"), seed=seed,
                                    coverage=coverage, speed_unit="rps (pinion)")
    return frame, (f"database condition: {frame.attrs['speed']:g} rps, load "
                   f"{frame.attrs['load']:g} N m")


def _inputs(database, healthy, faulty, faulty_size, frame, *, machine, speed, seed,
            coverage, speed_unit) -> dict:
    """The ``inputs`` of a predict JSON (kept in the frame's ``attrs``)."""
    load = frame.attrs.get("load")
    return {"database": str(database), "healthy": [str(p) for p in healthy],
            "faulty": str(faulty), "faulty_size": float(faulty_size),
            "speed": None if speed is None else float(speed), "speed_unit": speed_unit,
            "load": None if load is None else float(load),
            "machine": None if machine is None else str(machine), "seed": int(seed),
            "coverage": float(coverage)}


#: The keys of the fit a predict JSON carries, when the frame's ``attrs`` hold them
#: (``fit_check``: the frame's fit verdict, when a fit check ran).
FIT_KEYS = ("grade", "calibration", "simulated_reference", "detection_limit", "fit_check",
            "load_source", "load_choice", "sensor", "sensor_note", "fit_warning")


def _summary(frame: pd.DataFrame) -> dict:
    """Counts of a predict table: rows, recordings, rows per role, and per flag column."""
    summary: dict = {"segments": int(len(frame)),
                     "recordings": int(frame["recording"].nunique()) if len(frame) else 0}
    if "role" in frame:
        summary["segments_by_role"] = {str(k): int(v) for k, v in
                                       frame["role"].value_counts(sort=False).items()}
    for flag in ("comparable", "trusted", "below_detection_limit"):
        if flag in frame:
            summary[flag] = int(frame[flag].fillna(False).astype(bool).sum())
    return summary


def predictions_payload(frame: pd.DataFrame) -> dict:
    """The predict JSON: ``kind``, ``gearshot_version``, ``inputs`` (database, healthy
    files, faulty file, declared size, speed, load, machine, seed, coverage: from
    ``frame.attrs["inputs"]``), ``fit`` (grade or calibration, simulated reference, fit
    check: the frame's ``attrs``), ``summary`` (counts) and ``rows`` (one per segment,
    every column; NaN as null)."""
    import json

    from .. import __version__

    attrs = frame.attrs
    fit = {key: attrs[key] for key in FIT_KEYS if key in attrs}
    return {"kind": "predict", "gearshot_version": __version__,
            "inputs": dict(attrs.get("inputs") or {}),
            "fit": json.loads(json.dumps(fit, default=str)),
            "summary": _summary(frame),
            "rows": json.loads(frame.to_json(orient="records"))}


def write_predictions(frame: pd.DataFrame, out: str | Path) -> Path:
    """Write a predict table to ``out``: by suffix ``.json``, :func:`predictions_payload`
    (inputs and fit beside the rows); else CSV, one row per segment (through
    :func:`gearshot._atomic.atomic_path`)."""
    import json

    from .._atomic import atomic_path

    out = Path(out)
    with atomic_path(out, make_parents=True) as tmp:
        if out.suffix.lower() == ".json":
            tmp.write_text(json.dumps(predictions_payload(frame), indent=2))
        else:
            frame.to_csv(tmp, index=False)
    return out


def comparable_summary(frame: pd.DataFrame) -> str:
    """One line counting the comparable segments of a predict table (issue #19), and saying
    when the fit had too few healthy segments to calibrate comparability."""
    from ..estimator.comparability import MIN_HEALTHY

    if "comparable" not in frame or not len(frame):
        return "comparable: no segment estimated"
    n_yes = int(frame["comparable"].sum())
    n_no = len(frame) - n_yes
    line = f"comparable: {n_yes} segment(s), not comparable: {n_no}"
    if n_no:
        line += (" (they do not look like the fitted machine — another build, speed, load "
                 "or sensor? — do not act on their estimates)")
    if "comparability" in frame and frame["comparability"].isna().all():
        line += (f"; comparability is not calibrated: the fit holds fewer than {MIN_HEALTHY} "
                 f"healthy segments")
    return line


def input_check_summary(frame: pd.DataFrame) -> str:
    """One line counting the segments by their ``input_check`` (issue #29)."""
    if "input_check" not in frame or not len(frame):
        return "input_check: no segment checked"
    failed = frame.loc[frame["input_check"] != "ok", "input_check"]
    if failed.empty:
        return f"input_check: ok for all {len(frame)} segment(s)"
    counts = ", ".join(f"{name} {n}" for name, n in failed.value_counts().items())
    return (f"input_check: ok for {len(frame) - len(failed)} segment(s), failed for "
            f"{len(failed)} ({counts}): no estimate is given for them")


def failed_check_summary(frame: pd.DataFrame, column: str) -> str | None:
    """One line naming the recordings whose ``column`` check failed (``"speed_check"``,
    ``"path_check"``); None when none did."""
    if column not in frame or not len(frame):
        return None
    bad = frame.loc[frame[column] != "ok"].drop_duplicates("recording")
    if bad.empty:
        return None
    first = f"{Path(str(bad['recording'].iloc[0])).name}: {bad[column].iloc[0]}"
    return (f"{column}: failed for {len(bad)} recording(s) ({first}"
            + (", …" if len(bad) > 1 else "") + "): their estimates are not trusted")


def detection_summary(frame: pd.DataFrame) -> str | None:
    """One line counting the segments below the fit's detection limit (issue #30): their
    estimates say "no fault resolved", not a small size. None without the column."""
    if "below_detection_limit" not in frame or not len(frame):
        return None
    n = int(frame["below_detection_limit"].fillna(False).astype(bool).sum())
    limit = frame.attrs.get("detection_limit")
    at = "" if limit is None else f" {limit:.3f}"
    return (f"below the detection limit{at}: {n} of {len(frame)} segment(s) (not told apart "
            f"from healthy: read as no fault resolved, not as a small size)")


def format_predictions(frame: pd.DataFrame, where: str) -> str:
    """What ``gearshot predict`` prints: the condition, the fit's verdict
    (:func:`fit_check_line`), the summary per recording and role (:func:`summary_table`),
    the comparability, input-check and trusted counts."""
    table = summary_table(frame).to_string(index=False, float_format=lambda v: f"{v:.3f}")
    lines = [where]
    if "fit_check" in frame or frame.attrs.get("fit_check"):
        lines.append(fit_check_line(frame))
    if frame.attrs.get("fit_warning"):
        lines.append(f"warning: {frame.attrs['fit_warning']}")
    lines += [table, comparable_summary(frame), input_check_summary(frame)]
    lines += [line for line in (failed_check_summary(frame, "speed_check"),
                                failed_check_summary(frame, "path_check"),
                                detection_summary(frame)) if line]
    if "trusted" in frame:
        lines.append(trust_summary(frame))
    return "\n".join(lines)
