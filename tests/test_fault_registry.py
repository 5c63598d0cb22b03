"""One fault-type record (issue #21 item 3): names, classes, stable codes, versions, options."""

import dataclasses
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from gearshot import GearshotError
from gearshot.fault_registry import (
    FAULT_TYPE_NAMES,
    FAULT_TYPE_RECORDS,
    check_fault_type,
    fault_type_record,
)

SRC = Path(__file__).resolve().parents[1] / "src"
#: a store built before the fault-type registry, where a type's code was its
#: position in the dict ``FAULT_TYPES``: seed 11, 15 rev/s, 10 N m, grade 7, 1 + 1 signals
#: of 16 points per type, paired
OLD_STORE = Path(__file__).resolve().parent / "data" / "store_before_fault_registry.zip"
#: the codes and model versions every store built so far carries
OLD_CODES = {"ftff": 0, "partial_face": 1, "breakage": 2, "destruction": 3}
OLD_VERSIONS = {"ftff": 1, "partial_face": 1, "breakage": 2, "destruction": 1}


def test_codes_and_versions_are_the_old_ones():
    assert {n: r.code for n, r in FAULT_TYPE_RECORDS.items()} == OLD_CODES
    assert {n: r.version for n, r in FAULT_TYPE_RECORDS.items()} == OLD_VERSIONS
    assert FAULT_TYPE_NAMES == tuple(OLD_CODES)          # code order
    assert all(r.name == n for n, r in FAULT_TYPE_RECORDS.items())


def test_the_simulator_reads_the_registry():
    from gearshot.sim import FAULT_TYPES
    from gearshot.sim.fault_types import FAULT_MODEL_VERSIONS, fault_class

    assert tuple(FAULT_TYPES) == FAULT_TYPE_NAMES
    assert FAULT_MODEL_VERSIONS == OLD_VERSIONS
    for name, rec in FAULT_TYPE_RECORDS.items():
        cls = fault_class(name)
        assert cls.__name__ == rec.class_
        fields = {f.name for f in dataclasses.fields(cls)}
        assert set(rec.options) <= fields, (name, rec.options)
        assert type(FAULT_TYPES[name](0.4)) is cls


@pytest.mark.parametrize("name", FAULT_TYPE_NAMES)
def test_simulator_options_follow_the_record(name):
    """``simulate_sa``'s ``center``/``depth`` reach exactly the fields the record names."""
    from gearshot.sim._inputs import resolve_faults
    from gearshot.sim.fault_types import fault_class

    (fault,) = resolve_faults([0.4], None, center=0.35, depth=0.7, fault_type=name)
    default = fault_class(name)(size=0.4)
    opts = fault_type_record(name).options
    assert fault.size == 0.4
    for field, value in (("center", 0.35), ("depth", 0.7)):
        if field in opts:
            assert getattr(fault, field) == value
        elif hasattr(default, field):
            assert getattr(fault, field) == getattr(default, field)


def test_unknown_names_are_refused_naming_the_known_ones():
    assert check_fault_type("breakage") == "breakage"
    for bad in ("rust", None, 3, "FTFF"):
        with pytest.raises(GearshotError, match=r"fault_type must be one of .*'ftff'"):
            fault_type_record(bad)


def test_the_registry_imports_no_simulator():
    code = ("import sys, gearshot.fault_registry; "
            "bad = [m for m in sys.modules if m.startswith('gearshot.sim') or m == 'numba']; "
            "assert not bad, bad")
    env = dict(os.environ, PYTHONPATH=str(SRC))
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert res.returncode == 0, res.stderr


def test_a_store_built_before_the_registry_loads_and_matches(tmp_path, monkeypatch):
    from gearshot.sim import GearPair, build_database, load_database
    from gearshot.sim._integrity import block_draws

    with zipfile.ZipFile(OLD_STORE) as z:
        z.extractall(tmp_path)
    store = tmp_path / "store"
    for name, code in OLD_CODES.items():
        ds = load_database(store, speed=15, load=10, fault_type=name)
        sizes, seeds = block_draws(11, 0, 0, 0, code, 1, 1)
        np.testing.assert_array_equal(ds["seed"].values, seeds)
        np.testing.assert_array_equal(ds["fault_size"].values, sizes)
        assert np.all(np.isfinite(ds["sa"].values)) and ds["sa"].shape == (2, 16)
    # the same build finds every block its own: nothing is simulated again

    def no_simulation(*args, **kwargs):
        raise AssertionError("a block of the old store was rebuilt")

    monkeypatch.setattr("gearshot.sim.database.simulate_sa", no_simulation)
    monkeypatch.setattr("gearshot.sim.database.simulate_sa_paired", no_simulation)
    build_database(store, GearPair.paper(), speeds=[15.0], loads=[10.0], grades=[7],
                   n_healthy=1, n_faulty=1, seed=11, n_points=16, client=False,
                   progress=False, fault_types=list(OLD_CODES), paired=True)


def test_cli_lists_the_registrys_fault_types():
    from typer.testing import CliRunner

    from gearshot.app.cli import app

    res = CliRunner().invoke(app, ["simulate", "--help"], env={"COLUMNS": "200"})
    assert res.exit_code == 0
    assert f"Fault type(s): {', '.join(FAULT_TYPE_NAMES)}." in res.output
