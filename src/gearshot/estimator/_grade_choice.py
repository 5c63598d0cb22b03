"""The grade choice of ``fit``: step 1 on the nominal grade, the grade models (steps 4–8
per grade) and the strategies of ``calibration`` (tuned, soft, nominal, zero-shot)."""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from sklearn.base import BaseEstimator

from .._errors import GearshotError
from . import steps
from ._inputs import _FitInputs
from ._simulated import recorded_residue_spectrum, residue_noise_spectrum
from ._target import _TargetSide, target_features
from .calibration import resolve_calibration
from .regressors import StepModel, fit_regressor
from .uncertainty import grade_weights
from .zero_shot import healthy_signature, match_grade, signature_weights

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class _Selection:
    """Step 1's outcome."""

    selected: tuple[str, ...]
    errors: dict[str, float]
    features: tuple[FloatArray, FloatArray] | None


@dataclass(frozen=True)
class _GradeChoice:
    """A grade-choice strategy's outcome: the best grade and the weights that predict.

    ``settings``/``models`` (the joint calibration) are the weighted simulation settings
    and their models; without them every weighted grade is one setting at gain 1, width 1.
    """

    grade: int
    weights: dict[int, float]
    tuning_curve: dict[str, Any] | None
    settings: list[dict[str, Any]] | None = None
    models: list[StepModel] | None = None
    grid: dict[str, Any] | None = None


@dataclass
class _FitContext:
    """What the grade-choice strategies need: data, the target side and the grade models."""

    by_grade: Mapping[int, tuple[FloatArray, FloatArray]]
    grades: list[int]
    nominal: int | None
    target: _TargetSide
    inputs: _FitInputs
    example_features: Callable[[], FloatArray]
    model_for: Callable[[int], StepModel]
    names: tuple[str, ...] = ()
    cols: list[int] | None = None
    twins: Mapping[int, FloatArray] | None = None
    knn_seed: int = 0
    noise_seed: int = 0
    cache: dict[str, Any] = field(default_factory=dict)

    def matched_noise(self, n_signals: int) -> FloatArray:
        """The residue noise of ``n_signals`` simulated signals (:func:`_matched_noise`)."""
        return _matched_noise(self.cache, self.target.residue_power, self.inputs.n_points,
                              self.noise_seed, n_signals, self.target.residues)


def _matched_noise(cache: dict[str, Any], power: FloatArray, n_points: int, seed: int,
                   n_signals: int, recorded: FloatArray | None = None) -> FloatArray:
    """The residue noise of ``n_signals`` simulated signals (noise matching).

    Drawn from the ``match_noise`` step seed afresh for every set, so every grade and
    setting of the same size gets the same draw: it is drawn once and kept in ``cache``,
    as the inverse FFT of :func:`_matched_noise_spectrum` (what
    :func:`~gearshot.estimator.steps.residue_noise` computes from the same draw)."""
    key = f"noise/{n_signals}"
    if key not in cache:
        spectrum = _matched_noise_spectrum(cache, power, n_points, seed, n_signals,
                                           recorded)
        cache[key] = np.asarray(np.fft.irfft(spectrum, n=n_points, axis=-1), np.float64)
    noise: FloatArray = cache[key]
    return noise


def _matched_noise_spectrum(cache: dict[str, Any], power: FloatArray, n_points: int,
                            seed: int, n_signals: int, recorded: FloatArray | None = None
                            ) -> NDArray[np.complex128]:
    """The ``rfft`` of :func:`_matched_noise` (what the grade models add), kept in ``cache``:
    drawn from the ``recorded`` healthy differences when given
    (:func:`~gearshot.estimator._simulated.recorded_residue_spectrum`), else Gaussian with
    their mean ``power``."""
    key = f"noise_spectrum/{n_signals}"
    if key not in cache:
        rng = np.random.default_rng(np.random.RandomState(seed).randint(2**31 - 1))
        cache[key] = (residue_noise_spectrum(power, n_signals, n_points, rng)
                      if recorded is None else
                      recorded_residue_spectrum(recorded, n_signals, rng))
    spectrum: NDArray[np.complex128] = cache[key]
    return spectrum


