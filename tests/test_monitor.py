"""Monitoring a machine (issue #31): the model file, the history and the commands, on a
short virtual-rig life; and the README section "Monitoring a machine" run as written."""

from __future__ import annotations

import json
import os
import shlex
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from readme_sections import readme_commands

from gearshot import GearshotError

ROOT = Path(__file__).resolve().parents[1]
SMALL_DATABASE = "--n-healthy 6 --n-faulty 24 --grade 6 --grade 7 --workers 1"


def cli(*args, cwd=None, env=None):
    return subprocess.run([sys.executable, "-m", "gearshot.app.cli", *map(str, args)],
                          capture_output=True, text=True, timeout=900, cwd=cwd, env=env)


@pytest.fixture(scope="module")
def machine(tmp_path_factory):
    """A small database, a fit campaign and a 10-recording life (surrogate engine)."""
    from gearshot.rig import VirtualRig
    from gearshot.sim import GearPair, build_database

    top = tmp_path_factory.mktemp("monitor")
    db = build_database(top / "db", GearPair.paper(), speeds=[15.0], loads=[10.0],
                        grades=[6, 7], n_healthy=6, n_faulty=24, seed=0, progress=False)
    rig = VirtualRig(3, engine="surrogate")
    camp = rig.campaign(top / "camp", speed=15, load=10, duration=16, healthy=4,
                        sizes=(0.5,), repetitions=1, progress=False)
    life = rig.history(top / "life", n_recordings=10, duration=16, load_change=(0.3, 1, 5.0),
                       remount=None, progress=False)
    healthy = sorted(p for p, y in zip(camp["path"], camp["fault_size"], strict=True) if y == 0)
    faulty = [p for p, y in zip(camp["path"], camp["fault_size"], strict=True) if y > 0][0]
    from gearshot.app.monitor import fit_model

    zero = fit_model(db, healthy, model=top / "zero.skops", speed=15)
    return {"top": top, "db": db, "healthy": healthy, "faulty": faulty, "life": life,
            "zero": zero}


def test_model_file_carries_what_estimating_needs(machine, tmp_path):
    from gearshot.app.monitor import fit_model
    from gearshot.monitor import load_model

    m = fit_model(machine["db"], machine["healthy"], machine["faulty"], 0.5,
                  model=tmp_path / "m.skops", speed=15, load=10)
    back = load_model(tmp_path / "m.skops")
    assert back.calibration == "one_fault_shot" and back.faulty["size"] == 0.5
    assert back.condition == {"speed": 15.0, "load": 10.0, "speed_unit": "rps",
                              "gear_teeth": 38, "pinion_teeth": 17}
    manifest = (Path(machine["db"]) / "manifest.json").read_bytes()
    import hashlib

    assert back.database["manifest_sha256"] == hashlib.sha256(manifest).hexdigest()
    # the baseline: the last healthy recording (a quarter of 4) kept out of the fit, and
    # each of the 3 fit recordings estimated by a fit on the other two: 4 x 2 segments
    assert len(back.baseline) == 8 and back.threshold == pytest.approx(m.threshold)
    # what the threshold was set from is said with it
    assert (f"set from 8 healthy estimates, mean {np.mean(back.baseline):.3f}, largest "
            f"{np.max(back.baseline):.3f})") in back.describe()
    from gearshot.monitor import alarm_threshold

    assert back.threshold == pytest.approx(alarm_threshold(back.baseline))
    assert back.machine_toml is None and isinstance(back.fit_check["verdict"], str)
    sa = np.zeros((1, 2048))
    assert np.allclose(back.estimator.predict(sa), m.estimator.predict(sa))
    assert back.digest == m.digest and len(back.digest) == 16
    # each healthy recording's measured speed is kept, and the one-run warning is set from
    # them (this surrogate campaign's speeds drift 0.4 % between recordings: no warning)
    from gearshot.monitor.trust import runs_warning

    speeds = back.extras["healthy_speeds"]
    assert len(speeds) == 4 and np.allclose(speeds, 15.0, rtol=0.02)
    assert back.extras["fit_warning"] == runs_warning(speeds)
    # and the faulty recording's: a later recording's speed is checked against all of them
    assert back.extras["example_speed"] == pytest.approx(15.0, rel=0.02)
    # the faulty recording gives 2 segments: the example and one other, too few for the
    # fit check; the model says so wherever it is used (its estimates cannot be trusted)
    from gearshot.monitor.trust import model_warning

    assert back.fit_check["verdict"].startswith("unchecked: 1 other segment(s) of the example")
    warning = model_warning(back)
    assert warning.startswith(f"the fit did not pass its own check ({back.fit_check['verdict']})")
    assert "no estimate of this model is trusted" in warning and model_warning(m) == warning
    # a zero-shot fit says so
    z = load_model(machine["top"] / "zero.skops")
    assert z.calibration == "zero_shot" and z.faulty is None and "zero-shot" in z.describe()


