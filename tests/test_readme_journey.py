"""Issue #20: the README's "Your own gearbox" commands, run as written on the shared PHM09
subset (only the simulation counts are made smaller), and the speed checks against the
database they build."""

from __future__ import annotations

import json
import os
import shlex
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
from readme_sections import readme_commands

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"
PHM = SHARED / "data" / "phm09"
SPUR = ROOT / "examples" / "machines" / "phm09_spur.toml"
#: appended to the README's `gearshot simulate` line: a test-sized database (2 grades)
SMALL_DATABASE = "--n-healthy 6 --n-faulty 24 --grade 6 --grade 7 --workers 1"




def cli(*args, cwd=None, env=None, timeout=900):
    return subprocess.run([sys.executable, "-m", "gearshot.app.cli", *map(str, args)],
                          capture_output=True, text=True, timeout=timeout, cwd=cwd, env=env)


@pytest.fixture(scope="module")
def journey(tmp_path_factory):
    if not (PHM / "spur2_30hz_High_1.zip").is_file():
        pytest.skip(f"{PHM} is absent; the README journey runs on ../shared/data/phm09")
    top = tmp_path_factory.mktemp("journey")
    work = top / "work"
    work.mkdir()
    (top / "shared").symlink_to(SHARED)          # ../shared/... as from the repository
    (work / "examples").symlink_to(ROOT / "examples")
    env = {**os.environ, "GEARSHOT_DATA": str(top / "data")}
    gearshot = f"{shlex.quote(sys.executable)} -m gearshot.app.cli"
    runs = {}
    for command in readme_commands("Your own gearbox"):
        assert command.startswith("gearshot "), command
        sub = command.split()[1]
        line = gearshot + command[len("gearshot"):]
        if sub == "simulate":
            line += " " + SMALL_DATABASE
        res = subprocess.run(["bash", "-c", line], capture_output=True, text=True, cwd=work,
                             env=env, timeout=1200)
        runs[sub] = res
        assert res.returncode == 0, f"{command}\n{res.stderr}"
    return {"work": work, "env": env, "runs": runs}


def test_readme_journey_commands_run_as_written(journey):
    assert list(journey["runs"]) == ["indicators", "simulate", "predict", "report"]
    for res in journey["runs"].values():
        assert "Traceback" not in res.stderr


def test_readme_journey_ranks_the_indicators(journey):
    ranking = pd.read_csv(journey["work"] / "look" / "ranking.csv")
    assert (journey["work"] / "look" / "ranking.png").stat().st_size > 0
    assert {"auc[30hz_High]", "auc[30hz_Low]", "auc_overall"} <= set(ranking.columns)
    assert ranking["auc_overall"].between(0, 1).all()
    assert set(ranking["sensor"]) == {"acc_input", "acc_output"}   # every sensor by default
    assert (ranking["n_healthy"] == 4).all() and (ranking["n_faulty"] == 2).all()
    # the chip on the input gear raises the difference signal's kurtosis at the input
    # sensor in both cells: a threshold separates chipped from good
    row = ranking[(ranking["sensor"] == "acc_input")
                  & (ranking["indicator"] == "kurtosis_diff")].iloc[0]
    assert row["auc_overall"] == 1.0 and row["direction"] == "rises with fault"
    assert ranking["separation"].is_monotonic_decreasing


def test_readme_journey_estimates_are_self_describing(journey):
    res = journey["runs"]["predict"]
    # --speed and --load were left out: read from the tacho, the database's only load
    assert "database condition: tacho shaft 30 Hz, load 10 N m" in res.stdout
    assert "mean estimated size" in res.stdout          # the summary's value column is headed
    payload = json.loads((journey["work"] / "estimates.json").read_text())
    # the JSON carries its inputs and fit beside its rows (issue #32)
    assert payload["kind"] == "predict" and payload["inputs"]["faulty_size"] == 0.5
    assert payload["inputs"]["machine"] == "examples/machines/phm09_spur.toml"
    assert len(payload["inputs"]["healthy"]) == 2 and payload["inputs"]["speed"] == 30.0
    assert payload["fit"]["grade"] in (6, 7) and payload["fit"]["simulated_reference"] == "twin"
    assert payload["summary"]["segments"] == len(payload["rows"])
    frame = pd.DataFrame(payload["rows"])
    assert set(frame["role"]) == {"healthy_holdout", "faulty_rest", "test"}
    names = {Path(r).name for r in frame.loc[frame["role"] == "test", "recording"]}
    assert names == {f"spur{k}_30hz_Low_1.zip" for k in (1, 2, 3)}  # the glob, expanded
    held = {Path(r).name for r in frame.loc[frame["role"] == "healthy_holdout", "recording"]}
    assert held == {"spur1_30hz_High_1.zip", "spur3_30hz_High_1.zip"}  # two after --healthy
    assert (frame["database_speed_hz"] == 30.0).all()
    assert frame["speed_hz"].between(29.0, 30.0).all()   # 0.97-1.00 x nominal
    assert frame["predicted"].between(0, 1).all()
    assert (frame["low"] <= frame["predicted"]).all()
    assert (frame["predicted"] <= frame["high"]).all()
    # at the fitted condition the method separates: the chipped record's other segments
    # read above both healthy records' held-out segments, which read near 0
    mean = frame.groupby(["recording", "role"])["predicted"].mean()
    holdout = mean.xs("healthy_holdout", level="role")
    assert holdout.max() < 0.15
    assert mean.xs("faulty_rest", level="role").iloc[0] > holdout.max() + 0.1


