"""The fixed-width fast reader of text recordings: bit-identical to numpy's tokenizing
reader on the real PHM09 files, and None (the general reader takes over) for anything
else."""

from __future__ import annotations

import io
import zipfile
from pathlib import Path

import numpy as np
import pytest

from gearshot.io._fixed_width import read_fixed_width
from gearshot.io._format_text import read_text

PHM09 = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "phm09"


@pytest.mark.parametrize("name", ["spur2_30hz_High_1.zip", "helical5_40hz_Low_1.zip"])
def test_phm09_file_reads_bit_identical_to_loadtxt(name):
    path = PHM09 / name
    if not path.exists():
        pytest.skip("shared PHM09 subset not present")
    with zipfile.ZipFile(path) as zf:
        data = zf.read(zf.infolist()[0])
    table = read_fixed_width(data)
    reference = np.loadtxt(io.BytesIO(data), ndmin=2)
    assert table is not None and table.shape == reference.shape == (266656, 3)
    assert np.array_equal(table.view(np.int64), reference.view(np.int64))
    raw = read_text(path, columns=["acc_input", "acc_output", "tacho"])
    assert np.array_equal(raw.channels["tacho"], reference[:, 2])


def test_exact_on_hard_values():
    values = ["-0.0000000e+000", " 9.9999999e+008", " 1.2345678e-015", " 7.0000001e-001",
              " 1.0000000e+000", "-3.3333333e-003"]
    data = "".join(v + " " + v + "\r\n" for v in values).encode()
    table = read_fixed_width(data)
    assert table is not None
    expected = np.array([float(v) for v in values])
    assert np.array_equal(table[:, 0].view(np.int64), expected.view(np.int64))
    assert np.signbit(table[0, 0])


def test_last_line_without_line_end():
    assert read_fixed_width(b" 1.5 2.25\n-1.5 3.75").tolist() == [[1.5, 2.25], [-1.5, 3.75]]


@pytest.mark.parametrize("data", [
    b" 1.5 2.0\n 1.5 2.25\n",             # ragged
    b" 1.5 2.0\n 15. 2.0\n",              # the decimal point moves
    b"time acc\n 1.0 2.0\n",              # a header row
    b" 1.5 2.0\n nan 2.0\n",              # not a number
    b"# comment\n 1.5 2.0\n",             # a comment
    b" 1.2345678901234567 2.0\n 1.2345678901234567 2.0\n",   # 17 digits: not exact
    b" 1.0e+030 2.0\n 1.0e+030 2.0\n",    # a power of ten beyond 1e22
    b"",
])
def test_other_layouts_are_left_to_the_general_reader(data):
    assert read_fixed_width(data) is None


def test_read_text_falls_back_on_a_moving_column(tmp_path):
    path = tmp_path / "r.txt"
    path.write_text(" 1.5 2.0\n 15. 2.5\n -1 3\n")
    raw = read_text(path, columns=["acc", "tacho"])
    assert raw.channels["acc"].tolist() == [1.5, 15.0, -1.0]