def test_bad_model_files_and_options_are_refused(machine, tmp_path):
    from gearshot.app.monitor import fit_model
    from gearshot.monitor import load_model

    with pytest.raises(GearshotError, match="does not exist"):
        load_model(tmp_path / "none.skops")
    (tmp_path / "junk.skops").write_bytes(b"not a zip")
    with pytest.raises(GearshotError, match="junk.skops"):
        load_model(tmp_path / "junk.skops")
    with pytest.raises(GearshotError, match="--faulty and --faulty-size"):
        fit_model(machine["db"], machine["healthy"], machine["faulty"], None,
                  model=tmp_path / "m.skops", speed=15)
    with pytest.raises(GearshotError, match="at least 2"):
        fit_model(machine["db"], machine["healthy"][:1], model=tmp_path / "m.skops", speed=15)
    res = cli("fit", "--database", machine["db"], "--healthy", *machine["healthy"],
              "--speed", 15, "--model", tmp_path / "m.pkl")
    assert res.returncode == 2 and "must end in .skops" in res.stderr


def test_rerun_adds_only_the_new_recordings_and_untrusts_the_load_change(machine, tmp_path):
    from gearshot.app.monitor import monitor_history

    life = machine["top"] / "life"
    index = pd.read_csv(life / "index.csv", keep_default_na=False)
    index["file"] = [str(life / f) for f in index["file"]]
    index.iloc[:4].to_csv(tmp_path / "index.csv", index=False)
    model, hist = machine["top"] / "zero.skops", tmp_path / "h.parquet"
    first = monitor_history(model, tmp_path / "index.csv", hist)
    assert first["new"] == 4 and len(first["records"]) == 4
    stamp = pd.read_parquet(hist)["estimated_at"]
    index.to_csv(tmp_path / "index.csv", index=False)
    second = monitor_history(model, tmp_path / "index.csv", hist)
    assert second["new"] == 6 and len(second["records"]) == 10
    again = pd.read_parquet(hist)
    assert len(again) == 10 and (again["estimated_at"].iloc[:4].values == stamp.values).all()
    assert monitor_history(model, tmp_path / "index.csv", hist)["new"] == 0
    for rec in second["records"]:
        assert {"recording", "time", "predicted", "low", "high", "trusted", "alarm"} <= set(rec)
    events = index["event"].tolist()
    changed = [r for r, e in zip(second["records"], events, strict=True) if e == "load_change"]
    assert len(changed) == 1 and not changed[0]["trusted"] and not changed[0]["alarm"]
    assert "outside the fitted 10 N m" in again["note"].iloc[events.index("load_change")]
    # every untrusted recording says why, no trusted one carries a note
    assert (again["note"].astype(bool) == ~again["trusted"]).all()


