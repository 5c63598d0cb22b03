"""Databases with a fault_type dimension and the estimator's slice of it."""
import json

import numpy as np
import pytest

from gearshot import GearshotError
from gearshot.estimator._model import _select_fault_type
from gearshot.sim import GearPair, build_database, load_database


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    path = tmp_path_factory.mktemp("db") / "db"
    build_database(path, GearPair.paper(), speeds=[15], loads=[10], grades=[7],
                   n_healthy=2, n_faulty=3, fault_types=["ftff", "breakage"], client=False,
                   progress=False)
    return path


def test_fault_type_dimension(store):
    ds = load_database(store, speed=15, load=10)
    assert list(ds.fault_type.values) == ["ftff"] * 5 + ["breakage"] * 5
    br = load_database(store, speed=15, load=10, fault_type="breakage")
    assert br.sizes["signal"] == 5 and set(br.fault_type.values) == {"breakage"}
    # the FTFF block is the one an FTFF-only build makes (same seeds, same name)
    assert json.loads((store / "manifest.json").read_text())["fault_types"] == [
        "ftff", "breakage"]
    with pytest.raises(GearshotError, match="fault_type"):
        load_database(store, speed=15, load=10, fault_type="destruction")
    with pytest.raises(GearshotError, match="fault_types"):
        build_database(store.parent / "x", speeds=[15], loads=[10], grades=[7],
                       fault_types=["ftff", "ftff"], client=False, progress=False)


def test_ftff_only_store_keeps_old_layout(tmp_path, store):
    path = tmp_path / "old"
    build_database(path, GearPair.paper(), speeds=[15], loads=[10], grades=[7],
                   n_healthy=2, n_faulty=3, client=False, progress=False)
    man = json.loads((path / "manifest.json").read_text())
    assert "fault_types" not in man and "helix_angle" not in man["pair"]
    a = load_database(path, speed=15, load=10)
    b = load_database(store, speed=15, load=10, fault_type="ftff")
    np.testing.assert_array_equal(a.sa.values, b.sa.values)


def test_estimator_selects_fault_type(store):
    ds = load_database(store, speed=15, load=10)
    with pytest.raises(GearshotError, match="several fault types"):
        _select_fault_type(ds, None)
    sel = _select_fault_type(ds, "breakage")
    assert sel.sizes["signal"] == 5
    with pytest.raises(GearshotError, match="not in the database"):
        _select_fault_type(ds, "destruction")


def test_store_of_an_older_fault_model_is_refused(tmp_path, store):
    """A breakage store built before the breakage model changed (no or an older
    ``fault_models`` version) is refused, naming the type and both versions; its FTFF
    slice stays usable."""
    import shutil

    from gearshot.sim.fault_types import FAULT_MODEL_VERSIONS

    man = json.loads((store / "manifest.json").read_text())
    assert man["fault_models"] == {"ftff": 1, "breakage": FAULT_MODEL_VERSIONS["breakage"]}
    old = tmp_path / "old"
    shutil.copytree(store, old)
    del man["fault_models"]                 # as written before model versions existed
    (old / "manifest.json").write_text(json.dumps(man))
    for block in (old / "blocks").glob("*.zarr"):   # ... and the blocks' records then
        meta = json.loads((block / "zarr.json").read_text())
        record = meta["attributes"]["gearshot_block"]
        record["manifest"] = man
        del record["manifest_sha256"]
        (block / "zarr.json").write_text(json.dumps(meta))
    with pytest.raises(GearshotError, match=r"'breakage' SAs of an older model.*"
                                            r"version None, current 2"):
        load_database(old, speed=15, load=10, fault_type="breakage")
    with pytest.raises(GearshotError, match="older model"):
        load_database(old, speed=15, load=10)
    assert load_database(old, speed=15, load=10, fault_type="ftff").sizes["signal"] == 5
    with pytest.raises(GearshotError, match="different build.*fault_models"):
        build_database(old, GearPair.paper(), speeds=[15], loads=[10], grades=[7],
                       n_healthy=2, n_faulty=3, fault_types=["ftff", "breakage"],
                       client=False, progress=False)
