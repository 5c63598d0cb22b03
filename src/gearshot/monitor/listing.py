"""An index made from a folder or a glob of recordings, times from names or time stamps.

``gearshot monitor --index`` takes a CSV (:func:`gearshot.monitor.read_index`), a folder
or a quoted glob pattern. A folder that holds an ``index.csv`` (as
:meth:`gearshot.rig.VirtualRig.history` writes one) is that CSV; otherwise every recording
file of the folder (or of the pattern) is listed, each with its time:

* from its **file name** when every listed name holds a date and time
  (``2026-03-01T08-15-00``, ``2026-03-01_0815``, ``20260301T081500``, or a date alone,
  ``2026-03-01``), read as UTC;
* else from each file's **modification time** (UTC) when no name holds one.

Some names with a time and others without is refused (naming one of each): a history
ordered partly by names and partly by time stamps would be ordered wrongly without a
word.
"""

from __future__ import annotations

import glob
import re
from pathlib import Path

import pandas as pd

from .._errors import GearshotError

__all__ = ["listed_index", "recording_files", "name_time", "GLOB_CHARACTERS"]

#: Characters that make ``--index`` a glob pattern (when no such file or folder exists).
GLOB_CHARACTERS = frozenset("*?[")

_FULL = re.compile(r"(?<!\d)(\d{4})-?(\d{2})-?(\d{2})[T_ -]?(\d{2})[:h-]?(\d{2})"
                   r"(?:[:m-]?(\d{2}))?(?!\d)")
_DATE = re.compile(r"(?<!\d)(\d{4})-(\d{2})-(\d{2})(?!\d)")


def name_time(name: str) -> pd.Timestamp | None:
    """The date and time a file name holds (UTC, naive), or None.

    Examples
    --------
    >>> name_time("pump3_2026-03-01T08-15-00.h5")
    Timestamp('2026-03-01 08:15:00')
    >>> name_time("20260301_081500.wav")
    Timestamp('2026-03-01 08:15:00')
    >>> name_time("2026-03-01.zip")
    Timestamp('2026-03-01 00:00:00')
    >>> name_time("life_007.h5") is None
    True
    """
    stem = Path(name).name
    for pattern in (_FULL, _DATE):
        for match in pattern.finditer(stem):
            parts = [int(p) if p else 0 for p in match.groups()]
            try:
                return pd.Timestamp(*parts[:3], *parts[3:6])
            except ValueError:   # 2026-13-45: digits, not a date
                continue
    return None


def recording_files(spec: str | Path) -> list[Path]:
    """The recording files of a folder or glob pattern, sorted: a recording suffix, not
    ``index.csv``, not hidden (a partial copy, an editor's file)."""
    from ..io import FORMATS

    path = Path(spec)
    found = (path.iterdir() if path.is_dir() else (Path(p) for p in glob.glob(str(spec))))
    return sorted(p for p in found if p.is_file() and p.suffix.lower() in FORMATS
                  and p.name != "index.csv" and not p.name.startswith("."))


def _recording_files(spec: str) -> tuple[list[Path], str]:
    """The recording files a folder or pattern names, and how to say where they came from."""
    from ..io import FORMATS

    files = recording_files(spec)
    where = f"folder {spec!r}" if Path(spec).is_dir() else f"pattern {spec!r}"
    if not files:
        raise GearshotError(f"--index {where} holds no recording file (suffixes "
                            f"{sorted(FORMATS)})")
    return files, where


def listed_index(spec: str) -> pd.DataFrame:
    """Index rows (``file`` absolute, ``time``) of the recordings of a folder or pattern.

    ``attrs["source"]`` says where the recordings and their times came from.

    Raises
    ------
    GearshotError
        No recording file, or only some file names holding a time.
    """
    files, where = _recording_files(spec)
    found = [name_time(p.name) for p in files]
    named = [t is not None for t in found]
    if all(named):
        times = [t for t in found if t is not None]
        how = "times from the file names (UTC)"
    elif not any(named):
        times = [pd.Timestamp(p.stat().st_mtime, unit="s") for p in files]
        how = "times from the files' modification times (UTC)"
    else:
        with_time = files[named.index(True)].name
        without = files[named.index(False)].name
        raise GearshotError(f"--index {where}: some file names hold a time "
                            f"({with_time!r}) and some do not ({without!r}); name every "
                            f"file with its time or give a CSV index (columns file, time)")
    frame = pd.DataFrame({"file": [str(p.resolve()) for p in files],
                          "time": [t.isoformat() for t in times]})
    frame.attrs["source"] = f"{len(files)} recording(s) of {where}, {how}"
    return frame