def test_a_folder_of_recordings_named_by_time_is_an_index(machine, tmp_path):
    """The life's folder (its index.csv) and its recordings renamed with their times, with
    no index at all: the same estimates in the same order."""
    import shutil

    from gearshot.app.monitor import monitor_history
    from gearshot.app.monitor_report import format_monitor

    life = machine["top"] / "life"
    model = machine["top"] / "zero.skops"
    by_csv = monitor_history(model, life, tmp_path / "a.parquet")
    assert "index_source" not in by_csv and len(by_csv["records"]) == 10
    index = pd.read_csv(life / "index.csv", keep_default_na=False)
    named = tmp_path / "named"
    named.mkdir()
    for f, t in zip(index["file"], index["time"], strict=True):
        stamp = pd.Timestamp(t).strftime("%Y-%m-%dT%H-%M-%S")
        shutil.copy(life / f, named / f"gearbox_{stamp}.h5")
    by_names = monitor_history(model, named, tmp_path / "b.parquet")
    assert "file names" in by_names["index_source"]
    assert f"index: {by_names['index_source']}" in format_monitor(by_names)
    for a, b in zip(by_csv["records"], by_names["records"], strict=True):
        assert a["time"] == b["time"] and a["predicted"] == b["predicted"]


def test_an_unreadable_recording_is_kept_untrusted_with_its_reason(machine, tmp_path):
    from gearshot.app.monitor import monitor_history

    (tmp_path / "broken.h5").write_bytes(b"not a recording")
    (tmp_path / "index.csv").write_text("file,time\nbroken.h5,2026-01-01T00:00:00\n")
    payload = monitor_history(machine["top"] / "zero.skops", tmp_path / "index.csv",
                              tmp_path / "h.parquet")
    (rec,) = payload["records"]
    assert rec["predicted"] is None and not rec["trusted"] and not rec["alarm"]
    assert rec["note"].startswith("not estimated:") and "broken.h5" in rec["note"]
    json.dumps(payload, allow_nan=False)       # strict JSON: no NaN


def test_a_clipped_recording_is_untrusted_by_its_raw_samples(machine, tmp_path):
    """A run whose sensor saturated (flat tops at half its peak): the synchronous averages
    smooth the flat tops away, so only the raw samples show it; the monitor checks them as
    predict does and keeps the recording untrusted, with the check in its note."""
    import dataclasses

    from gearshot.app.monitor import monitor_history
    from gearshot.rig import VirtualRig

    rec = VirtualRig(3, engine="surrogate").record(speed=15, load=10, fault_size=0.0,
                                                   duration=16, repetition=60)
    rail = 0.5 * np.abs(rec.acceleration).max()
    clipped = dataclasses.replace(rec, acceleration=np.clip(rec.acceleration, -rail, rail))
    clipped.write(tmp_path / "clipped.h5")
    (tmp_path / "index.csv").write_text(f"file,time\n{tmp_path / 'clipped.h5'},"
                                        f"2026-03-01T00:00:00\n")
    (record,) = monitor_history(machine["top"] / "zero.skops", tmp_path / "index.csv",
                                tmp_path / "h.parquet")["records"]
    assert not record["trusted"] and not record["alarm"]
    assert "input check" in record["note"] and "clipped" in record["note"]


def test_a_recording_at_a_speed_the_fit_never_saw_is_untrusted(machine, tmp_path):
    """The same rig run 20 % faster (a recording's own measured speed, no index speed):
    estimated, kept untrusted with the reason; a run at the fitted speed is not flagged
    for its speed."""
    from gearshot.app.monitor import monitor_history
    from gearshot.rig import VirtualRig

    fast = VirtualRig(3, engine="surrogate").campaign(
        tmp_path / "fast", speed=18, load=10, duration=16, healthy=1, sizes=(),
        repetitions=1, progress=False)
    path = tmp_path / "fast" / fast["path"].iloc[0]
    same = machine["healthy"][-1]
    (tmp_path / "index.csv").write_text(f"file,time\n{same},2026-01-01T00:00:00\n"
                                        f"{path},2026-01-02T00:00:00\n")
    payload = monitor_history(machine["top"] / "zero.skops", tmp_path / "index.csv",
                              tmp_path / "h.parquet")
    at15, at18 = payload["records"]
    assert "speed" not in (at15["note"] or "")
    assert not at18["trusted"] and not at18["alarm"] and at18["predicted"] is not None
    assert at18["note"].startswith("speed 18.") and "% outside the fit's " \
        "recordings' 1" in at18["note"] and at18["note"].endswith("rev/s")


