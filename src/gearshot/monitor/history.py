"""A monitored machine's index and history.

The **index** (:func:`read_index`) lists the recordings to watch: columns ``file`` (or
``path``; relative paths are relative to the index's folder) and ``time`` (ISO 8601),
optional ``speed`` and ``load``; other columns are kept; or a folder or glob pattern of
recording files (:mod:`gearshot.monitor.listing`). The **history**
(:func:`read_history`, :func:`append_history`) is a Parquet table of every estimate made,
one row per (recording, model): :data:`HISTORY_COLUMNS`. It is only ever replaced whole
through the atomic writer, so a reader sees the old history or the new one, never half.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from .._atomic import atomic_path
from .._errors import GearshotError

__all__ = ["read_index", "read_history", "append_history", "HISTORY_COLUMNS", "pending"]

#: Columns of a history table: the recording (absolute path) and its time, the combined
#: estimate and interval, the segments estimated and trusted, the recording's trust, the
#: model that made the estimate (its file digest), how that model was calibrated, when the
#: estimate was made and ``note`` (why a recording is untrusted beyond its segments, or
#: why it could not be estimated; "" otherwise).
HISTORY_COLUMNS = ["recording", "time", "predicted", "low", "high", "segments",
                   "trusted_segments", "trusted", "model", "calibration", "estimated_at",
                   "note"]


def read_index(path: str | Path) -> pd.DataFrame:
    """The index of recordings to monitor, sorted by time.

    ``path`` is a CSV, a folder (its ``index.csv`` when it has one, else its recording
    files) or a glob pattern of recording files; listed files take their times from their
    names or time stamps (:func:`gearshot.monitor.listing.listed_index`, which says which
    in ``attrs["source"]``).

    Returns
    -------
    pandas.DataFrame
        ``recording`` (absolute path), ``time`` (UTC-naive pandas timestamps) and the
        index's other columns.

    Raises
    ------
    GearshotError
        A missing file, no ``file``/``path`` or ``time`` column, an unreadable time, a
        listed recording that does not exist, or a recording listed twice.
    """
    from .listing import GLOB_CHARACTERS, listed_index

    spec, path = str(path), Path(path)
    if path.is_dir() and (path / "index.csv").is_file():
        return _folder_index(path)
    if path.is_dir() or (not path.exists() and GLOB_CHARACTERS & set(spec)):
        table = listed_index(spec)
    elif not path.is_file():
        raise GearshotError(f"--index {spec!r} does not exist")
    else:
        try:
            table = pd.read_csv(path, keep_default_na=False)
        except (ValueError, pd.errors.ParserError) as exc:
            raise GearshotError(f"--index {spec!r} is not a readable CSV ({exc})") from None
    column = "file" if "file" in table else "path" if "path" in table else None
    if column is None or "time" not in table:
        raise GearshotError(f"--index {str(path)!r} needs columns file (or path) and time; "
                            f"it has {list(table.columns)}")
    try:
        times = pd.to_datetime(table["time"].astype(str), utc=True, format="ISO8601")
    except (ValueError, TypeError) as exc:
        raise GearshotError(f"--index {str(path)!r}: column time must hold ISO 8601 times "
                            f"({exc})") from None
    files = [Path(f) if Path(f).is_absolute() else path.parent / f
             for f in table[column].astype(str)]
    missing = [str(f) for f in files if not f.is_file()]
    if missing:
        raise GearshotError(f"--index {str(path)!r} lists {len(missing)} missing "
                            f"recording(s), e.g. {missing[0]!r}")
    out = table.drop(columns=[column, "time"])
    out.insert(0, "recording", [str(f.resolve()) for f in files])
    out.insert(1, "time", times.dt.tz_localize(None))
    dup = out["recording"].duplicated()
    if dup.any():
        raise GearshotError(f"--index {str(path)!r} lists {out['recording'][dup].iloc[0]!r} "
                            f"more than once")
    out = out.sort_values("time", kind="stable").reset_index(drop=True)
    if "source" in table.attrs:
        out.attrs["source"] = table.attrs["source"]
    return out


def _folder_index(folder: Path) -> pd.DataFrame:
    """A folder's ``index.csv``, saying so when recordings of the folder are not in it
    (new files dropped beside an index are not estimated until it lists them)."""
    from .listing import recording_files

    table = read_index(folder / "index.csv")
    listed = set(table["recording"])
    extra = [p.name for p in recording_files(folder) if str(p.resolve()) not in listed]
    if extra:
        table.attrs["source"] = (f"{folder / 'index.csv'}; {len(extra)} recording file(s) "
                                 f"of the folder are not in it and not estimated (e.g. "
                                 f"{extra[0]!r})")
    return table


def read_history(path: str | Path) -> pd.DataFrame:
    """The history table (empty with :data:`HISTORY_COLUMNS` when the file does not
    exist yet)."""
    path = Path(path)
    if not path.exists():
        return pd.DataFrame({c: pd.Series(dtype=object) for c in HISTORY_COLUMNS})
    try:
        table = pd.read_parquet(path)
    except Exception as exc:  # pyarrow raises its own types for a damaged file
        raise GearshotError(f"--history {str(path)!r} is not a readable Parquet history "
                            f"({type(exc).__name__}: {exc})") from None
    missing = [c for c in HISTORY_COLUMNS if c not in table]
    if missing:
        raise GearshotError(f"--history {str(path)!r} is not a gearshot history (missing "
                            f"columns {missing})")
    return table


def pending(index: pd.DataFrame, history: pd.DataFrame, model: str) -> pd.DataFrame:
    """Rows of ``index`` that ``history`` holds no estimate of by ``model`` (a digest)."""
    done = set(history.loc[history["model"] == model, "recording"])
    return index[~index["recording"].isin(done)]


def append_history(path: str | Path, rows: pd.DataFrame) -> pd.DataFrame:
    """Add ``rows`` to the history at ``path`` and replace the file atomically.

    A (recording, model) pair already held is replaced by the new row. Returns the new
    history (sorted by time, then model).
    """
    path = Path(path)
    old = read_history(path)
    missing = [c for c in HISTORY_COLUMNS if c not in rows]
    if missing:
        raise GearshotError(f"history rows lack columns {missing}")
    if len(old):
        key = set(zip(rows["recording"], rows["model"], strict=True))
        keep = [(r, m) not in key for r, m in zip(old["recording"], old["model"],
                                                   strict=True)]
        new = pd.concat([old[keep], rows], ignore_index=True)
    else:
        new = rows.reset_index(drop=True)
    new = new.sort_values(["time", "estimated_at"], kind="stable").reset_index(drop=True)
    with atomic_path(path, make_parents=True) as tmp:
        new.to_parquet(tmp, index=False)
    return new
