"""The rig family of issue #12: its draw, its path bank, its resumable result store."""

import json

import numpy as np
import pandas as pd
import pytest
from numpy.testing import assert_allclose

from gearshot import GearshotError
from gearshot.experiments import family


@pytest.fixture(scope="module")
def paths():
    return family.family_paths(None, n_synthetic=3, seed=1)


def test_paths_are_named_by_kind(paths):
    names = [p.name for p in paths]
    assert names == [f"synthetic_rig_{i}" for i in range(3)] + \
        [f"synthetic_bank_{i}" for i in range(3)]
    assert {family.path_kind(n) for n in names} == {"synthetic_rig", "synthetic_bank"}
    assert family.path_kind("beam_h7") == "beam"
    assert family.path_kind("structure_b_h2") == "structure_b"
    assert family.path_kind("machine_tool") == "measured"
    with pytest.raises(GearshotError, match="at least one path"):
        family.family_paths(None, n_synthetic=0)


def test_draw_depends_on_the_seed_only_and_is_balanced(paths):
    rigs = family.draw_family(range(50, 74), paths)
    again = family.draw_family([60, 51], paths)
    assert again[0] == rigs[10] and again[1] == rigs[1]
    assert {r.path_index for r in rigs} == set(range(len(paths)))
    conditions = pd.Series([(r.speed, r.load) for r in rigs]).value_counts()
    assert set(conditions.index) == set(family.PAPER_CONDITIONS)
    assert conditions.min() == conditions.max() == 6
    assert all(1 <= r.grade <= 12 for r in rigs)
    assert len({r.grade for r in rigs}) > 6
    assert all(10 <= r.attenuation_db <= 30 for r in rigs)


def test_dev_and_heldout_ranges_are_disjoint():
    assert not set(family.DEV_SEEDS) & set(family.HELDOUT_SEEDS)


def test_duration_gives_the_wanted_segments():
    camp = dict(duration=None, segments=4)
    # 4 SAs of 50 gear revolutions (+1 for the resampling edge), 2 % speed margin
    assert family._duration(camp, 15.0) == pytest.approx(1.02 * 201 / (15 * 17 / 38))
    assert family._duration(camp, 30.0) == pytest.approx(family._duration(camp, 15.0) / 2)
    assert family._duration(dict(duration=12.0, segments=4), 15.0) == 12.0


def test_family_rig_is_the_drawn_rig_with_its_reality_overridden(shared_dir):
    from gearshot.experiments import family_rigs

    frf = shared_dir / "data" / "frf"
    rig, vr = family_rigs.family_rig(102, frf)
    assert rig == family.draw_family([102], family.family_paths(frf, n_synthetic=4,
                                                                seed=2023))[0]
    assert (vr.seed, vr.reveal_path()[0]) == (102, rig.path)
    assert vr.reveal().speed_drift > 0
    _, still = family_rigs.family_rig(102, frf, speed_drift=0, speed_ripple=0)
    hidden = still.reveal()
    assert (hidden.speed_drift, hidden.speed_ripple) == (0, 0)
    assert hidden.load_ripple == vr.reveal().load_ripple


def test_true_path_on_grid_is_hermitian(paths):
    rig = family.draw_family([55], paths)[0]
    tf = family.true_path_on_grid(rig, paths, n_points=64)
    assert_allclose(tf[1:][::-1], np.conj(tf[1:]), atol=1e-15)
    assert tf[32].imag == 0 and tf[0].imag == pytest.approx(0, abs=1e-15)


def test_results_resume_and_tables(tmp_path, monkeypatch, paths):
    calls = []

    def fake_task(spec):
        calls.append((spec["rig"]["seed"], tuple(spec["draws"]), frozenset(spec["done"])))
        rows = []
        for d in spec["draws"]:
            for v in spec["variants"]:
                if (d, v) in spec["done"]:
                    continue
                rows.append(dict(config=spec["config"], **spec["rig"], draw=d, variant=v,
                                 mae=0.1 if v == "full" else 0.2, coverage=0.9, n_test=10,
                                 seconds=1.0, record_seconds=2.0))
        return rows

    monkeypatch.setattr(family, "family_paths", lambda *a, **k: paths)
    monkeypatch.setattr(family, "_family_task", fake_task)
    out = tmp_path / "r.jsonl"
    kw = dict(results=out, n_draws=2, progress=False)
    frame = family.rig_family_experiment("db", range(50, 54), variants=["full"], **kw)
    assert len(frame) == 8 and len(calls) == 4
    frame = family.rig_family_experiment("db", range(50, 54), variants=["full"], **kw)
    assert len(frame) == 8 and len(calls) == 4  # nothing recomputed
    frame = family.rig_family_experiment("db", range(50, 54), variants=["full", "rms_only"],
                                         **kw)
    assert len(frame) == 16 and len(calls) == 8
    assert all(done == {(0, "full"), (1, "full")} for _, _, done in calls[4:])
    # another estimator configuration is a new set of rows
    frame = family.rig_family_experiment("db", range(50, 52), variants=["full"],
                                         params={"options": {"selection_threshold": 0.2}},
                                         **kw)
    assert len(frame) == 4 and len(calls) == 10
    with open(out, "a") as fh:  # an interrupted write leaves a cut line: skipped
        fh.write('{"config": "x", "se')
    rows = family.read_family_results(out)
    assert len(rows) == 20
    tables = family.family_tables(family.rig_family_experiment("db", range(50, 54),
                                                               variants=["full", "rms_only"],
                                                               **kw))
    assert_allclose(tables["condition"].loc["full", "mean"], 10.0)
    assert_allclose(tables["condition"].loc["rms_only", "mean"], 20.0)
    assert_allclose(tables["coverage"].loc["full", "pooled"], 90.0)
    assert json.loads(out.read_text().splitlines()[0])["variant"] == "full"