# scikit-learn ships no type information: its classes are Any to mypy
class _GradeChoosing(BaseEstimator):  # type: ignore[misc,unused-ignore]
    """The grade-choice part of :class:`~gearshot.estimator.OneFaultShotEstimator`."""

    def _grades_in(self, by_grade: Mapping[int, Any]) -> list[int]:
        """The tried grades that the database holds (in the order of ``grades``)."""
        grades = [int(g) for g in self.grades if int(g) in by_grade]
        if not grades:
            raise GearshotError(f"none of grades={list(self.grades)!r} is in the database "
                                f"(it has {sorted(by_grade)})")
        return grades

    def _nominal_grade_in(self, by_grade: Mapping[int, Any]) -> int | None:
        """``nominal_grade`` when it is used (feature selection, no tuning), else None."""
        used_by = [what for what, used in (
            ("feature_selection=True", self.feature_selection),
            ("calibration='nominal'", self._strategy_name() == "nominal"))
            if used]
        if not used_by:
            return None
        if int(self.nominal_grade) not in by_grade:
            raise GearshotError(
                f"nominal_grade={self.nominal_grade!r} is not in the database (it has grades "
                f"{sorted(by_grade)}); it is needed with {' and '.join(used_by)}")
        return int(self.nominal_grade)

    # ------------------------------------------------------------------ fit: step 1
    def _select_features(self, by_grade: Mapping[int, tuple[FloatArray, FloatArray]],
                         nominal: int | None, inputs: _FitInputs, names: tuple[str, ...],
                         seed: int, twins: Mapping[int, FloatArray] | None = None
                         ) -> _Selection:
        """Step 1 on the nominal grade's simulated SAs (or every candidate when off); with
        twins, both simulated sets subtract each signal's twin, as the grade models do."""
        if not self.feature_selection or nominal is None:
            return _Selection(names, {}, None)
        sa, y = by_grade[nominal]
        selected, errors, features = steps.select_features(
            sa, y, inputs.selection_tf, mesh_order=self._mesh_orders(), names=names,
            threshold=self._options().selection_threshold,
            fallback=self._options().selection_fallback,
            random_state=seed, return_features=True,
            twins=None if twins is None else twins[nominal])
        return _Selection(tuple(selected), errors, features)

    # ------------------------------------------------------------------ fit: grade models
    def _fit_context(self, by_grade: Mapping[int, tuple[FloatArray, FloatArray]],
                     grades: list[int], nominal: int | None, target: _TargetSide,
                     inputs: _FitInputs, names: tuple[str, ...], cols: list[int],
                     seed: int, twins: Mapping[int, FloatArray] | None = None,
                     noise_seed: int = 0) -> _FitContext:
        """Bundle what the strategies need; grade models are fitted on first use and kept.

        (The closures hold the context's parts, not the context: no reference cycle keeps
        a fit's arrays alive after it.)"""
        models: dict[int, StepModel] = {}
        cache: dict[str, Any] = {}

        def model_for(grade: int) -> StepModel:
            if grade not in models:
                sa = by_grade[grade][0]
                models[grade] = self._fit_grade_model(
                    by_grade[grade], target, names, cols, seed,
                    None if twins is None else twins[grade],
                    None if twins is None else _matched_noise_spectrum(
                        cache, target.residue_power, inputs.n_points, noise_seed,
                        sa.shape[0], target.residues), cache)
            return models[grade]

        def example_features() -> FloatArray:
            feats = target_features(self, inputs.faulty_example, target.scale,
                                    target.references, target.healthy_mean, names,
                                    target.weights, target.blend)
            return feats[:, cols]

        return _FitContext(by_grade, grades, nominal, target, inputs, example_features,
                           model_for, names, cols, twins, seed, noise_seed, cache)

    def _fit_grade_model(self, grade_data: tuple[FloatArray, FloatArray], target: _TargetSide,
                         names: tuple[str, ...], cols: list[int], seed: int,
                         twins: FloatArray | None = None,
                         noise_spectrum: NDArray[np.complex128] | None = None,
                         kept: dict[str, Any] | None = None) -> StepModel:
        """Steps 4–8 for one grade: its simulated features with the target healthy, KNN.

        With twins (``simulated_reference="twin"``), step 6 subtracts each signal's twin
        and the target's residue (``noise_spectrum``: its ``rfft``) is added; ``kept``: the
        fit's cache (the residue-only rows' features, the same in every grade)."""
        sa, y = grade_data
        selected = [names[c] for c in cols]   # the unselected features are not computed
        X_sim = steps.simulated_features(
            sa, y == 0, target.simulated_tf, mesh_order=self._mesh_orders(),
            names=selected,
            rms_normalization=self.rms_normalization, twins=twins,
            noise_spectrum=noise_spectrum, kept=kept)
        X = np.vstack([X_sim, target.healthy_features[:, cols]])
        labels = np.concatenate([y, np.zeros(len(target.healthy_features))])
        opts = self._options()
        return fit_regressor(getattr(self, "estimator", "paper"), X, labels,
                             n_neighbors=opts.n_neighbors,
                             validation_fraction=opts.validation_fraction, random_state=seed,
                             n_own=len(target.healthy_features))

    # ------------------------------------------------------------------ fit: grade choice
    def _choose_grades(self, ctx: _FitContext, grades: Sequence[int], paired: bool
                       ) -> dict[str, Any]:
        """Run the grade-choice strategy of ``calibration``; the learned attributes it
        gives (``grade_strategy_``, ``grade_``, weights, models, ``calibration_`` ...)."""
        options = resolve_calibration(self.calibration)
        strategy = self._grade_strategy(grades, joint=options is not None and paired)
        strategies: dict[str, Callable[[_FitContext], _GradeChoice]] = {
            "tuned": self._grade_tuned, "soft": self._grade_soft,
            "nominal": self._grade_nominal, "zero_shot": self._grade_zero_shot,
            "joint": functools.partial(self._grade_joint, options=options)}
        choice = strategies[strategy](ctx)
        settings, setting_models = self._settings_of(choice, ctx)
        grade_w: dict[int, float] = {}
        for st in settings:
            grade_w[st["grade"]] = grade_w.get(st["grade"], 0.0) + st["weight"]
        grade_w = dict(sorted(grade_w.items(), key=lambda kv: -kv[1]))
        models: dict[int, StepModel] = {}
        for st, m in zip(settings, setting_models):
            models.setdefault(st["grade"], m)   # settings come largest weight first
        joint = choice.settings is not None
        best = setting_models[0] if joint else ctx.model_for(choice.grade)
        calibration = dict(strategy="joint" if joint else "grade", settings=settings,
                           grid=choice.grid,
                           options=options.as_dict() if joint and options is not None else None)
        return dict(grade_strategy_=strategy, grade_=choice.grade,
                    grade_weights_=grade_w if joint else choice.weights,
                    grade_models_=models, model_=best, tuning_curve_=choice.tuning_curve,
                    calibration_=calibration, setting_models_=setting_models,
                    n_neighbors_=best.n_neighbors)

    def _strategy_name(self) -> str | None:
        """``calibration`` when it is a strategy name (None for a joint grid)."""
        return self.calibration if isinstance(self.calibration, str) else None

    def _grade_strategy(self, grades: Sequence[int], joint: bool) -> str:
        """Which grade-choice strategy ``calibration`` asks for with these grades
        (``joint``: a joint grid and a paired database)."""
        name = self._strategy_name()
        if name == "zero_shot":
            return "zero_shot"
        if name == "nominal" or len(grades) == 1:
            return "nominal"
        if name == "tuned":
            return "tuned"
        return "joint" if joint else "soft"

    def _grade_tuned(self, ctx: _FitContext) -> _GradeChoice:
        """Step 2 (the paper): the one grade whose model predicts the example best."""
        x_example = ctx.example_features()
        assert ctx.inputs.faulty_size is not None
        grade, curve = steps.tune_grade(lambda g: float(ctx.model_for(g).predict(x_example)[0]),
                                        ctx.grades, ctx.inputs.faulty_size,
                                        smoothing=self._options().tuning_smoothing)
        return _GradeChoice(grade, {grade: 1.0}, curve)

    def _grade_soft(self, ctx: _FitContext) -> _GradeChoice:
        """Step 2, soft: every grade weighted by the likelihood of the example's size."""
        tuned = self._grade_tuned(ctx)
        assert tuned.tuning_curve is not None and ctx.inputs.faulty_size is not None
        weights = grade_weights(tuned.tuning_curve["prediction"], ctx.grades,
                                ctx.inputs.faulty_size,
                                ctx.model_for(tuned.grade).validation_residuals)
        return _GradeChoice(tuned.grade, weights, tuned.tuning_curve)

    def _grade_nominal(self, ctx: _FitContext) -> _GradeChoice:
        """No tuning: ``nominal_grade`` (or the only grade tried)."""
        grade = ctx.nominal if self._strategy_name() == "nominal" else ctx.grades[0]
        assert grade is not None
        return _GradeChoice(int(grade), {int(grade): 1.0}, None)

    def _grade_zero_shot(self, ctx: _FitContext) -> _GradeChoice:
        """No example: match healthy-signal statistics of target and simulation."""
        opts = self._options()
        residue = ctx.target.residue_ms if opts.zero_shot_signature == "denoised" else 0.0
        target_sig = healthy_signature(ctx.target.scaled_healthy, self._mesh_orders(),
                                       residue_ms=residue)
        sims = {g: healthy_signature(
            steps.propagate_simulated(sa[y == 0], ctx.target.transfer_function),
            self._mesh_orders()) for g, (sa, y) in ctx.by_grade.items() if g in ctx.grades}
        grade, curve = match_grade(target_sig, sims)
        tuning_curve: dict[str, Any] = dict(curve)
        weights = {grade: 1.0}
        if opts.zero_shot_weighting == "soft":
            weights, tuning_curve["consistent"] = signature_weights(target_sig, sims)
        return _GradeChoice(grade, weights, tuning_curve)

    def _settings_of(self, choice: _GradeChoice, ctx: _FitContext
                     ) -> tuple[list[dict[str, Any]], list[StepModel]]:
        """The weighted settings and their models (grade strategies: one per grade)."""
        if choice.settings is not None and choice.models is not None:
            return choice.settings, choice.models
        mode = "tf" if ctx.target.transfer_function is not None else "none"
        settings = [dict(grade=int(g), gain=1.0, width=1.0, tf=mode, noise=1.0,
                         weight=float(w)) for g, w in choice.weights.items()]
        return settings, [ctx.model_for(int(g)) for g in choice.weights]
