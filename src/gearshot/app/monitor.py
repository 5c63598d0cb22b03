"""``gearshot fit`` and ``gearshot monitor``: fit once, then estimate every new recording.

:func:`fit_model` fits through the fit of ``gearshot predict`` (with or without a machine
file; without a faulty recording zero-shot) and writes a model file
(:class:`gearshot.monitor.MonitorModel`) with the healthy baseline of recordings kept out
of the fit. :func:`estimate_recordings` estimates recordings with a saved model through
the estimate of ``gearshot predict`` (:func:`gearshot.app.predict.estimate_segments`), one
combined row per recording. :func:`monitor_history` brings a history up to date with an
index and returns the ``--json`` payload; :func:`monitor_fleet` does that for many
machines in one call, on a Dask cluster.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .._errors import GearshotError
from .._validation import check_in_range, check_int
from ..estimator.holdouts import HOLDOUT

__all__ = ["fit_model", "estimate_recordings", "monitor_history", "monitor_fleet",
           "write_monitor_outputs", "LOAD_TOLERANCE"]

#: Relative distance of an index's ``load`` from the model's load beyond which a
#: recording is not covered by the fit (untrusted).
LOAD_TOLERANCE = 0.15


def _holdout_split(healthy: Sequence[str | Path], holdout: float) -> tuple[list, list]:
    """(fit, baseline) healthy recordings: the last ``holdout`` share (at least one) is
    kept out of the fit for the alarm baseline."""
    healthy = list(healthy)
    if len(healthy) < 2:
        raise GearshotError(f"--healthy needs at least 2 recordings (one is kept out of the "
                            f"fit for the alarm's healthy baseline); got {len(healthy)}")
    n_hold = min(max(1, int(round(holdout * len(healthy)))), len(healthy) - 1)
    return healthy[:-n_hold], healthy[-n_hold:]


def fit_model(database, healthy: Sequence[str | Path], faulty: str | Path | None = None,
              faulty_size: float | None = None, *, model: str | Path,
              machine: str | Path | None = None, speed: float | None = None,
              load: float | None = None, coverage: float = 0.9,
              gear_teeth: int | None = None, pinion_teeth: int | None = None, seed: int = 0,
              cycles_per_segment: int | None = None, sensor: str | None = None,
              holdout: float = HOLDOUT, speed_tolerance: float = 0.05,
              false_alarm_rate: float | None = None, sustain: int | None = None):
    """Fit and write a model file (``gearshot fit``).

    Parameters
    ----------
    database, healthy, faulty, faulty_size, machine, speed, load, coverage, gear_teeth,
    pinion_teeth, seed, cycles_per_segment, sensor, speed_tolerance
        As for ``gearshot predict`` (:func:`gearshot.app.predict.predict_recordings`);
        ``faulty`` None fits zero-shot.
    model : path
        The model file to write (skops).
    holdout : float
        Without a machine file: the share of the healthy recordings (at least one) kept
        out of the fit; with one: the share of each healthy recording's segments. Their
        estimates are the healthy baseline the alarm threshold is set from (without a
        machine file, from 3 fit recordings on, with each fit recording's estimates by a
        fit on the others).
    false_alarm_rate, sustain
        Of the alarm (default :data:`gearshot.monitor.alarm.FALSE_ALARM_RATE`,
        :data:`~gearshot.monitor.alarm.SUSTAIN`).

    Returns
    -------
    MonitorModel
        Saved at ``model``.
    """
    from ..monitor import MonitorModel, alarm_threshold, database_identity
    from ..monitor.trust import runs_warning
    from .predict import estimate_segments

    if (faulty is None) != (faulty_size is None):
        raise GearshotError("--faulty and --faulty-size go together (neither: zero-shot)")
    check_in_range(holdout, "holdout (--holdout)", 0.0, 1.0, low_inclusive=False,
                   high_inclusive=False)
    rate, sustain = _alarm_options(false_alarm_rate, sustain)
    identity = database_identity(database)
    if machine is None:
        if speed is None:
            raise GearshotError("--speed is required without --machine (the database's "
                                "speed, rps)")
        from .predict import fit_from_files

        fit_files, base_files = _holdout_split(healthy, holdout)
        reads: dict = {}   # each file and the database read once, for the fit and cross-fits
        est, fitted = fit_from_files(database, fit_files, faulty, faulty_size, speed=speed,
                                     load=load, coverage=coverage, gear_teeth=gear_teeth,
                                     pinion_teeth=pinion_teeth, seed=seed,
                                     recordings=base_files, holdout=0.0,
                                     holdout_files=base_files, reads=reads)
        baseline = np.concatenate([estimate_segments(est, sa, coverage=coverage)["predicted"]
                                   for _, sa in fitted.targets]
                                  + _cross_fitted(database, fit_files, faulty, faulty_size,
                                                  speed=speed, load=load, coverage=coverage,
                                                  seed=seed, teeth=fitted.teeth,
                                                  reads=reads))
        condition = {"speed": fitted.speed, "load": fitted.load, "speed_unit": "rps",
                     **{k: int(v) for k, v in fitted.teeth.items()}}
        read = [fitted.health[Path(p).resolve()] for p in healthy]   # what the fit's read kept
        speeds, paths = [float(h.get("speed", np.nan)) for h in read], [h.get("path") for h in read]
        example_speed = np.nan if faulty is None else float(
            fitted.health[Path(faulty).resolve()].get("speed", np.nan))
        toml, sensor_note = None, ""
    else:
        est, baseline, condition, speeds, example_speed, sensor_note, paths = _fit_with_machine(
            machine, database, healthy, faulty, faulty_size, speed=speed, load=load,
            coverage=coverage, cycles_per_segment=cycles_per_segment, sensor=sensor,
            holdout=holdout, seed=seed, speed_tolerance=speed_tolerance)
        toml = Path(machine).read_text(encoding="utf-8")
    baseline = np.asarray(baseline, float)
    result = MonitorModel(
        estimator=est, calibration="zero_shot" if faulty is None else "one_fault_shot",
        condition=condition, database=identity, baseline=baseline.tolist(),
        threshold=alarm_threshold(baseline, false_alarm_rate=rate),
        false_alarm_rate=float(rate), sustain=int(sustain), machine_toml=toml,
        faulty=None if faulty is None or faulty_size is None else {
            "recording": str(Path(faulty).resolve()), "size": float(faulty_size)},
        fit_check=getattr(est, "fit_check_", None), coverage=float(coverage), seed=int(seed),
        extras={"healthy": [str(Path(p).resolve()) for p in healthy],
                "grade": getattr(est, "grade_", None), "healthy_speeds": list(speeds),
                "example_speed": None if not np.isfinite(example_speed) else example_speed,
                "fit_warning": runs_warning(speeds), "sensor_note": sensor_note,
                "healthy_paths": [None if v is None else list(map(float, v)) for v in paths]})
    result.save(model)
    return result


def _alarm_options(false_alarm_rate: float | None, sustain: int | None) -> tuple[float, int]:
    """The alarm's false-alarm rate and sustain, defaults filled in and checked."""
    from ..monitor.alarm import FALSE_ALARM_RATE, SUSTAIN

    rate = check_in_range(FALSE_ALARM_RATE if false_alarm_rate is None else false_alarm_rate,
                          "false_alarm_rate (--false-alarm-rate)", 0.0, 0.5,
                          low_inclusive=False, high_inclusive=False)
    return rate, check_int(SUSTAIN if sustain is None else sustain, "sustain (--sustain)",
                           minimum=1)


