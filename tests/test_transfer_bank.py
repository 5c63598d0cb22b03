"""Tests of gearshot.transfer.bank.TransferFunctionBank."""

from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from gearshot import GearshotError
from gearshot.transfer import TransferFunction, TransferFunctionBank, write_frf

SHARED = Path(__file__).resolve().parents[1].parent / "shared"
FRF_DIR = SHARED / "data" / "frf"


def _bank(n=4):
    f = np.linspace(0, 100, 11)
    return TransferFunctionBank([TransferFunction(f, (i + 1) * np.ones(11), name=f"t{i}")
                                 for i in range(n)])


def test_real_folder():
    if len(list(FRF_DIR.glob("*.uff"))) != 12:
        pytest.skip(f"the 12 real FRFs are not in {FRF_DIR}")
    bank = TransferFunctionBank.from_folder(FRF_DIR)
    assert len(bank) == 12
    assert bank.names[0] == "beam_h1" and bank.names[-1] == "structure_b_h3"
    assert bank["beam_h5"].reference_node == 5
    grid = bank.to_signal_grid(2048)
    assert grid.shape == (12, 2048) and np.iscomplexobj(grid)
    held, rest = bank.hold_out("structure_b_h2")
    assert held is bank["structure_b_h2"] and len(rest) == 11 and "structure_b_h2" not in rest.names


def test_container_protocol_and_hold_out():
    bank = _bank()
    assert len(bank) == 4 and [tf.name for tf in bank] == ["t0", "t1", "t2", "t3"]
    assert bank[-1] is bank["t3"]
    held, rest = bank.hold_out(1)
    assert held.name == "t1" and rest.names == ("t0", "t2", "t3")
    h1, _ = bank.hold_out(rng=5)
    h2, _ = bank.hold_out(rng=np.random.default_rng(5))
    assert h1 is h2
    norm = bank.normalized()
    for tf in norm:
        assert_allclose(np.sqrt(np.mean(np.abs(tf.values) ** 2)), 1.0)
    assert dict(bank.items())["t2"] is bank[2]


def test_folder_with_csv_and_uff_and_default_names(tmp_path):
    bank = _bank(3)
    write_frf(tmp_path / "b.csv", bank[0])
    write_frf(tmp_path / "a.uff", bank[1])
    (tmp_path / "notes.txt").write_text("ignored")
    loaded = TransferFunctionBank.from_folder(tmp_path)
    assert loaded.names == ("a", "b")
    assert loaded["a"] == bank[1] and loaded["b"] == bank[0]
    dup = TransferFunctionBank([bank[0], bank[0]])
    assert dup.names == ("tf_0", "tf_1")


def test_synthetic_constructor():
    b = TransferFunctionBank.synthetic(3, rng=0)
    assert len(b) == 3 and b.names == ("synthetic_000", "synthetic_001", "synthetic_002")


def test_errors(tmp_path):
    bank = _bank()
    with pytest.raises(GearshotError, match="at least one"):
        TransferFunctionBank([])
    with pytest.raises(GearshotError, match=r"tfs\[0\] must be a TransferFunction"):
        TransferFunctionBank([np.ones(3)])
    with pytest.raises(GearshotError, match="unique"):
        TransferFunctionBank([bank[0], bank[1]], names=["x", "x"])
    with pytest.raises(GearshotError, match="no TF named"):
        bank["nope"]
    with pytest.raises(GearshotError, match="key must index"):
        bank[9]
    with pytest.raises(GearshotError, match="which= .* or rng="):
        bank.hold_out()
    with pytest.raises(GearshotError, match="at least 2"):
        TransferFunctionBank([bank[0]]).hold_out(0)
    with pytest.raises(GearshotError, match="not a folder"):
        TransferFunctionBank.from_folder(tmp_path / "missing")
    with pytest.raises(GearshotError, match="no FRF files"):
        TransferFunctionBank.from_folder(tmp_path)
    (tmp_path / "bad.uff").write_text("")
    with pytest.raises(GearshotError, match=r"bad\.uff.*empty"):
        TransferFunctionBank.from_folder(tmp_path)
