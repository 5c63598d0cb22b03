"""The alarm of a monitored machine: a size threshold from its own healthy baseline.

Gear indicators have no universal limits: the threshold is the size a healthy recording
of this machine exceeds with probability ``false_alarm_rate`` (:func:`alarm_threshold`,
from the healthy estimates the model file carries), and an alarm is believed only when
``sustain`` consecutive trusted recordings exceed it (:func:`alarm_states`). Untrusted
recordings neither raise nor clear an alarm: they are skipped.

Once the history holds :data:`COMMISSIONING` trusted recordings, their estimates set a
threshold of their own by the same law, and from the next recording on the threshold is
the lower of the two (:func:`history_thresholds`): the fit's healthy baseline is a few
recordings of one campaign, cross-fitted, and may read higher than the machine's later
runs do; the first recordings of the watched machine say how it reads. The lower of the
two only: a history that starts with a fault already present raises its own threshold,
which is then not used, so it cannot mask the fault. Until then the history is young:
the threshold rests on the fit's campaign alone, whose runs may vary less than the
machine's, and one more consecutive recording over it (:data:`YOUNG_EXTRA`) is needed
to raise or clear the alarm (:func:`history_sustain`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy import stats

from .._errors import GearshotError
from .._validation import check_in_range, check_int

__all__ = ["alarm_threshold", "alarm_states", "baseline_warning", "history_thresholds",
           "AlarmResult", "Thresholds", "FALSE_ALARM_RATE", "SUSTAIN", "MIN_THRESHOLD",
           "MIN_BASELINE", "COMMISSIONING", "YOUNG_EXTRA", "history_sustain"]

#: Per-recording false-alarm probability the threshold is set at (chosen on the
#: development lives, benchmarks/RESULTS.md "Monitoring": 0.02, with ``SUSTAIN`` 2, raised
#: more zero-shot alarms in time than 0.01 and no more one-fault-shot false alarms than
#: the target allows; ``benchmarks/alarm_lives.py``).
FALSE_ALARM_RATE = 0.02
#: Consecutive trusted recordings over the threshold that raise (or under it that clear)
#: the alarm (chosen on the development lives).
SUSTAIN = 2
#: Smallest threshold: a baseline of near-identical healthy estimates would otherwise set
#: the threshold at the estimator's own resolution (chosen on the development lives:
#: 0.08 raised false alarms, 0.10–0.15 none, and 0.10 the most alarms in time).
MIN_THRESHOLD = 0.10


#: Trusted recordings at the start of a history whose estimates also set a threshold
#: (:func:`history_thresholds`). Chosen on the development lives 1–10, 51–60
#: (benchmarks/RESULTS.md "Monitoring"): 7 to 12 gave the same alarms in time, 6 and
#: fewer false alarms; 10 is the largest with the most zero-shot alarms in time.
COMMISSIONING = 10

#: Consecutive recordings a young history (fewer than :data:`COMMISSIONING` trusted
#: recordings so far) needs beyond ``sustain`` (:func:`history_sustain`). Chosen on the
#: development lives 1–10, 51–60 and the lives 243–274 (benchmarks/RESULTS.md
#: "Monitoring"): their false alarms came from healthy runs reading high within a
#: history's first recordings (8 in 624 healthy recordings with 0, none with 1, and the
#: same alarms in time but for one zero-shot life).
YOUNG_EXTRA = 1

#: Healthy estimates under which the threshold's false-alarm rate is not stated as known
#: (:func:`baseline_warning`): as few as comparability calibrates on
#: (:data:`gearshot.estimator.comparability.MIN_HEALTHY`).
MIN_BASELINE = 6


def baseline_warning(baseline: ArrayLike) -> str | None:
    """A warning for a threshold set from fewer than :data:`MIN_BASELINE` finite healthy
    estimates: a normal law fitted to so few says little of its tail (a fit on one
    short healthy recording holds its 2 hold-outs only).

    >>> baseline_warning([0.12, 0.13]) is not None, baseline_warning([0.1] * 6)
    (True, None)
    """
    n = int(np.isfinite(np.asarray(baseline, dtype=float).ravel()).sum())
    if n >= MIN_BASELINE:
        return None
    return (f"the alarm threshold rests on {n} healthy estimate(s) (fewer than "
            f"{MIN_BASELINE}): its false-alarm rate is not known; fit on longer or more "
            f"healthy recordings")


def alarm_threshold(baseline: ArrayLike, *, false_alarm_rate: float = FALSE_ALARM_RATE
                    ) -> float:
    """Size a healthy recording exceeds with probability ``false_alarm_rate``.

    A normal law fitted to the baseline (mean and standard deviation of healthy
    recordings' estimates): ``mean + z(1 - false_alarm_rate) * std``, at least
    :data:`MIN_THRESHOLD`.

    Parameters
    ----------
    baseline : array_like, shape (n,)
        Estimated sizes of healthy recordings the fit did not see (n ≥ 2).
    false_alarm_rate : float in (0, 0.5)

    Raises
    ------
    GearshotError
        Fewer than two finite baseline values, or a rate outside (0, 0.5).
    """
    rate = check_in_range(false_alarm_rate, "false_alarm_rate", 0.0, 0.5,
                          low_inclusive=False, high_inclusive=False)
    values = np.asarray(baseline, dtype=float).ravel()
    values = values[np.isfinite(values)]
    if values.size < 2:
        raise GearshotError(f"baseline needs at least 2 finite healthy estimates; got "
                            f"{values.size}")
    z = float(stats.norm.isf(rate))
    return max(float(values.mean() + z * values.std(ddof=1)), MIN_THRESHOLD)


@dataclass(frozen=True)
class Thresholds:
    """The alarm threshold of each recording of a history.

    Attributes
    ----------
    per_recording : ndarray (n,)
        The threshold each recording is judged against.
    fit : float
        The fit's threshold (from the model's healthy baseline).
    own : float or None
        The threshold of the history's first :data:`COMMISSIONING` trusted recordings
        (None: the history holds fewer).
    young : int
        Recordings before the history holds its commissioning recordings (all of them
        while it holds fewer): the young history of :func:`history_sustain`.
    """

    per_recording: np.ndarray
    fit: float
    own: float | None
    young: int

    @property
    def from_index(self) -> int | None:
        """The first recording judged against ``min(fit, own)`` (None: none yet)."""
        return self.young if self.own is not None and self.young < self.per_recording.size \
            else None


def history_thresholds(predicted: ArrayLike, trusted: ArrayLike, fit_threshold: float, *,
                       false_alarm_rate: float = FALSE_ALARM_RATE,
                       commissioning: int = COMMISSIONING) -> Thresholds:
    """The threshold of each recording of a history, in time order (module docstring).

    Up to the ``commissioning``-th trusted recording every recording is judged against
    ``fit_threshold``; after it against the lower of ``fit_threshold`` and
    :func:`alarm_threshold` of those ``commissioning`` recordings' estimates.

    >>> t = history_thresholds([0.05, 0.06, 0.04, 0.3], [True] * 4, 0.35, commissioning=3)
    >>> [round(float(v), 2) for v in t.per_recording], t.from_index
    ([0.35, 0.35, 0.35, 0.1], 3)
    """
    commissioning = check_int(commissioning, "commissioning", minimum=2)
    y = np.asarray(predicted, dtype=float)
    ok = np.asarray(trusted, dtype=bool)
    if y.shape != ok.shape or y.ndim != 1:
        raise GearshotError(f"predicted and trusted must be one value per recording; got "
                            f"shapes {y.shape} and {ok.shape}")
    fit = float(fit_threshold)
    per = np.full(y.size, fit)
    usable = np.flatnonzero(ok & np.isfinite(y))
    if usable.size < commissioning:
        return Thresholds(per, fit, None, int(y.size))
    own = alarm_threshold(y[usable[:commissioning]], false_alarm_rate=false_alarm_rate)
    start = int(usable[commissioning - 1]) + 1
    per[start:] = min(fit, own)
    return Thresholds(per, fit, own, start)


def history_sustain(thresholds: Thresholds, sustain: int = SUSTAIN, *,
                    extra: int = YOUNG_EXTRA) -> np.ndarray:
    """The consecutive trusted recordings that raise or clear the alarm, per recording:
    ``sustain + extra`` while the history is young (``thresholds.young``), ``sustain``
    after.

    >>> t = history_thresholds([0.05] * 4, [True] * 4, 0.35, commissioning=2)
    >>> history_sustain(t, 2).tolist()
    [3, 3, 2, 2]
    """
    sustain = check_int(sustain, "sustain", minimum=1)
    extra = check_int(extra, "extra", minimum=0)
    per = np.full(thresholds.per_recording.size, sustain)
    per[:thresholds.young] += extra
    return per


@dataclass(frozen=True)
class AlarmResult:
    """Alarm state per recording and when it was first raised.

    Attributes
    ----------
    alarm : ndarray of bool
        Per recording: a trusted recording while the alarm stands (untrusted: False).
    first_index : int or None
        Index of the recording that first raised the alarm.
    """

    alarm: np.ndarray
    first_index: int | None


def alarm_states(predicted: ArrayLike, trusted: ArrayLike, threshold: float | ArrayLike, *,
                 sustain: int | ArrayLike = SUSTAIN) -> AlarmResult:
    """Run the alarm over recordings in time order.

    The alarm is raised at the ``sustain``-th consecutive trusted recording over
    ``threshold`` (one value, or one per recording: :func:`history_thresholds`) and
    cleared at the ``sustain``-th consecutive trusted one at or under it (``sustain``:
    one count, or the count in force at each recording: :func:`history_sustain`);
    untrusted recordings are skipped (they neither count nor break a run).
    """
    y = np.asarray(predicted, dtype=float)
    if np.ndim(sustain) == 0:
        runs = np.full(y.shape, check_int(sustain, "sustain", minimum=1))
    else:
        runs = np.asarray(sustain)
        if runs.shape != y.shape or not np.issubdtype(runs.dtype, np.integer) \
                or np.any(runs < 1):
            raise GearshotError(f"sustain must be one count >= 1 or one per recording "
                                f"({y.size}); got {sustain!r}")
    ok = np.asarray(trusted, dtype=bool)
    if y.shape != ok.shape:
        raise GearshotError(f"predicted and trusted differ in shape: {y.shape} vs {ok.shape}")
    limits = np.asarray(threshold, dtype=float)
    if limits.ndim and limits.shape != y.shape:
        raise GearshotError(f"threshold must be one value or one per recording ({y.size}); "
                            f"got shape {limits.shape}")
    limits = np.broadcast_to(limits, y.shape)
    alarm = np.zeros(y.size, dtype=bool)
    state, run, first = False, 0, None
    for i in range(y.size):
        if not ok[i] or not np.isfinite(y[i]):
            continue
        crossing = bool(y[i] > limits[i]) != state
        run = run + 1 if crossing else 0
        if run >= runs[i]:
            state, run = not state, 0
            if state and first is None:
                first = i
        alarm[i] = state
    return AlarmResult(alarm, first)
