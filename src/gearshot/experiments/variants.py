"""The paper's estimator variants (Fig. 13 and Fig. 14 ablations) as parameter sets."""

from __future__ import annotations

from types import MappingProxyType

__all__ = ["VARIANTS", "SIMULATED_VARIANTS", "RIG_VARIANTS", "variant_params"]

VARIANTS = MappingProxyType({
    # no domain adaptation: simulated signals as they are, raw target levels
    "before_da": dict(transfer_function="none", rms_normalization=False,
                      feature_selection=False),
    # domain adaptation by RMS normalization only
    "rms_only": dict(transfer_function="none", rms_normalization=True,
                     feature_selection=False),
    # full algorithm without step 1
    "no_feature_selection": dict(feature_selection=False),
    # full algorithm without step 2 (nominal grade)
    "no_tuning": dict(calibration="nominal"),
    # the full algorithm
    "full": dict(),
    # no faulty example at all: grade from healthy statistics (the paper's future work)
    "zero_shot": dict(calibration="zero_shot"),
})

SIMULATED_VARIANTS = ("before_da", "rms_only", "full")
RIG_VARIANTS = ("no_feature_selection", "no_tuning", "before_da", "rms_only", "full")


def variant_params(name):
    """Estimator parameters of a named variant."""
    from .._errors import GearshotError

    if name not in VARIANTS:
        raise GearshotError(f"unknown variant {name!r}; valid variants are {list(VARIANTS)}")
    return dict(VARIANTS[name])
