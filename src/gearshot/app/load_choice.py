"""An unquantified load chosen from the healthy recordings.

When the load of a machine is not known in N m (the PHM 2009 records say only High or
Low), simulate its database over several loads and let the healthy recordings pick one.
The load sets the *regular* part of a healthy gear's vibration: how much of the mesh
excitation comes from the teeth deflecting under load (the mesh stiffness varying as
teeth come in and out of contact) against the geometric errors, which do not grow with
load. That balance shows in the relative amplitudes of the mesh harmonics, the **harmonic
profile** of :mod:`gearshot.estimator.comparability`.

For each load of the database (at the condition's speed), the simulated healthy SAs of
each grade are passed through the transfer path estimated from the user's long healthy
signal (step 3 of the method, as in the fit), and their mean harmonic profile at the
monitored pair's mesh harmonics is compared with the mean profile of the user's healthy SA
segments. The distance of a load is that of its nearest grade (the grade is unknown too,
and it moves the balance the same way), in units of the recordings' own spread (the
comparability score's unit). The load with the smallest distance is chosen; the
**clarity** of the choice is the second-smallest distance over the smallest. A choice
with a clarity below :data:`MIN_CLARITY` is ambiguous: ``predict`` refuses it with one
line listing the distances (give ``--load``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from .._errors import GearshotError
from .._validation import as_signal_array, check_positive

__all__ = ["MIN_CLARITY", "LoadChoice", "choose_load", "load_distances"]

#: Smallest clarity (second-smallest distance over the smallest) of an unambiguous choice.
#: Chosen on the development seeds of the virtual rig (benchmarks/load_choice.py,
#: benchmarks/RESULTS.md "Unknown load, chosen from the healthy recordings").
MIN_CLARITY = 1.5


@dataclass(frozen=True)
class LoadChoice:
    """The load the healthy recordings pick from a database over several loads.

    Attributes
    ----------
    load : float
        The chosen load, N m (smallest distance).
    loads : tuple of float
        Every load of the database, ascending.
    distances : tuple of float
        Distance of the recordings' mean harmonic profile from each load's nearest grade,
        in the recordings' healthy spreads (same order as ``loads``).
    grades : tuple of int
        The nearest grade at each load.
    clarity : float
        Second-smallest distance over the smallest (``inf`` with one load).
    min_clarity : float
    """

    load: float
    loads: tuple[float, ...]
    distances: tuple[float, ...]
    grades: tuple[int, ...]
    clarity: float
    min_clarity: float

    @property
    def ambiguous(self) -> bool:
        """Whether the clarity is below ``min_clarity``."""
        return bool(self.clarity < self.min_clarity)

    def describe(self) -> str:
        """One line: the chosen load, its clarity, every load's distance."""
        pairs = ", ".join(f"{x:g} N m: {d:.3g}" for x, d in zip(self.loads, self.distances))
        return (f"load {self.load:g} N m chosen from the healthy recordings (clarity "
                f"{self.clarity:.2f}, needed {self.min_clarity:g}; distances in healthy "
                f"spreads {pairs})")

    def as_dict(self) -> dict:
        """JSON-ready fields."""
        return {"load": self.load, "loads": list(self.loads),
                "distances": list(self.distances), "grades": list(self.grades),
                "clarity": self.clarity, "min_clarity": self.min_clarity,
                "ambiguous": self.ambiguous}


def _profiles(sa: np.ndarray, mesh_order: int) -> np.ndarray:
    from ..estimator.comparability import harmonic_profile

    return harmonic_profile(sa, mesh_order)


def _spread(prof: np.ndarray) -> float:
    """The recordings' healthy spread (the comparability score's unit)."""
    from ..estimator.comparability import healthy_spread

    n = len(prof)
    if n < 2:
        raise GearshotError(f"the healthy recordings give {n} SA segment(s); choosing the "
                            f"load needs at least 2")
    return healthy_spread(prof)


