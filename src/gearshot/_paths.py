"""Where gearshot keeps databases and rig campaigns."""

from __future__ import annotations

import os
from pathlib import Path

import platformdirs

__all__ = ["data_home"]


def data_home(create: bool = True) -> Path:
    """Return gearshot's data folder.

    ``$GEARSHOT_DATA`` when set, otherwise the user cache folder
    (e.g. ``~/.cache/gearshot``). Databases and rig campaigns live below it.
    """
    env = os.environ.get("GEARSHOT_DATA")
    path = Path(env).expanduser() if env else Path(platformdirs.user_cache_dir("gearshot"))
    if create:
        path.mkdir(parents=True, exist_ok=True)
    return path
