"""The joint calibration of ``fit`` (``calibration="joint"``): grade × fault gain × fault
width × TF mode (× noise) settings weighted by how well each explains the example
(:mod:`gearshot.estimator.calibration` holds the grid's options and arithmetic)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray
from sklearn.base import BaseEstimator

from . import steps
from ._grade_choice import _FitContext, _GradeChoice
from ._target import target_features
from .calibration import (
    CalibrationOptions,
    fault_centre,
    setting_differences,
    setting_log_likelihoods,
)
from .regressors import StepModel, fit_regressor
from .uncertainty import prune_weights

FloatArray = NDArray[np.float64]


# scikit-learn ships no type information: its classes are Any to mypy
class _JointCalibration(BaseEstimator):  # type: ignore[misc,unused-ignore]
    """The joint-calibration part of :class:`~gearshot.estimator.OneFaultShotEstimator`."""

    def _grade_joint(self, ctx: _FitContext, options: CalibrationOptions | None
                     ) -> _GradeChoice:
        """Calibration beyond the grade: (grade, gain, width, TF mode, noise) weighted by
        how well each explains the example's feature vector (paired databases only)."""
        from ..features import extract_features

        assert options is not None and ctx.twins is not None and ctx.cols is not None
        target, names = ctx.target, ctx.names
        match_cols = (list(range(len(names))) if options.features == "candidates"
                      else list(ctx.cols))
        example_sa, example_size = self._calibration_examples(ctx)
        x_ex = target_features(self, example_sa, target.scale, target.references,
                               target.healthy_mean, names, target.weights,
                               target.blend)[:, match_cols]
        spread = target.healthy_features[:, match_cols].std(axis=0, ddof=1)
        modes = options.tf_modes if target.transfer_function is not None else ("none",)
        n_near = int(options.n_near)
        rng = np.random.default_rng(ctx.noise_seed)
        noise0 = steps.residue_noise(target.residue_power, n_near + 50, ctx.inputs.n_points,
                                     rng)
        healthy_mean = {ns: extract_features(np.sqrt(ns) * noise0[n_near:],
                                             self._mesh_orders(),
                                             names=names)[:, match_cols].mean(axis=0)
                        for ns in options.noise_scales}
        keys: list[tuple[int, float, float, str, float]] = []
        parts = []
        for y0 in np.unique(example_size):
            keys, ll = self._joint_grid(ctx, options, float(y0), x_ex[example_size == y0],
                                        spread, modes, noise0, healthy_mean, match_cols)
            parts.append(ll)
        loglik = np.sum(parts, axis=0)
        z = (loglik - loglik.max()) / float(options.temperature)
        w_all = np.exp(z)
        w_all /= w_all.sum()
        order = np.argsort(-w_all, kind="stable")[: int(options.max_settings)]
        kept = prune_weights(order, w_all[order])
        settings: list[dict[str, Any]] = []
        for i, wt in kept.items():
            g, a, w, m, ns = keys[i]
            settings.append(dict(grade=g, gain=a, width=w, tf=m, noise=ns, weight=wt,
                                 log_likelihood=float(loglik[i])))
        models = [self._fit_setting_model(ctx, st) for st in settings]
        grid = dict(grade=np.array([k[0] for k in keys]), gain=np.array([k[1] for k in keys]),
                    width=np.array([k[2] for k in keys]), tf=np.array([k[3] for k in keys]),
                    noise=np.array([k[4] for k in keys]), log_likelihood=loglik,
                    weight=w_all)
        return _GradeChoice(int(settings[0]["grade"]), {}, None, settings, models, grid)

    def _calibration_examples(self, ctx: _FitContext) -> tuple[FloatArray, FloatArray]:
        """The faulty SAs (and sizes) the calibration explains: the one example.

        (The diagnostic :class:`gearshot.experiments.family.CalibrationOracle` returns the
        test set's faulty SAs instead, to measure what a perfect calibration gives.)"""
        assert ctx.inputs.faulty_example is not None and ctx.inputs.faulty_size is not None
        return (np.atleast_2d(ctx.inputs.faulty_example),
                np.array([float(ctx.inputs.faulty_size)]))

    def _joint_grid(self, ctx: _FitContext, options: CalibrationOptions, y0: float,
                    examples: FloatArray, spread: FloatArray, modes: Sequence[str],
                    noise0: FloatArray, healthy_mean: Mapping[float, FloatArray],
                    match_cols: list[int]) -> tuple[list[Any], FloatArray]:
        """Summed log-likelihood of ``examples`` (feature rows, all of size ``y0``) under
        every setting of the grid, and the settings' keys (grade, gain, width, tf, noise)."""
        from ..features import extract_features
        from .calibration import stretch_about

        assert ctx.twins is not None
        tfs = {"tf": ctx.target.transfer_function, "none": None}
        n_near, mesh = int(options.n_near), self._mesh_orders()
        keys: list[tuple[int, float, float, str, float]] = []
        sims: list[FloatArray] = []
        for g in ctx.grades:
            sa, y = ctx.by_grade[g]
            healthy = y == 0
            delta = sa - ctx.twins[g]
            faulty = np.flatnonzero(~healthy)
            centre = fault_centre(delta[faulty])
            near = faulty[np.argsort(np.abs(y[faulty] - y0), kind="stable")[:n_near]]
            blocks, block_keys = [], []
            for m in modes:
                scale = (steps.rms_scale(steps.propagate_simulated(sa[healthy], tfs[m]))
                         if self.rms_normalization else 1.0)
                ctx.cache[f"{g}/{m}"] = (scale, centre)
                for w in options.widths:
                    d = steps.propagate_simulated(stretch_about(delta[near], w, centre),
                                                  tfs[m]) / scale
                    for a in options.gains:
                        for ns in options.noise_scales:
                            blocks.append(a * d + np.sqrt(ns) * noise0[: near.size])
                            block_keys.append((int(g), float(a), float(w), m, float(ns)))
            feats = extract_features(np.vstack(blocks), mesh, names=ctx.names)[:, match_cols]
            for i, key in enumerate(block_keys):
                sims.append(feats[i * near.size:(i + 1) * near.size] - healthy_mean[key[4]])
                keys.append(key)
        loglik = np.sum([setting_log_likelihoods(x, sims, spread) for x in examples], axis=0)
        return keys, loglik

    def _fit_setting_model(self, ctx: _FitContext, setting: Mapping[str, Any]) -> StepModel:
        """Steps 4–8 for one calibration setting on its grade's whole simulated set."""
        assert ctx.twins is not None and ctx.cols is not None
        g = int(setting["grade"])
        sa, y = ctx.by_grade[g]
        healthy = y == 0
        scale, centre = ctx.cache[f"{g}/{setting['tf']}"]
        tf = ctx.target.transfer_function if setting["tf"] == "tf" else None
        d = setting_differences(sa - ctx.twins[g], tf, scale, gain=setting["gain"],
                                width=setting["width"], centre=centre)
        d = d + np.sqrt(setting["noise"]) * ctx.matched_noise(d.shape[0])
        selected = [ctx.names[c] for c in ctx.cols]
        feats, _ = steps.centred_features(d, mesh_order=self._mesh_orders(), names=selected,
                                          healthy_mask=healthy)
        X = np.vstack([feats, ctx.target.healthy_features[:, ctx.cols]])
        labels = np.concatenate([y, np.zeros(len(ctx.target.healthy_features))])
        opts = self._options()
        return fit_regressor(getattr(self, "estimator", "paper"), X, labels,
                             n_neighbors=opts.n_neighbors,
                             validation_fraction=opts.validation_fraction,
                             random_state=ctx.knn_seed,
                             n_own=len(ctx.target.healthy_features))
