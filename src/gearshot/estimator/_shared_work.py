"""Target-side work shared by the estimators fitted on one dataset (the paper's variants):
:func:`shared_target_work` and the store it keeps, keyed by inputs equal to the bit."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["shared_target_work", "sharing", "shared", "kept", "keep"]

# (kind, fingerprint of the inputs) -> [(inputs, result), ...] inside a block, None outside
_SHARED: ContextVar[dict[tuple[Any, ...], list[tuple[Any, Any]]] | None] = ContextVar(
    "gearshot_shared_target_work", default=None)


@contextmanager
def shared_target_work() -> Iterator[None]:
    """Within the block, target-side work on the same inputs is done once.

    Step 6's delay-aligned subtraction (the costliest part of the target side), its lag
    search and step 7's centred features of target SAs are kept with their inputs (SAs,
    references, healthy mean, scale, feature names, mesh orders, ``upsample``) and handed
    out again (copies) when inputs equal to the bit come back: e.g. the estimator variants
    of one dataset (:func:`gearshot.experiments.evaluate_variants`) that see the same
    target arrays, or ``predict`` and ``predict_interval`` of the same SAs. The lag search
    is also shared between the arrays with and without RMS normalization (it does not
    depend on a common scale). Blocks nest (an inner block shares the outer one's store);
    everything kept is dropped when the outermost block ends.

    Examples
    --------
    >>> from gearshot.estimator._shared_work import sharing, shared_target_work
    >>> with shared_target_work():
    ...     print(sharing())        # fit / predict several estimators on one dataset here
    True
    >>> sharing()
    False
    """
    if _SHARED.get() is not None:
        yield
        return
    token = _SHARED.set({})
    try:
        yield
    finally:
        _SHARED.reset(token)


def sharing() -> bool:
    """Whether a :func:`shared_target_work` block is open."""
    return _SHARED.get() is not None


def kept(kind: str, parts: tuple[Any, ...]) -> Any:
    """What :func:`keep` kept for ``kind`` and inputs equal to ``parts`` in the open block
    (arrays as copies), or None."""
    store = _SHARED.get()
    for kept_parts, value in (store or {}).get((kind, _fingerprint(parts)), []):
        if _same(parts, kept_parts):
            return value.copy() if isinstance(value, np.ndarray) else value
    return None


def keep(kind: str, parts: tuple[Any, ...], value: Any) -> None:
    """Keep ``value`` (arrays read-only) for ``kind`` and ``parts`` in the open block
    (nothing outside one)."""
    store = _SHARED.get()
    if store is None:
        return
    if isinstance(value, np.ndarray):
        value = value.copy()
        value.flags.writeable = False
    store.setdefault((kind, _fingerprint(parts)), []).append((_frozen(parts), value))


def shared(kind: str, parts: tuple[Any, ...],
           compute: Callable[[], NDArray[np.float64]]) -> NDArray[np.float64]:
    """``compute()``, or a copy of what it gave for the same ``kind`` and equal ``parts``
    (to the bit) in the open :func:`shared_target_work` block."""
    if not sharing():
        return compute()
    value = kept(kind, parts)
    if value is None:
        value = compute()
        keep(kind, parts, value)
    return np.asarray(value, dtype=np.float64)


def _fingerprint(value: Any) -> Any:
    """A cheap key part for ``value``: an array by dtype, shape and a strided sample of its
    values (equal arrays give equal fingerprints; :func:`_same` tells the rest apart)."""
    if isinstance(value, np.ndarray):
        flat = value.reshape(-1)
        return (value.dtype.str, value.shape,
                flat[:: max(1, flat.size // 64)].tobytes() if flat.size else b"")
    if isinstance(value, (list, tuple)):
        return tuple(_fingerprint(v) for v in value)
    if isinstance(value, float):
        return ("float", value.hex())
    return value


def _same(a: Any, b: Any) -> bool:
    """Whether two inputs are equal to the bit (arrays compared byte for byte)."""
    if isinstance(a, np.ndarray):
        return (isinstance(b, np.ndarray) and a.dtype == b.dtype and a.shape == b.shape
                and np.array_equal(_raw(a), _raw(b)))
    if isinstance(a, (list, tuple)):
        return (isinstance(b, (list, tuple)) and len(a) == len(b)
                and all(_same(x, y) for x, y in zip(a, b)))
    return type(a) is type(b) and (a.hex() == b.hex() if isinstance(a, float) else a == b)


def _raw(a: NDArray[Any]) -> NDArray[Any]:
    """The bytes of an array as integers (compared exactly: -0.0 differs from 0.0)."""
    data = np.ascontiguousarray(a).reshape(-1)
    return data.view(np.int64) if data.itemsize == 8 else data.view(np.uint8)


def _frozen(value: Any) -> Any:
    """``value`` with its arrays copied (the caller may change its own afterwards)."""
    if isinstance(value, np.ndarray):
        return value.copy()
    if isinstance(value, (list, tuple)):
        return tuple(_frozen(v) for v in value)
    return value
