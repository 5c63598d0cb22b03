"""A machine's life on the virtual rig: recordings over time while a fault grows.

:func:`record_history` (``VirtualRig.history``) records one machine at regular times: the
gear runs healthy for the first ``onset`` share of its life, then the fault grows by a
stated law (:func:`growth_size`) past ``end_size``. Every recording is its own run
(its own repetition seed: start position, drift, noise), the run-to-run speed and load
vary a little, and two episodes break the routine partway:

``load_change``
    ``(fraction, count, load)``: from that share of the life, ``count`` recordings are made
    at another load (the operator ran the machine harder or lighter), then the nominal
    load comes back.
``remount``
    ``(fraction, count)``: from that share of the life, ``count`` recordings are made with
    the sensor remounted on another spot (another transfer path and attenuation), then it
    is put back on its own mount.

The folder receives the recordings (native HDF5) and ``index.csv`` with columns ``file``,
``time`` (ISO 8601), ``size`` (the true fault size), ``event`` (``""``,
``"load_change"`` or ``"remount"``) and the run's set-points ``speed`` (rev/s) and
``load`` (N m), as a machine's log would give them; everything is staged and moved
into place only when every recording succeeded (index last).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .._atomic import atomic_path, check_writable, commit_staged, staging_dir
from .._errors import GearshotError
from .._validation import check_in_range, check_int, check_load, check_positive, check_speed

__all__ = ["record_history", "growth_size", "first_crossing", "LAWS", "HISTORY_COLUMNS"]

#: Growth laws of :func:`growth_size`.
LAWS = ("linear", "exponential", "power")
#: Columns of a history folder's ``index.csv``.
HISTORY_COLUMNS = ["file", "time", "size", "event", "speed", "load"]


def growth_size(life: np.ndarray, *, onset: float, end_size: float, law: str = "power",
                exponent: float = 2.0, rate: float = 3.0) -> np.ndarray:
    """True fault size along a life.

    Parameters
    ----------
    life : ndarray
        Share of the life elapsed, in [0, 1].
    onset : float in [0, 1)
        Share of the life the gear runs healthy (size 0).
    end_size : float in (0, 1]
        Size at the end of the life.
    law : {"linear", "exponential", "power"}
        With ``v = (life - onset) / (1 - onset)`` the share of the growth phase elapsed:
        linear ``end_size * v``; exponential ``end_size * (exp(rate v) - 1) / (exp(rate) -
        1)``; power (Paris-like) ``end_size * v ** exponent``.

    Returns
    -------
    ndarray
        Sizes, 0 before the onset.
    """
    if law not in LAWS:
        raise GearshotError(f"law must be one of {LAWS}; got {law!r}")
    onset = check_in_range(onset, "onset", 0.0, 1.0, high_inclusive=False)
    end_size = check_in_range(end_size, "end_size", 0.0, 1.0, low_inclusive=False)
    exponent = check_positive(exponent, "exponent")
    rate = check_positive(rate, "rate")
    v = np.clip((np.asarray(life, float) - onset) / (1.0 - onset), 0.0, 1.0)
    if law == "linear":
        g = v
    elif law == "exponential":
        g = np.expm1(rate * v) / np.expm1(rate)
    else:
        g = v ** exponent
    return end_size * g


def first_crossing(times: np.ndarray, sizes: np.ndarray, level: float) -> float | None:
    """When a life's true size first reaches ``level``: linear between the recordings
    (``times`` in any unit, e.g. days), the first time itself when it starts there, None
    when it never does. What the monitoring benchmarks score an alarm and a forecast
    against.

    >>> first_crossing(np.array([0.0, 1.0, 2.0]), np.array([0.0, 0.4, 0.8]), 0.6)
    1.5
    """
    t = np.asarray(times, dtype=float)
    y = np.asarray(sizes, dtype=float)
    above = np.nonzero(y >= level)[0]
    if not above.size:
        return None
    i = int(above[0])
    if i == 0:
        return float(t[0])
    return float(t[i - 1] + (level - y[i - 1]) / (y[i] - y[i - 1]) * (t[i] - t[i - 1]))


def _episode(value, name: str, n: int, *, with_load: bool) -> tuple[int, int, float | None]:
    """(first recording, count, load) of an episode given as shares of the life."""
    if value is None:
        return 0, 0, None
    parts = tuple(value)
    if len(parts) != (3 if with_load else 2):
        form = "(fraction, count, load)" if with_load else "(fraction, count)"
        raise GearshotError(f"{name} must be {form} or None; got {value!r}")
    frac = check_in_range(parts[0], f"{name}[0] (fraction)", 0.0, 1.0, high_inclusive=False)
    count = check_int(parts[1], f"{name}[1] (count)", minimum=0)
    load = check_load(parts[2], f"{name}[2] (load)") if with_load else None
    return int(round(frac * n)), count, load


def record_history(rig: Any, folder: str | os.PathLike, *, speed: float = 15.0,
                   load: float = 10.0, n_recordings: int = 40, duration: float = 16.0,
                   start: str = "2026-01-05T08:00:00", interval_hours: float = 24.0,
                   onset: float = 0.3, end_size: float = 0.8, law: str = "power",
                   exponent: float = 1.5, rate: float = 3.0, variation: float = 0.01,
                   load_change: tuple | None = (0.15, 3, 5.0),
                   remount: tuple | None = (0.8, 3),
                   dtype: str = "float32", progress: bool = True) -> pd.DataFrame:
    """Record a machine's life into ``folder`` (see the module docstring).

    Parameters
    ----------
    rig : VirtualRig
        The rig (this module is imported by :mod:`.virtual`, so it names the type only
        here).
    folder : path
        Created; its recordings ``life_NNN.h5`` and ``index.csv`` are replaced.
    speed, load : float
        Nominal input speed (rev/s) and load (N m).
    n_recordings : int
        Recordings over the life (one every ``interval_hours``).
    duration : float
        Seconds per recording (16 s at 15 rev/s: two SA segments of 50 gear revolutions).
    start : str
        ISO 8601 time of the first recording.
    interval_hours : float
        Nominal time between recordings; each is made up to ±10 % of it off schedule.
    onset, end_size, law, exponent, rate
        The fault's growth (:func:`growth_size`); the size is taken at the recording's
        actual time.
    variation : float
        Relative run-to-run spread (standard deviation) of the speed and the load.
    load_change : (fraction, count, load) or None
    remount : (fraction, count) or None
        The episodes (module docstring).

    Returns
    -------
    pandas.DataFrame
        The index (``file``, ``time``, ``size``, ``event``, ``speed``, ``load``).
    """
    from .._progress import track

    folder = Path(folder)
    speed = check_speed(speed)
    load = check_load(load)
    n = check_int(n_recordings, "n_recordings", minimum=2, maximum=10_000)
    duration = check_positive(duration, "duration")
    interval = check_positive(interval_hours, "interval_hours")
    variation = check_in_range(variation, "variation", 0.0, 0.1)
    try:
        t0 = pd.Timestamp(start)
    except (ValueError, TypeError):
        raise GearshotError(f"start must be an ISO 8601 time; got {start!r}") from None
    lc_first, lc_count, lc_load = _episode(load_change, "load_change", n, with_load=True)
    rm_first, rm_count, _ = _episode(remount, "remount", n, with_load=False)
    rng = np.random.default_rng([int(rig.seed), 41])
    hours = interval * (np.arange(n) + rng.uniform(-0.1, 0.1, n))
    hours -= hours[0]
    sizes = growth_size(hours / hours[-1], onset=onset, end_size=end_size, law=law,
                        exponent=exponent, rate=rate)
    speeds = speed * (1.0 + variation * rng.standard_normal(n))
    loads = load * (1.0 + variation * rng.standard_normal(n))
    events = [""] * n
    for i in range(lc_first, min(lc_first + lc_count, n)):
        events[i] = "load_change"
        loads[i] = float(lc_load or load) * (1.0 + variation * rng.standard_normal())
    reality = rig.reveal()
    n_tfs = 8 if rig.tf_bank is None else None
    remounted = None
    if rm_count:
        from .path import as_tf_list

        n_tfs = n_tfs or len(as_tf_list(rig.tf_bank))
        att = reality.attenuation_db
        remounted = rig.with_reality(tf_index=(reality.tf_index + 1) % n_tfs,
                                     attenuation_db=att - 6.0 if att > 16.0 else att + 6.0)
    for i in range(rm_first, min(rm_first + rm_count, n)):
        events[i] = "remount"
    check_writable(folder, "folder", folder=True)
    rows = []
    with staging_dir(folder) as staging:
        for i in track(range(n), f"life of rig {rig.seed}", enabled=progress):
            source = remounted if events[i] == "remount" and remounted is not None else rig
            rec = source.record(speed=float(speeds[i]), load=float(loads[i]),
                                fault_size=float(sizes[i]), duration=duration,
                                repetition=i)
            name = f"life_{i:03d}.h5"
            rec.write(staging / name, dtype=dtype)
            time = (t0 + pd.Timedelta(hours=float(hours[i]))).floor("s")
            rows.append({"file": name, "time": time.isoformat(), "size": float(sizes[i]),
                         "event": events[i], "speed": round(float(speeds[i]), 3),
                         "load": round(float(loads[i]), 3)})
        index = pd.DataFrame(rows, columns=HISTORY_COLUMNS)
        with atomic_path(staging / "index.csv") as tmp:
            index.to_csv(tmp, index=False)
        commit_staged(staging, folder, [*index["file"], "index.csv"])
    return index
