"""The fast paths of issue #23 against their references: batch FTFF tables, lane-grouped
kernels, one read per chunk in load_database, sizes-only resume."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from gearshot import GearshotError
from gearshot.sim import Fault, GearPair, simulate_sa
from gearshot.sim.stiffness import _faulty_gear_compliance, _healthy_compliances


def _generic_ftff_table(pair, fault):
    """The stiffness table of an FTFF by the generic (per-fault numpy) path."""
    import math

    inv_p, _ = _healthy_compliances(pair)
    inv_g = _faulty_gear_compliance(pair, fault)
    k_h = math.pi * pair.youngs_modulus * pair.face_width / (4 * (1 - pair.poisson ** 2))
    return 1.0 / (1.0 / k_h + inv_p + inv_g)


def test_batch_ftff_tables_match_the_generic_path():
    from gearshot.sim._ftff_batch import bridge_batch, ftff_tables

    pair = GearPair.paper()
    faults = [Fault.ftff(y) for y in (0.05, 0.3, 0.61, 0.97, 1.0)] + [
        Fault.ftff(0.2, center=0.2, depth=0.9)]
    k, ef = ftff_tables(pair, faults)
    knots, ret, _ = bridge_batch(pair, faults)
    u = np.linspace(0.0, 1.0, k.shape[1])
    for i, f in enumerate(faults):
        ref = _generic_ftff_table(pair, f)
        assert np.max(np.abs(k[i] / ref - 1)) < 1e-12
        # the displacement is the bridge's retreat, interpolated over the cut
        inside = (1 - u > f.window[0]) & (1 - u < f.window[1])
        np.testing.assert_allclose(
            ef[i][inside], -np.interp((1 - u)[inside], knots[i], ret[i]), rtol=0, atol=0)
        assert ef[i][~inside].max() == 0 and ef[i].min() < 0
        # a fault's rows do not depend on the batch it is computed in
        k1, ef1 = ftff_tables(pair, [f])
        np.testing.assert_array_equal(k1[0], k[i])
        np.testing.assert_array_equal(ef1[0], ef[i])
    # deeper cuts retreat further (physical sanity)
    assert ret[3].max() > ret[1].max() > ret[0].max() > 0


@pytest.mark.parametrize("helical", [False, True])
def test_signal_does_not_depend_on_its_batch(helical):
    """Lane groups and padding: a signal alone equals the same signal in a batch of 11
    (8 lanes + a padded group of 3)."""
    import math

    pair = GearPair.helical(math.radians(20)) if helical else GearPair.paper()
    sizes = np.linspace(0.0, 1.0, 11)
    seeds = list(range(100, 111))
    kw = dict(speed=30, load=10, grade=6, n_points=256)
    batch = simulate_sa(pair, fault_sizes=sizes, rng=seeds, **kw)
    for i in (0, 5, 10):
        alone = simulate_sa(pair, fault_sizes=[sizes[i]], rng=[seeds[i]], **kw)[0]
        scale = np.max(np.abs(alone))
        assert np.max(np.abs(batch[i] - alone)) <= 1e-12 * scale
    assert np.all(np.isfinite(batch)) and not np.allclose(batch[0], batch[-1])


# ------------------------------------------------------------------- database reads
def _fake_simulate_sa(pair, *, speed, load, grade, fault_sizes, n_points, rng,
                      fault_type="ftff"):
    return np.stack([np.random.default_rng(s).standard_normal(n_points) for s in rng])


KW = dict(speeds=[15], loads=[10], grades=[7, 8], n_healthy=2, n_faulty=3, seed=5,
          n_points=64, client=False, progress=False)


@pytest.fixture
def store(tmp_path, monkeypatch):
    from gearshot.sim import build_database

    monkeypatch.setattr("gearshot.sim.database.simulate_sa", _fake_simulate_sa)
    monkeypatch.setattr("gearshot.sim.database.simulate_sa_paired",
                        lambda pair, **kw: (_fake_simulate_sa(pair, **kw),) * 2)
    return build_database(tmp_path / "db", **KW)


def _count_reads(monkeypatch):
    """Count reads of chunk files (paths with a '/c/' component) by path."""
    import builtins
    import io

    counts: dict[str, int] = {}
    real_open = io.open

    def counting_open(file, mode="r", *args, **kwargs):
        name = os.fspath(file) if isinstance(file, (str, Path)) else ""
        if "r" in mode and f"{os.sep}c{os.sep}" in name:
            counts[name] = counts.get(name, 0) + 1
        return real_open(file, mode, *args, **kwargs)

    monkeypatch.setattr(builtins, "open", counting_open)
    monkeypatch.setattr(io, "open", counting_open)
    return counts


def test_load_reads_every_chunk_once(store, monkeypatch):
    from gearshot.sim import load_database

    chunks = sorted(str(p) for p in store.rglob("*") if p.is_file() and "/c/" in str(p))
    counts = _count_reads(monkeypatch)
    ds = load_database(store, speed=15, load=10)
    assert ds.sa.shape == (10, 64) and np.all(np.isfinite(ds.sa.values))
    assert chunks and sorted(counts) == chunks
    assert set(counts.values()) == {1}


def test_resume_reads_no_chunk(store, monkeypatch):
    from gearshot.sim import build_database

    counts = _count_reads(monkeypatch)
    monkeypatch.setattr("gearshot.sim.database.simulate_sa", _fake_simulate_sa)
    monkeypatch.setattr("gearshot.sim.database.simulate_sa_paired",
                        lambda pair, **kw: (_fake_simulate_sa(pair, **kw),) * 2)
    build_database(store, **KW)
    assert counts == {}


def test_same_size_damage_is_caught_on_load(store, monkeypatch):
    """A damage keeping a chunk's size and time (bit rot) passes the resume check but
    is named when the block is read."""
    from gearshot.sim import build_database, load_database

    chunk = store / "blocks" / "s0_l0_g1.zarr" / "sa" / "c" / "0" / "0"
    st = chunk.stat()
    data = bytearray(chunk.read_bytes())
    data[len(data) // 2] ^= 0xFF
    chunk.write_bytes(bytes(data))
    os.utime(chunk, ns=(st.st_atime_ns, st.st_mtime_ns))
    monkeypatch.setattr("gearshot.sim.database.simulate_sa", _fake_simulate_sa)
    monkeypatch.setattr("gearshot.sim.database.simulate_sa_paired",
                        lambda pair, **kw: (_fake_simulate_sa(pair, **kw),) * 2)
    build_database(store, **KW)                       # sizes and times agree: kept
    with pytest.raises(GearshotError, match=r"s0_l0_g1\.zarr.*corrupt.*remove"):
        load_database(store, speed=15, load=10)


def test_modified_chunk_is_rebuilt_on_resume(store, monkeypatch):
    from gearshot.sim import build_database, load_database

    ref = load_database(store, speed=15, load=10).sa.values
    chunk = store / "blocks" / "s0_l0_g0.zarr" / "sa" / "c" / "0" / "0"
    data = bytearray(chunk.read_bytes())
    data[3] ^= 0x01                                   # same size, newer time
    chunk.write_bytes(bytes(data))
    st = chunk.stat()
    os.utime(chunk, ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))
    monkeypatch.setattr("gearshot.sim.database.simulate_sa", _fake_simulate_sa)
    monkeypatch.setattr("gearshot.sim.database.simulate_sa_paired",
                        lambda pair, **kw: (_fake_simulate_sa(pair, **kw),) * 2)
    build_database(store, **KW)
    np.testing.assert_array_equal(load_database(store, speed=15, load=10).sa.values, ref)


@pytest.mark.parametrize("helical", [False, True])
def test_cut_from_the_lowest_contact_point_has_no_retreat_at_its_edge(helical):
    """A cut starting at the lowest contact point (s0 = 0): at that edge the pinion tip
    touches the intact involute, so the retreat is 0 there (the flank point at the
    pinion tip counts; it was kept or dropped by rounding before, a 0.5 mm spike)."""
    import math

    pair = GearPair.helical(math.radians(20)) if helical else GearPair.paper()
    for fault in (Fault.ftff(1.0), Fault.ftff(0.3, center=0.15)):
        knots, ret, _ = fault.bridge(pair)
        assert knots[0] == 0.0
        assert ret[0] < 1e-9 and ret.max() > 1e-6
