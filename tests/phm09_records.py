"""Small copies of the shared PHM 2009 records for the command-line tests."""

from __future__ import annotations

import zipfile
from pathlib import Path

import pytest

PHM = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "phm09"


def crop(name: str, folder: Path, rows: int = 100_000) -> Path:
    """A zipped copy of the original record ``name`` holding its first ``rows`` rows
    (skips the test when ``../shared/data/phm09`` is absent)."""
    src = PHM / name
    if not src.is_file():
        pytest.skip(f"{src} is absent; real-data checks need ../shared/data/phm09")
    with zipfile.ZipFile(src) as zf:
        member = zf.namelist()[0]
        lines = zf.read(member).splitlines(keepends=True)[:rows]
    out = folder / name
    with zipfile.ZipFile(out, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        zf.writestr(member, b"".join(lines))
    return out
