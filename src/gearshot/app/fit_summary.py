"""What a fitted estimator chose, as plain values for a predict table's ``attrs`` (and so
the ``fit`` of its JSON)."""

from __future__ import annotations

__all__ = ["fit_attrs"]


def fit_attrs(est, healthy_speeds=None) -> dict:
    """What a fitted estimator chose, for a predict table's ``attrs`` (and so its JSON's
    ``fit``): ``grade``, ``calibration`` (strategy and the weighted settings' grades),
    ``simulated_reference`` and ``detection_limit`` (the smallest size the fit tells apart
    from healthy, :attr:`~gearshot.estimator.OneFaultShotEstimator.detection_limit_`);
    with ``healthy_speeds`` (each healthy recording's measured speed), ``fit_warning``:
    :func:`gearshot.monitor.trust.runs_warning` of them (None when it has nothing to say).
    """
    from ..monitor.trust import runs_warning

    calibration = getattr(est, "calibration_", None) or {}
    settings = [{"grade": int(s["grade"]), "weight": float(s.get("weight", 1.0))}
                for s in calibration.get("settings", []) if "grade" in s]
    grade = getattr(est, "grade_", None)
    limit = getattr(est, "detection_limit_", None)
    extra = {} if healthy_speeds is None else {"fit_warning": runs_warning(healthy_speeds)}
    return {**extra, "grade": None if grade is None else int(grade),
            "calibration": {"strategy": calibration.get("strategy"), "settings": settings},
            "simulated_reference": getattr(est, "simulated_reference_", None),
            "detection_limit": None if limit is None else float(limit)}