def _cross_fitted(database, fit_files, faulty, faulty_size, *, speed, load, coverage, seed,
                  teeth, reads=None) -> list:
    """Estimates of each fit recording by a fit on the other healthy recordings (from
    :data:`~gearshot.estimator.comparability.MIN_GROUPS` fit recordings on; else none):
    the healthy baseline then holds every healthy recording's run, not one kept out.
    Chosen on the development lives (``benchmarks/monitor_lives.py``, seeds 1-10): with
    the kept-out recordings alone the threshold reached 0.29-0.31 in three lives and
    one alarm came 6 recordings late; cross-fitted, every alarm came in time, none false."""
    from ..estimator.comparability import MIN_GROUPS
    from .predict import estimate_segments, fit_from_files

    if len(fit_files) < MIN_GROUPS:
        return []
    out = []
    for path in fit_files:
        others = [p for p in fit_files if p != path]
        est, fitted = fit_from_files(database, others, faulty, faulty_size, speed=speed,
                                     load=load, coverage=coverage, seed=seed,
                                     recordings=[path], holdout=0.0, holdout_files=[path],
                                     reads=reads, **teeth)
        out.append(estimate_segments(est, fitted.targets[0][1],
                                     coverage=coverage)["predicted"].to_numpy())
    return out


def _fit_with_machine(machine, database, healthy, faulty, faulty_size, *, speed, load,
                      coverage, cycles_per_segment, sensor, holdout, seed, speed_tolerance):
    """``fit_model`` with a machine file: estimator, baseline, condition, healthy speeds,
    the faulty recording's speed (NaN without one), why the sensor is not the
    machine's first ("" when it is: :mod:`gearshot.app.sensor_choice`) and the healthy
    recordings' resonance patterns."""
    from ..machine import Machine
    from .predict import estimate_segments
    from .predict_machine import fit_machine

    mach = Machine.from_toml(machine)
    est, seg, cond = fit_machine(mach, database, healthy, faulty, faulty_size, speed=speed,
                                 load=load, cycles_per_segment=cycles_per_segment,
                                 sensor=sensor, holdout=holdout, seed=seed,
                                 speed_tolerance=speed_tolerance)
    held = [r[4] for r in seg.rows if r[1] == "healthy_holdout"]
    if not held:
        raise GearshotError(f"--holdout {holdout:g} keeps no healthy segment out of the "
                            f"fit; the alarm baseline needs some (raise --holdout)")
    baseline = estimate_segments(est, np.stack(held), coverage=coverage)["predicted"]
    cps = mach.cycles_per_segment if cycles_per_segment is None else cycles_per_segment
    assert cps is not None   # fit_machine refused a machine without one
    condition = {"speed": float(cond.speed), "load": float(cond.load),
                 "speed_unit": "Hz (tacho shaft)", "cycles_per_segment": int(cps),
                 "sensor": seg.sensor,
                 "speed_tolerance": float(speed_tolerance)}
    speeds = pd.DataFrame([(r[0], r[3]) for r in seg.rows if r[1].startswith("healthy")])
    return (est, baseline, condition, [float(v) for v in speeds.groupby(0)[1].mean()],
            float(seg.example_speed), seg.sensor_note,
            [seg.sources[f].get("path") for f in seg.healthy_files])


