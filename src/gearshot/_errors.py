"""The exception types of gearshot: one base, :class:`GearshotError`."""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

__all__ = ["GearshotError", "NotFittedError"]


class GearshotError(ValueError):
    """Raised on invalid input or an unusable file.

    Subclasses :class:`ValueError` so that callers who already guard numeric code with
    ``except ValueError`` keep working. Messages name the offending parameter (or file)
    and quote the bad value.
    """


_NOT_FITTED_DOC = """Raised when a fitted estimator's method is called before ``fit``.

    Both a :class:`GearshotError` and scikit-learn's
    :class:`sklearn.exceptions.NotFittedError` (itself a ``ValueError`` and an
    ``AttributeError``), so ``except GearshotError`` and scikit-learn's own checks both
    catch it.
    """

if TYPE_CHECKING:
    from sklearn.exceptions import NotFittedError as _SklearnNotFittedError

    class NotFittedError(GearshotError, _SklearnNotFittedError):
        __doc__ = _NOT_FITTED_DOC
else:
    _lock = threading.Lock()

    def __getattr__(name: str) -> Any:
        # NotFittedError subclasses scikit-learn's, and importing scikit-learn takes
        # seconds; the class is made on first use so that ``import gearshot`` stays light.
        if name != "NotFittedError":
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
        with _lock:
            if "NotFittedError" not in globals():
                from sklearn.exceptions import NotFittedError as _SklearnNotFittedError

                globals()["NotFittedError"] = type(
                    "NotFittedError", (GearshotError, _SklearnNotFittedError),
                    {"__doc__": _NOT_FITTED_DOC, "__module__": __name__})
        return globals()["NotFittedError"]
