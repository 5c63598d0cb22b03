"""Rig datasets of the paper's Sec. 4.2: recordings → SA segments → train / example / test."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from .._errors import GearshotError
from .._validation import check_int
from ..estimator.holdouts import HOLDOUT, recording_holdouts
from ..io import recording_segments
from ..paper import CYCLES_PER_SEGMENT, GEAR_TEETH, PINION_TEETH, SAMPLES_PER_CYCLE

__all__ = ["RigDataset", "rig_dataset", "CHECKED_HOLDOUT"]

#: Share of each healthy recording's segments a ``checked`` fit holds out (``gearshot
#: predict``'s default, :data:`gearshot.estimator.holdouts.HOLDOUT`).
CHECKED_HOLDOUT = HOLDOUT


@dataclass(frozen=True)
class RigDataset:
    """One Sec. 4.2 dataset built from a recording campaign of one condition.

    Attributes
    ----------
    target_healthy : ndarray (n, n_points)
        SA segments of the training healthy recordings.
    healthy_long : ndarray
        Angle-domain signal of one training healthy recording (for the TF estimate).
    faulty_example : ndarray (n_points,)
    faulty_size : float
    test_sa : ndarray (m, n_points)
    test_size : ndarray (m,)
    test_recording : ndarray of str (m,)
        The recording each test SA comes from.
    example_recording : str
    gear_teeth, pinion_teeth : int
        The pair the SAs were segmented for (declared to the estimator's ``fit``, which
        refuses a database of another pair).
    healthy_recordings : ndarray of str (n,) or None
        The recording each training healthy SA comes from (``fit``'s
        ``healthy_recordings``: references from other runs, residue whitening).
    example_rest : ndarray (k, n_points) or None
        The example recording's other segments (``fit``'s ``example_record`` with
        ``checked``; they are in no test set).
    """

    target_healthy: np.ndarray
    healthy_long: np.ndarray
    faulty_example: np.ndarray
    faulty_size: float
    test_sa: np.ndarray
    test_size: np.ndarray
    test_recording: np.ndarray
    example_recording: str
    gear_teeth: int = GEAR_TEETH
    pinion_teeth: int = PINION_TEETH
    healthy_recordings: np.ndarray | None = None
    example_rest: np.ndarray | None = None

    def fit_args(self, database, checked: bool = False):
        """Positional arguments for :meth:`OneFaultShotEstimator.fit` (with ``checked``,
        the healthy SAs the fit keeps: :meth:`fit_kwargs`)."""
        healthy = self.target_healthy[self._checked_split()[0]] if checked \
            else self.target_healthy
        return (database, healthy, self.faulty_example, self.faulty_size, self.healthy_long)

    def fit_kwargs(self, recordings: bool = True, checked: bool = False):
        """Keyword arguments for :meth:`OneFaultShotEstimator.fit`: the SAs' pair and,
        with ``recordings``, the healthy SAs' recordings (the paper's Sec. 4.2 experiment,
        :func:`~gearshot.experiments.rig_experiment`, passes none, as the paper).

        ``checked``: the fit checks itself as ``gearshot predict``'s does: the last
        quarter of each healthy recording's segments is held out (``healthy_holdout``,
        ``holdout=CHECKED_HOLDOUT``) and the example recording's other segments are its
        ``example_record``."""
        kw: dict[str, object] = {"gear_teeth": self.gear_teeth,
                                 "pinion_teeth": self.pinion_teeth}
        keep, hold = self._checked_split() if checked else (None, None)
        if recordings and self.healthy_recordings is not None:
            kw["healthy_recordings"] = self.healthy_recordings if keep is None \
                else self.healthy_recordings[keep]
        if checked:
            kw.update(healthy_holdout=self.target_healthy[hold], holdout=CHECKED_HOLDOUT,
                      example_record=self.example_rest)
        return kw

    def _checked_split(self):
        """Indices of the healthy SAs kept and held out: the last ``CHECKED_HOLDOUT`` of
        each recording's (:func:`~gearshot.estimator.holdouts.recording_holdouts`)."""
        labels = self.healthy_recordings
        if labels is None:
            labels = np.zeros(len(self.target_healthy), dtype=int)
        return recording_holdouts(labels, CHECKED_HOLDOUT)