def _fake_task(spec):
    checked = spec.get("checked", False)
    return [dict(config=spec["config"], **spec["rig"], draw=d, variant=v,
                 mae=(0.05 + 0.15 * d) if checked else (0.1 if v == "full" else 0.3),
                 coverage=0.9, n_test=10, seconds=1.0, record_seconds=2.0, width=0.3,
                 fit_check=("passed" if d == 0 else "healthy hold-outs read 0.30")
                 if checked else "unchecked: no hold-outs")
            for d in spec["draws"] for v in spec["variants"] if (d, v) not in spec["done"]]


def test_cli_rig_family_runs_resumes_and_writes_tables(tmp_path, monkeypatch, paths):
    from typer.testing import CliRunner

    from gearshot.app.cli import app

    calls = []

    def task(spec):
        calls.append(spec["rig"]["seed"])
        return _fake_task(spec)

    stores = []
    monkeypatch.setenv("GEARSHOT_DATA", str(tmp_path))
    monkeypatch.setattr(family, "family_paths", lambda *a, **k: paths)
    monkeypatch.setattr(family, "_family_task", task)
    monkeypatch.setattr(family, "family_database",
                        lambda folder, paired=False, **k: stores.append(paired) or tmp_path)
    out = tmp_path / "summary.json"
    args = ["experiment", "rig-family", "--n-rigs", "3", "--draws", "2", "--variant", "full",
            "--variant", "rms_only", "--param", "model_discrepancy=0.16",
            "--json", str(out)]
    res = CliRunner().invoke(app, args)
    assert res.exit_code == 0, res.output
    assert calls == [100, 101, 102] and stores == [True]   # paired by default (#19)
    assert (tmp_path / "family" / "dev.jsonl").is_file()
    summary = json.loads(out.read_text())
    assert summary["seeds"] == [100, 101, 102] and summary["params"] == {
        "model_discrepancy": 0.16}
    cond = summary["tables"]["condition"]
    mean = cond["data"][cond["index"].index("full")][cond["columns"].index("mean")]
    assert mean == pytest.approx(10.0)
    assert "MAE % by condition" in res.output
    res = CliRunner().invoke(app, args + ["--no-paired"])      # the explicit opt-out
    assert res.exit_code == 0, res.output
    assert stores == [True, False]
    res = CliRunner().invoke(app, args)   # resumed: nothing recomputed
    assert res.exit_code == 0, res.output
    assert calls == [100, 101, 102]
    # another parameter value is another configuration
    res = CliRunner().invoke(app, args[:-4] + ["--param", "model_discrepancy=0.1"])
    assert res.exit_code == 0, res.output
    assert calls == [100, 101, 102] * 2
    assert "own check" not in res.output   # unchecked fits: no verdict table
    # fits that check themselves (--checked) are another configuration, with their table
    res = CliRunner().invoke(app, args + ["--checked"])
    assert res.exit_code == 0, res.output
    assert calls == [100, 101, 102] * 3
    assert "The fits' own check" in res.output
    check = json.loads(out.read_text())["tables"]["check"]
    row = dict(zip(check["columns"], check["data"][check["index"].index("full")]))
    assert row["fits"] == 6 and row["passed %"] == pytest.approx(50.0)
    assert row["MAE passed"] == pytest.approx(5.0)
    assert row["MAE refused"] == pytest.approx(20.0)


def test_parse_params_names_the_option_and_value():
    assert family.parse_params(["model_discrepancy=0.16", "calibration=tuned"]) == {
        "model_discrepancy": 0.16, "calibration": "tuned"}
    with pytest.raises(GearshotError, match="'nope'"):
        family.parse_params(["nope=1"])
    with pytest.raises(GearshotError, match=r"--param.*NAME=VALUE.*'x'"):
        family.parse_params(["x"])
    with pytest.raises(GearshotError,
                       match=r"--param: options: simulated_reference.*'other'"):
        family.parse_params(['options={"simulated_reference": "other"}'])
