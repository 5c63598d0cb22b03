"""Virtual-rig campaigns of the command line: the rig a user asks for, recorded once.

``gearshot rig`` records a campaign into a folder; ``gearshot experiment rig`` reuses the
campaign recorded from exactly the same inputs (:func:`cached_campaign`), keyed by a hash
of every input, the measured FRF files' content included (:func:`folder_digest`).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

from .._atomic import check_writable, write_json_atomic
from .._errors import GearshotError

__all__ = ["CACHE_MANIFEST", "make_rig", "folder_digest", "cached_campaign", "check_rig_grade"]

#: The inputs a cached campaign was recorded from, in its folder
CACHE_MANIFEST = "gearshot-cache.json"


def check_rig_grade(rig_grade: int | None) -> None:
    """``--rig-grade``: a DIN grade 1 … 12 or None (hidden, drawn)."""
    if rig_grade is not None and not 1 <= rig_grade <= 12:
        raise GearshotError(f"--rig-grade must be 1 … 12; got {rig_grade}")


def make_rig(seed: int, frf_folder: Path | None = None, rig_grade: int | None = None,
             attenuation_db: float | None = None) -> Any:
    """The virtual rig of ``seed``: its path from ``frf_folder`` (default synthetic), its
    true grade ``rig_grade`` and path attenuation ``attenuation_db`` when given (default:
    hidden, drawn from the seed)."""
    from ..rig import VirtualRig

    kwargs: dict[str, Any] = {}
    if frf_folder is not None:
        kwargs["tf_bank"] = str(frf_folder)
    if rig_grade is not None:
        check_rig_grade(rig_grade)
        kwargs["grade"] = rig_grade
    rig = VirtualRig(seed=seed, **kwargs)
    if attenuation_db is not None:
        rig = rig.with_reality(attenuation_db=attenuation_db)
    return rig


def folder_digest(folder: Path | None) -> str | None:
    """Content hash of every file of an FRF folder (names and bytes), or None."""
    if folder is None:
        return None
    h = hashlib.sha256()
    for path in sorted(p for p in folder.rglob("*") if p.is_file()):
        h.update(path.relative_to(folder).as_posix().encode() + b"\0")
        with open(path, "rb") as fh:
            while chunk := fh.read(1 << 20):
                h.update(chunk)
        h.update(b"\0")
    return h.hexdigest()


def cached_campaign(campaign: Path | None, inputs: dict,
                    record: Callable[[Path], object]) -> Path:
    """The campaign for ``inputs``: reuse one recorded from exactly these inputs, else record.

    The default folder's name carries a hash of every input (seed, condition, grade,
    attenuation, the FRF files' content, duration, counts) and the folder holds those
    inputs in ``gearshot-cache.json``, checked on every reuse.
    """
    from .. import data_home

    key = hashlib.sha256(json.dumps(inputs, sort_keys=True).encode()).hexdigest()[:16]
    if campaign is None:
        campaign = data_home() / (f"campaign-s{inputs['seed']}-{inputs['speed']:g}rps-"
                                  f"{inputs['load']:g}Nm-{key}")
    manifest = campaign / CACHE_MANIFEST
    if (campaign / "index.csv").is_file():
        if not manifest.exists():
            return campaign   # a campaign the user recorded (gearshot rig): theirs to vouch for
        _check_manifest(campaign, manifest, inputs)
        return campaign
    check_writable(campaign, "--campaign", folder=True)
    record(campaign)
    write_json_atomic(inputs, manifest)
    return campaign


def _check_manifest(campaign: Path, manifest: Path, inputs: dict) -> None:
    """A cached campaign was recorded from ``inputs``, or a one-line refusal."""
    try:
        old = json.loads(manifest.read_text())
    except (OSError, ValueError) as exc:
        raise GearshotError(f"--campaign {str(campaign)!r}: {CACHE_MANIFEST} is "
                            f"unreadable ({exc}); delete the folder to record it again") \
            from None
    if old != inputs:
        diff = sorted(k for k in set(old) | set(inputs) if old.get(k) != inputs.get(k))
        raise GearshotError(f"--campaign {str(campaign)!r} was recorded from other inputs "
                            f"(differs in {', '.join(diff)}); pass another --campaign or "
                            f"delete it")
