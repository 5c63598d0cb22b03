"""Issue #20 item 2, unknown loads: a database over several loads, the load chosen from the
healthy recordings (gearshot.app.load_choice), refused with one line when ambiguous."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from test_cli_journey import crop  # cropped copies of the shared PHM09 records

from gearshot import GearshotError, Machine
from gearshot.app import load_choice
from gearshot.app.load_choice import LoadChoice, choose_load
from gearshot.sim import GearPair, build_database, load_database

ROOT = Path(__file__).resolve().parents[1]
SPUR = ROOT / "examples" / "machines" / "phm09_spur.toml"
LOADS = (5.0, 320.0)


@pytest.fixture(scope="module")
def stores(tmp_path_factory):
    """A database over two loads far apart (seed 0) and a second draw of the same model
    (seed 1) standing in for recordings of a machine the simulator describes exactly."""
    folder = tmp_path_factory.mktemp("loads")
    out = {}
    for seed in (0, 1):
        out[seed] = build_database(folder / f"db{seed}", GearPair.paper(), speeds=[15],
                                   loads=list(LOADS), grades=[5], n_healthy=8, n_faulty=0,
                                   seed=seed)
    return out


def _recordings(store, load, rng):
    """Healthy SAs of one load and a long signal (the SAs repeated, with 10 % noise)."""
    sa = np.asarray(load_database(store, speed=15, load=load)["sa"].values)
    long = np.concatenate([np.tile(s, 3) for s in sa])
    return sa, long + 0.1 * long.std() * rng.standard_normal(long.size)


@pytest.mark.parametrize("load", LOADS)
def test_model_matched_recordings_pick_their_own_load(stores, load):
    """Signals of the simulated model at a known load (another draw of gear errors): the
    load they were simulated at is chosen, clearly."""
    sa, long = _recordings(stores[1], load, np.random.default_rng(0))
    choice = choose_load(stores[0], 15, sa, long, mesh_order=38)
    assert choice.loads == LOADS and choice.load == load
    assert not choice.ambiguous and choice.clarity >= load_choice.MIN_CLARITY
    assert choice.distances[LOADS.index(load)] == min(choice.distances)
    assert choice.grades == (5, 5)
    line = choice.describe()
    assert f"load {load:g} N m chosen" in line and "\n" not in line
    assert json.loads(json.dumps(choice.as_dict()))["ambiguous"] is False


def test_virtual_rig_known_load_is_ambiguous_not_guessed(tmp_path):
    """The virtual rig (simulator engine, hidden build and path) at 10 N m against a
    database over the paper's loads: its healthy signals do not tell 5-20 N m apart
    (benchmarks/RESULTS.md), so the choice is ambiguous rather than a guess."""
    from gearshot.rig import VirtualRig

    store = build_database(tmp_path / "db", GearPair.paper(), speeds=[15],
                           loads=[5, 10, 20], grades=[6, 8], n_healthy=6, n_faulty=0)
    rec = VirtualRig(seed=7).record(speed=15, load=10, duration=4.0)
    kw = dict(gear_teeth=38, pinion_teeth=17, samples_per_cycle=2048)
    sa = rec.to_sa_segments(cycles_per_segment=5, **kw)
    choice = choose_load(store, 15, sa, rec.angle_domain(**kw), mesh_order=38)
    assert choice.loads == (5.0, 10.0, 20.0)
    assert choice.ambiguous and 1.0 <= choice.clarity < load_choice.MIN_CLARITY


def test_bad_inputs_name_the_parameter(stores):
    sa, long = _recordings(stores[1], 5.0, np.random.default_rng(0))
    with pytest.raises(GearshotError, match="min_clarity"):
        choose_load(stores[0], 15, sa, long, mesh_order=38, min_clarity=-1)
    with pytest.raises(GearshotError, match="at least 2"):
        choose_load(stores[0], 15, sa[:1], long, mesh_order=38)


def test_clarity_and_ambiguity():
    c = LoadChoice(load=5.0, loads=(5.0, 10.0), distances=(2.0, 2.2), grades=(6, 6),
                   clarity=1.1, min_clarity=1.5)
    assert c.ambiguous and "clarity 1.10" in c.describe()


# ---------------------------------------------------------------- predict --machine
@pytest.fixture(scope="module")
def phm(tmp_path_factory):
    """Cropped PHM09 30 Hz High records and a machine database over two loads."""
    folder = tmp_path_factory.mktemp("phm_loads")
    machine = Machine.from_toml(SPUR)
    store = build_database(folder / "db", machine.gear_pair(), speeds=[machine.sim_speed(30)],
                           loads=[5, 80], grades=[6, 7], n_healthy=6, n_faulty=24)
    files = {n: crop(f"{n}_30hz_High_1.zip", folder) for n in ("spur1", "spur2", "spur3")}
    return machine, store, files


def test_cli_refuses_an_ambiguous_load_in_one_line(phm, tmp_path):
    """PHM09: the records' load is High/Low; against 5 and 80 N m their healthy signals do
    not pick one clearly, and predict says so in one line instead of guessing."""
    _, store, files = phm
    res = subprocess.run(
        [sys.executable, "-m", "gearshot.app.cli", "predict", "--machine", str(SPUR),
         "--database", str(store), "--healthy", str(files["spur3"]), "--faulty",
         str(files["spur2"]), "--faulty-size", "0.5", "--cycles-per-segment", "10",
         "--out", str(tmp_path / "p.json")], capture_output=True, text=True, timeout=600)
    err = res.stderr.strip()
    assert res.returncode != 0 and len(err.splitlines()) == 1, err
    assert err.startswith("gearshot: error: --load is needed: the healthy recordings do not "
                          "tell the loads of database"), err
    assert "5 N m:" in err and "80 N m:" in err and "needed 1.5" in err
    assert not (tmp_path / "p.json").exists()


def test_predict_reports_the_chosen_load(phm, monkeypatch):
    """Where the choice is clear (here forced by lowering MIN_CLARITY), the load is used
    and every row says which and how clear (``load_source``, ``load_clarity``)."""
    from gearshot.app.predict_machine import predict_from_machine

    machine, store, files = phm
    monkeypatch.setattr(load_choice, "MIN_CLARITY", 1.0)
    frame = predict_from_machine(machine, store, [files["spur3"]], files["spur2"], 0.5,
                                 [files["spur1"]], cycles_per_segment=10)
    choice = frame.attrs["load_choice"]
    assert frame.attrs["load_source"] == "chosen" and choice["load"] in (5.0, 80.0)
    assert choice["loads"] == [5.0, 80.0] and choice["clarity"] >= 1.0
    assert (frame["database_load"] == choice["load"]).all()
    assert (frame["load_source"] == "chosen").all()
    assert np.allclose(frame["load_clarity"].astype(float), choice["clarity"])
    given = predict_from_machine(machine, store, [files["spur3"]], files["spur2"], 0.5,
                                 [files["spur1"]], cycles_per_segment=10,
                                 load=choice["load"])
    assert (given["load_source"] == "given").all() and given["load_clarity"].isna().all()
    # the same condition gives the same estimates, however the load was found
    assert np.array_equal(given["predicted"], frame["predicted"])
