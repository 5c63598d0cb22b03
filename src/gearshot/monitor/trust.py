"""Which estimates of a monitored machine can be acted on: one place for the trust rule.

``gearshot predict`` rows carry the trust columns of the estimate they belong to:
``comparable`` (the segment looks like the fitted machine), and, where the predict side
provides them, ``input_check`` (``"ok"`` or the failed check of the recording) and
``trusted`` (every check passed). :func:`row_trust` reads them the same way for every
caller: ``trusted`` when present, else ``comparable`` (and ``input_check == "ok"`` when
that column is present). :func:`recording_trust` combines the segments of one recording.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from ..estimator.fit_check import LABEL_CHECKS, MIN_TRUSTED_SHARE, PASSED

__all__ = ["untrusted_reason", "untrusted_counts", "row_trust", "recording_trust",
           "change_notice", "one_run_warning", "few_runs_warning", "runs_warning",
           "fit_check_warning", "model_warning", "MIN_TRUSTED_SHARE", "CHANGE_RUN",
           "ONE_RUN_SPREAD", "SPREAD_RECORDINGS", "OTHER_PATH"]


def row_trust(frame: pd.DataFrame) -> np.ndarray:
    """Whether each row (segment) of a predict table can be acted on.

    Parameters
    ----------
    frame : pandas.DataFrame
        Rows of :func:`gearshot.app.predict.estimate_segments` (or of ``gearshot
        predict``).

    Returns
    -------
    ndarray of bool, shape (len(frame),)
        ``frame["trusted"]`` when present; else ``frame["comparable"]`` and, when present,
        ``frame["input_check"] == "ok"``; all True when the frame carries none of them.
    """
    n = len(frame)
    if "trusted" in frame:
        return np.asarray(frame["trusted"], dtype=bool)
    ok = np.ones(n, dtype=bool)
    if "comparable" in frame:
        ok &= np.asarray(frame["comparable"], dtype=bool)
    if "input_check" in frame:
        ok &= np.asarray(frame["input_check"].astype(str) == "ok", dtype=bool)
    return ok


#: Latest recordings in a row not comparable with the fitted machine that make
#: :func:`change_notice` speak. Chosen on the development lives (seeds 1-10, 51-60): at 3,
#: one notice over the 240 healthy recordings outside the load changes and remounts, every
#: load change and remount of 16 lives noticed (at 2: 3 healthy notices; at 4: the
#: 3-recording episodes are missed).
CHANGE_RUN = 3

#: Relative spread (standard deviation over mean) of the healthy fit recordings' speeds
#: under which :func:`one_run_warning` speaks. Measured on the virtual rig's fit campaigns
#: (seeds 1, 3, 9): recorded at one set-point, 0.04-0.05 %; over runs whose speed varies
#: 1 %, 0.58-0.83 %.
ONE_RUN_SPREAD = 0.002

#: Healthy recordings from which their speeds' spread bounds how far a later run's may
#: move (:func:`gearshot.app.conditions.fit_speed_check`); a fit on fewer trusts a later
#: run only within 0.3 % of one of its recordings' speeds (:func:`few_runs_warning`).
SPREAD_RECORDINGS = 3

#: How :func:`untrusted_reason` names the segments that comparability flags (what
#: :func:`untrusted_counts` finds again in a note).
NOT_COMPARABLE = "not comparable with the fitted machine"

#: What every reason of :func:`gearshot.app.conditions.fit_speed_check` holds (a
#: recording's speed outside the fit's recordings': found again in a note).
OUTSIDE_FIT_SPEEDS = "outside the fit's recordings'"

#: What every failing reason of :func:`gearshot.app.conditions.fit_path_check` holds (a
#: recording whose resonance pattern is not the fit's healthy recordings': found again
#: in a note).
OTHER_PATH = "another transfer path"


def untrusted_reason(frame: pd.DataFrame, *, zero_shot: bool = False) -> str:
    """Why a recording (the rows of its segments) is not trusted, in one line ("" when it
    is): each check that fails, joined by "; " -- the fit's own check, the label checks
    that :func:`gearshot.estimator.fit_check.trusted_column` requires (input, speed), the
    segments not comparable with the fitted machine."""
    if recording_trust(frame):
        return ""
    n, parts = len(frame), []
    verdict = frame["fit_check"].astype(str) if "fit_check" in frame else None
    if verdict is not None and n and (verdict != PASSED).all():
        parts.append(f"fit check: {verdict.iloc[0]}")
    for check in LABEL_CHECKS:
        if check in frame:
            bad = frame[check].astype(str)
            bad = bad[bad != "ok"]
            if len(bad):
                parts.append(f"{check.replace('_', ' ')}: {len(bad)} of {n} segments "
                             f"({bad.iloc[0]})")
    if "comparable" in frame:
        off = int((~frame["comparable"].astype(bool)).sum())
        if off:
            fault = "or a fault" if zero_shot else "or a fault beyond the example's"
            parts.append(f"{off} of {n} segments {NOT_COMPARABLE} (another load, speed, "
                         f"sensor or path, {fault})")
    if not parts:
        parts.append(f"{int(row_trust(frame).sum())} of {n} segments trusted (more than "
                     f"half needed)")
    return "; ".join(parts)


def recording_trust(frame: pd.DataFrame) -> bool:
    """Whether one recording (the rows of its segments) is trusted: more than
    :data:`MIN_TRUSTED_SHARE` of its segments are (:func:`row_trust`)."""
    trust = row_trust(frame)
    return bool(trust.size and trust.mean() > MIN_TRUSTED_SHARE)


def untrusted_counts(notes) -> dict[str, int]:
    """How many untrusted recordings fail each kind of check, from their notes (the
    ``note`` of :func:`untrusted_reason` or of the monitor's condition and read checks),
    most frequent first; a recording failing several counts under each."""
    kinds = {"fit check": "fit check failed",
             OUTSIDE_FIT_SPEEDS: "speed outside the fit's recordings' (another load?)",
             OTHER_PATH: "another transfer path (sensor moved?)",
             **{c.replace("_", " "): f"{c.replace('_', ' ')} failed" for c in LABEL_CHECKS},
             NOT_COMPARABLE: NOT_COMPARABLE,
             "outside the fitted": "outside the fitted condition (index speed or load)",
             "not estimated": "not estimated (unreadable or too short)"}
    counts: dict[str, int] = {}
    for note in notes:
        text = str(note or "")
        if not text:
            continue
        found = [label for key, label in kinds.items() if key in text] or ["other"]
        for label in found:
            counts[label] = counts.get(label, 0) + 1
    return dict(sorted(counts.items(), key=lambda kv: -kv[1]))


def change_notice(times, trusted, notes, *, zero_shot: bool = False) -> dict | None:
    """Whether the machine has stopped looking like the fitted one: the latest
    :data:`CHANGE_RUN` or more recordings in a row untrusted because their segments are
    not comparable with the fitted machine (another load, speed, sensor or path, or a
    fault beyond the example's), because they ran at a speed outside the fit's
    recordings' (:func:`gearshot.app.conditions.fit_speed_check`: another load or speed,
    which makes a predict row not comparable too) or through another transfer path
    (:func:`gearshot.app.conditions.fit_path_check`). Such recordings never raise an alarm,
    so a machine that changed, or a fault that outgrew the fit, would otherwise go quiet.

    Parameters
    ----------
    times, trusted, notes : sequences, one item per recording in time order
        ISO times, whether trusted, and the ``note`` of each (:func:`untrusted_reason`).
    zero_shot : bool
        The model has no faulty example (its fitted states hold no fault at all).

    Returns
    -------
    dict or None
        ``since`` (the time of the first recording of the run), ``recordings`` (its
        length) and ``message``; None when the latest recordings are not such a run.
    """
    run = 0
    for ok, note in zip(reversed(list(trusted)), reversed(list(notes)), strict=True):
        if ok or not any(why in str(note or "") for why in (NOT_COMPARABLE,
                                                            OUTSIDE_FIT_SPEEDS, OTHER_PATH)):
            break
        run += 1
    if run < CHANGE_RUN:
        return None
    since = list(times)[-run]
    fault = ("a fault may be growing, which a zero-shot model's states do not hold"
             if zero_shot else "the fault may have grown beyond the example's size, where "
             "the estimates are no longer trusted")
    return {"since": since, "recordings": run,
            "message": f"the latest {run} recordings (since {since}) are {NOT_COMPARABLE}: "
                       f"check its load, speed and sensor mount; if none changed, {fault} "
                       f"(refit with an inspected recording)"}


def one_run_warning(speeds) -> str | None:
    """A warning for a model whose healthy recordings all ran at one speed (from 3 on):
    it cannot see how a later run moves. A machine recorded on many days runs at speeds
    that differ a little, which moves the transfer path's resonances against the mesh
    orders: fitted on one day, later days are flagged as not comparable or read as small
    faults (``benchmarks/RESULTS.md``, "Monitoring": alarms in time 7 of 10 development
    lives instead of 10).

    Parameters
    ----------
    speeds : sequence of float
        The mean shaft speed of each healthy recording the fit used.

    Returns
    -------
    str or None
    """
    values = np.asarray(list(speeds), dtype=float)
    values = values[np.isfinite(values)]
    if values.size < 3 or values.mean() <= 0:
        return None
    spread = float(values.std(ddof=1) / values.mean())
    if spread >= ONE_RUN_SPREAD:
        return None
    return (f"the {values.size} healthy recordings ran within {100 * spread:.2f} % of one "
            f"speed (as one run); if the machine's speed varies more from run to run, "
            f"later runs may be flagged as not comparable or read as small faults: fit on "
            f"healthy recordings from several runs or days")


def few_runs_warning(speeds) -> str | None:
    """A warning for a model fitted on 1 or 2 healthy recordings (with known speeds): they
    show no spread of runs, so a later recording is trusted only within 0.3 % of one of
    the fit's recordings' speeds (:func:`gearshot.app.conditions.fit_speed_check`; on the
    virtual rig a healthy run 0.6-1.9 % off a one-recording fit's speed read 0.24-0.30).

    >>> few_runs_warning([15.0]) is not None, few_runs_warning([15.0, 15.1, 14.9])
    (True, None)
    """
    values = np.asarray(list(speeds), dtype=float)
    n = int(np.isfinite(values).sum())
    if not 0 < n < SPREAD_RECORDINGS:
        return None
    return (f"fitted on {n} healthy recording(s), which show no spread of runs: a later "
            f"recording more than 0.3 % off their speeds (and the example's) is not "
            f"trusted; fit on healthy recordings of {SPREAD_RECORDINGS} or more runs or days")


def runs_warning(speeds) -> str | None:
    """The warning a model's healthy recordings' speeds give: :func:`one_run_warning`
    (3 or more at one speed) or :func:`few_runs_warning` (1 or 2), else None."""
    return one_run_warning(speeds) or few_runs_warning(speeds)


def fit_check_warning(fit_check) -> str | None:
    """A warning for a model whose fit did not pass its own check: every estimate it makes
    is untrusted, so ``gearshot monitor`` would raise no alarm and forecast nothing, for
    as long as it is used.

    Parameters
    ----------
    fit_check : FitCheck, mapping or None
        The estimator's ``fit_check_`` (a saved model holds it as a mapping).

    Returns
    -------
    str or None
        None when the check passed (or the model holds none).
    """
    verdict = (fit_check.get("verdict") if isinstance(fit_check, Mapping)
               else getattr(fit_check, "verdict", None))
    if verdict is None or verdict == PASSED:
        return None
    return (f"the fit did not pass its own check ({verdict}): no estimate of this model is "
            f"trusted, so no alarm can be raised and no forecast made; refit after fixing "
            f"what the check names (longer or more recordings, or another example)")


def model_warning(model) -> str | None:
    """Every warning of a model, one string (None: none): its fit check's
    (:func:`fit_check_warning`), the runs warning it was saved with (:func:`runs_warning`)
    and its baseline's (:func:`gearshot.monitor.alarm.baseline_warning`)."""
    from .alarm import baseline_warning

    extras = getattr(model, "extras", None) or {}
    baseline = getattr(model, "baseline", None)
    found = [w for w in (fit_check_warning(getattr(model, "fit_check", None)),
                         extras.get("fit_warning"),
                         None if baseline is None else baseline_warning(baseline)) if w]
    return "; ".join(found) or None
