"""An index from a folder or a glob of recordings (gearshot.monitor.listing, read_index)."""

from __future__ import annotations

import os

import pandas as pd
import pytest

from gearshot import GearshotError
from gearshot.monitor import read_index
from gearshot.monitor.listing import name_time


@pytest.mark.parametrize("name, expected", [
    ("pump3_2026-03-01T08-15-00.h5", "2026-03-01 08:15:00"),
    ("2026-03-01_0815.zip", "2026-03-01 08:15:00"),
    ("20260301T081500.wav", "2026-03-01 08:15:00"),
    ("20260301_0815.wav", "2026-03-01 08:15:00"),
    ("run 2026-03-01 08:15:30.csv", "2026-03-01 08:15:30"),
    ("2026-03-01.zip", "2026-03-01 00:00:00"),
])
def test_name_time_reads_the_usual_spellings(name, expected):
    assert name_time(name) == pd.Timestamp(expected)


@pytest.mark.parametrize("name", ["life_007.h5", "s15_l10_y0.00_r3.h5", "2026-13-45.h5",
                                  "spur3_30hz_High_2.zip", "123456789012345.h5"])
def test_name_time_is_none_without_a_date(name):
    assert name_time(name) is None


def _touch(folder, names, mtimes=None):
    folder.mkdir(parents=True, exist_ok=True)
    for i, name in enumerate(names):
        path = folder / name
        path.write_bytes(b"")
        if mtimes is not None:
            stamp = pd.Timestamp(mtimes[i]).timestamp()
            os.utime(path, (stamp, stamp))
    return folder


def test_a_folder_with_an_index_is_that_index(tmp_path):
    _touch(tmp_path, ["a.h5", "b.h5"])
    (tmp_path / "index.csv").write_text("file,time,speed\nb.h5,2026-01-02T00:00:00,15.1\n"
                                        "a.h5,2026-01-01T00:00:00,14.9\n")
    from_folder, from_csv = read_index(tmp_path), read_index(tmp_path / "index.csv")
    pd.testing.assert_frame_equal(from_folder, from_csv)
    assert list(from_folder["speed"]) == [14.9, 15.1] and "source" not in from_folder.attrs


def test_a_folder_index_says_which_recordings_it_leaves_out(tmp_path):
    _touch(tmp_path, ["a.h5", "b.h5", "c.zip"])
    (tmp_path / "index.csv").write_text("file,time\na.h5,2026-01-01T00:00:00\n")
    table = read_index(tmp_path)
    assert len(table) == 1
    assert table.attrs["source"] == (f"{tmp_path / 'index.csv'}; 2 recording file(s) of "
                                     f"the folder are not in it and not estimated (e.g. "
                                     f"'b.h5')")
    assert "source" not in read_index(tmp_path / "index.csv").attrs


def test_a_folder_of_named_recordings_is_ordered_by_the_names(tmp_path):
    names = ["m_2026-02-03T10-00-00.h5", "m_2026-02-01T10-00-00.h5", "m_2026-02-02T09-30-00.h5"]
    # modification times in the opposite order: the names win
    _touch(tmp_path, [*names, "notes.txt.json", "model.skops", ".m_partial.h5"],
           ["2026-05-01", "2026-05-03", "2026-05-02", "2026-05-04", "2026-05-05",
            "2026-05-06"])
    table = read_index(tmp_path)
    assert [os.path.basename(p) for p in table["recording"]] == [names[1], names[2], names[0]]
    assert list(table["time"]) == [pd.Timestamp("2026-02-01 10:00"),
                                   pd.Timestamp("2026-02-02 09:30"),
                                   pd.Timestamp("2026-02-03 10:00")]
    assert table.attrs["source"].startswith("3 recording(s) of folder")
    assert "file names" in table.attrs["source"]


def test_without_times_in_the_names_the_time_stamps_order_them(tmp_path):
    _touch(tmp_path, ["x.h5", "y.h5", "z.zip"],
           ["2026-03-03 12:00", "2026-03-01 12:00", "2026-03-02 12:00"])
    table = read_index(tmp_path)
    assert [os.path.basename(p) for p in table["recording"]] == ["y.h5", "z.zip", "x.h5"]
    assert table["time"].iloc[0] == pd.Timestamp("2026-03-01 12:00")
    assert "modification times" in table.attrs["source"]


def test_a_glob_lists_only_what_it_matches(tmp_path):
    _touch(tmp_path / "d", ["a_2026-01-01.h5", "b_2026-01-02.h5", "c_2026-01-03.zip"])
    table = read_index(str(tmp_path / "d" / "*.h5"))
    assert len(table) == 2 and "pattern" in table.attrs["source"]


def test_names_with_and_without_times_are_refused(tmp_path):
    _touch(tmp_path, ["a_2026-01-01.h5", "b.h5"])
    with pytest.raises(GearshotError, match=r"'a_2026-01-01.h5'.*'b.h5'"):
        read_index(tmp_path)


def test_an_empty_folder_or_pattern_is_refused(tmp_path):
    _touch(tmp_path / "empty", ["readme.md"])
    with pytest.raises(GearshotError, match="holds no recording file"):
        read_index(tmp_path / "empty")
    with pytest.raises(GearshotError, match="holds no recording file"):
        read_index(str(tmp_path / "nothing-*.h5"))
    with pytest.raises(GearshotError, match="does not exist"):
        read_index(tmp_path / "missing.csv")
