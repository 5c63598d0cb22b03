"""National Instruments TDMS recordings (optional dependency ``npTDMS``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._errors import GearshotError
from ._fileio import RawFile

__all__ = ["read_tdms"]


def read_tdms(path: Path) -> RawFile:
    """Read a National Instruments TDMS file (optional dependency ``npTDMS``).

    Every channel of every group becomes a channel named ``"group/channel"`` (and, when
    unique, by its bare channel name); ``fs`` from the channels' ``wf_increment``.
    """
    try:
        from nptdms import TdmsFile
    except ImportError:
        raise GearshotError(f"reading {str(path)!r} needs the optional package npTDMS: "
                            f"pip install 'gearshot[tdms]'") from None
    tdms = TdmsFile.read(path)
    chans: dict[str, np.ndarray] = {}
    rates = set()
    bare: dict[str, int] = {}
    for group in tdms.groups():
        for ch in group.channels():
            bare[ch.name] = bare.get(ch.name, 0) + 1
    for group in tdms.groups():
        for ch in group.channels():
            data = np.asarray(ch[:], dtype=np.float64)
            name = ch.name if bare[ch.name] == 1 else f"{group.name}/{ch.name}"
            chans[name] = data
            inc = ch.properties.get("wf_increment")
            if inc:
                rates.add(round(1.0 / float(inc), 6))
    if not chans:
        raise GearshotError(f"{str(path)!r} holds no TDMS channel")
    if len(rates) > 1:
        raise GearshotError(f"{str(path)!r}: channels have different sampling rates "
                            f"{sorted(rates)} Hz")
    return RawFile(path, chans, rates.pop() if rates else None, {},
                   positional_defaults=False)
