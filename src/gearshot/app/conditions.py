"""Operating conditions in the user's terms: the database's speeds as tacho-shaft speeds,
every recording's tacho speed checked against the condition it is estimated at.

A simulated database of a machine stores the speed of the monitored gear's mate (the
simulator's input, :meth:`gearshot.Machine.sim_speed`); a user types and reads the
speed of the shaft the tacho watches, in Hz (revolutions per second). Everything here
speaks tacho-shaft Hz.

Speed tolerance
---------------
:data:`SPEED_TOLERANCE` (5 %): a recording whose tacho speed lies further than this from
the database's condition is refused, with one line naming the file, its speed, the nearest
condition and the tolerance. The PHM 2009 gearbox, for one, runs 0-3 % below its nominal
speed under load (its README: 0.97-1.00 x nominal), so 5 % accepts a record at its
nominal condition and refuses one at the next 5 Hz step (35 Hz against a 30 or 40 Hz
database: 12-14 %). Within the tolerance the record is estimated; its own tacho speed
and the condition are both in the output (``speed_hz``, ``database_speed_hz``).

The fit's own speeds
--------------------
Within the gate, a recording is estimated but not trusted (the ``speed_check`` column,
and ``comparable`` false) when its speed lies outside the speeds of the fit's own
recordings (healthy and the faulty example) by more than their run-to-run spread allows
(:func:`fit_speed_check`): further than :data:`RUN_SPEED_SPREADS` of their relative
standard deviations beyond their range, and at least :data:`RUN_SPEED_FLOOR` beyond it;
with fewer than 3 healthy recordings (no spread of runs to go by), further than
:data:`RUN_SPEED_FLOOR` from every one of the fit's recordings.
A machine's speed tells its operating condition: a motor's slip (or its drive's
response) changes with the load, so another load runs at another speed; the PHM 2009
gearbox runs about 1.5 % slower at its "Low" load than at "High" at every case and speed
(30 Hz: High 29.89-29.92 Hz, Low 29.41-29.72 Hz), while a run recorded again at the same
condition lies within 0.07 % of the first (the chipped gear's Low records: 0.65 %: run 2
of the Low condition is not trusted under a fit on run 1, whose healthy baseline drifts
anyway, :mod:`gearshot.estimator.drift`). When 3 or more healthy recordings ran within 0.2 %
of one speed (recorded as one run: ``gearshot fit``'s one-run warning), their speeds
cannot show how far a later run's moves, and the bound is :data:`SPEED_TOLERANCE`: a
virtual rig's fit campaign recorded at one set-point must not untrust the life it
watches, whose runs vary 1 %. Measured on the PHM09 spur records (the README database, a
30 Hz High fit, ``--speed-tolerance 0.5``): the healthy gear's 40 Hz run-2 record read
0.77 with 8 of its 15 segments comparable; under the README journey's High fit the
chipped gear's Low record read 0.73 [0.52, 1.00], comparable: both are refused trust now.

Load
----
A database slice is one (speed, load) condition. When the load is not quantified (the PHM
2009 records say only High / Low), build the database at one nominal load and leave
``--load`` out: the database's only load is used and reported. With ``--machine``, a
database over several loads lets the healthy recordings choose
(:mod:`gearshot.app.load_choice`, refused when ambiguous); elsewhere it needs ``--load``,
and the error lists them.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .._errors import GearshotError

__all__ = ["SPEED_TOLERANCE", "RUN_SPEED_FLOOR", "RUN_SPEED_SPREADS", "PATH_MIN_CORRELATION",
           "fit_path_check", "database_conditions",
           "choose_condition", "check_speeds", "check_database_pair", "fit_speed_check",
           "fit_recording_checks"]

#: Largest relative distance between a recording's tacho speed and the database condition
SPEED_TOLERANCE = 0.05

#: Smallest relative distance beyond the fit's recordings' speeds that fails
#: :func:`fit_speed_check` (unless its healthy recordings ran as one run): above what
#: the supply frequency moves a mains-fed motor (about ±0.2 %: ±0.1 Hz on 50 Hz) and the
#: 0.07 % between two runs of one PHM09 condition, below the 0.58 % of the nearest other
#: load (chosen on the 30 Hz PHM09 records, ``benchmarks/comparability_matrix.py``).
RUN_SPEED_FLOOR = 0.003

#: Relative standard deviations of the fit's recordings' speeds beyond their range that
#: fail :func:`fit_speed_check` when their spread is wider than the floor: a spread from a
#: handful of runs is itself uncertain (chosen on the development lives of
#: ``benchmarks/monitor_lives.py``, speeds varying 1 % run to run: 3, 4, 5 and 6 leave
#: 9, 5, 4 and 1 of 680 ordinary recordings untrusted).
RUN_SPEED_SPREADS = 6.0


def database_conditions(store: str | Path, machine=None) -> tuple[list[float], list[float]]:
    """The (speeds, loads) of a database; speeds as tacho-shaft Hz with ``machine``.

    Raises
    ------
    GearshotError
        ``store`` is not a gearshot database (no readable ``manifest.json``).
    """
    path = Path(store) / "manifest.json"
    try:
        man = json.loads(path.read_text())
        speeds, loads = [float(s) for s in man["speeds"]], [float(x) for x in man["loads"]]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        what = "does not exist" if not Path(store).exists() else \
            f"is not a gearshot database ({type(exc).__name__}: {exc})"
        raise GearshotError(f"--database {str(store)!r} {what}") from None
    if machine is not None:
        ratio = machine.sim_speed(1.0)
        speeds = [s / ratio for s in speeds]
    return speeds, loads


def _fmt(values: Sequence[float]) -> str:
    return "[" + ", ".join(f"{v:.4g}" for v in values) + "]"


def choose_condition(store: str | Path, machine, *, speed: float | None,
                     load: float | None, measured: Sequence[float]) -> tuple[float, float]:
    """The database condition (tacho-shaft Hz, load) to estimate at.

    Parameters
    ----------
    store : path
        The database.
    machine : gearshot.Machine or None
        Speeds are tacho-shaft Hz with a machine, the database's own unit without.
    speed : float or None
        What the user typed; None: the condition nearest to the median of ``measured``.
    load : float or None
        What the user typed; None: the database's only load.
    measured : sequence of float
        Tacho speeds of the healthy recordings (used when ``speed`` is None).
    """
    speeds, loads = database_conditions(store, machine)
    unit = "Hz (tacho shaft)" if machine is not None else "rps"
    if speed is None:
        if not measured:
            raise GearshotError("--speed is needed: no recording to read the speed from")
        mid = sorted(measured)[len(measured) // 2]
        speed = min(speeds, key=lambda s: abs(s - mid))
    else:
        match = [s for s in speeds if abs(s - speed) <= 1e-6 * max(1.0, abs(speed))]
        if not match:
            raise GearshotError(f"--speed {speed:g} is not a condition of database "
                                f"{str(store)!r}: it holds {_fmt(speeds)} {unit}")
        speed = match[0]
    if load is None:
        if len(loads) != 1:
            raise GearshotError(f"--load is needed: database {str(store)!r} holds loads "
                                f"{_fmt(loads)} N m (an unquantified load: build the "
                                f"database at one load and leave --load out)")
        load = loads[0]
    elif not any(abs(x - load) <= 1e-9 * max(1.0, abs(load)) for x in loads):
        raise GearshotError(f"--load {load:g} is not a condition of database "
                            f"{str(store)!r}: it holds {_fmt(loads)} N m")
    return float(speed), float(load)


def check_speeds(measured: Sequence[tuple[str, float]], condition: float, *,
                 conditions: Sequence[float] = (),
                 tolerance: float = SPEED_TOLERANCE) -> None:
    """Refuse a recording whose tacho speed is further than ``tolerance`` from
    ``condition``.

    Parameters
    ----------
    measured : sequence of (file, tacho speed in Hz)
    condition : float
        The database condition the records are estimated at, tacho-shaft Hz.
    conditions : sequence of float
        Every speed of the database (the nearest is named in the error).
    tolerance : float
        Relative; :data:`SPEED_TOLERANCE` by default.
    """
    for name, hz in measured:
        off = abs(hz - condition) / condition
        if off > tolerance:
            nearest = min([*conditions, condition], key=lambda s: abs(s - hz))
            raise GearshotError(
                f"recording {name!r}: its tacho reads {hz:.4g} Hz, {100 * off:.0f} % from the "
                f"database condition {condition:.4g} Hz (nearest condition {nearest:.4g} Hz, "
                f"tolerance {100 * tolerance:.0f} %); estimate it against a database "
                f"simulated at its speed (gearshot simulate --machine ... --speed "
                f"{round(hz):d})")


def check_database_pair(database: str | Path, machine) -> None:
    """Refuse a database simulated for another pair than the machine's monitored pair.

    Teeth, module, face width, pressure angle and helix angle of the store's pair
    (its manifest) must be those of :meth:`gearshot.Machine.gear_pair` (which itself
    refuses a helical stage without its helix angle). A store whose manifest holds no
    readable pair is left to the estimator's tooth check.
    """
    from ..sim._db_manifest import pair_from_manifest, read_manifest

    want = machine.gear_pair()
    have = pair_from_manifest(read_manifest(Path(database)))
    if have is None:
        return
    diffs = []
    for name, unit, scale in (("z_pinion", "", 1.0), ("z_gear", "", 1.0),
                              ("module", " mm", 1e3), ("face_width", " mm", 1e3),
                              ("pressure_angle", " deg", 180 / np.pi),
                              ("helix_angle", " deg", 180 / np.pi)):
        a, b = float(getattr(have, name)), float(getattr(want, name))
        if not np.isclose(a, b, rtol=1e-9, atol=1e-12):
            diffs.append(f"{name} {a * scale:g}{unit} in the database, {b * scale:g}{unit} "
                         f"in the machine")
    if diffs:
        raise GearshotError(f"--database {str(database)!r} was simulated for another pair than "
                            f"the monitored pair of machine {machine.name!r}: "
                            f"{'; '.join(diffs)}; build it with gearshot simulate --machine")


def fit_speed_check(speed: float, healthy_speeds: Sequence[float], *,
                    example_speed: float | None = None, unit: str = "Hz") -> str:
    """``"ok"``, or why a recording's speed is outside what the fit has seen: beyond the
    range of the fit's recordings' speeds (``healthy_speeds`` and the faulty example's
    ``example_speed``) by more than :data:`RUN_SPEED_SPREADS` of their relative standard
    deviations, and at least :data:`RUN_SPEED_FLOOR` (relative to their mean). When 3 or
    more healthy recordings ran within
    :data:`~gearshot.monitor.trust.ONE_RUN_SPREAD` of one speed (recorded as one run:
    the one-run warning of ``gearshot fit``), their speeds say nothing of how far a later
    run's moves, and the bound is the database gate's :data:`SPEED_TOLERANCE` instead.
    With fewer than 3 healthy recordings (:data:`~gearshot.monitor.trust.SPREAD_RECORDINGS`)
    there is no spread of runs to go by, and the recording must lie within
    :data:`RUN_SPEED_FLOOR` of one of the fit's recordings' speeds: the target side
    subtracts healthy references recorded at those speeds, and on the virtual rig a
    healthy recording of another run 0.6-1.9 % off them read 0.24-0.30 on average with
    its regular part comparable (one-recording fits, rig seeds 201-216:
    ``benchmarks/run_spread.py``), while within 0.3 % none read above 0.10. Unknown
    speeds (NaN) pass. ``unit`` names the speeds' unit in the reason ("Hz" of the tacho
    shaft with a machine file, "rev/s" without).

    >>> fit_speed_check(29.90, [29.92, 29.89])
    'ok'
    >>> fit_speed_check(29.72, [29.92], example_speed=29.89)
    "speed 29.72 Hz lies 0.57 % outside the fit's recordings' 29.89-29.92 Hz (another load?)"
    >>> fit_speed_check(14.6, [15.1, 14.9, 15.0, 14.85, 15.15])   # runs vary 0.8 %
    'ok'
    >>> fit_speed_check(14.6, [15.0, 15.001, 14.999])   # one run: the gate's 5 %
    'ok'
    >>> fit_speed_check(15.08, [15.16], example_speed=14.98)   # between, near neither
    "speed 15.08 Hz lies 0.53 % outside the fit's recordings' 14.98, 15.16 Hz (another load?)"
    """
    from ..monitor.trust import OUTSIDE_FIT_SPEEDS, SPREAD_RECORDINGS, one_run_warning

    healthy = np.asarray([h for h in healthy_speeds if np.isfinite(h)], dtype=float)
    known = np.append(healthy, [] if example_speed is None or not np.isfinite(example_speed)
                      else [float(example_speed)])
    if not known.size or not np.isfinite(speed):
        return "ok"
    lo, hi, mean = float(known.min()), float(known.max()), float(known.mean())
    if healthy.size < SPREAD_RECORDINGS:
        # no run-to-run spread to go by: the nearest recording's speed, within the floor
        off = float(np.min(np.abs(known - speed))) / mean
        if off <= RUN_SPEED_FLOOR:
            return "ok"
        seen = (f"{lo:.2f}-{hi:.2f}" if not lo < speed < hi
                else ", ".join(f"{v:.2f}" for v in np.unique(np.round(known, 2))))
    else:
        spread = float(known.std(ddof=1)) / mean
        one_run = one_run_warning(healthy) is not None   # no run-to-run spread in them
        tolerance = (SPEED_TOLERANCE if one_run
                     else max(RUN_SPEED_FLOOR, RUN_SPEED_SPREADS * spread))
        off = max(lo - speed, speed - hi, 0.0) / mean
        if off <= tolerance:
            return "ok"
        seen = f"{lo:.2f}-{hi:.2f}"
    hint = " (another load?)" if off < SPEED_TOLERANCE else ""
    return (f"speed {speed:.2f} {unit} lies {100 * off:.2g} % {OUTSIDE_FIT_SPEEDS} "
            f"{seen} {unit}{hint}")


#: Lowest correlation of a recording's resonance pattern
#: (:func:`gearshot.signal.path_pattern.path_pattern`) with the fit's healthy
#: recordings' mean pattern for the recording to count as heard through the fit's
#: transfer path (:func:`fit_path_check`). Chosen on the development lives of
#: ``benchmarks/monitor_lives.py`` (rig seeds 1-10, 51-60: the remounted sensor's 60
#: recordings correlate −0.32 to 0.62, median 0.14; the 680 ordinary recordings, faults
#: up to 0.9 included, 0.67 to 1.00): 0.5 flags 57 of the 60 and none of the 680, with a
#: margin below the largest faults, whose impacts reshape the background most (0.6 would
#: catch one more, 0.07 above the lowest fault). PHM09 (30 Hz, development): the same
#: sensor's second run correlates 0.99, the chipped gear's build 0.75-0.87
#: (benchmarks/RESULTS.md "Trust: another transfer path").
PATH_MIN_CORRELATION = 0.5


def fit_path_check(pattern, healthy_patterns: Sequence) -> str:
    """``"ok"``, or why a recording was not heard through the fit's transfer path: its
    resonance pattern correlates below :data:`PATH_MIN_CORRELATION` with the mean pattern
    of the fit's healthy recordings (:func:`gearshot.signal.path_pattern.
    pattern_correlation`: the sensor moved, another sensor, another gearbox). A fault
    changes what the gears excite, not where the path resonates. Unknown patterns
    (None, or too few grid points shared) pass.

    >>> import numpy as np
    >>> grid = np.linspace(0, 12, 200)
    >>> fit_path_check(np.sin(grid) + 0.1 * np.cos(5 * grid), [np.sin(grid)])
    'ok'
    >>> fit_path_check(np.cos(1.7 * grid), [np.sin(grid)])[:64]
    "resonance pattern correlates -0.17 with the fit's healthy record"
    """
    from ..monitor.trust import OTHER_PATH
    from ..signal.path_pattern import pattern_correlation

    refs = [p for p in healthy_patterns if p is not None]
    if pattern is None or not refs:
        return "ok"
    r = pattern_correlation(pattern, refs)
    if not np.isfinite(r) or r >= PATH_MIN_CORRELATION:
        return "ok"
    return (f"resonance pattern correlates {r:.2f} with the fit's healthy recordings' (at "
            f"least {PATH_MIN_CORRELATION:g}): {OTHER_PATH} (sensor moved, another sensor "
            f"or gearbox?)")


def fit_recording_checks(speed: float, pattern: object, healthy_speeds: Sequence[float],
                         healthy_patterns: Sequence, *, example_speed: float | None = None,
                         unit: str = "Hz", tracked: str = "ok") -> tuple[str, str]:
    """One recording's ``speed_check`` and ``path_check`` against a fit's recordings:
    ``tracked`` (the check of a speed tracked from the vibration,
    :func:`gearshot.machine.signal_check.speed_check`) when it failed, else
    :func:`fit_speed_check` of ``speed``; and :func:`fit_path_check` of ``pattern``
    (``gearshot predict --machine`` writes both columns, ``gearshot monitor`` the first
    that fails in the recording's note).

    >>> fit_recording_checks(30.0, None, [29.9, 30.0], [])
    ('ok', 'ok')
    """
    if tracked == "ok":
        tracked = fit_speed_check(speed, healthy_speeds, example_speed=example_speed,
                                  unit=unit)
    return tracked, fit_path_check(pattern, healthy_patterns)
