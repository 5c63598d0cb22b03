"""CSV recordings: one column per channel, a header row of names.

A gearshot CSV starts with one comment line ``# gearshot.recording {json}`` holding ``fs``,
``n_samples`` and the metadata; foreign CSVs need ``fs=`` from the caller, a sidecar
(``<name>.csv.json``) or a uniformly spaced ``time``/``t`` column (seconds). Other ``#`` lines
before the header are ignored. Channel indices count every column, the time column included
(it is never picked by default).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from .._errors import GearshotError
from ._fileio import TIME_NAMES, RawFile, atomic_path, read_sidecar, time_column_fs

__all__ = ["read_csv", "write_csv"]

_TAG = "# gearshot.recording "


def read_csv(path: Path) -> RawFile:
    """Read a CSV file into channels, fs and metadata."""
    import pandas as pd  # imported on use

    path = Path(path)
    header: dict[str, Any] = dict(read_sidecar(path))
    n_comment = 0
    with open(path, encoding="utf-8") as fh:
        for line in fh:
            if not line.startswith("#"):
                break
            n_comment += 1
            if line.startswith(_TAG):
                try:
                    header.update(json.loads(line[len(_TAG):]))
                except ValueError as exc:
                    raise GearshotError(f"{str(path)!r}: damaged header line ({exc})") from None
    first = ""
    with open(path, encoding="utf-8") as fh:
        for i, line in enumerate(fh):
            if i >= n_comment and line.strip():
                first = line
                break
    if first and (_numeric_row(first) or "," not in first):
        # no header row (never take the first data row for channel names), or not
        # comma-separated: the delimited-text reader sniffs the delimiter and the header
        from ._format_text import read_text

        raw = read_text(path, skip_rows=n_comment)
        raw.fs = header.get("fs", raw.fs)
        return raw
    try:
        frame = pd.read_csv(path, skiprows=n_comment, skipinitialspace=True)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise GearshotError(f"{str(path)!r} is not a readable CSV: {exc}") from None
    chans: dict[str, np.ndarray] = {}
    fs = header.get("fs")
    time_name = None
    for name in frame.columns:
        col = pd.to_numeric(frame[name], errors="coerce").to_numpy(dtype=np.float64)
        if np.isnan(col).any():
            bad = int(np.flatnonzero(np.isnan(col))[0])
            raise GearshotError(f"{str(path)!r}: column {name!r} has a missing or non-numeric "
                                f"value in data row {bad} (truncated or damaged file?)")
        chans[str(name).strip()] = col
        if str(name).strip().lower() in TIME_NAMES and time_name is None:
            time_name = str(name).strip()
            if fs is None:
                fs = time_column_fs(path, col)
    n_expected = header.get("n_samples")
    if n_expected is not None and int(n_expected) != len(frame):
        raise GearshotError(f"{str(path)!r} holds {len(frame)} rows but its header says "
                            f"{n_expected} (truncated file?)")
    return RawFile(path, chans, fs, dict(header.get("metadata", {})),
                   positional_defaults=True, time_channel=time_name)


def _numeric_row(line: str) -> bool:
    cells = [c.strip() for c in line.split(",")]
    try:
        [float(c) for c in cells if c]
    except ValueError:
        return False
    return True


def write_csv(rec: Any, path: Path) -> None:
    """Write ``rec`` as CSV (17 significant digits: values round-trip exactly), atomically."""
    names = ["acceleration"] + (["tacho"] if rec.tacho is not None else [])
    cols = [rec.acceleration] + ([rec.tacho] if rec.tacho is not None else [])
    head = {"fs": float(rec.fs), "n_samples": int(rec.acceleration.size),
            "metadata": rec.metadata}
    with atomic_path(path) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="") as fh:
            fh.write(_TAG + json.dumps(head, sort_keys=True) + "\n")
            np.savetxt(fh, np.stack(cols, axis=1), fmt="%.17g", delimiter=",",
                       header=",".join(names), comments="")
