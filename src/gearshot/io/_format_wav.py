"""Multi-channel WAV recordings (scipy.io.wavfile) with an optional JSON sidecar.

Samples are float32, int16 or int32. Integer samples are first normalized to [-1, 1)
(divided by 2**(bits-1)); the physical value is that times the channel's ``scale`` from the
sidecar (1 if there is none). The sidecar ``<name>.wav.json`` (or ``<name>.json``) may hold
``channels`` (one name per channel), ``scale`` (one factor per channel), ``fs`` (must agree
with the WAV header), ``n_samples``, ``sha256`` (of the WAV file: a damaged or zeroed file is
refused) and ``metadata`` (the Recording's metadata fields).
The caller's ``channels=`` argument names channels the same way.
"""

from __future__ import annotations

import hashlib
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from .._errors import GearshotError
from ._fileio import RawFile, atomic_path, read_sidecar, sidecar_path, write_json_atomic

__all__ = ["read_wav", "write_wav", "WAV_DTYPES"]

WAV_DTYPES = ("float32", "int16", "int32")


def read_wav(path: Path) -> RawFile:
    """Read a WAV file (and its sidecar) into channels, fs and metadata."""
    import scipy.io.wavfile  # imported on use
    path = Path(path)
    side = read_sidecar(path)
    with warnings.catch_warnings():
        warnings.simplefilter("error", scipy.io.wavfile.WavFileWarning)
        try:
            rate, data = scipy.io.wavfile.read(path, mmap=False)
        except scipy.io.wavfile.WavFileWarning as exc:
            raise GearshotError(f"{str(path)!r} is damaged or truncated: {exc}") from None
    data = np.asarray(data)
    if data.ndim == 1:
        data = data[:, None]
    kind = data.dtype
    if kind == np.int16 or kind == np.int32:
        values = data.astype(np.float64) / float(2 ** (8 * kind.itemsize - 1))
    elif kind.kind == "f":
        values = data.astype(np.float64)
    elif kind == np.uint8:
        values = (data.astype(np.float64) - 128.0) / 128.0
    else:
        raise GearshotError(f"{str(path)!r}: unsupported WAV sample type {kind}")
    n_ch = values.shape[1]
    names = side.get("channels") or [f"ch{i}" for i in range(n_ch)]
    if len(names) != n_ch:
        raise GearshotError(f"{str(path)!r}: its sidecar names {len(names)} channels but the "
                            f"file has {n_ch}")
    scale = np.asarray(side.get("scale", np.ones(n_ch)), dtype=np.float64)
    if scale.shape != (n_ch,):
        raise GearshotError(f"{str(path)!r}: sidecar 'scale' must hold {n_ch} numbers")
    n_expected = side.get("n_samples")
    if n_expected is not None and int(n_expected) != values.shape[0]:
        raise GearshotError(f"{str(path)!r} holds {values.shape[0]} samples but its sidecar "
                            f"says {n_expected} (truncated file?)")
    digest = side.get("sha256")
    if digest is not None and _sha256(path) != digest:
        raise GearshotError(f"{str(path)!r} does not match the SHA-256 its sidecar records "
                            f"(damaged or changed after writing)")
    side_fs = side.get("fs")
    if side_fs is not None and abs(float(side_fs) - rate) > 1e-9 * rate:
        raise GearshotError(f"{str(path)!r}: the WAV header says fs={rate} Hz but its sidecar "
                            f"says fs={side_fs}")
    chans = {str(name): values[:, i] * scale[i] for i, name in enumerate(names)}
    return RawFile(path, chans, float(rate), dict(side.get("metadata", {})),
                   positional_defaults=True)


def write_wav(rec: Any, path: Path, *, dtype: Any = "float32") -> None:
    """Write ``rec`` as a WAV file plus sidecar, both atomically.

    ``dtype`` is the sample type: "float32", "int16" or "int32" (integer channels are scaled
    to their peak; the factor goes to the sidecar).
    """
    import scipy.io.wavfile
    path = Path(path)
    dtype = str(np.dtype(dtype))
    if dtype not in WAV_DTYPES:
        raise GearshotError(f"dtype for WAV must be one of {WAV_DTYPES}; got {dtype!r}")
    if float(rec.fs) != round(float(rec.fs)):
        raise GearshotError(f"WAV needs an integer sampling rate; fs={rec.fs!r}")
    cols = [rec.acceleration] + ([rec.tacho] if rec.tacho is not None else [])
    names = ["acceleration"] + (["tacho"] if rec.tacho is not None else [])
    data = np.stack(cols, axis=1)
    if dtype == "float32":
        scale = np.ones(len(cols))
        samples = data.astype(np.float32)
    else:
        full = float(2 ** (8 * np.dtype(dtype).itemsize - 1))
        peak = np.max(np.abs(data), axis=0)
        scale = np.where(peak > 0, peak * full / (full - 1), 1.0)
        samples = np.round(data / scale * full).clip(-full, full - 1).astype(dtype)
    side = {
        "format": "gearshot.recording.wav-sidecar",
        "format_version": 1,
        "fs": float(rec.fs),
        "n_samples": int(data.shape[0]),
        "channels": names,
        "scale": [float(s) for s in scale],
        "metadata": rec.metadata,
    }
    with atomic_path(path) as tmp:
        scipy.io.wavfile.write(tmp, int(round(rec.fs)), samples)
        side["sha256"] = _sha256(tmp)
        write_json_atomic(side, sidecar_path(path))


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        while chunk := fh.read(1 << 22):
            h.update(chunk)
    return h.hexdigest()