def _campaign_rows(campaign, speed, load):
    from ..io import read_campaign

    index = campaign if isinstance(campaign, pd.DataFrame) else read_campaign(Path(campaign))
    rows = index
    if speed is not None:
        rows = rows[np.isclose(rows["speed"], speed)]
    if load is not None:
        rows = rows[np.isclose(rows["load"], load)]
    if rows.empty:
        raise GearshotError(f"campaign holds no recording at speed={speed!r}, load={load!r} "
                            f"(it has speeds {sorted(set(index['speed']))}, loads "
                            f"{sorted(set(index['load']))})")
    return rows.reset_index(drop=True)


def rig_dataset(campaign, *, speed=None, load=None, n_train_healthy=5,
                gear_teeth=GEAR_TEETH, pinion_teeth=PINION_TEETH,
                cycles_per_segment=CYCLES_PER_SEGMENT, samples_per_cycle=SAMPLES_PER_CYCLE,
                random_state=None, segments=None):
    """Build a Sec. 4.2 dataset from a campaign (folder with an index, or its DataFrame).

    ``n_train_healthy`` random healthy recordings go to training (their SA segments are the
    target healthy SAs; the first one's angle-domain signal is the long healthy signal);
    one random segment of one random faulty recording is the faulty example and all
    segments of that recording leave the test set; every other segment is a test SA.

    Parameters
    ----------
    campaign : path or pandas.DataFrame
        Campaign folder (``index.csv``) or index with ``path, speed, load, fault_size,
        repetition``.
    speed, load : float, optional
        Condition to use (required when the campaign holds several).
    n_train_healthy : int, default 5
    gear_teeth, pinion_teeth, cycles_per_segment, samples_per_cycle
        SA construction (the paper's 38/17, 50 cycles, 2048 points).
    random_state : int or Generator
    segments : dict path → (sa, angle_signal or None), optional
        Cache of already computed segments, filled in place (for repeated datasets).

    Returns
    -------
    RigDataset
    """
    rng = np.random.default_rng(random_state)
    n_train_healthy = check_int(n_train_healthy, "n_train_healthy", minimum=1)
    rows = _campaign_rows(campaign, speed, load)
    if len(set(zip(rows["speed"], rows["load"]))) > 1:
        raise GearshotError("campaign holds several conditions; give speed= and load=")
    healthy = rows.index[rows["fault_size"] == 0].to_numpy()
    faulty = rows.index[rows["fault_size"] > 0].to_numpy()
    if healthy.size <= n_train_healthy:
        raise GearshotError(f"campaign holds {healthy.size} healthy recordings; "
                            f"n_train_healthy={n_train_healthy} leaves none for testing")
    if faulty.size < 2:
        raise GearshotError(f"campaign holds {faulty.size} faulty recordings; at least 2 "
                            f"are needed (one gives the example)")
    cache = {} if segments is None else segments
    kw = dict(gear_teeth=gear_teeth, pinion_teeth=pinion_teeth,
              cycles_per_segment=cycles_per_segment, samples_per_cycle=samples_per_cycle)

    def sa_of(i, long=False):
        path = rows.loc[i, "path"]
        have = cache.get(path)
        if have is None or (long and have[1] is None):
            got = recording_segments(path, long=long, **kw)
            have = got if long else (got, None)
            cache[path] = have
        return have

    train_h = rng.permutation(healthy)[:n_train_healthy]
    target_healthy = np.vstack([sa_of(i)[0] for i in train_h])
    labels = np.concatenate([[str(rows.loc[i, "path"])] * len(sa_of(i)[0]) for i in train_h])
    healthy_long = sa_of(train_h[0], long=True)[1]
    ex_rec = int(rng.choice(faulty))
    ex_sa = sa_of(ex_rec)[0]
    ex_k = int(rng.integers(ex_sa.shape[0]))
    example = ex_sa[ex_k]
    test_rows = [i for i in rows.index if i not in set(train_h) and i != ex_rec]
    test_sa, test_y, test_rec = [], [], []
    for i in test_rows:
        sa = sa_of(i)[0]
        test_sa.append(sa)
        test_y.append(np.full(sa.shape[0], float(rows.loc[i, "fault_size"])))
        test_rec.extend([rows.loc[i, "path"]] * sa.shape[0])
    return RigDataset(
        target_healthy=target_healthy,
        healthy_long=healthy_long,
        faulty_example=example,
        faulty_size=float(rows.loc[ex_rec, "fault_size"]),
        test_sa=np.vstack(test_sa),
        test_size=np.concatenate(test_y),
        test_recording=np.asarray(test_rec),
        example_recording=str(rows.loc[ex_rec, "path"]),
        gear_teeth=int(gear_teeth),
        pinion_teeth=int(pinion_teeth),
        healthy_recordings=labels,
        example_rest=np.delete(ex_sa, ex_k, axis=0),
    )
