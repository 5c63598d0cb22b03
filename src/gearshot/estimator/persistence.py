"""Saving and loading fitted estimators (joblib, with version metadata)."""

from __future__ import annotations

import os
import warnings
from pathlib import Path
from typing import Any

import joblib
import sklearn

from .. import __version__
from .._atomic import atomic_path
from .._errors import GearshotError, NotFittedError

__all__ = ["save_estimator", "load_estimator"]

_FORMAT = "gearshot-estimator/1"


def save_estimator(estimator: Any, path: str | os.PathLike[str]) -> None:
    """Write the fitted ``estimator`` to ``path`` atomically (temporary file, then rename).

    Raises
    ------
    NotFittedError
        When ``estimator`` has not been fitted.
    """
    if not hasattr(estimator, "model_"):
        raise NotFittedError(f"estimator {type(estimator).__name__} is not fitted; fit it "
                             f"before saving")
    path = Path(path)
    payload = {"format": _FORMAT, "gearshot_version": __version__,
               "sklearn_version": sklearn.__version__, "estimator": estimator}
    with atomic_path(path, make_parents=True) as tmp:
        joblib.dump(payload, tmp)


def load_estimator(path: str | os.PathLike[str]) -> Any:
    """Read an estimator written by :func:`save_estimator`; warn on version differences."""
    path = Path(path)
    if not path.is_file():
        raise GearshotError(f"estimator file {str(path)!r} does not exist")
    try:
        payload = joblib.load(path)
    except Exception as exc:
        raise GearshotError(f"{str(path)!r} is not a readable gearshot estimator ({exc})") \
            from None
    if not isinstance(payload, dict) or payload.get("format") != _FORMAT:
        raise GearshotError(f"{str(path)!r} is not a gearshot estimator file")
    for key, now in (("gearshot_version", __version__), ("sklearn_version",
                                                        sklearn.__version__)):
        if payload.get(key) != now:
            warnings.warn(f"{path} was saved with {key.split('_')[0]} {payload.get(key)}; "
                          f"this is {now}", UserWarning, stacklevel=3)
    return payload["estimator"]
