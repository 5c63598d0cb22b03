"""Input normalisation of the simulator's public functions: pair, grade, fault sizes,
seeds, speed/load profiles, one fault object per signal, profile-error draws."""

from __future__ import annotations

import numpy as np

from .._errors import GearshotError
from .._validation import check_finite, check_int, check_positive, describe
from ..fault_registry import fault_type_record
from .fault_types import fault_class
from .faults import ToothFault
from .geometry import GearPair
from .profile_errors import draw_profile_errors

__all__ = ["check_pair", "check_grade", "check_sizes", "as_rng", "profile", "profile_fn",
           "resolve_faults", "draw_errors"]


def check_pair(pair):
    if not isinstance(pair, GearPair):
        raise GearshotError(f"pair must be a GearPair (e.g. GearPair.paper()); got "
                            f"{describe(pair)}")


def check_grade(grade):
    return check_int(grade, "grade", minimum=1, maximum=12)


def check_sizes(fault_sizes):
    try:
        arr = (None if isinstance(fault_sizes, str)
               else np.atleast_1d(np.asarray(fault_sizes, dtype=float)))
    except (TypeError, ValueError):
        arr = None
    if arr is None or arr.ndim != 1 or arr.size == 0:
        raise GearshotError(f"fault_sizes must be a non-empty 1-D sequence; got "
                            f"{describe(fault_sizes)}")
    check_finite(arr, "fault_sizes")
    bad = (arr < 0) | (arr > 1)
    if bad.any():
        raise GearshotError(f"fault_sizes must lie in [0, 1]; got {arr[bad][0]!r} "
                            f"at index {int(np.flatnonzero(bad)[0])}")
    return arr


def as_rng(rng, n=None):
    """A Generator, or a list of Generators (one per signal) when ``rng`` is a list."""
    if isinstance(rng, (list, tuple)):
        if n is not None and len(rng) != n:
            raise GearshotError(f"rng must hold one seed per signal ({n}); got {len(rng)}")
        return [as_rng(r) for r in rng]
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None or isinstance(rng, (int, np.integer, np.random.SeedSequence)):
        return np.random.default_rng(rng)
    raise GearshotError(f"rng must be a numpy Generator, a seed or None; got {describe(rng)}")


def profile(value, name, times):
    """Constant, callable f(t) or array (resampled onto ``times``) -> array over times."""
    if callable(value):
        arr = np.asarray(value(times), dtype=float)
        if arr.shape == ():
            arr = np.full(times.shape, float(arr))
        if arr.shape != times.shape:
            raise GearshotError(f"{name}(t) must return an array shaped like t {times.shape};"
                                f" got shape {arr.shape}")
    elif np.ndim(value) == 0:
        arr = np.full(times.shape, check_positive(value, name))
    else:
        src = np.asarray(value, dtype=float)
        if src.ndim != 1 or src.size < 2:
            raise GearshotError(f"{name} must be a scalar, a callable or a 1-D array of "
                                f">= 2 samples; got {describe(value)}")
        arr = src
    check_finite(arr, name)
    if np.any(arr <= 0):
        raise GearshotError(f"{name} must be > 0 everywhere; got minimum {arr.min()!r}")
    return arr


def profile_fn(value, name, fs):
    """A vectorised f(t) for a constant, a callable or samples at ``fs``."""
    if callable(value):
        return lambda t: profile(value, name, t)
    if np.ndim(value) == 0:
        v = check_positive(value, name)
        return lambda t: np.full(np.shape(t), v)
    src = profile(value, name, np.zeros(1))
    t_src = np.arange(src.size) / fs
    return lambda t: np.interp(t, t_src, src)


def resolve_faults(fault_sizes, faults, center, depth, fault_type="ftff"
                   ) -> list[ToothFault]:
    """One fault object per signal, from sizes of ``fault_type`` (its class, with the
    shared options ``center``/``depth`` its record takes) or from fault objects."""
    record = fault_type_record(fault_type)      # refuses an unknown type, naming the known
    if faults is not None:
        if fault_sizes is not None:
            raise GearshotError("give fault_sizes or faults, not both")
        faults = list(faults) if not isinstance(faults, ToothFault) else [faults]
        if not faults:
            raise GearshotError("faults must not be empty")
        for i, f in enumerate(faults):
            if f is not None and not isinstance(f, ToothFault):
                raise GearshotError(f"faults[{i}] must be a ToothFault (e.g. Fault.ftff(0.3))"
                                    f" or None; got {describe(f)}")
        return [f if f is not None else ToothFault() for f in faults]
    if fault_sizes is None:
        raise GearshotError("give fault_sizes (FTFF sizes) or faults (fault objects)")
    sizes = check_sizes(fault_sizes)
    shared = {"center": center, "depth": depth}
    options = {k: shared[k] for k in record.options}
    cls = fault_class(fault_type)     # sizes as given: an FTFF off the profile is an error
    return [cls(size=float(y), **options) for y in sizes]


def draw_errors(pair, grade, n, rng, same_gear, average_pinion):
    """Gear and pinion profile errors of ``n`` signals (lists of ToothProfileErrors)."""
    if isinstance(rng, list):          # one generator per signal
        ge = [draw_profile_errors(pair.z_gear, grade, r) for r in rng]
        pe = [draw_profile_errors(pair.z_pinion, grade, r) for r in rng]
        if average_pinion:
            pe = [e.mean_tooth() for e in pe]
        return ge, pe
    if same_gear:
        ge = [draw_profile_errors(pair.z_gear, grade, rng)] * n
        pe = [draw_profile_errors(pair.z_pinion, grade, rng)] * n
    else:
        ge, pe = [], []
        for _ in range(n):
            ge.append(draw_profile_errors(pair.z_gear, grade, rng))
            pe.append(draw_profile_errors(pair.z_pinion, grade, rng))
    if average_pinion:
        pe = [e.mean_tooth() for e in pe]
    return ge, pe
