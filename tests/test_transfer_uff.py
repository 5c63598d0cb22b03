"""Tests of gearshot.transfer.uff: UFF58 / CSV reading and writing, bad files."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from gearshot import GearshotError
from gearshot.transfer import TransferFunction, read_frf, read_uff_records, write_frf

SHARED = Path(__file__).resolve().parents[1].parent / "shared"
FRF_DIR = SHARED / "data" / "frf"
IMPACT_FILE = SHARED / "data" / "impact" / "hammer_impacts.uff"


def _real_frf_files():
    files = sorted(FRF_DIR.glob("*.uff"))
    if len(files) != 12:
        pytest.skip(f"expected the 12 real FRFs in {FRF_DIR}; found {len(files)}")
    return files


def _synthetic_tf():
    f = np.arange(257) * (25600 / 2**17)   # 0.1953125 Hz: not exact in %13.5e
    rng = np.random.default_rng(1)
    v = rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size)
    return TransferFunction(f, v, name="synthetic", response_node=7, response_direction=-2,
                            reference_node=3, reference_direction=1, units="g/N")


def test_real_frfs_load_with_metadata():
    files = _real_frf_files()
    for p in files:
        tf = read_frf(p)
        assert tf.response_quantity == "acceleration" and tf.reference_quantity == "force"
        assert tf.values.dtype == np.complex128
        assert tf.band[1] == pytest.approx(1000.0, abs=0.5)
        if p.stem.startswith("beam"):
            assert tf.n_lines == 5120 and tf.df == pytest.approx(0.195312, rel=1e-6)
            assert tf.reference_node == int(p.stem[-1])   # hammer roving over points 1..9
            assert tf.response_node == 100
        else:
            assert tf.n_lines == 1001 and tf.band[0] == 0.0 and tf.df == 1.0
    first = read_frf(files[0])
    assert_allclose(first.values[:2], [-0.1366724 + 0.007331555j, -0.1664887 - 0.06202861j])
    assert first.metadata["source"] == str(files[0])


@pytest.mark.parametrize("suffix", [".uff", ".csv"])
def test_real_frfs_round_trip_exactly(tmp_path, suffix):
    for p in _real_frf_files():
        tf = read_frf(p)
        out = tmp_path / (p.stem + suffix)
        write_frf(out, tf)
        back = read_frf(out)
        assert back == tf, p.name          # freqs, values, name, DOFs, quantities, units
        assert_array_equal(back.values, tf.values)
        assert_array_equal(back.freqs, tf.freqs)
        if suffix == ".uff":  # the measured files are representable in ASCII: stays ASCII
            assert out.read_bytes()[6:14].strip() == b"58"


def test_uff_ascii_and_binary_precision(tmp_path):
    tf = _synthetic_tf()
    write_frf(tmp_path / "auto.uff", tf)              # not ASCII-exact -> binary 58b
    assert b"58b" in (tmp_path / "auto.uff").read_bytes()[:20]
    back = read_frf(tmp_path / "auto.uff")
    assert back == tf
    write_frf(tmp_path / "ascii.uff", tf, binary=False)  # forced ASCII: 12 / 6 digits
    asc = read_frf(tmp_path / "ascii.uff")
    assert_allclose(asc.values, tf.values, rtol=1e-11)
    assert_allclose(asc.freqs, tf.freqs, rtol=1e-5)
    assert not np.array_equal(asc.freqs, tf.freqs)
    write_frf(tmp_path / "x.csv", tf)
    assert read_frf(tmp_path / "x.csv") == tf


def test_several_frfs_in_one_file(tmp_path):
    p = tmp_path / "multi.uff"
    f = np.arange(6.0)
    _raw58(p, func_type=1, x=f / 10, data=np.ones(6))               # a time record first
    _raw58(p, x=f, data=np.ones(6) * (1 + 1j), id1="first")
    _raw58(p, x=f, data=np.ones(6) * (2 - 1j), id1="second", rsp_node=4)
    assert read_frf(p).name == "first"
    second = read_frf(p, index=1)
    assert second.name == "second" and second.response_node == 4
    assert_array_equal(second.values, np.full(6, 2 - 1j))
    with pytest.raises(GearshotError, match=r"multi\.uff.*index=2.*2 FRF"):
        read_frf(p, index=2)
    assert len(read_uff_records(p)) == 1


def test_write_is_atomic_and_leaves_no_temp_file(tmp_path, monkeypatch):
    tf = _synthetic_tf()
    target = tmp_path / "a.uff"
    write_frf(target, tf)
    before = target.read_bytes()
    import pyuff

    def boom(self, *a, **k):
        raise RuntimeError("disk full")

    monkeypatch.setattr(pyuff.UFF, "write_sets", boom)
    with pytest.raises(GearshotError, match="could not write"):
        write_frf(target, replace(tf, values=tf.values * 2))
    assert target.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["a.uff"]


def _raw58(path, **fields):
    """Write one dataset 58 with pyuff directly (bypassing write_frf's checks)."""
    import pyuff

    dset = {"type": 58, "func_type": 4, "rsp_node": 1, "rsp_dir": 3, "ref_node": 1,
            "ref_dir": 3, "abscissa_spacing": 1, "binary": 0, "abscissa_spec_data_type": 18,
            "ordinate_spec_data_type": 12, "orddenom_spec_data_type": 13}
    dset.update(fields)
    pyuff.UFF(str(path)).write_sets(dset, mode="add")
    return path


def _write_text(path, text):
    path.write_text(text)
    return path


@pytest.fixture
def good_text(tmp_path):
    tf = TransferFunction(np.arange(8.0), np.arange(8.0) + 1j, name="small")
    write_frf(tmp_path / "good.uff", tf)
    text = (tmp_path / "good.uff").read_text()
    assert read_frf(tmp_path / "good.uff") == tf
    return text


def test_bad_file_truncated(tmp_path, good_text):
    p = _write_text(tmp_path / "trunc.uff", good_text[: len(good_text) // 2])
    with pytest.raises(GearshotError, match=r"trunc\.uff.*truncated"):
        read_frf(p)


def test_bad_file_truncated_but_closed(tmp_path, good_text):
    lines = good_text.splitlines(keepends=True)
    # drop two data lines but keep the closing '    -1'
    p = _write_text(tmp_path / "short.uff", "".join(lines[:-3] + lines[-1:]))
    with pytest.raises(GearshotError, match=r"short\.uff.*truncated.*8 points"):
        read_frf(p)


def test_bad_file_empty(tmp_path):
    p = _write_text(tmp_path / "empty.uff", "")
    with pytest.raises(GearshotError, match=r"empty\.uff.*empty"):
        read_frf(p)
    with pytest.raises(GearshotError, match="empty"):
        read_frf(_write_text(tmp_path / "empty.csv", ""))
    with pytest.raises(GearshotError, match="no data rows"):
        read_frf(_write_text(tmp_path / "header.csv", "freq_hz,re,im\n"))


def test_bad_file_wrong_dataset_type(tmp_path):
    import pyuff

    p = _raw58(tmp_path / "time.uff", func_type=1, x=np.arange(16) / 100.0, data=np.ones(16))
    with pytest.raises(GearshotError, match=r"time\.uff.*wrong dataset type.*function type 1"):
        read_frf(p)
    p2 = tmp_path / "nodes.uff"
    pyuff.UFF(str(p2)).write_sets(
        {"type": 15, "node_nums": [1, 2], "def_cs": [0, 0], "disp_cs": [0, 0], "color": [1, 1],
         "x": [0.0, 1.0], "y": [0.0, 0.0], "z": [0.0, 0.0]}, mode="overwrite")
    with pytest.raises(GearshotError, match=r"nodes\.uff.*wrong dataset type.*dataset 15"):
        read_frf(p2)
    if IMPACT_FILE.exists():
        with pytest.raises(GearshotError, match="wrong dataset type"):
            read_frf(IMPACT_FILE)


def test_bad_file_nan(tmp_path, good_text):
    lines = good_text.splitlines(keepends=True)
    i = 14  # second data line (13 header lines after the opening '    -1')
    fields = [lines[i][20 * j:20 * (j + 1)] for j in range(4)]
    fields[1] = f"{'nan':>20}"
    lines[i] = "".join(fields) + "\n"
    p = _write_text(tmp_path / "nan.uff", "".join(lines))
    with pytest.raises(GearshotError, match=r"nan\.uff.*non-finite"):
        read_frf(p)
    with pytest.raises(GearshotError, match=r"nan\.csv.*non-finite"):
        read_frf(_write_text(tmp_path / "nan.csv", "0,1,0\n1,nan,0\n2,1,0\n"))


def test_bad_file_non_increasing_frequencies(tmp_path):
    p = _raw58(tmp_path / "order.uff", abscissa_spacing=0, binary=1,
               x=np.array([0.0, 1.0, 3.0, 2.0, 4.0]), data=np.ones(5, complex))
    with pytest.raises(GearshotError, match=r"order\.uff.*not strictly increasing.*x\[2\]=3"):
        read_frf(p)
    with pytest.raises(GearshotError, match=r"dup\.csv.*not strictly increasing"):
        read_frf(_write_text(tmp_path / "dup.csv", "0,1,0\n1,1,0\n1,1,0\n"))


def test_bad_paths_and_suffixes(tmp_path):
    with pytest.raises(GearshotError, match="does not exist"):
        read_frf(tmp_path / "missing.uff")
    with pytest.raises(GearshotError, match="suffix"):
        read_frf(_write_text(tmp_path / "a.txt", "x"))
    with pytest.raises(GearshotError, match="garbage.uff.*no UFF dataset"):
        read_frf(_write_text(tmp_path / "garbage.uff", "hello\nworld\n"))
    with pytest.raises(GearshotError, match="3 columns"):
        read_frf(_write_text(tmp_path / "two.csv", "0,1\n1,2\n"))
    with pytest.raises(GearshotError, match="TransferFunction"):
        write_frf(tmp_path / "x.uff", np.ones(3))


def test_read_uff_records_impacts():
    if not IMPACT_FILE.exists():
        pytest.skip(f"impact records not found at {IMPACT_FILE}")
    recs = read_uff_records(IMPACT_FILE)
    assert len(recs) == 10
    assert [r.quantity for r in recs] == ["force", "acceleration"] * 5
    assert all(r.fs == 25600.0 and r.data.size == 25600 for r in recs)
    assert recs[0].name == "impact 1 force" and recs[1].node == 1 and recs[0].node == 2
    assert_allclose(recs[0].time[:2], [0.0, 1 / 25600])
    assert max(abs(recs[0].data)) == pytest.approx(68.64, rel=1e-3)  # a hammer pulse of ~69 N


def test_read_uff_records_needs_time_records():
    files = _real_frf_files()
    with pytest.raises(GearshotError, match="no UFF58 time record"):
        read_uff_records(files[0])
