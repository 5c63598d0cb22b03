"""`gearshot indicators`, `gearshot simulate --machine`, `gearshot predict --machine` on
(cropped copies of) the PHM09 recordings in ../shared/data/phm09."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
from phm09_records import crop

from gearshot.features import CONDITION_INDICATORS

ROOT = Path(__file__).resolve().parents[1]
SPUR = ROOT / "examples" / "machines" / "phm09_spur.toml"
PHM = ROOT.parent / "shared" / "data" / "phm09"


def run(*args, env=None, timeout=300):
    return subprocess.run([sys.executable, "-m", "gearshot.app.cli", *args],
                          capture_output=True, text=True, timeout=timeout, env=env)



@pytest.fixture(scope="module")
def small(tmp_path_factory):
    folder = tmp_path_factory.mktemp("phm")
    return {n: crop(f"{n}_30hz_High_1.zip", folder, 100_000)
            for n in ("spur2", "spur3", "spur1")}


def test_indicators_json_layout_and_figures(small, tmp_path):
    out = tmp_path / "ind.json"
    figs = tmp_path / "figs"
    res = run("indicators", "--machine", str(SPUR), "--shaft", "idler", "--sensor",
              "acc_input", str(small["spur2"]), str(small["spur3"]), "--json", str(out),
              "--out", str(figs))
    assert res.returncode == 0, res.stderr
    payload = json.loads(out.read_text())
    assert payload["kind"] == "indicators" and len(payload["records"]) == 2
    want = {*CONDITION_INDICATORS, "rms_raw", "rms_residual"}
    for rec, name in zip(payload["records"], ("spur2", "spur3")):
        assert list(rec) == ["file", "sensor", "tacho_speed_hz", "shaft_speed_hz",
                             "speed_source", "speed_uncertainty_hz", "n_cycles", "indicators",
                             "input_check"]
        assert rec["input_check"] == "ok"
        assert rec["file"] == f"{name}_30hz_High_1.zip" and rec["sensor"] == "acc_input"
        assert rec["speed_source"] == "tacho" and rec["speed_uncertainty_hz"] is None
        assert 29.0 < rec["tacho_speed_hz"] < 30.0  # read from the tacho, input shaft
        assert rec["shaft_speed_hz"] == pytest.approx(rec["tacho_speed_hz"] / 3)  # 32 -> 96
        assert rec["n_cycles"] == 14  # 1.5 s at ~29.9 Hz: 44 whole input revs, 14 idler revs
        assert set(rec["indicators"]) == want
        assert all(isinstance(v, float) for v in rec["indicators"].values())
    assert sorted(p.stem for p in figs.glob("*.png")) == sorted(want)
    # the other sensor and a healthy baseline for NA4
    res = run("indicators", "--machine", str(SPUR), "--shaft", "input", "--sensor",
              "acc_output", str(small["spur2"]), "--baseline", str(small["spur3"]),
              "--json", str(out))
    assert res.returncode == 0, res.stderr
    assert [r["n_cycles"] for r in json.loads(out.read_text())["records"]] == [44]


@pytest.mark.parametrize("args, words", [
    (["--shaft", "brake"], ["--shaft='brake'", "not a shaft"]),
    (["--shaft", "input", "--sensor", "mic"], ["sensor='mic'"]),
])
def test_indicators_errors_are_one_line(small, tmp_path, args, words):
    res = run("indicators", "--machine", str(SPUR), *args, str(small["spur2"]), "--json",
              str(tmp_path / "x.json"))
    assert res.returncode != 0 and "Traceback" not in res.stderr
    err = res.stderr.strip()
    assert err.startswith("gearshot: error:") and len(err.splitlines()) == 1, err
    for w in words:
        assert w in err, err


def test_simulate_and_predict_with_a_machine_end_to_end(small, tmp_path):
    env = {**__import__("os").environ, "GEARSHOT_DATA": str(tmp_path / "data")}
    store = tmp_path / "db"
    res = run("simulate", "--machine", str(SPUR), "--speed", "30", "--load", "10",
              "--grade", "6", "--grade", "7", "--n-healthy", "6", "--n-faulty", "24",
              "--store", str(store), env=env, timeout=600)
    assert res.returncode == 0, res.stderr
    assert ("monitored gear 32 teeth on the input shaft (the fault's gear) meshing with 96 "
            "teeth on the idler shaft") in res.stdout and "input (tacho) shaft 30 Hz" in res.stdout
    assert "rev/s" not in res.stdout     # no internal (idler) speeds
    # a machine's database is paired by default (each signal's healthy twin stored)
    assert json.loads((store / "manifest.json").read_text()).get("paired") is True
    out = tmp_path / "pred.csv"
    res = run("predict", "--machine", str(SPUR), "--database", str(store), "--healthy",
              str(small["spur3"]), "--faulty", str(small["spur2"]), "--faulty-size", "0.5",
              "--recordings", str(small["spur1"]), "--speed", "30", "--load", "10",
              "--cycles-per-segment", "10", "--out", str(out), env=env, timeout=600)
    assert res.returncode == 0, res.stderr
    frame = pd.read_csv(out)
    assert set(frame["role"]) == {"healthy_holdout", "faulty_rest", "test"}
    assert frame["predicted"].between(0, 1).all()
    assert (frame["low"] <= frame["predicted"]).all() and (frame["predicted"]
                                                          <= frame["high"]).all()
    # spur2's remaining segments (3) and spur1's (4); spur3 holds 1 of 4 out
    assert (frame["role"] == "faulty_rest").sum() == 3
    assert (frame["role"] == "test").sum() == 4
    assert (frame["role"] == "healthy_holdout").sum() == 1
    # issue #29 item 3: every estimate says whether the segment is in the fitted machine's
    # distribution; 3 healthy segments (cropped records) cannot calibrate that test, so no
    # estimate is comparable and the summary says why
    assert frame["comparable"].dtype == bool and frame["comparability"].isna().all()
    assert not frame["comparable"].any()
    assert "comparable: 0 segment(s), not comparable: 8" in res.stdout
    assert "comparability is not calibrated" in res.stdout
    # issue #30 item 3: every estimate says whether it lies below the fit's detection
    # limit; the flagged estimates are the smallest ones
    flagged = frame["below_detection_limit"]
    assert flagged.dtype == bool
    if flagged.any() and not flagged.all():
        assert frame.loc[flagged, "predicted"].max() < frame.loc[~flagged, "predicted"].min()
    out_json = tmp_path / "pred.json"
    res = run("predict", "--machine", str(SPUR), "--database", str(store), "--healthy",
              str(small["spur3"]), "--faulty", str(small["spur2"]), "--faulty-size", "0.5",
              "--recordings", str(small["spur1"]), "--speed", "30", "--load", "10",
              "--cycles-per-segment", "10", "--out", str(out_json), env=env, timeout=600)
    assert res.returncode == 0, res.stderr
    records = json.loads(out_json.read_text())["rows"]
    assert [r["comparable"] for r in records] == frame["comparable"].tolist()
    assert all(isinstance(r["comparable"], bool) for r in records)
    assert [r["below_detection_limit"] for r in records] == flagged.tolist()
