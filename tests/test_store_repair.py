"""Repairs that repair (issue #32): the command a damaged store names leaves a store that
loads; a lost, empty, invalid or edited manifest.json is restored from the blocks by
``gearshot simulate --repair --store S``; an edited manifest speed is reported as
tampering, not as the caller's wrong speed."""

from __future__ import annotations

import json
import sys

import fake_store
import numpy as np
import pytest

from gearshot import GearshotError

KW = fake_store.KW
# the stand-in simulator (autouse) and the tiny store, as this module's fixtures
fast_simulator, store = fake_store.fast_simulator, fake_store.store


def _reference(store):
    from gearshot.sim import load_database

    return {s: load_database(store, speed=s, load=10).sa.values for s in (15, 20)}


def _assert_loads_as(store, ref):
    from gearshot.sim import load_database

    for s, values in ref.items():
        np.testing.assert_array_equal(load_database(store, speed=s, load=10).sa.values,
                                      values)


def _edit_crc(block):
    meta_path = block / "zarr.json"
    meta = json.loads(meta_path.read_text())
    files = meta["attributes"]["gearshot_block"]["files"]
    rel = sorted(files)[0]
    files[rel] = [files[rel][0], (files[rel][1] + 1) % 2 ** 32]
    meta_path.write_text(json.dumps(meta))
    return rel


def _cli(args, monkeypatch, capsys):
    from gearshot.app.cli import main

    monkeypatch.setattr(sys, "argv", ["gearshot", *map(str, args)])
    try:
        main()
        code = 0
    except SystemExit as exc:
        code = int(exc.code or 0)
    out = capsys.readouterr()
    return code, out.out, out.err.strip()


def test_edited_crc_is_named_and_the_offered_build_leaves_a_store_that_loads(store):
    """One CRC edited in a block's checksum list: loading names it; the build command the
    message offers (the store's own arguments) rebuilds that block, and the store loads."""
    from gearshot.sim import build_database, load_database

    ref = _reference(store)
    block = store / "blocks" / "s1_l0_g1.zarr"
    _edit_crc(block)
    with pytest.raises(GearshotError) as info:
        load_database(store, speed=20, load=10)
    msg = str(info.value)
    assert "s1_l0_g1.zarr" in msg and "changed after the build" in msg, msg
    assert f"gearshot simulate --repair --store {store}" in msg
    build_database(store, **KW)                 # the offered build, as before
    _assert_loads_as(store, ref)


def test_edited_crc_is_repaired_by_the_repair_command(store, monkeypatch, capsys):
    ref = _reference(store)
    _edit_crc(store / "blocks" / "s0_l0_g0.zarr")
    code, out, err = _cli(["simulate", "--repair", "--store", store], monkeypatch, capsys)
    assert code == 0, err
    assert "s0_l0_g0.zarr" in out and "database ready" in out
    _assert_loads_as(store, ref)


def test_bit_rot_that_keeps_size_and_time_is_repaired(store):
    """A chunk overwritten in place with its size and time kept: a resuming build cannot
    see it (sizes and times only); the repair's full check does, and rebuilds it."""
    import os

    from gearshot.sim import load_database, repair_database

    ref = _reference(store)
    chunk = store / "blocks" / "s0_l0_g1.zarr" / "sa" / "c" / "0" / "0"
    st = chunk.stat()
    data = bytearray(chunk.read_bytes())
    data[-1] ^= 0xFF
    chunk.write_bytes(bytes(data))
    os.utime(chunk, ns=(st.st_atime_ns, st.st_mtime_ns))
    with pytest.raises(GearshotError, match="is corrupt"):
        load_database(store, speed=15, load=10)
    done = repair_database(store, progress=False)
    assert len(done) == 1 and "s0_l0_g1.zarr" in done[0] and "corrupt" in done[0]
    _assert_loads_as(store, ref)


@pytest.mark.parametrize("damage", ["deleted", "empty", "invalid", "not a manifest",
                                    "edited speed"])