def _healthy_by_grade(db) -> dict[int, np.ndarray]:
    """The healthy simulated SAs of one database slice, by grade."""
    sa = np.asarray(db["sa"].values, dtype=float)
    sizes = np.asarray(db["fault_size"].values, dtype=float)
    grades = np.asarray(db["grade"].values)
    out = {}
    for g in np.unique(grades[sizes == 0]):
        out[int(g)] = sa[(sizes == 0) & (grades == g)]
    if "sa_twin" in db:  # a paired store: every signal's healthy twin is healthy too
        twins = np.asarray(db["sa_twin"].values, dtype=float)
        for g in np.unique(grades):
            have = out.get(int(g))
            extra = twins[grades == g]
            out[int(g)] = extra if have is None else np.vstack([have, extra])
    if not out:
        raise GearshotError("the database slice holds no healthy signal")
    return out


def load_distances(database: str | Path, speed: float, healthy_sa: ArrayLike,
                   healthy_long: ArrayLike, *, mesh_order: int,
                   loads: Sequence[float] | None = None
                   ) -> tuple[list[float], list[float], list[int]]:
    """(loads, distances in healthy spreads, nearest grades) of a database slice per load.

    Parameters
    ----------
    database : path
        A simulated database (:func:`gearshot.sim.build_database`).
    speed : float
        The database speed to compare at, in the database's own unit (rev/s of the
        simulated pair's input: :meth:`gearshot.Machine.sim_speed` of the tacho speed).
    healthy_sa : array_like (n_segments, n_points)
        Healthy SA segments of the recordings, cycle = one revolution of the database's
        gear.
    healthy_long : array_like (n_samples,)
        One long healthy angle-domain signal (the transfer path is estimated from it).
    mesh_order : int
        The database pair's mesh order (the gear's tooth count).
    loads : sequence of float, optional
        The loads to compare (default: every load of the database).
    """
    from ..estimator.steps import estimate_tf, propagate_simulated
    from ..sim import load_database
    from .conditions import database_conditions

    real = as_signal_array(healthy_sa, "healthy_sa", min_ndim=2, max_ndim=2, min_length=4)
    all_loads = database_conditions(database)[1]
    loads = sorted(all_loads if loads is None else [float(x) for x in loads])
    prof = _profiles(real, mesh_order)
    spread = _spread(prof)
    target = prof.mean(axis=0)
    tf = estimate_tf(np.asarray(healthy_long, dtype=float), real.shape[1])
    distances, grades = [], []
    for load in loads:
        by_grade = _healthy_by_grade(load_database(database, speed=speed, load=load))
        best = min((float(np.linalg.norm(_profiles(propagate_simulated(sims, tf), mesh_order)
                                          .mean(axis=0) - target)) / spread, g)
                   for g, sims in by_grade.items())
        distances.append(best[0])
        grades.append(best[1])
    return loads, distances, grades


def choose_load(database: str | Path, speed: float, healthy_sa: ArrayLike,
                healthy_long: ArrayLike, *, mesh_order: int,
                min_clarity: float | None = None) -> LoadChoice:
    """The database load whose simulated healthy signals best match the recordings.

    Parameters are those of :func:`load_distances`; ``min_clarity`` sets
    :attr:`LoadChoice.ambiguous` (default :data:`MIN_CLARITY`, read at the call).

    Returns
    -------
    LoadChoice
    """
    min_clarity = check_positive(MIN_CLARITY if min_clarity is None else min_clarity,
                                 "min_clarity")
    loads, dist, grades = load_distances(database, speed, healthy_sa, healthy_long,
                                         mesh_order=mesh_order)
    order = np.argsort(dist, kind="stable")
    best = int(order[0])
    clarity = float("inf") if len(dist) < 2 else \
        float(dist[int(order[1])] / max(dist[best], 1e-12))
    return LoadChoice(load=float(loads[best]), loads=tuple(float(x) for x in loads),
                      distances=tuple(dist), grades=tuple(grades), clarity=clarity,
                      min_clarity=float(min_clarity))
