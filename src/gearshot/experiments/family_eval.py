"""One family rig's evaluation: every (example draw, estimator variant), with the
diagnostics of issue #19's error budget (oracle path, oracle calibration, true grade) and
the interval coverage at several model discrepancies. Runs on a Dask worker or in-process
(:func:`family_task`)."""

from __future__ import annotations

import time
from dataclasses import asdict
from pathlib import Path

import numpy as np

from .._errors import GearshotError
from .family_rigs import FamilyRig, family_paths, rig_segments, true_path_on_grid

__all__ = ["DIAGNOSTIC_VARIANTS", "DISCREPANCIES", "family_task"]

# Diagnostics only (they use the rig's hidden truth or the test set): the full algorithm
# with the true transfer path instead of its blind estimate (oracle_tf), with its
# calibration chosen on every faulty test SA instead of the one example
# (oracle_calibration), with both (oracle_both), or with the rig's true grade and no
# tuning (true_grade). They make the error budget of issue #19.
DIAGNOSTIC_VARIANTS = ("oracle_tf", "true_grade", "oracle_calibration", "oracle_both")


def _calibration_oracle_class():
    from ..estimator import OneFaultShotEstimator

    class CalibrationOracle(OneFaultShotEstimator):
        """Diagnostic: the joint calibration explains every faulty SA of ``oracle_sa``
        (sizes ``oracle_size``) instead of the one example: the best calibration the
        grid can give on this target (an in-sample oracle; never a product)."""

        oracle_sa = None
        oracle_size = None

        def _calibration_examples(self, ctx):
            keep = np.asarray(self.oracle_size) > 0
            return (np.asarray(self.oracle_sa, float)[keep],
                    np.asarray(self.oracle_size, float)[keep])

    return CalibrationOracle




def _diagnostic_params(name, rig, paths):
    if name == "oracle_tf":
        return dict(transfer_function=true_path_on_grid(rig, paths))
    if name == "oracle_both":
        return dict(transfer_function=true_path_on_grid(rig, paths), calibration="joint")
    if name == "true_grade":
        return dict(calibration="nominal", nominal_grade=int(rig.grade))
    if name == "oracle_calibration":
        return dict(calibration="joint")
    raise GearshotError(f"unknown diagnostic variant {name!r}")


DISCREPANCIES = (0.0, 0.04, 0.06, 0.08, 0.10, 0.12, 0.14, 0.16, 0.20, 0.24)


def _interval_sweep(est, test_sa, test_size, coverage=0.9):
    """Coverage and mean width of the ``coverage`` intervals at several model
    discrepancies (one feature extraction; for choosing the discrepancy on the dev range),
    plus the grade weights."""
    from ..estimator.uncertainty import mixture_interval

    X = est.features_of(test_sa)
    settings, models = est.calibration_["settings"], est.setting_models_
    preds = {i: m.predict(X) for i, m in enumerate(models)}
    residuals = {i: m.validation_residuals for i, m in enumerate(models)}
    weights = {i: st["weight"] for i, st in enumerate(settings)}
    cov, width = {}, {}
    for d in DISCREPANCIES:
        low, high = mixture_interval(preds, weights, residuals, coverage, discrepancy=d)
        low, high = np.clip(low, 0, 1), np.clip(high, 0, 1)
        cov[f"{d:g}"] = float(np.mean((test_size >= low - 1e-12) & (test_size <= high + 1e-12)))
        width[f"{d:g}"] = float(np.mean(high - low))
    floor = sum(st["weight"] * float(m.validation_mae[m.n_neighbors - 1])
                for st, m in zip(settings, models))
    return {"coverage_by_discrepancy": cov, "width_by_discrepancy": width,
            "simulated_floor": floor,
            "grade_weights": {str(g): round(float(w), 4) for g, w in est.grade_weights_.items()},
            "calibration": [{k: (round(v, 4) if isinstance(v, float) else v)
                             for k, v in st.items()} for st in settings],
            "n_selected": len(est.selected_features_)}


