"""What a fitted :class:`~gearshot.estimator.OneFaultShotEstimator` answers: sizes,
intervals, comparability, score; saving and loading."""

from __future__ import annotations

from typing import Any, Self, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray
from sklearn.base import BaseEstimator

from .._errors import GearshotError, NotFittedError
from .._validation import as_signal_array, check_in_range
from ._target import target_features
from .comparability import Comparability, ComparabilityReference
from .detection import reach_zero_below_limit
from .fit_check import TRUST_COLUMNS, FitCheck, recording_majority, trusted_column
from .trusted import comparable_at_speed
from .uncertainty import conformal_quantile, fit_discrepancy, holdout_interval, mixture_interval

FloatArray = NDArray[np.float64]

def _per_row(value: Any, n: int, name: str) -> list[str]:
    """One string per row from one string or a sequence of ``n``."""
    if isinstance(value, str):
        return [value] * n
    values = [str(v) for v in value]
    if len(values) != n:
        raise GearshotError(f"{name} holds {len(values)} value(s) for {n} SA(s); give one "
                            f"string or one per SA")
    return values


# scikit-learn ships no type information: its classes are Any to mypy
class _Prediction(BaseEstimator):  # type: ignore[misc,unused-ignore]
    """The prediction part of :class:`~gearshot.estimator.OneFaultShotEstimator`."""

    def __sklearn_is_fitted__(self) -> bool:
        return hasattr(self, "model_")

    def _check_fitted(self, method: str) -> None:
        if not self.__sklearn_is_fitted__():
            raise NotFittedError(f"This {type(self).__name__} is not fitted yet; call fit "
                                 f"before {method}")

    @property
    def model_discrepancy_(self) -> float:
        """The ``model_discrepancy`` this fit's intervals use (``"auto"`` resolved by
        :func:`~gearshot.estimator.uncertainty.fit_discrepancy`)."""
        self._check_fitted("model_discrepancy_")
        return fit_discrepancy(self)

    def features_of(self, sa: ArrayLike) -> FloatArray:
        """Selected, centred target features of SAs (what the KNN sees, before scaling).

        Parameters
        ----------
        sa : array_like (n_signals, n_points) or (n_points,)

        Returns
        -------
        ndarray (n_signals, n_selected_features)
        """
        self._check_fitted("features_of")
        arr = as_signal_array(sa, "sa", max_ndim=2)
        if arr.shape[-1] != self.n_points_:
            raise GearshotError(f"sa has {arr.shape[-1]} points per cycle; the estimator was "
                                f"fitted on {self.n_points_}")
        feats = target_features(self, arr, self.target_scale_, self.references_,
                                self.target_healthy_mean_, self.candidate_features_,
                                getattr(self, "residue_weights_", None),
                                getattr(self, "reference_blend_", 1))   # 1: saved before
        return feats[:, self.selected_columns_]

    def predict(self, sa: ArrayLike) -> FloatArray:
        """Fault sizes of target SAs.

        Parameters
        ----------
        sa : array_like (n_signals, n_points) or (n_points,)

        Returns
        -------
        ndarray (n_signals,)
        """
        self._check_fitted("predict")
        X = self.features_of(sa)
        return self._combined([m.predict(X) for m in self.setting_models_], len(X))

    def _combined(self, per_model: list[FloatArray], n: int) -> FloatArray:
        """The estimate: the models' estimates weighted as the calibration weighs them."""
        return sum((st["weight"] * p for st, p in zip(self.calibration_["settings"],
                                                       per_model)), np.zeros(n))

    def comparability(self, sa: ArrayLike, false_alarm_rate: float | None = None
                      ) -> Comparability:
        """Whether target SAs come from the fitted machine (know when not to answer).

        An out-of-distribution test of each SA's regular part
        (:func:`~gearshot.estimator.comparability.regular_features`: level, mesh
        harmonics, shaft orders, background and sidebands in octave bands, kurtosis),
        standardised by the fitted healthy SAs and measured from the fitted machine's
        states (the healthy mean moved toward the faulty example as a fault grows),
        calibrated on the healthy SAs' own leave-one-out scores. A segment of another
        load, speed, build, gearbox or sensor lies outside and is not comparable: its
        estimate should not be acted on.

        Parameters
        ----------
        sa : array_like (n_signals, n_points) or (n_points,)
            SAs in the units of the fit's (the level is compared).
        false_alarm_rate : float in (0, 1), optional
            Share of the fitted machine's healthy segments flagged; default
            :data:`~gearshot.estimator.comparability.DEFAULT_FALSE_ALARM` (0.01).

        Returns
        -------
        Comparability
            ``score``, ``p_value``, ``comparable`` (``p_value >= false_alarm_rate``) per
            segment, and ``record_p_value``/``record_comparable`` for the SAs judged
            together as one recording.
        """
        self._check_fitted("comparability")
        reference: ComparabilityReference | None = getattr(self, "comparability_reference_",
                                                            None)
        if reference is None:  # an estimator saved before comparability existed
            raise GearshotError("this estimator was fitted by an older gearshot without "
                                "a comparability reference; fit it again")
        return reference.evaluate(sa, false_alarm_rate)

    def trust(self, sa: ArrayLike, input_check: Any = None, *,
              coverage: float = 0.9, recording: Any = None, speed_check: Any = None,
              path_check: Any = None) -> Any:
        """Every estimate with the checks it passed or failed (issue #29).

        Parameters
        ----------
        sa : array_like (n_signals, n_points) or (n_points,)
        input_check : str or sequence of str, optional
            The input-health verdict of each SA ("ok" or the failed check), one for all or
            one per SA; None: "ok".
        coverage : float in (0, 1), default 0.9
            Coverage of ``low`` and ``high``.
        recording : sequence, optional
            Each SA's recording (any labels): a segment is then trusted only in a
            recording more than half of whose segments pass every check
            (:func:`~gearshot.estimator.fit_check.recording_majority`), as ``gearshot
            predict`` does.
        speed_check : str or sequence of str, optional
            Whether each SA's recording ran at a speed the fit has seen ("ok" or why not,
            one for all or one per SA; e.g.
            :func:`gearshot.app.conditions.fit_speed_check` of its speed against the fit's
            recordings'): a segment that fails it is not comparable, as in ``gearshot
            predict``'s tables. None: "ok".
        path_check : str or sequence of str, optional
            Whether each SA's recording was heard through the fit's transfer path ("ok"
            or why not; e.g. :func:`gearshot.app.conditions.fit_path_check` of its
            :func:`~gearshot.signal.path_pattern.path_pattern` against the fit's
            healthy recordings'): as ``speed_check``. None: "ok".

        Returns
        -------
        pandas.DataFrame
            One row per SA: ``predicted, low, high`` (:meth:`predict`,
            :meth:`predict_interval`), ``comparability, comparable``
            (:meth:`comparability`: its p-value and verdict), ``input_check``,
            ``fit_check`` (the fit's verdict, ``fit_check_.verdict``: "passed" or the
            reason) and ``trusted``: the input
            check is "ok", the segment is comparable (and its speed check "ok") and the
            fit check passed.
        """
        import pandas as pd

        self._check_fitted("trust")
        arr = as_signal_array(sa, "sa", max_ndim=2)
        arr = arr.reshape(-1, arr.shape[-1])
        low, high = self.predict_interval(arr, coverage=coverage)
        comp = self.comparability(arr)
        frame = pd.DataFrame(dict(predicted=self.predict(arr), low=low, high=high,
                                  comparability=comp.p_value, comparable=comp.comparable))
        frame["input_check"] = "ok" if input_check is None else _per_row(
            input_check, len(arr), "input_check")
        for name, value in (("speed_check", speed_check), ("path_check", path_check)):
            if value is not None:
                frame[name] = _per_row(value, len(arr), name)
        frame["comparable"] = comparable_at_speed(frame)
        check: FitCheck | None = getattr(self, "fit_check_", None)
        frame["fit_check"] = "unchecked: fitted before the fit check existed" \
            if check is None else check.verdict
        frame["trusted"] = trusted_column(frame)
        if recording is not None:
            labels = pd.Series(_per_row(recording, len(arr), "recording"), index=frame.index)
            frame["trusted"] &= recording_majority(labels, frame["trusted"])
        return frame.loc[:, list(TRUST_COLUMNS)]

    def predict_interval(self, sa: ArrayLike, coverage: float = 0.9,
                         ) -> tuple[FloatArray, FloatArray]:
        """Prediction intervals, calibrated on the fit's real hold-outs when it has them.

        A checked fit (``fit_check_`` with enough healthy hold-outs and segments of the
        example record, passed or failed) gives intervals calibrated on their real
        residuals, widened by the run-to-run spread (:attr:`FitCheck.run_spread
        <gearshot.estimator.fit_check.FitCheck.run_spread>`, wider for a healthy baseline
        that drifts; :func:`~gearshot.estimator.uncertainty.holdout_interval`): a healthy segment of
        the machine has 0 in its interval, the example record's segments the declared
        size, at ``coverage``. Without hold-outs (an unchecked fit) the intervals are
        the simulated ones below, which cannot show the simulation-to-reality bias.

        Each grade model says ``y = ŷ_g ± r + δ``: ``r`` from its validation residuals
        (split conformal), ``δ ~ N(0, model_discrepancy²)`` the simulation-to-reality
        error the validation split cannot show (``"auto"``:
        :func:`~gearshot.estimator.uncertainty.fit_discrepancy`). With soft grade
        weighting the interval is the central ``coverage`` range of the weighted mixture
        over the grade models
        (:func:`~gearshot.estimator.mixture_interval`); with one model and
        ``model_discrepancy=0`` it is the plain split-conformal interval.

        Parameters
        ----------
        sa : array_like (n_signals, n_points) or (n_points,)
        coverage : float in (0, 1), default 0.9

        An estimate below ``detection_limit_`` is not told apart from healthy at the
        limit's confidence (95 %, one-sided): at ``coverage`` ≥ 0.9 its interval reaches
        0 (:func:`~gearshot.estimator.detection.reach_zero_below_limit`), whatever the
        fit check says; the plain split-conformal interval (one model,
        ``model_discrepancy=0``) is left as it is.

        Returns
        -------
        low, high : ndarray (n_signals,)
            Clipped to [0, 1].
        """
        self._check_fitted("predict_interval")
        coverage = check_in_range(coverage, "coverage", 0, 1, low_inclusive=False,
                                  high_inclusive=False)
        check: FitCheck | None = getattr(self, "fit_check_", None)
        if check is not None and check.checked and check.n_healthy and check.n_example:
            healthy, example = check.residuals()
            pred = self.predict(sa)
            low, high = holdout_interval(pred, healthy, example, coverage,
                                         run_spread=check.run_spread,
                                         example_size=check.declared_size)
            low = reach_zero_below_limit(self, pred, low, coverage)
            return np.clip(low, 0, 1), np.clip(high, 0, 1)
        X = self.features_of(sa)
        discrepancy = fit_discrepancy(self)
        settings, models = self.calibration_["settings"], self.setting_models_
        per_model = [m.predict(X) for m in models]
        if len(models) == 1 and discrepancy == 0:
            pred = per_model[0]
            q = conformal_quantile(models[0].validation_residuals, coverage)
            return np.clip(pred - q, 0, 1), np.clip(pred + q, 0, 1)
        low, high = mixture_interval(
            dict(enumerate(per_model)),
            {i: st["weight"] for i, st in enumerate(settings)},
            {i: m.validation_residuals for i, m in enumerate(models)},
            coverage, discrepancy=discrepancy)
        low = reach_zero_below_limit(self, self._combined(per_model, len(X)), low, coverage)
        return np.clip(low, 0, 1), np.clip(high, 0, 1)

    def score(self, X: ArrayLike, y: ArrayLike,
              sample_weight: ArrayLike | None = None) -> float:
        """Negative mean absolute error (higher is better) on SAs ``X`` of sizes ``y``."""
        pred = self.predict(X)
        weights = None if sample_weight is None else np.asarray(sample_weight, float)
        return -float(np.average(np.abs(pred - np.asarray(y, float)), weights=weights))

    # ------------------------------------------------------------------ persistence
    def save(self, path: str | Any) -> None:
        """Save the fitted estimator (skops format: loading it runs no code) with version
        metadata, atomically."""
        from .persistence import save_estimator

        save_estimator(self, path)

    @classmethod
    def load(cls, path: str | Any, *, trusted: bool = False) -> Self:
        """Load an estimator saved by :meth:`save`; a file that would construct other types
        than an estimator's, or an old joblib pickle, needs ``trusted=True`` (which runs
        the file's code: only for files you made; see
        :func:`gearshot.estimator.persistence.load_estimator`)."""
        from .persistence import load_estimator

        return cast(Self, load_estimator(path, trusted=trusted))