def _segments_of(model, path: Path, machine) -> tuple[np.ndarray, str, list[str]]:
    """SA segments of one recording as the model's fit segmented its recordings, a note
    ("" or why the recording is not covered: with a machine file, a tacho speed beyond
    the model's speed tolerance; with or without one, the speed and path checks of
    :func:`gearshot.app.conditions.fit_recording_checks` against the fit's recordings,
    healthy and the faulty example) and each segment's ``input_check`` (the recording's
    raw samples and its segments, :func:`gearshot.io.input_health.input_check_column`,
    as ``gearshot predict`` checks them)."""
    from ..io.input_health import input_check_column
    from .conditions import fit_recording_checks

    cond = model.condition
    extras = getattr(model, "extras", None) or {}
    health: dict = {}
    note, unit = "", "rev/s"
    if machine is None:
        from ..io import recording_segments

        sa = recording_segments(path, gear_teeth=cond["gear_teeth"],
                                pinion_teeth=cond["pinion_teeth"], health=health)
        speed = float(health.get("speed", np.nan))
    else:
        from .predict_machine import machine_segments

        sa, _, speed = machine_segments(path, machine, sensor=cond["sensor"],
                                        cycles_per_segment=cond["cycles_per_segment"],
                                        info=health)
        off = abs(speed - cond["speed"]) / cond["speed"]
        note = "" if off <= cond["speed_tolerance"] else (
            f"tacho {speed:.4g} Hz is {100 * off:.0f} % from the fitted {cond['speed']:.4g} Hz")
        unit = "Hz"
    checks = fit_recording_checks(speed, health.get("path"), extras.get("healthy_speeds") or [],
                                  extras.get("healthy_paths") or [],   # older models: none
                                  example_speed=extras.get("example_speed"), unit=unit,
                                  tracked=health.get("speed_check", "ok"))
    failed = next((c for c in checks if c != "ok"), "")
    inputs = input_check_column(health["recording"], health["segments"])
    return np.asarray(sa), note or failed, inputs