def test_a_remounted_sensor_is_untrusted_whatever_the_fault(machine, tmp_path):
    """The sensor moved to another spot (the rig's next transfer path): its recordings,
    healthy or with a fault larger than the example's, are untrusted for their path and
    never alarmed; the same rig's other runs pass the path check."""
    from gearshot.app.monitor import fit_model, monitor_history
    from gearshot.monitor import load_model
    from gearshot.monitor.trust import OTHER_PATH
    from gearshot.rig import VirtualRig

    fit_model(machine["db"], machine["healthy"], machine["faulty"], 0.5,
              model=tmp_path / "m.skops", speed=15, load=10)
    assert len(load_model(tmp_path / "m.skops").extras["healthy_paths"]) == 4
    rig = VirtualRig(3, engine="surrogate")
    moved = rig.with_reality(tf_index=(rig.reveal().tf_index + 1) % 8)
    rows = []
    for i, (source, size) in enumerate([(rig, 0.0), (moved, 0.0), (moved, 0.7), (rig, 0.7)]):
        rec = source.record(speed=15, load=10, fault_size=size, duration=16, repetition=40 + i)
        rec.write(tmp_path / f"r{i}.h5")
        rows.append(f"{tmp_path / f'r{i}.h5'},2026-02-0{i + 1}T00:00:00")
    (tmp_path / "index.csv").write_text("file,time\n" + "\n".join(rows) + "\n")
    records = monitor_history(tmp_path / "m.skops", tmp_path / "index.csv",
                              tmp_path / "h.parquet")["records"]
    assert OTHER_PATH not in (records[0]["note"] or "") + (records[3]["note"] or "")
    for rec in records[1:3]:
        assert OTHER_PATH in rec["note"] and not rec["trusted"] and not rec["alarm"]


@pytest.mark.slow
def test_monitor_adds_only_the_new_then_reestimates_after_a_refit(machine, tmp_path):
    life = machine["top"] / "life"
    index = pd.read_csv(life / "index.csv")
    index["file"] = [str(life / f) for f in index["file"]]
    index.iloc[:6].to_csv(tmp_path / "index.csv", index=False)
    base = ["--database", machine["db"], "--speed", 15, "--load", 10, "--healthy",
            *machine["healthy"]]
    assert cli("fit", *base, "--model", tmp_path / "m.skops").returncode == 0
    watch = ["monitor", "--model", tmp_path / "m.skops", "--index", tmp_path / "index.csv",
             "--history", tmp_path / "h.parquet", "--json", tmp_path / "out.json"]
    first = cli(*watch, "--out", tmp_path / "figs")
    assert first.returncode == 0, first.stderr
    assert "6 new recording(s)" in first.stdout and "zero-shot" in first.stdout
    assert (tmp_path / "figs" / "trend.png").stat().st_size > 0
    index.to_csv(tmp_path / "index.csv", index=False)          # the folder grew
    again = cli(*watch)
    assert again.returncode == 0 and "4 new recording(s)" in again.stdout
    payload = json.loads((tmp_path / "out.json").read_text())
    assert len(payload["records"]) == 10
    for rec in payload["records"]:
        assert {"recording", "time", "predicted", "low", "high", "trusted", "alarm"} <= set(rec)
        assert rec["low"] <= rec["predicted"] <= rec["high"]
    assert {"threshold", "first_time"} <= set(payload["alarm"])
    assert {"limit", "time", "low", "high", "law", "reason"} <= set(payload["forecast"])
    assert payload["forecast"]["limit"] == 0.6 and payload["calibration"] == "zero_shot"
    # the load-change recording is outside the fitted load: untrusted, never in alarm
    changed = [r for r, e in zip(payload["records"], index["event"].fillna(""),
                                 strict=True) if e == "load_change"]
    assert changed and not any(r["trusted"] or r["alarm"] for r in changed)
    # an inspection of the 8th recording: refit with it, the history is estimated again
    inspected = index["file"].iloc[7]
    refit = cli("fit", *base, "--faulty", inspected, "--faulty-size",
                round(float(index["size"].iloc[7]), 2), "--model", tmp_path / "m.skops")
    assert refit.returncode == 0, refit.stderr
    third = cli(*watch)
    assert third.returncode == 0 and "10 new recording(s)" in third.stdout
    hist = pd.read_parquet(tmp_path / "h.parquet")
    assert len(hist) == 20 and hist["model"].nunique() == 2
    assert set(hist["calibration"]) == {"zero_shot", "one_fault_shot"}
    payload = json.loads((tmp_path / "out.json").read_text())
    assert payload["calibration"] == "one_fault_shot"
    assert len(payload["earlier_estimates"]) == 10
    assert cli(*watch).stdout.count("0 new recording(s)") == 1
    rep = cli("report", tmp_path / "out.json", "--out", tmp_path / "rep")
    assert rep.returncode == 0, rep.stderr
    report = (tmp_path / "rep" / "report.md").read_text()
    assert "Alarm threshold" in report
    assert "outside the fitted 10 N m" in report   # an untrusted recording's reason
    assert (tmp_path / "rep" / "trend.png").stat().st_size > 0


