"""The PHM09 text recordings read exactly: numpy's reader (the general path, which
replaced a hand-written fixed-width parser) gives, bit for bit, the float ``float()``
gives for each field of the file."""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np
import pytest

from gearshot.io._format_text import read_text

PHM09 = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "phm09"


@pytest.mark.parametrize("name", ["spur2_30hz_High_1.zip", "helical5_40hz_Low_1.zip"])
def test_phm09_channels_are_the_floats_of_the_text_fields(name):
    path = PHM09 / name
    if not path.exists():
        pytest.skip("shared PHM09 subset not present")
    with zipfile.ZipFile(path) as zf:
        lines = zf.read(zf.infolist()[0]).decode("ascii").splitlines()
    raw = read_text(path, columns=["acc_input", "acc_output", "tacho"])
    assert raw.channels["tacho"].shape == (len(lines),) == (266656,)
    rows = np.random.default_rng(0).choice(len(lines), 2000, replace=False)
    want = np.array([[float(v) for v in lines[r].split()] for r in rows])
    for j, name_ in enumerate(["acc_input", "acc_output", "tacho"]):
        got = raw.channels[name_][rows]
        assert np.array_equal(got.view(np.int64), want[:, j].view(np.int64)), name_