def estimate_recordings(model, recordings: pd.DataFrame, *,
                        progress: bool = False) -> pd.DataFrame:
    """Estimate recordings with a saved model: one history row per recording.

    Parameters
    ----------
    model : MonitorModel
        Saved (its digest names the rows).
    recordings : pandas.DataFrame
        Rows of :func:`gearshot.monitor.read_index` (``recording``, ``time``, optional
        ``speed``/``load``).

    Returns
    -------
    pandas.DataFrame
        :data:`gearshot.monitor.HISTORY_COLUMNS`. A recording that cannot be
        read or segmented, or whose index ``load`` (or ``speed``) lies outside the fitted
        condition, is kept, untrusted, with the reason in ``note``. ``progress``: a
        progress bar, or plain lines on standard error (:mod:`gearshot._progress`).
    """
    from .._progress import track
    from ..monitor import combine_segments
    from ..monitor.trust import untrusted_reason
    from .predict import estimate_segments

    machine = model.machine
    digest = model.digest
    now = pd.Timestamp.now(tz="UTC").tz_localize(None)
    rows = []
    for rec in track(list(recordings.itertuples(index=False)), "estimating recordings",
                     enabled=progress):
        row = {"recording": rec.recording, "time": pd.Timestamp(rec.time), "model": digest,
               "calibration": model.calibration, "estimated_at": now}
        try:
            sa, note, inputs = _segments_of(model, Path(rec.recording), machine)
            frame = estimate_segments(model.estimator, sa, coverage=model.coverage,
                                      input_check=inputs)
            row.update(combine_segments(frame))
            note = (note or _condition_note(model, rec)
                    or untrusted_reason(frame, zero_shot=model.calibration == "zero_shot"))
        except GearshotError as exc:
            row.update(predicted=np.nan, low=np.nan, high=np.nan, segments=0,
                       trusted_segments=0, trusted=False)
            note = f"not estimated: {exc}"
        if note:
            row["trusted"] = False
        row["note"] = note
        rows.append(row)
    from ..monitor import HISTORY_COLUMNS

    return pd.DataFrame(rows, columns=HISTORY_COLUMNS)


def _condition_note(model, rec) -> str:
    """Why an index row's declared speed/load lies outside the fit ("" when it does not
    or the index declares none)."""
    cond = model.condition
    load = getattr(rec, "load", None)
    if load not in (None, "") and np.isfinite(float(load)):
        off = abs(float(load) - cond["load"]) / cond["load"]
        if off > LOAD_TOLERANCE:
            return f"index load {float(load):g} N m is outside the fitted {cond['load']:g} N m"
    speed = getattr(rec, "speed", None)
    if speed not in (None, "") and np.isfinite(float(speed)):
        tol = cond.get("speed_tolerance", 0.05)
        off = abs(float(speed) - cond["speed"]) / cond["speed"]
        if off > tol:
            return f"index speed {float(speed):g} is outside the fitted {cond['speed']:g}"
    return ""