def test_readme_journey_flags_every_low_record(journey):
    """Issue #29: fitted at High load, the Low records are out of the fitted machine's
    distribution (not comparable); the fit's own hold-outs and the example record's other
    segments are comparable. The healthy gears' Low records by their regular part; the
    chipped gear's, whose regular part lies within the example's fault states on this
    sensor, by its speed: the motor runs 0.6-1.6 % slower at Low load."""
    frame = pd.DataFrame(json.loads((journey["work"] / "estimates.json").read_text())["rows"])
    name = frame["recording"].map(lambda r: Path(r).name)
    for case in ("spur1", "spur3"):
        rows = frame[name == f"{case}_30hz_Low_1.zip"]
        assert len(rows) and (~rows["comparable"]).mean() >= 0.8, case
        assert rows["comparability"].median() < 0.01, case
    assert frame.loc[frame["role"] != "test", "comparable"].mean() >= 0.9
    assert (frame.loc[frame["role"] != "test", "speed_check"] == "ok").all()
    low = frame[name.str.contains("_Low_")]
    assert low["speed_check"].str.endswith("(another load?)").all()
    assert not low["comparable"].any() and not low["trusted"].any()


def test_readme_journey_report(journey):
    report = journey["work"] / "estimates-report" / "report.md"
    text = report.read_text()
    assert "fault-size estimates" in text and "healthy_holdout" in text
    assert (journey["work"] / "estimates-report" / "estimates.png").stat().st_size > 0


def _predict(journey, *extra):
    return cli("predict", "--machine", SPUR, "--database", journey["work"] / "phm09-db",
               "--healthy", PHM / "spur1_30hz_High_1.zip", "--faulty",
               PHM / "spur2_30hz_High_1.zip", "--faulty-size", "0.5", *extra,
               "--out", journey["work"] / "x.csv", env=journey["env"])


def test_speed_not_in_database_is_named_in_tacho_hz(journey):
    res = _predict(journey, "--speed", "40")
    err = res.stderr.strip()
    assert res.returncode == 2 and len(err.splitlines()) == 1, err
    assert "--speed 40 is not a condition" in err and "[30] Hz (tacho shaft)" in err
    assert "13.3" not in err and "10.0" not in err       # never the idler's internal speeds


def test_record_off_the_database_speed_is_refused_with_one_line(journey):
    res = _predict(journey, "--recordings", PHM / "spur1_40hz_High_1.zip")
    err = res.stderr.strip()
    assert res.returncode == 2 and len(err.splitlines()) == 1, err
    assert "spur1_40hz_High_1.zip" in err and "its tacho reads 39.9" in err
    assert "nearest condition 30 Hz" in err and "tolerance 5 %" in err
    assert not (journey["work"] / "x.csv").exists()


def test_unquantified_load_with_a_several_load_database_asks_for_load(tmp_path):
    from gearshot import GearshotError, Machine
    from gearshot.app.conditions import choose_condition

    (tmp_path / "manifest.json").write_text(json.dumps(
        {"speeds": [10.0], "loads": [5.0, 20.0], "grades": [7]}))
    machine = Machine.from_toml(SPUR)
    with pytest.raises(GearshotError, match=r"--load is needed.*\[5, 20\] N m"):
        choose_condition(tmp_path, machine, speed=None, load=None, measured=[29.9])
    # the idler runs at 1/3 of the input: the database's 10 rev/s are 30 Hz at the tacho
    assert choose_condition(tmp_path, machine, speed=None, load=20.0,
                            measured=[29.1, 29.9]) == (30.0, 20.0)
    with pytest.raises(GearshotError, match=r"--load 10 is not a condition"):
        choose_condition(tmp_path, machine, speed=30.0, load=10.0, measured=[])