def test_monitor_refuses_bad_indexes_before_estimating(machine, tmp_path):
    (tmp_path / "index.csv").write_text("file,when\nx.h5,2026\n")
    res = cli("monitor", "--model", tmp_path / "m.skops", "--index", tmp_path / "index.csv",
              "--history", tmp_path / "h.parquet", "--limit", 1.5)
    assert res.returncode == 2 and "--limit" in res.stderr
    res = cli("monitor", "--model", tmp_path / "m.skops", "--index", tmp_path / "index.csv",
              "--history", tmp_path / "h.parquet", "--history", tmp_path / "g.parquet")
    assert res.returncode == 2 and "one --history per --index" in res.stderr




@pytest.mark.slow
def test_readme_monitoring_commands_run_as_written(tmp_path):
    env = {**os.environ, "GEARSHOT_DATA": str(tmp_path / "data")}
    py = shlex.quote(sys.executable)
    commands = readme_commands("Monitoring a machine")
    assert [c.split()[1] if c.startswith("gearshot") else "python" for c in commands] == [
        "simulate", "rig", "python", "fit", "monitor", "fit", "monitor", "report"]
    runs = []
    for command in commands:
        if command.startswith("gearshot "):
            line = f"{py} -m gearshot.app.cli" + command[len("gearshot"):]
            if command.split()[1] == "simulate":
                line += " " + SMALL_DATABASE
        else:   # the life: shorter (the refit's inspected recording is its 30th)
            line = py + command[len("python"):].replace("history('life')",
                                                        "history('life', n_recordings=30)")
        res = subprocess.run(["bash", "-c", line], capture_output=True, text=True,
                             cwd=tmp_path, env=env, timeout=1200)
        assert res.returncode == 0, f"{command}\n{res.stderr}"
        runs.append(res)
    assert "zero-shot" in runs[4].stdout and "30 new recording(s)" in runs[4].stdout
    assert "30 new recording(s)" in runs[6].stdout
    payload = json.loads((tmp_path / "life.json").read_text())
    assert payload["calibration"] == "one_fault_shot" and len(payload["records"]) == 30
    assert len(payload["earlier_estimates"]) == 30
    assert (tmp_path / "trend" / "trend.png").is_file()
    assert (tmp_path / "monitor-report" / "report.md").is_file()