def _estimate_chunk(model_path: str, chunk: pd.DataFrame) -> pd.DataFrame:
    """A worker's share: load the model once, estimate its recordings."""
    from ..monitor import load_model

    return estimate_recordings(load_model(model_path), chunk)


def monitor_history(model: str | Path, index: str | Path, history: str | Path, *,
                    limit: float = 0.6, client: Any = None) -> dict:
    """Estimate the recordings of ``index`` that ``history`` holds no estimate of by this
    model, append them (atomically) and return the ``--json`` payload.

    Parameters
    ----------
    model : path
        Model file (``gearshot fit --model``).
    index : path
        CSV, folder or glob pattern (:func:`gearshot.monitor.read_index`).
    history : path
        Parquet history (created when missing).
    limit : float
        Size whose crossing is forecast.
    client : dask.distributed.Client, optional
        Spread the recordings over its workers.
    """
    from ..monitor import append_history, load_model, monitor_payload, pending, read_history
    from ..monitor import read_index as read_idx

    limit = check_in_range(limit, "limit (--limit)", 0.0, 1.0, low_inclusive=False)
    mdl = load_model(model)
    table = read_idx(index)
    past = read_history(history)
    todo = pending(table, past, mdl.digest)
    if len(todo):
        if client is None:
            rows = estimate_recordings(mdl, todo, progress=True)
        else:
            n = max(1, min(len(todo), 4 * len(client.nthreads())))
            chunks = [c for c in np.array_split(np.arange(len(todo)), n) if c.size]
            futures = client.map(_estimate_chunk, [str(Path(model).resolve())] * len(chunks),
                                 [todo.iloc[c] for c in chunks], pure=False)
            rows = pd.concat(client.gather(futures), ignore_index=True)
        past = append_history(history, rows)
    payload = monitor_payload(past, mdl, limit=limit)
    payload["new"] = int(len(todo))
    payload["history"] = str(Path(history))
    if "source" in table.attrs:   # a folder or pattern of recordings, not a CSV
        payload["index_source"] = table.attrs["source"]
    return payload


def monitor_fleet(jobs: Sequence[tuple[str | Path, str | Path, str | Path]], *,
                  limit: float = 0.6, scheduler: str | None = None,
                  workers: int = 2) -> list[dict]:
    """:func:`monitor_history` for many machines, ``(model, index, history)`` each, the
    new recordings of all of them estimated on one Dask cluster (``scheduler``, or a
    LocalCluster of ``workers``; in-process with one worker)."""
    from .._cluster import dask_client

    with dask_client(scheduler, workers, needed=True) as client:
        return [monitor_history(m, i, h, limit=limit, client=client)
                for m, i, h in jobs]


def write_monitor_outputs(payload: dict, *, json_out: Path | None = None,
                          out: Path | None = None) -> list[Path]:
    """Write the JSON and (``out``) the trend figure ``trend.png`` and the history as
    CSV; returns the paths written."""
    from .._atomic import atomic_path, write_json_atomic
    from ..monitor.figure import trend_figure

    written = []
    if json_out is not None:
        write_json_atomic(payload, json_out, make_parents=True, indent=2, sort_keys=False,
                          default=float)
        written.append(Path(json_out))
    if out is not None:
        written.append(trend_figure(payload, Path(out) / "trend.png"))
        with atomic_path(Path(out) / "records.csv", make_parents=True) as tmp:
            pd.DataFrame(payload["records"]).to_csv(tmp, index=False)
        written.append(Path(out) / "records.csv")
    return written
