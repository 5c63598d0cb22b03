"""Fit and predict on a real machine: SA segments of the monitored gear's shaft, through a
machine description (gear train, tacho, sensors, file layout)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from .._errors import GearshotError
from .._validation import check_in_range, check_int
from .conditions import SPEED_TOLERANCE, check_speeds, choose_condition, database_conditions

__all__ = ["machine_segments", "predict_from_machine", "machine_database_path"]


def machine_database_path(machine_file: str | Path, *, n_healthy: int, n_faulty: int,
                          seed: int, paired: bool = True) -> Path:
    """Default store of ``gearshot simulate --machine FILE``."""
    from ..sim import default_database_path

    return default_database_path(f"machine-{Path(machine_file).stem}-h{n_healthy}-"
                                 f"f{n_faulty}-s{seed}" + ("-paired" if paired else ""))


def machine_segments(path: str | Path, machine, *, cycles_per_segment: int,
                     sensor: str | None = None, info: dict | None = None
                     ) -> tuple[np.ndarray, np.ndarray, float]:
    """SA segments of the monitored gear's shaft for one recording file.

    ``info``, when given, receives ``speed_source`` (``"tacho"`` or ``"vibration"``: a
    machine without ``[tacho]``) and ``speed_uncertainty_hz`` (rev/s of the reference
    shaft, ``None`` with a tacho).

    Returns
    -------
    sa : ndarray, shape (n_segments, samples_per_cycle)
    x : ndarray, shape (n_cycles * samples_per_cycle,)
        The whole angle-domain signal (whole cycles from the first pulse).
    speed : float
        Tacho-shaft speed read from the tacho, rev/s.
    """
    from ..io import Recording

    if machine.monitored is None:
        raise GearshotError(f"machine {machine.name!r} names no [monitored] gear")
    rec = Recording.read(path, machine=machine)
    name = machine.sensor(sensor).name
    spc = machine.samples_per_cycle
    x = rec.angle_domain(shaft=machine.monitored.shaft, sensor=name, samples_per_cycle=spc,
                         antialias=machine.antialias)
    n_cycles = x.size // spc
    n_seg = n_cycles // cycles_per_segment
    if n_seg < 1:
        raise GearshotError(f"{str(path)!r} holds {n_cycles} revolution(s) of shaft "
                            f"{machine.monitored.shaft!r}; --cycles-per-segment="
                            f"{cycles_per_segment} is too many")
    blocks = x[: n_seg * cycles_per_segment * spc].reshape(n_seg, cycles_per_segment, spc)
    if info is not None:
        info.update(speed_source=rec.speed_source, speed_uncertainty_hz=rec.speed_uncertainty)
    return blocks.mean(axis=1), x, rec.shaft_speed()


def _comparability_columns(est, sas) -> tuple[np.ndarray, np.ndarray]:
    """The ``comparability`` (score) and ``comparable`` columns of a predict table."""
    result = est.comparability(sas)
    return result.score, result.comparable


def predict_from_machine(machine, database, healthy: Sequence[str | Path],
                         faulty: str | Path, faulty_size: float,
                         recordings: Sequence[str | Path] = (), *,
                         speed: float | None = None, load: float | None = None,
                         cycles_per_segment: int | None = None, sensor: str | None = None,
                         holdout: float = 0.25, example_segment: int = 0,
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
        The faulty recording; its segment ``example_segment`` is the one example.
    faulty_size : float
        The example's declared size in (0, 1].
    recordings : sequence of path
        Further recordings to estimate (every segment).
    speed : float, optional
        Tacho-shaft speed of the database condition, Hz (rev/s). Default: the database
        speed nearest to the healthy recordings' tacho speed (their median).
    load : float, optional
        Load of the database slice, N m. Default: the database's only load (an
        unquantified load: build the database at one load, see
        :mod:`gearshot.app.conditions`).
    speed_tolerance : float
        Every recording's tacho speed must lie within this relative distance of the
        condition, else a :class:`~gearshot.GearshotError` names the file, its speed and
        the nearest condition (:data:`~gearshot.app.conditions.SPEED_TOLERANCE`).
    cycles_per_segment : int, optional
        Shaft revolutions per SA segment (default: the machine's).
    sensor : str, optional
        Default: the machine's first sensor.
    holdout : float
        Fraction of each healthy recording's segments (the last ones) kept out of the fit
        and estimated (``role="healthy_holdout"``); the faulty recording's other segments
        are estimated too (``role="faulty_rest"``; they come from the example's record).
    example_segment, coverage, seed
        Which faulty segment is the example; interval coverage; random state.
    params : dict, optional
        Further :class:`~gearshot.estimator.OneFaultShotEstimator` parameters (its
        ``mesh_order`` and ``random_state`` come from the machine and ``seed``).

    Returns
    -------
    pandas.DataFrame
        ``recording, role, segment, speed_hz, database_speed_hz, predicted, low, high,
        comparability, comparable, speed_source, speed_uncertainty_hz`` (``speed_hz``: the
        recording's reference-shaft speed; ``database_speed_hz``: the condition it is
        estimated at, both in Hz of the tacho (reference) shaft;
        ``comparability``/``comparable``: the score of
        :meth:`~gearshot.estimator.OneFaultShotEstimator.comparability` and whether the
        segment looks like the fitted machine; ``speed_source``: ``tacho`` or
        ``vibration``, with the standard uncertainty of the instantaneous speed, rev/s, for
        ``vibration``); ``attrs`` hold the condition (``speed_hz``, ``load``), the grade and
        the simulated reference.
    """
    from ..estimator import OneFaultShotEstimator, default_selection_tf
    from ..sim import load_database

    cps = machine.cycles_per_segment if cycles_per_segment is None else cycles_per_segment
    if cps is None:
        raise GearshotError("the machine file says cycles_per_segment = 'all'; predict needs "
                            "several segments per record: pass --cycles-per-segment")
    cps = check_int(cps, "cycles_per_segment", minimum=1)
    holdout = check_in_range(holdout, "holdout", 0.0, 1.0, high_inclusive=False)
    spc = machine.samples_per_cycle
    if not healthy:
        raise GearshotError("--healthy needs at least one recording")
    for p in [*healthy, faulty, *recordings]:
        if not Path(p).is_file():
            raise GearshotError(f"recording {str(p)!r} does not exist")
    db_speeds, _ = database_conditions(database, machine)   # a bad --database fails now
    rows = []
    sources: dict[str, dict] = {}
    train, long = [], None
    speeds: dict[str, float] = {}
    for p in healthy:
        sa, x, sp = machine_segments(p, machine, cycles_per_segment=cps, sensor=sensor,
                                     info=sources.setdefault(str(p), {}))
        speeds[str(p)] = sp
        n_hold = int(np.floor(holdout * sa.shape[0]))
        n_fit = sa.shape[0] - n_hold
        if n_fit < 1:
            raise GearshotError(f"{str(p)!r}: no segment left for the fit after holdout="
                                f"{holdout}")
        train.append(sa[:n_fit])
        if long is None:
            long = x[: n_fit * cps * spc]  # held-out segments stay out of the TF estimate
        for k in range(n_fit, sa.shape[0]):
            rows.append((str(p), "healthy_holdout", k, sp, sa[k]))
    fsa, _, fsp = machine_segments(faulty, machine, cycles_per_segment=cps, sensor=sensor,
                                   info=sources.setdefault(str(faulty), {}))
    speeds.setdefault(str(faulty), fsp)
    example_segment = check_int(example_segment, "example_segment", minimum=0,
                                maximum=fsa.shape[0] - 1)
    for k in range(fsa.shape[0]):
        if k != example_segment:
            rows.append((str(faulty), "faulty_rest", k, fsp, fsa[k]))
    for p in recordings:
        sa, _, sp = machine_segments(p, machine, cycles_per_segment=cps, sensor=sensor,
                                     info=sources.setdefault(str(p), {}))
        speeds.setdefault(str(p), sp)
        rows.extend((str(p), "test", k, sp, sa[k]) for k in range(sa.shape[0]))
    cond_speed, cond_load = choose_condition(database, machine, speed=speed, load=load,
                                             measured=[speeds[str(p)] for p in healthy])
    check_speeds(list(speeds.items()), cond_speed, conditions=db_speeds,
                 tolerance=speed_tolerance)
    db = load_database(database, speed=machine.sim_speed(cond_speed), load=cond_load)
    # every mesh synchronous with the shaft leaves the difference signal (the second stage's
    # too), on the simulated side as on the recorded one
    meshes = list(machine.mesh_orders(machine.monitored.shaft))
    est = OneFaultShotEstimator(**{**(params or {}), "random_state": seed,
                                   "mesh_order": meshes})
    est.fit(db, np.vstack(train), fsa[example_segment], faulty_size, long,
            selection_tf=default_selection_tf(seed))
    frame = pd.DataFrame([r[:4] for r in rows],
                         columns=["recording", "role", "segment", "speed_hz"])
    frame["database_speed_hz"] = cond_speed
    if rows:
        sas = np.stack([r[4] for r in rows])
        low, high = est.predict_interval(sas, coverage=coverage)
        frame["predicted"] = est.predict(sas)
        frame["low"], frame["high"] = low, high
        frame["comparability"], frame["comparable"] = _comparability_columns(est, sas)
    frame.attrs["speed_hz"], frame.attrs["load"] = cond_speed, cond_load
    frame["speed_source"] = [sources[r]["speed_source"] for r in frame["recording"]]
    frame["speed_uncertainty_hz"] = [sources[r]["speed_uncertainty_hz"]
                                     for r in frame["recording"]]
    frame.attrs["grade"] = getattr(est, "grade_", None)
    frame.attrs["simulated_reference"] = getattr(est, "simulated_reference_", None)
    return frame
