"""Fit and predict on a real machine: SA segments of the monitored gear's shaft, through a
machine description (gear train, tacho, sensors, file layout)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from .._errors import GearshotError
from .._validation import check_in_range, check_int
from ..estimator.example import typical_segment
from ..estimator.holdouts import HOLDOUT
from ..io.input_health import input_check_column, mark_rows, require_ok
from ..machine.signal_check import verify_machine
from .conditions import (
    SPEED_TOLERANCE,
    check_database_pair,
    check_speeds,
    choose_condition,
    database_conditions,
    fit_recording_checks,
)
from .fit_summary import fit_attrs
from .load_choice import LoadChoice, choose_load
from .machine_read import machine_segments
from .predict_fit import recording_labels
from .trust import add_trust_columns

__all__ = ["machine_segments", "predict_from_machine", "fit_machine", "machine_database_path",
           "check_database_pair"]


def machine_database_path(machine_file: str | Path, *, n_healthy: int, n_faulty: int,
                          seed: int, paired: bool = True) -> Path:
    """Default store of ``gearshot simulate --machine FILE``."""
    from ..sim import default_database_path

    return default_database_path(f"machine-{Path(machine_file).stem}-h{n_healthy}-"
                                 f"f{n_faulty}-s{seed}" + ("-paired" if paired else ""))


def _require_fit_input(info: dict, path, role: str) -> None:
    """Refuse a recording the fit uses unless it and each of its segments pass."""
    for check in (info["recording"], *info["segments"]):
        require_ok(check, path, role)


def _comparability_columns(est, sas) -> tuple[np.ndarray, np.ndarray]:
    """The ``comparability`` (p-value) and ``comparable`` columns of a predict table."""
    result = est.comparability(sas)
    return result.p_value, result.comparable


def predict_from_machine(machine, database, healthy: Sequence[str | Path],
                         faulty: str | Path, faulty_size: float,
                         recordings: Sequence[str | Path] = (), *,
                         speed: float | None = None, load: float | None = None,
                         cycles_per_segment: int | None = None, sensor: str | None = None,
                         holdout: float = HOLDOUT, example_segment: int | None = None,
                         coverage: float = 0.9, seed: int = 0,
                         params: dict | None = None,
                         speed_tolerance: float = SPEED_TOLERANCE) -> pd.DataFrame:
    """Fit on healthy recordings + one faulty recording; estimate segments of a machine.

    Parameters
    ----------
    machine : gearshot.Machine
        With a ``[monitored]`` gear; its shaft's revolution is the SA cycle and its tooth
        count the mesh order.
    database : path
        Simulated database built for ``machine.gear_pair()`` (``gearshot simulate
        --machine``); its speeds are the mate's speeds (:meth:`Machine.sim_speed`).
    healthy : sequence of path
        Healthy recordings.
    faulty : path
        The faulty recording; its segment ``example_segment`` is the one example (None:
        its most typical, :func:`~gearshot.estimator.example.typical_segment`).
    faulty_size : float
        The example's declared size in (0, 1].
    recordings : sequence of path
        Further recordings to estimate (every segment).
    speed : float, optional
        Tacho-shaft speed of the database condition, Hz (rev/s). Default: the database
        speed nearest to the healthy recordings' tacho speed (their median).
    load : float, optional
        Load of the database slice, N m. Default: the database's only load; with a
        database over several loads, the load whose simulated healthy signals best match
        the healthy recordings (:func:`gearshot.app.load_choice.choose_load`), refused with
        one line when the choice is ambiguous (clarity below
        :data:`~gearshot.app.load_choice.MIN_CLARITY`).
    speed_tolerance : float
        Every recording's tacho speed must lie within this relative distance of the
        condition, else a :class:`~gearshot.GearshotError` names the file, its speed and
        the nearest condition (:data:`~gearshot.app.conditions.SPEED_TOLERANCE`).
    cycles_per_segment : int, optional
        Shaft revolutions per SA segment (default: the machine's).
    sensor : str, optional
        Default: chosen (:mod:`gearshot.app.sensor_choice`: the machine's first sensor,
        or the next whose fit passes its check when the first one's does not).
    holdout : float
        Fraction of each healthy recording's segments (the last ``floor(holdout · n)``)
        kept out of the fit and estimated (``role="healthy_holdout"``); the faulty
        recording's other segments are estimated too (``role="faulty_rest"``; they come
        from the example's record). Both groups check the fit (``fit_check``) and
        calibrate the intervals; a recording too short to give hold-outs leaves the fit
        "unchecked", and its estimates untrusted.
    example_segment, coverage, seed
        Which faulty segment is the example; interval coverage; random state.
    params : dict, optional
        Further :class:`~gearshot.estimator.OneFaultShotEstimator` parameters (its
        ``mesh_order`` and ``random_state`` come from the machine and ``seed``).

    Returns
    -------
    pandas.DataFrame
        ``recording, role, segment, speed_hz, database_speed_hz, database_load,
        load_source, load_clarity, predicted, low, high, below_detection_limit,
        comparability, comparable, input_check, speed_source, speed_uncertainty_hz,
        speed_check, fit_check, trusted``: ``database_load`` the load estimated at (N m;
        ``load_source`` ``given``, ``only`` or ``chosen`` with its ``load_clarity``);
        ``speed_hz`` the recording's and ``database_speed_hz`` the condition's speed (Hz of
        the tacho shaft); ``comparability`` the p-value of
        :meth:`~gearshot.estimator.OneFaultShotEstimator.comparability`; ``speed_check``
        ``ok`` or why a tracked speed is not to be trusted; ``input_check`` ``ok`` or the
        failed check (:mod:`gearshot.io.input_health`; the estimate withdrawn); ``fit_check``
        the fit's verdict; ``trusted`` every check passed
        (:func:`gearshot.estimator.trusted_column`). ``attrs``: the ``fit_check``, the
        condition, the grade, the simulated reference, the ``sensor`` used and
        ``sensor_note`` (why, when not the first).
    """
    est, seg, cond = fit_machine(machine, database, healthy, faulty, faulty_size, recordings,
                                 speed=speed, load=load,
                                 cycles_per_segment=cycles_per_segment, sensor=sensor,
                                 holdout=holdout, example_segment=example_segment, seed=seed,
                                 params=params, speed_tolerance=speed_tolerance)
    frame = _estimates(est, seg, cond, coverage)
    add_trust_columns(frame, est.fit_check_)
    frame.attrs.update(fit_attrs(est, seg.healthy_speeds), sensor=seg.sensor,
                       sensor_note=seg.sensor_note)
    return frame


def fit_machine(machine, database, healthy: Sequence[str | Path], faulty: str | Path | None,
                faulty_size: float | None, recordings: Sequence[str | Path] = (), *,
                speed: float | None = None, load: float | None = None,
                cycles_per_segment: int | None = None, sensor: str | None = None,
                holdout: float = HOLDOUT, example_segment: int | None = None, seed: int = 0,
                params: dict | None = None, speed_tolerance: float = SPEED_TOLERANCE):
    """The fit of :func:`predict_from_machine` (same parameters); ``faulty`` None fits
    zero-shot (``calibration="zero_shot"``). With ``sensor`` None the sensor is chosen
    (:mod:`gearshot.app.sensor_choice`); every file is read once whatever it tries.

    Returns
    -------
    estimator : OneFaultShotEstimator
    segments : _Segments
        Every recording's SA segments by role (``rows``: file, role, segment, speed, SA),
        the ``sensor`` they are of and ``sensor_note`` (why, when not the first).
    condition : _Condition
        The database condition estimated at.
    """
    from ..estimator import OneFaultShotEstimator, default_selection_tf
    from ..io import Recording
    from .sensor_choice import fit_with_sensor_choice

    others = [*([] if faulty is None else [faulty]), *recordings]
    cps = _check_options(machine, healthy, others, cycles_per_segment, holdout)
    database_conditions(database, machine)   # a bad --database fails now
    check_database_pair(database, machine)
    # the machine file must put its mesh orders where the healthy recordings have them
    read = {str(p): Recording.read(p, machine=machine) for p in healthy}   # read once
    verify_machine(machine, list(read.values()))
    read.update((str(p), Recording.read(p, machine=machine)) for p in others)
    # every mesh synchronous with the shaft leaves the difference signal, on both sides
    meshes = list(machine.mesh_orders(machine.monitored.shaft))
    calibration = {} if faulty is not None else {"calibration": "zero_shot"}

    def fit_on(name: str | None):
        seg = _segment_recordings(machine, healthy, faulty, recordings, read=read, cps=cps,
                                  sensor=name, holdout=holdout,
                                  example_segment=example_segment)
        cond = _condition(database, machine, seg, speed=speed, load=load,
                          speed_tolerance=speed_tolerance)
        est = OneFaultShotEstimator(**{**(params or {}), "random_state": seed,
                                       "mesh_order": meshes, **calibration})
        # the database must be of the machine's monitored pair (refused otherwise)
        est.fit(cond.slice, np.vstack(seg.train), seg.example,
                None if faulty is None else faulty_size, seg.long,
                selection_tf=default_selection_tf(seed), gear_teeth=machine.monitored.teeth,
                pinion_teeth=machine.mate()[1], holdout=holdout,
                healthy_recordings=recording_labels(seg.train),
                healthy_holdout=seg.holdout_sas("healthy_holdout"),
                example_record=None if faulty is None else seg.holdout_sas("faulty_rest"))
        return est, seg, cond

    (est, seg, cond), seg_sensor, note = fit_with_sensor_choice(fit_on, machine, sensor)
    seg.sensor, seg.sensor_note = seg_sensor, note
    return est, seg, cond


def _check_options(machine, healthy, others, cycles_per_segment, holdout) -> int:
    """The SA segment length in cycles, after checking the options and the files."""
    cps = machine.cycles_per_segment if cycles_per_segment is None else cycles_per_segment
    if cps is None:
        raise GearshotError("the machine file says cycles_per_segment = 'all'; predict needs "
                            "several segments per record: pass --cycles-per-segment")
    cps = check_int(cps, "cycles_per_segment", minimum=1)
    check_in_range(holdout, "holdout", 0.0, 1.0, high_inclusive=False)
    if not healthy:
        raise GearshotError("--healthy needs at least one recording")
    for p in [*healthy, *others]:
        if not Path(p).is_file():
            raise GearshotError(f"recording {str(p)!r} does not exist")
    return cps


@dataclass
class _Segments:
    """The SA segments of every recording, by role."""

    rows: list = field(default_factory=list)    # (file, role, segment, speed, sa)
    train: list = field(default_factory=list)   # healthy segments of the fit
    long: np.ndarray | None = None              # angle-domain signal for the TF estimate
    example: np.ndarray | None = None           # the faulty example's SA
    speeds: dict = field(default_factory=dict)  # file -> tacho speed, Hz
    healthy_speeds: list = field(default_factory=list)
    healthy_files: list = field(default_factory=list)   # str paths of the healthy recordings
    example_speed: float = float("nan")          # the faulty recording's tacho speed, Hz
    sources: dict = field(default_factory=dict)  # file -> speed_source, uncertainty
    sensor: str = ""                             # the sensor the SAs are of
    sensor_note: str = ""                        # why it is not the machine's first

    def holdout_sas(self, role: str) -> np.ndarray:
        """The SAs of the rows of ``role`` (hold-outs), stacked; (0, n) when none."""
        sas = [r[4] for r in self.rows if r[1] == role]
        n = self.example.size if self.example is not None else 0
        return np.stack(sas) if sas else np.empty((0, n))


def _segment_recordings(machine, healthy, faulty, recordings, *, cps, sensor, holdout,
                        example_segment, read=None) -> _Segments:
    """Cut every recording (``read``: those already read, by path) into SA segments;
    healthy hold-outs, the example, the rest."""
    spc = machine.samples_per_cycle
    seg = _Segments()

    def cut(p):
        sa, x, sp = machine_segments(p, machine, cycles_per_segment=cps, sensor=sensor,
                                     info=seg.sources.setdefault(str(p), {}),
                                     rec=(read or {}).get(str(p)))
        seg.speeds.setdefault(str(p), sp)
        return sa, x, sp

    for p in healthy:
        sa, x, sp = cut(p)
        _require_fit_input(seg.sources[str(p)], p, "healthy")
        seg.healthy_speeds.append(sp)
        seg.healthy_files.append(str(p))
        n_fit = sa.shape[0] - int(np.floor(holdout * sa.shape[0]))
        if n_fit < 1:
            raise GearshotError(f"{str(p)!r}: no segment left for the fit after holdout="
                                f"{holdout}")
        seg.train.append(sa[:n_fit])
        if seg.long is None:
            seg.long = x[: n_fit * cps * spc]  # held-out segments stay out of the TF estimate
        seg.rows.extend((str(p), "healthy_holdout", k, sp, sa[k])
                        for k in range(n_fit, sa.shape[0]))
    if faulty is not None:
        fsa, _, fsp = cut(faulty)
        seg.example_speed = fsp
        _require_fit_input(seg.sources[str(faulty)], faulty, "faulty")
        example_segment = typical_segment(fsa) if example_segment is None else check_int(
            example_segment, "example_segment", minimum=0, maximum=fsa.shape[0] - 1)
        seg.example = fsa[example_segment]
        seg.rows.extend((str(faulty), "faulty_rest", k, fsp, fsa[k])
                        for k in range(fsa.shape[0]) if k != example_segment)
    for p in recordings:
        sa, _, sp = cut(p)
        seg.rows.extend((str(p), "test", k, sp, sa[k]) for k in range(sa.shape[0]))
    return seg


@dataclass
class _Condition:
    """The database condition estimated at, and how its load was found."""

    speed: float                 # tacho-shaft Hz
    load: float                  # N m
    load_source: str             # "given", "only" (the database's one load) or "chosen"
    slice: object = None         # the database slice (xarray.Dataset)
    choice: LoadChoice | None = None


def _condition(database, machine, seg: _Segments, *, speed, load,
               speed_tolerance) -> _Condition:
    """The (speed, load) condition, every recording's speed checked against it: the load
    given, the database's only load, or the load the healthy recordings pick from a
    database over several (refused when the choice is ambiguous)."""
    from ..sim import load_database

    db_speeds, loads = database_conditions(database, machine)
    several = load is None and len(loads) > 1
    cond_speed, cond_load = choose_condition(database, machine, speed=speed,
                                             load=loads[0] if several else load,
                                             measured=seg.healthy_speeds)
    check_speeds(list(seg.speeds.items()), cond_speed, conditions=db_speeds,
                 tolerance=speed_tolerance)
    choice, source = None, "given" if load is not None else "only"
    if several:
        assert seg.long is not None  # at least one healthy recording was cut
        choice = choose_load(database, machine.sim_speed(cond_speed), np.vstack(seg.train),
                             seg.long, mesh_order=machine.monitored.teeth)
        if choice.ambiguous:
            raise GearshotError(
                f"--load is needed: the healthy recordings do not tell the loads of database "
                f"{str(database)!r} apart ({choice.describe()}); give --load, or build the "
                f"database at one nominal load and leave --load out")
        cond_load, source = choice.load, "chosen"
    db = load_database(database, speed=machine.sim_speed(cond_speed), load=cond_load)
    return _Condition(cond_speed, cond_load, source, db, choice)


def _estimates(est, seg: _Segments, cond: _Condition, coverage: float) -> pd.DataFrame:
    """One row per estimated segment, with the condition and how it was found."""
    frame = pd.DataFrame([r[:4] for r in seg.rows],
                         columns=["recording", "role", "segment", "speed_hz"])
    frame["database_speed_hz"] = cond.speed
    frame["database_load"] = cond.load
    frame["load_source"] = cond.load_source
    frame["load_clarity"] = None if cond.choice is None else cond.choice.clarity
    if seg.rows:
        from ..estimator import below_detection_limit

        sas = np.stack([r[4] for r in seg.rows])
        low, high = est.predict_interval(sas, coverage=coverage)
        frame["predicted"] = est.predict(sas)
        frame["low"], frame["high"] = low, high
        frame["below_detection_limit"] = below_detection_limit(est, frame["predicted"])
        frame["comparability"], frame["comparable"] = _comparability_columns(est, sas)
    frame.attrs["speed_hz"], frame.attrs["load"] = cond.speed, cond.load
    frame.attrs["load_source"] = cond.load_source
    frame.attrs["load_choice"] = None if cond.choice is None else cond.choice.as_dict()
    frame.attrs["load_note"] = "" if cond.choice is None else f" ({cond.choice.describe()})"
    mark_rows(frame, [input_check_column(seg.sources[r]["recording"],
                                         seg.sources[r]["segments"], [k])[0]
                      for r, k in zip(frame["recording"], frame["segment"])])
    frame["speed_source"] = [seg.sources[r]["speed_source"] for r in frame["recording"]]
    frame["speed_uncertainty_hz"] = [seg.sources[r]["speed_uncertainty_hz"]
                                     for r in frame["recording"]]
    refs = [seg.sources[f].get("path") for f in seg.healthy_files]
    checks = {r: fit_recording_checks(seg.speeds[r], seg.sources[r].get("path"),
                                      seg.healthy_speeds, refs, example_speed=seg.example_speed,
                                      tracked=seg.sources[r]["speed_check"])
              for r in set(frame["recording"])}
    frame["speed_check"] = frame["recording"].map({r: c[0] for r, c in checks.items()})
    frame["path_check"] = frame["recording"].map({r: c[1] for r, c in checks.items()})
    return frame