def test_lost_or_damaged_manifest_is_restored_by_the_repair_command(
        damage, store, monkeypatch, capsys):
    from gearshot.sim import load_database

    ref = _reference(store)
    man = json.loads((store / "manifest.json").read_text())
    stamp = (store / "blocks" / "s0_l0_g0.zarr" / "zarr.json").stat().st_mtime_ns
    path = store / "manifest.json"
    if damage == "deleted":
        path.unlink()
    else:
        path.write_text({"empty": "", "invalid": "{not json", "not a manifest": "[1, 2]",
                         "edited speed": json.dumps({**man, "speeds": [16.0, 20.0]})}[damage])
    with pytest.raises(GearshotError) as info:
        load_database(store, speed=15, load=10)
    assert f"gearshot simulate --repair --store {store}" in str(info.value)
    code, out, err = _cli(["simulate", "--repair", "--store", store], monkeypatch, capsys)
    assert code == 0, err
    assert "restored from the blocks' copies" in out and "database ready" in out
    assert json.loads(path.read_text()) == man
    _assert_loads_as(store, ref)
    # no block rebuilt: the manifest alone was restored
    assert (store / "blocks" / "s0_l0_g0.zarr" / "zarr.json").stat().st_mtime_ns == stamp
    del load_database


def test_edited_manifest_speed_is_reported_as_tampering_not_a_wrong_speed(store):
    from gearshot.sim import load_database

    man = json.loads((store / "manifest.json").read_text())
    (store / "manifest.json").write_text(json.dumps({**man, "speeds": [16.0, 20.0]}))
    with pytest.raises(GearshotError) as info:
        load_database(store, speed=15, load=10)       # the speed the store was built at
    msg = str(info.value)
    assert "manifest.json was changed after the build" in msg, msg
    assert "speeds ([16.0, 20.0] vs [15.0, 20.0])" in msg
    assert "is not in the database" not in msg


def test_a_wrong_speed_on_a_whole_store_is_still_the_callers(store):
    from gearshot.sim import load_database

    with pytest.raises(GearshotError, match=r"speed 17 is not in the database"):
        load_database(store, speed=17, load=10)


def test_repair_of_a_whole_store_changes_nothing(store, monkeypatch, capsys):
    ref = _reference(store)
    code, out, err = _cli(["simulate", "--repair", "--store", store], monkeypatch, capsys)
    assert code == 0 and "nothing to repair" in out, (out, err)
    _assert_loads_as(store, ref)


def test_repair_rebuilds_a_deleted_block(store):
    import shutil

    from gearshot.sim import repair_database

    ref = _reference(store)
    shutil.rmtree(store / "blocks" / "s1_l0_g0.zarr")
    assert repair_database(store, progress=False) == [
        "1 missing block(s) to build: s1_l0_g0.zarr"]
    _assert_loads_as(store, ref)


@pytest.mark.parametrize("args, words", [
    (["simulate", "--repair"], ["--repair needs --store"]),
    (["simulate", "--repair", "--store", "{tmp}/db", "--seed", "4"], ["--seed"]),
    (["simulate", "--repair", "--store", "{tmp}/db", "--speed", "20", "--grade", "3"],
     ["--speed", "--grade"]),
    (["simulate", "--repair", "--store", "{tmp}/none"], ["no such folder"]),
])
def test_repair_refusals_are_one_line(args, words, tmp_path, monkeypatch, capsys):
    code, _, err = _cli([a.format(tmp=tmp_path) for a in args], monkeypatch, capsys)
    assert code == 2 and len(err.splitlines()) == 1, err
    for word in words:
        assert word in err


def test_repair_without_anything_to_restore_from_says_so(tmp_path):
    from gearshot.sim import repair_database

    (tmp_path / "db" / "blocks").mkdir(parents=True)
    (tmp_path / "db" / "manifest.json").write_text("")
    with pytest.raises(GearshotError, match="none of its 0 block"):
        repair_database(tmp_path / "db", progress=False)


def test_blocks_of_different_builds_are_not_merged_by_a_repair(store, tmp_path):
    import shutil

    from gearshot.sim import build_database, repair_database

    other = build_database(tmp_path / "other", **{**KW, "seed": 4})
    shutil.rmtree(store / "blocks" / "s0_l0_g0.zarr")
    shutil.copytree(other / "blocks" / "s0_l0_g0.zarr", store / "blocks" / "s0_l0_g0.zarr")
    (store / "manifest.json").unlink()
    with pytest.raises(GearshotError, match="record different builds"):
        repair_database(store, progress=False)