def _detection_check(est, pred, test_size) -> dict:
    """The fit's ``detection_limit_`` and how the test segments fall about it (issue #30):
    the share of healthy segments below it and of faulty ones of size ≥ 2 × limit above."""
    limit = getattr(est, "detection_limit_", None)
    if limit is None:
        return {}
    below = pred < limit
    healthy, big = test_size == 0, test_size >= 2 * limit
    return dict(detection_limit=float(limit), n_healthy_test=int(healthy.sum()),
                healthy_below=int(np.sum(below & healthy)), n_faulty_2x=int(big.sum()),
                faulty_2x_above=int(np.sum(~below & big)))


def family_task(spec: dict) -> list[dict]:
    """Every (draw, variant) of one rig; runs on a Dask worker or in-process."""
    import dask

    # the database's Zarr blocks are loaded here, not as tasks of the cluster whose
    # every worker thread is busy with a rig (that waits forever)
    with dask.config.set(scheduler="synchronous"):
        return _family_rows(spec)


def _family_rows(spec: dict) -> list[dict]:
    from ..sim import load_database
    from ..transfer import TransferFunctionBank
    from .rig import rig_dataset
    from .runner import evaluate_variants

    rig = FamilyRig(**spec["rig"])
    paths = family_paths(spec["frf_folder"], n_synthetic=spec["n_synthetic"],
                         seed=spec["bank_seed"])
    t0 = time.perf_counter()
    index, segments = rig_segments(rig, paths, Path(spec["cache_dir"]), spec["campaign"])
    record_seconds = time.perf_counter() - t0
    database = load_database(spec["store"], speed=rig.speed, load=rig.load)
    selection = TransferFunctionBank.synthetic(1, rng=np.random.default_rng([rig.seed, 99]))[0]
    rows = []
    checked = bool(spec.get("checked", False))   # fit as gearshot predict does
    for draw in spec["draws"]:
        todo = [v for v in spec["variants"] if (draw, v) not in spec["done"]]
        if not todo:
            continue
        ds = rig_dataset(index, random_state=[rig.seed, draw], segments=segments)
        out = []
        plain = [v for v in todo if v not in DIAGNOSTIC_VARIANTS]
        if plain:
            out += evaluate_variants(ds.fit_args(database, checked), ds.test_sa, ds.test_size,
                                     variants=plain, selection_tf=selection,
                                     fit_kwargs=ds.fit_kwargs(checked=checked),
                                     random_state=1000 * rig.seed + draw,
                                     keep_estimators=True, **spec["params"])
        for name in (v for v in todo if v in DIAGNOSTIC_VARIANTS):
            extra = _diagnostic_params(name, rig, paths)
            factory = None
            if name in ("oracle_calibration", "oracle_both"):
                oracle = _calibration_oracle_class()
                oracle.oracle_sa, oracle.oracle_size = ds.test_sa, ds.test_size
                factory = oracle
            row, = evaluate_variants(ds.fit_args(database, checked), ds.test_sa, ds.test_size,
                                     variants=["full"], selection_tf=selection,
                                     fit_kwargs=ds.fit_kwargs(checked=checked),
                                     random_state=1000 * rig.seed + draw,
                                     keep_estimators=True, estimator_class=factory,
                                     **{**spec["params"], **extra})
            row["variant"] = name
            out.append(row)
        for row in out:
            pred = row.pop("prediction")
            row["fitted_grade"] = row.pop("grade")  # "grade" is the rig's true grade
            est = row.pop("estimator")
            row["fit_check"] = est.fit_check_.verdict
            row["example_contrast"] = est.fit_check_.example_contrast
            row.update(_interval_sweep(est, ds.test_sa, ds.test_size))
            row.update(_detection_check(est, pred, ds.test_size))
            by_size = {f"{y:.2f}": float(np.mean(pred[ds.test_size == y]))
                       for y in np.unique(ds.test_size)}
            rows.append(dict(config=spec["config"], **asdict(rig), draw=draw,
                             example_size=ds.faulty_size, n_test=int(ds.test_size.size),
                             mean_prediction=by_size, record_seconds=record_seconds,
                             **{k: (v if not isinstance(v, np.generic) else v.item())
                                for k, v in row.items()}))
    return rows

