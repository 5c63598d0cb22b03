"""Campaign folders: recordings of one or more conditions listed in an index file."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pandas as pd

from .._errors import GearshotError

__all__ = ["read_campaign", "INDEX_NAME", "INDEX_COLUMNS"]

INDEX_NAME = "index.csv"
INDEX_COLUMNS = ["path", "speed", "load", "fault_size", "repetition"]


def read_campaign(folder: str | os.PathLike[str]) -> pd.DataFrame:
    """The index of a campaign folder, with absolute paths."""
    import pandas as pd  # imported on use: reading one recording never needs it

    folder = Path(folder)
    index_path = folder / INDEX_NAME
    if not index_path.is_file():
        raise GearshotError(f"{str(folder)!r} holds no campaign index ({INDEX_NAME})")
    try:
        frame = pd.read_csv(index_path)
    except Exception as exc:
        raise GearshotError(f"cannot read {str(index_path)!r}: {exc}") from None
    if list(frame.columns) != INDEX_COLUMNS:
        raise GearshotError(f"{str(index_path)!r} has columns {list(frame.columns)}; "
                            f"expected {INDEX_COLUMNS}")
    frame["path"] = [str((folder / p).resolve()) for p in frame["path"]]
    return frame


