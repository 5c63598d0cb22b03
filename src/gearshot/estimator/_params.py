"""Declarative parameter constraints (in the style of scikit-learn's ``_parameter_constraints``).

An estimator lists, per ``__init__`` parameter, the constraints a value may satisfy
(any one suffices); :func:`validate_params` checks them all at the start of ``fit`` and
raises a :class:`~gearshot.GearshotError` that names the parameter, quotes the value and
says what was expected.
"""

from __future__ import annotations

import numbers
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._errors import GearshotError
from .._validation import describe

__all__ = [
    "Constraint",
    "Interval",
    "Options",
    "Boolean",
    "NoneValue",
    "IntegerSequence",
    "NameSequence",
    "ArrayOrObject",
    "RandomStateValue",
    "Resolvable",
    "validate_params",
    "check_estimator_params",
]


class Constraint:
    """A set of accepted values: :meth:`accepts` tests one, ``str()`` describes them."""

    def accepts(self, value: Any) -> bool:  # pragma: no cover - abstract
        raise NotImplementedError


def _is_int(value: Any) -> bool:
    return isinstance(value, numbers.Integral) and not isinstance(value, (bool, np.bool_))


def _is_real(value: Any) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))


def _is_collection(value: Any) -> bool:
    """Iterable more than once and not a string (lists, tuples, ranges, arrays)."""
    return (isinstance(value, Iterable) and not isinstance(value, (str, bytes, Iterator))
            and not _is_int(value))


@dataclass(frozen=True)
class Interval(Constraint):
    """Finite integers (``kind=int``) or reals (``kind=float``) in an interval.

    ``low``/``high`` of None mean unbounded; ``closed`` is "both", "left", "right" or
    "neither".
    """

    kind: type
    low: float | None
    high: float | None
    closed: str = "both"

    def accepts(self, value: Any) -> bool:
        if not (_is_int(value) if self.kind is int else _is_real(value)):
            return False
        v = float(value)
        if not np.isfinite(v):
            return False
        if self.low is not None and (v < self.low or (v == self.low and self.closed in
                                                      ("right", "neither"))):
            return False
        return not (self.high is not None and (v > self.high or (
            v == self.high and self.closed in ("left", "neither"))))

    def __str__(self) -> str:
        what = "an integer" if self.kind is int else "a finite real number"
        left = "[" if self.closed in ("both", "left") and self.low is not None else "("
        right = "]" if self.closed in ("both", "right") and self.high is not None else ")"
        low = "-inf" if self.low is None else f"{self.low:g}"
        high = "inf" if self.high is None else f"{self.high:g}"
        return f"{what} in {left}{low}, {high}{right}"


@dataclass(frozen=True)
class Options(Constraint):
    """One of a few strings."""

    values: tuple[str, ...]

    def accepts(self, value: Any) -> bool:
        return isinstance(value, str) and value in self.values

    def __str__(self) -> str:
        return "one of " + ", ".join(repr(v) for v in self.values)


class Boolean(Constraint):
    """True or False (Python or NumPy bool)."""

    def accepts(self, value: Any) -> bool:
        return isinstance(value, (bool, np.bool_))

    def __str__(self) -> str:
        return "a bool"


class NoneValue(Constraint):
    """None."""

    def accepts(self, value: Any) -> bool:
        return value is None

    def __str__(self) -> str:
        return "None"


@dataclass(frozen=True)
class IntegerSequence(Constraint):
    """A non-empty collection (no string or one-shot iterator) of integers in [low, high]."""

    low: int | None = None
    high: int | None = None

    def accepts(self, value: Any) -> bool:
        if not _is_collection(value):
            return False
        item = Interval(int, self.low, self.high)
        if isinstance(value, range):  # integers: in [low, high] when its ends are
            return len(value) > 0 and item.accepts(min(value)) and item.accepts(max(value))
        items = list(value)
        return bool(items) and all(item.accepts(v) for v in items)

    def __str__(self) -> str:
        return f"a non-empty sequence of {Interval(int, self.low, self.high)}"


