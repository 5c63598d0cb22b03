"""Saving and loading fitted estimators: skops files, which run no code on load.

:func:`save_estimator` writes the skops format (:mod:`skops.io`: a zip of JSON and ``.npy``
arrays; no pickle). :func:`load_estimator` lists the types a file would construct and
loads it only when every one is a type a fitted gearshot estimator is made of (numpy
arrays, builtins, scikit-learn's scaler, KNN regressor and its KD-tree, gearshot's
estimator and step-8 model): a crafted file that names anything else (``os.system``,
``builtins.eval``, ...) is refused before anything in it is constructed.

Files written by gearshot before this format are joblib pickles: loading a pickle runs
whatever code it holds, so they are refused unless the caller says ``trusted=True``
(only for files you made yourself); save them again to get a safe file.
"""

from __future__ import annotations

import os
import warnings
import zipfile
from pathlib import Path
from typing import Any

import sklearn

from .. import __version__
from .._atomic import atomic_path
from .._errors import GearshotError, NotFittedError

__all__ = ["save_estimator", "load_estimator", "read_skops", "SAFE_TYPES"]

_FORMAT = "gearshot-estimator/2"
_PICKLE_FORMAT = "gearshot-estimator/1"

#: Types beyond skops' defaults (numpy, builtins, scikit-learn estimators) that a fitted
#: estimator holds; constructing them runs none of a file's code.
SAFE_TYPES = (
    "builtins.range",
    "gearshot.estimator._model.OneFaultShotEstimator",
    "gearshot.estimator.knn.KnnModel",
    "gearshot.estimator.regressors.LearnedModel",
    "gearshot.estimator.regressors.ScoreIsotonic",
    "gearshot.estimator.calibration.CalibrationOptions",
    "gearshot.estimator.options.EstimatorOptions",
    "gearshot.estimator.comparability.Comparability",
    "gearshot.estimator.comparability.ComparabilityReference",
    "gearshot.estimator.fit_check.FitCheck",
    "gearshot.estimator.drift.Drift",
    "sklearn.metrics._dist_metrics.EuclideanDistance64",
    "sklearn.neighbors._kd_tree.KDTree",
    "sklearn.ensemble._hist_gradient_boosting.predictor.TreePredictor",
)


def save_estimator(estimator: Any, path: str | os.PathLike[str]) -> None:
    """Write the fitted ``estimator`` to ``path`` (skops format) atomically.

    Raises
    ------
    NotFittedError
        When ``estimator`` has not been fitted.
    """
    import skops.io as sio

    if not hasattr(estimator, "model_"):
        raise NotFittedError(f"estimator {type(estimator).__name__} is not fitted; fit it "
                             f"before saving")
    path = Path(path)
    payload = {"format": _FORMAT, "gearshot_version": __version__,
               "sklearn_version": sklearn.__version__, "estimator": estimator}
    with atomic_path(path, make_parents=True) as tmp:
        sio.dump(payload, tmp)


def load_estimator(path: str | os.PathLike[str], *, trusted: bool = False) -> Any:
    """Read an estimator written by :func:`save_estimator`; warn on version differences.

    Parameters
    ----------
    path : str or path-like
        The file.
    trusted : bool, default False
        Load even what cannot be checked: a skops file naming types outside
        :data:`SAFE_TYPES`, or a joblib pickle from gearshot before the skops format.
        **Loading such a file runs any code it holds**: only for files you made yourself.

    Raises
    ------
    GearshotError
        Missing, damaged or foreign file; a file that would construct other types, or a
        pickle, without ``trusted=True`` (the message names them).
    """
    path = Path(path)
    if not path.is_file():
        raise GearshotError(f"estimator file {str(path)!r} does not exist")
    if not zipfile.is_zipfile(path):
        return _load_pickle(path, trusted)
    return _checked(path, read_skops(path, trusted=trusted), _FORMAT)


def read_skops(path: str | os.PathLike[str], *, trusted: bool = False) -> Any:
    """The object of a skops file, constructed only when every type it names is in
    :data:`SAFE_TYPES` (or ``trusted=True``); a damaged file is a GearshotError. For
    files that carry a fitted estimator with more (the monitor's model file)."""
    import skops.io as sio

    path = Path(path)
    _check_schema_size(path)
    try:
        found = sio.get_untrusted_types(file=path)
    except Exception as exc:
        raise GearshotError(f"{str(path)!r} is not a readable gearshot estimator "
                            f"({type(exc).__name__}: {exc})") from None
    unknown = sorted(set(found) - set(SAFE_TYPES))
    if unknown and not trusted:
        raise GearshotError(f"{str(path)!r} would construct types that no gearshot "
                            f"estimator holds ({', '.join(unknown[:5])}); not loaded. Load "
                            f"it only if you made it: load_estimator(path, trusted=True)")
    try:
        return sio.load(path, trusted=list(found))
    except Exception as exc:
        raise GearshotError(f"{str(path)!r} is not a readable gearshot estimator "
                            f"({type(exc).__name__}: {exc})") from None


#: Largest ``schema.json`` member of a skops file read (a saved estimator's is tens of kB):
#: a larger one is refused from its declared size, before any of it is read.
MAX_SCHEMA_BYTES = 64 * 2**20


def _check_schema_size(path: Path) -> None:
    """Refuse a skops file whose ``schema.json`` declares more than
    :data:`MAX_SCHEMA_BYTES` (from the zip's directory: nothing is decompressed)."""
    try:
        with zipfile.ZipFile(path) as archive:
            sizes = [info.file_size for info in archive.infolist()
                     if info.filename == "schema.json"]
    except (zipfile.BadZipFile, OSError, ValueError) as exc:
        raise GearshotError(f"{str(path)!r} is not a readable gearshot estimator "
                            f"({type(exc).__name__}: {exc})") from None
    if sizes and max(sizes) > MAX_SCHEMA_BYTES:
        raise GearshotError(f"{str(path)!r} declares a schema.json of {max(sizes)} bytes "
                            f"(more than {MAX_SCHEMA_BYTES}); not a gearshot estimator, "
                            f"not read")


def _load_pickle(path: Path, trusted: bool) -> Any:
    if not trusted:
        raise GearshotError(f"{str(path)!r} is not a gearshot (skops) estimator file; if it "
                            f"is a joblib/pickle file (gearshot before 0.2 wrote those), "
                            f"loading it runs any code it holds: load it only if you made "
                            f"it, with load_estimator(path, trusted=True), and save it again")
    import joblib

    try:
        payload = joblib.load(path)
    except Exception as exc:
        raise GearshotError(f"{str(path)!r} is not a readable gearshot estimator ({exc})") \
            from None
    return _checked(path, payload, _PICKLE_FORMAT)


def _checked(path: Path, payload: Any, fmt: str) -> Any:
    if not isinstance(payload, dict) or payload.get("format") != fmt:
        raise GearshotError(f"{str(path)!r} is not a gearshot estimator file")
    for key, now in (("gearshot_version", __version__), ("sklearn_version",
                                                        sklearn.__version__)):
        if payload.get(key) != now:
            warnings.warn(f"{path} was saved with {key.split('_')[0]} {payload.get(key)}; "
                          f"this is {now}", UserWarning, stacklevel=4)
    est = payload.get("estimator")
    if not hasattr(est, "model_"):
        raise GearshotError(f"{str(path)!r} holds no fitted gearshot estimator")
    return est