@pytest.mark.slow
def test_fit_and_monitor_with_a_machine_file_on_phm09(tmp_path):
    """The machine-file path end to end on real PHM 2009 spur records (30 Hz, High load):
    zero-shot fit on two healthy records, then the chipped and the other records
    monitored; a Low-load record in the index is outside the fitted load."""
    phm = ROOT.parent / "shared" / "data" / "phm09"
    if not (phm / "spur1_30hz_High_1.zip").is_file():
        pytest.skip(f"{phm} is absent")
    spur = ROOT / "examples" / "machines" / "phm09_spur.toml"
    env = {**os.environ, "GEARSHOT_DATA": str(tmp_path / "data")}
    res = cli("simulate", "--machine", spur, "--speed", 30, "--load", 10, "--store",
              tmp_path / "db", *SMALL_DATABASE.split(), env=env)
    assert res.returncode == 0, res.stderr
    res = cli("fit", "--machine", spur, "--database", tmp_path / "db", "--healthy",
              phm / "spur1_30hz_High_1.zip", phm / "spur3_30hz_High_1.zip",
              "--model", tmp_path / "m.skops", env=env)
    assert res.returncode == 0, res.stderr
    from gearshot.monitor import load_model

    model = load_model(tmp_path / "m.skops")
    assert model.machine.name and model.machine_toml == spur.read_text(encoding="utf-8")
    assert model.condition["speed_unit"] == "Hz (tacho shaft)" and model.baseline
    # two healthy recordings show no spread of runs: the model says a later run is trusted
    # only within 0.3 % of their speeds
    assert len(model.extras["healthy_speeds"]) == 2
    assert model.extras["fit_warning"].startswith("fitted on 2 healthy recording(s)")
    assert model.extras["example_speed"] is None                      # zero-shot: no example
    assert [len(p) for p in model.extras["healthy_paths"]] == [200, 200]  # resonance patterns
    rows = [("spur2_30hz_High_1.zip", "2026-01-01T00:00:00", 10),
            ("spur2_30hz_High_2.zip", "2026-01-02T00:00:00", 10),
            ("spur2_30hz_Low_1.zip", "2026-01-03T00:00:00", 5)]
    pd.DataFrame([(str(phm / f), t, ld) for f, t, ld in rows],
                 columns=["file", "time", "load"]).to_csv(tmp_path / "index.csv",
                                                          index=False)
    res = cli("monitor", "--model", tmp_path / "m.skops", "--index", tmp_path / "index.csv",
              "--history", tmp_path / "h.parquet", "--json", tmp_path / "out.json", env=env)
    assert res.returncode == 0, res.stderr
    payload = json.loads((tmp_path / "out.json").read_text())
    assert [Path(r["recording"]).name for r in payload["records"]] == [r[0] for r in rows]
    assert not payload["records"][2]["trusted"] and not payload["records"][2]["alarm"]
    assert payload["forecast"]["time"] is None and "too few" in payload["forecast"]["reason"]


def test_a_gain_other_than_the_fits_is_not_comparable_a_new_run_is(machine, tmp_path):
    """Fitted on three healthy runs (comparability left one recording out at a time),
    a fourth run of the same machine stays comparable; the same run through a gain of
    x100 or x0.01 (a physical level, so the input check passes) is not: the estimate it
    moves is never trusted."""
    from gearshot.app.predict_fit import estimate_segments, fit_from_files
    from gearshot.io import Recording, recording_segments

    healthy = machine["healthy"]
    est, _ = fit_from_files(machine["db"], healthy[:3], machine["faulty"], 0.5, speed=15,
                            load=10)
    ref = est.comparability_reference_
    assert ref.calibrated
    new = recording_segments(healthy[3])
    same = estimate_segments(est, new)
    assert same["input_check"].eq("ok").all() and same["comparable"].mean() > 0.5
    rec = Recording.read(healthy[3])
    for gain in (100.0, 0.01):
        path = Recording(rec.acceleration * gain, rec.tacho, rec.fs, speed=rec.speed,
                         load=rec.load).write(tmp_path / f"x{gain:g}.h5")
        scaled = recording_segments(path)
        rows = estimate_segments(est, scaled)
        assert rows["input_check"].eq("ok").all(), gain
        assert not rows["comparable"].any() and not rows["trusted"].any(), gain
        from gearshot.monitor.trust import untrusted_reason

        assert "not comparable with the fitted machine" in untrusted_reason(rows), gain
    # this fit keeps no hold-out: every estimate says its fit is unchecked
    assert untrusted_reason(same).startswith("fit check: unchecked")