@dataclass(frozen=True)
class NameSequence(Constraint):
    """A non-empty collection (no string or one-shot iterator) of names from choices()."""

    choices: Callable[[], Sequence[str]]

    def accepts(self, value: Any) -> bool:
        if not _is_collection(value):
            return False
        names = list(value)
        valid = set(self.choices())
        return bool(names) and all(isinstance(n, str) and n in valid for n in names)

    def __str__(self) -> str:
        return f"a non-empty sequence of names from {list(self.choices())}"


@dataclass(frozen=True)
class ArrayOrObject(Constraint):
    """A non-empty 1-D numeric (real or complex) array-like, or an object with ``method``."""

    method: str

    def accepts(self, value: Any) -> bool:
        if hasattr(value, self.method):
            return True
        if isinstance(value, (str, bytes)):
            return False
        try:
            arr = np.asarray(value)
        except (TypeError, ValueError):  # ragged nesting and the like
            return False
        return arr.ndim == 1 and arr.size > 0 and (
            np.issubdtype(arr.dtype, np.number) and not np.issubdtype(arr.dtype, np.bool_))

    def __str__(self) -> str:
        return f"a 1-D numeric array or an object with {self.method}()"


class RandomStateValue(Constraint):
    """None, an integer >= 0, a ``numpy.random.RandomState`` or a ``numpy.random.Generator``."""

    def accepts(self, value: Any) -> bool:
        return (value is None or (_is_int(value) and value >= 0)
                or isinstance(value, (np.random.RandomState, np.random.Generator)))

    def __str__(self) -> str:
        return "None, an integer >= 0, a numpy RandomState or a numpy Generator"


@dataclass(frozen=True)
class Resolvable(Constraint):
    """A value that ``resolve`` turns into its object without raising a GearshotError
    (a strategy name, an options object or a mapping of its fields).

    When it refuses a mapping, :meth:`reason` gives ``resolve``'s own message (naming the
    inner field and value), which :func:`validate_params` reports after the parameter.
    """

    resolve: Callable[[Any], Any]
    description: str

    def reason(self, value: Any) -> str | None:
        try:
            self.resolve(value)
        except (GearshotError, TypeError) as exc:
            return str(exc)
        return None

    def accepts(self, value: Any) -> bool:
        return self.reason(value) is None

    def __str__(self) -> str:
        return self.description


def validate_params(params: Mapping[str, Any],
                    constraints: Mapping[str, Sequence[Constraint]]) -> None:
    """Raise a :class:`GearshotError` for the first parameter no constraint accepts.

    Parameters
    ----------
    params : mapping name → value
        E.g. ``estimator.get_params(deep=False)``.
    constraints : mapping name → sequence of Constraint
        Every parameter must have an entry (a value passes when any constraint accepts it).
    """
    missing = sorted(set(params) - set(constraints))
    if missing:
        raise GearshotError(f"no constraint declared for parameter(s) {missing}")
    for name, value in params.items():
        allowed = constraints[name]
        if not any(c.accepts(value) for c in allowed):
            reasons = [c.reason(value) for c in allowed if isinstance(c, Resolvable)]
            if reasons and reasons[0] is not None and isinstance(value, Mapping):
                raise GearshotError(f"{name}: {reasons[0]}")
            expected = " or ".join(str(c) for c in allowed)
            raise GearshotError(f"{name} must be {expected}; got {describe(value)}")


def check_estimator_params(estimator: Any) -> None:
    """Check an estimator's parameters against its ``_parameter_constraints`` table.

    The public entry for callers outside the estimator package (the CLI's ``--param``
    parsing): the same check ``fit`` runs first, without fitting.

    Parameters
    ----------
    estimator : object with ``get_params`` and ``_parameter_constraints``
        E.g. a :class:`~gearshot.estimator.OneFaultShotEstimator`.

    Raises
    ------
    GearshotError
        Naming the first parameter no constraint accepts, and its value.

    Examples
    --------
    >>> from gearshot.estimator import OneFaultShotEstimator, check_estimator_params
    >>> check_estimator_params(OneFaultShotEstimator())
    >>> check_estimator_params(OneFaultShotEstimator(grades=[0]))
    Traceback (most recent call last):
    ...
    gearshot._errors.GearshotError: grades must be ...
    """
    validate_params(estimator.get_params(deep=False), estimator._parameter_constraints)
