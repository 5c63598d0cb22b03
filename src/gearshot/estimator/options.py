"""The estimator's research knobs: :class:`EstimatorOptions`, one constructor parameter.

:class:`~gearshot.estimator.OneFaultShotEstimator` keeps the choices a user makes in its
public constructor (features, grades, the calibration strategy, the domain adaptation,
the mesh orders, the fault type, the interval width, the seed). The settings below were
chosen once on a development range, or exist to reproduce the paper's literal rules and
earlier screens; they are set through ``options=EstimatorOptions(...)`` (or a mapping of
its fields, e.g. ``--param 'options={"selection_threshold": 0.2}'`` on the command
line). Their defaults are the product.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass, fields
from typing import Any

from .._errors import GearshotError
from ._params import Constraint, IntegerSequence, Interval, Options, validate_params

__all__ = ["EstimatorOptions", "resolve_options"]


@dataclass(frozen=True)
class EstimatorOptions:
    """Research settings of :class:`~gearshot.estimator.OneFaultShotEstimator`.

    Every field is checked when the options are made; a bad value raises a
    :class:`~gearshot.GearshotError` naming the field and quoting the value.

    Attributes
    ----------
    selection_threshold : float > 0, default 0.10
        Step 1 keeps the features whose invariance error is below this.
    selection_fallback : {"best", "all"}, default "best"
        What step 1 keeps when no feature passes the threshold: the one with the smallest
        error, or every candidate (the invariance test then tells the features apart by
        how badly each fails, and "all" does not stake the estimate on one of them).
    tuning_smoothing : {"isotonic", "none"}, default "isotonic"
        Step 2 fits the example's predicted size over the grades by a monotone curve
        before choosing (robust to KNN scatter); "none" is the paper's literal nearest
        rule (RESULTS: no measurable difference on the rig family).
    zero_shot_signature : {"raw", "denoised"}, default "denoised"
        The target's healthy signature of the zero-shot grade match: as measured, or with
        the target's non-synchronous residue (half the mean square of its healthy
        difference signals off the mesh harmonics) taken off the off-harmonic power
        first (:func:`~gearshot.estimator.zero_shot.healthy_signature`); simulated SAs
        have no residue, so the raw target signature points at rougher grades.
        "denoised" was chosen on the rig family's development range (zero-shot MAE
        16.4 % against 18.8 % raw, benchmarks/RESULTS.md).
    zero_shot_weighting : {"soft", "best"}, default "soft"
        With ``calibration="zero_shot"``: weight the grades by how well their simulated
        healthy signatures match the target's
        (:func:`~gearshot.estimator.signature_weights`, uniform when none matches), or
        keep the one best-matching grade.
    simulated_reference : {"auto", "first_healthy", "twin"}, default "auto"
        What step 6 subtracts on the simulated side (in step 1's simulated sets and in
        the grade models). "first_healthy" (the paper): the first healthy simulated SA,
        a *different* gear from every other signal's (profile errors are drawn per
        signal), so every simulated difference carries the profile-error difference of
        two gears, a floor the target (one gear against itself) does not have. "twin":
        each signal's own healthy twin (same profile errors, no fault; needs a paired
        database, ``build_database(..., paired=True)``), so the simulated difference is
        the fault signature alone; in the grade models the target's non-synchronous
        residue is then matched by adding Gaussian noise with the power spectrum of the
        target's healthy difference signals (noise matching, seeded by the
        ``match_noise`` step seed). "auto": "twin" when the database holds twins, else
        "first_healthy". The one used is ``simulated_reference_``. On the rig family's
        development range the twin reference scored 11.3 % against 12.0 % (and 14.2 %
        when step 1 kept the paper's reference: both steps must subtract the same).
    upsample : int >= 1, default 100
        Delay resolution (1/upsample sample) of the target's harmonic suppression (step 6).
    n_neighbors : sequence of int >= 1, default range(1, 101)
        Candidate K of step 8.
    validation_fraction : float in (0, 1), default 0.3
        Share of step 8's training rows in the split that chooses K (the paper's 70/30).
    residue_whitening : {"auto", "on", "off"}, default "auto"
        Weight the difference signals of both sides, order by order, by the inverse of
        the target's healthy residue (:mod:`gearshot.estimator.whitening`). "auto": on,
        except for the paper's estimator (``estimator="paper"``), which keeps its literal
        pipeline. Chosen on the rig family's development range (RESULTS, "Estimator").
    residue_draws : {"auto", "recorded", "gaussian"}, default "auto"
        What the grade models add to each simulated difference as the target's residue
        (with twins): one of the target's own healthy difference signals, turned by a
        random number of points and given a random sign ("recorded": the spread of levels
        between runs kept), or Gaussian noise with their mean power spectrum
        ("gaussian"). "auto": recorded when the fit whitens, else Gaussian. Chosen on the
        rig family's development range (RESULTS, "Estimator").
    reference_blend : int >= 1 or "auto", default "auto"
        How many delay-aligned healthy references step 6 subtracts from a target SA: 1,
        the paper's best single reference; more, the least-squares blend of that many
        best-aligned ones (:func:`~gearshot.signal.reference_blend.subtract_blend`),
        which follows a healthy pattern that moves from segment to segment (a rough
        gear's vibration through a lightly damped path while the speed drifts). "auto":
        3 in a fit that whitens its residue (``residue_whitening``: healthy recordings
        of 3 runs or more, not the paper's estimator), else 1 (blended within one run,
        the references follow that run closer than the next). Chosen on the rig
        family's development range and PHM09's 30 Hz cells (RESULTS, "Estimator").

    Examples
    --------
    >>> from gearshot.estimator import EstimatorOptions, OneFaultShotEstimator
    >>> est = OneFaultShotEstimator(options=EstimatorOptions(selection_threshold=0.2))
    >>> est.options.selection_threshold, est.options.upsample
    (0.2, 100)
    >>> EstimatorOptions(upsample=0)
    Traceback (most recent call last):
    ...
    gearshot._errors.GearshotError: upsample must be an integer in [1, inf); got 0
    """

    selection_threshold: float = 0.10
    selection_fallback: str = "best"
    tuning_smoothing: str = "isotonic"
    zero_shot_signature: str = "denoised"
    zero_shot_weighting: str = "soft"
    simulated_reference: str = "auto"
    upsample: int = 100
    n_neighbors: Iterable[int] = range(1, 101)
    validation_fraction: float = 0.3
    residue_whitening: str = "auto"
    residue_draws: str = "auto"
    reference_blend: int | str = "auto"

    def __post_init__(self) -> None:
        validate_params({f.name: getattr(self, f.name) for f in fields(self)},
                        OPTION_CONSTRAINTS)

    def as_dict(self) -> dict[str, Any]:
        """The fields as a dict (``n_neighbors`` as given)."""
        return asdict(self)


#: What each field of :class:`EstimatorOptions` accepts.
OPTION_CONSTRAINTS: dict[str, list[Constraint]] = {
    "selection_threshold": [Interval(float, 0, None, closed="neither")],
    "selection_fallback": [Options(("best", "all"))],
    "tuning_smoothing": [Options(("isotonic", "none"))],
    "zero_shot_signature": [Options(("raw", "denoised"))],
    "zero_shot_weighting": [Options(("soft", "best"))],
    "simulated_reference": [Options(("auto", "first_healthy", "twin"))],
    "upsample": [Interval(int, 1, None)],
    "n_neighbors": [IntegerSequence(1, None)],
    "validation_fraction": [Interval(float, 0, 1, closed="neither")],
    "residue_whitening": [Options(("auto", "on", "off"))],
    "residue_draws": [Options(("auto", "recorded", "gaussian"))],
    "reference_blend": [Options(("auto",)), Interval(int, 1, None)],
}


def resolve_options(value: Any) -> EstimatorOptions:
    """The :class:`EstimatorOptions` of ``options=``: None → the defaults, a mapping → its
    fields over the defaults, an :class:`EstimatorOptions` → itself.

    Raises
    ------
    GearshotError
        For an unknown field, a bad field value (naming both) or another type.
    """
    if value is None:
        return EstimatorOptions()
    if isinstance(value, EstimatorOptions):
        return value
    if isinstance(value, Mapping):
        known = [f.name for f in fields(EstimatorOptions)]
        unknown = sorted(str(k) for k in set(value) - set(known))
        if unknown:
            raise GearshotError(f"options has unknown field(s) {unknown}; the fields are "
                                f"{known}")
        return EstimatorOptions(**dict(value))
    raise GearshotError(f"options must be None, an EstimatorOptions or a mapping of its "
                        f"fields; got {value!r}")
