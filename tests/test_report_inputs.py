"""gearshot report reads every output gearshot writes (CSV included) and answers anything
malformed in one line, exit 2; the predict JSON carries its inputs and fit (issue #32)."""

from __future__ import annotations

import json
import sys

import numpy as np
import pandas as pd
import pytest

from gearshot import GearshotError
from gearshot.app.predict import predictions_payload, write_predictions
from gearshot.app.report import read_output, report_from_any_json


def _frame() -> pd.DataFrame:
    frame = pd.DataFrame(dict(
        recording=["/d/a.zip"] * 3 + ["/d/b.zip"] * 2,
        role=["example", "faulty_rest", "faulty_rest", "test", "test"],
        segment=[0, 1, 2, 0, 1], predicted=[0.3, 0.4, 0.5, 0.1, 0.2], low=[0.1] * 5,
        high=[0.6] * 5, comparability=[1.0, 2.0, np.nan, 1.0, 1.0],
        comparable=[True, True, False, True, True]))
    frame.attrs.update(
        inputs={"database": "db", "healthy": ["h1.zip", "h2.zip"], "faulty": "f.zip",
                "faulty_size": 0.5, "speed": 15.0, "load": 10.0, "machine": None,
                "seed": 3, "coverage": 0.9},
        grade=7, calibration={"strategy": "grade", "settings": [{"grade": 7, "weight": 1.0}]},
        simulated_reference="twin", fit_check="ok")
    return frame


def _cli(args, monkeypatch, capsys) -> tuple[int, str]:
    from gearshot.app.cli import main

    monkeypatch.setattr(sys, "argv", ["gearshot", *map(str, args)])
    with pytest.raises(SystemExit) as info:
        main()
    return int(info.value.code or 0), capsys.readouterr().err.strip()


def test_predict_json_carries_inputs_fit_and_summary_beside_its_rows(tmp_path):
    path = write_predictions(_frame(), tmp_path / "p.json")
    payload = json.loads(path.read_text())
    assert payload["kind"] == "predict" and payload["gearshot_version"]
    assert payload["inputs"]["faulty_size"] == 0.5
    assert payload["inputs"]["healthy"] == ["h1.zip", "h2.zip"]
    assert payload["fit"] == {"grade": 7, "calibration": {"strategy": "grade", "settings":
                              [{"grade": 7, "weight": 1.0}]},
                              "simulated_reference": "twin", "fit_check": "ok"}
    assert payload["summary"]["segments"] == 5 and payload["summary"]["comparable"] == 4
    assert payload["summary"]["segments_by_role"] == {"example": 1, "faulty_rest": 2,
                                                      "test": 2}
    assert len(payload["rows"]) == 5 and payload["rows"][2]["comparability"] is None
    assert predictions_payload(_frame())["rows"][0] == payload["rows"][0]


def test_predict_csv_stays_one_row_per_segment(tmp_path):
    path = write_predictions(_frame(), tmp_path / "p.csv")
    back = pd.read_csv(path)
    assert len(back) == 5 and list(back.columns) == list(_frame().columns)


@pytest.mark.parametrize("name", ["p.json", "p.csv", "bare.json"])
def test_report_reads_predict_csv_new_json_and_bare_list(name, tmp_path):
    if name == "bare.json":
        (tmp_path / name).write_text(_frame().to_json(orient="records"))
    else:
        write_predictions(_frame(), tmp_path / name)
    md = report_from_any_json(tmp_path / name, tmp_path / "rep")
    text = md.read_text()
    assert "| a.zip | faulty_rest | 2 | 0.45 |" in text
    assert ("* faulty size: 0.5" in text) == (name == "p.json")
    assert ("* grade: 7" in text) == (name == "p.json")
    page = (tmp_path / "rep" / "report.html").read_text()
    assert page.startswith("<!DOCTYPE html>") and "data:image/png;base64,iVBOR" in page
    assert 'src="estimates.png"' not in page and "<td>faulty_rest</td>" in page


def test_report_says_which_recordings_failed_the_speed_check(tmp_path):
    frame = _frame()
    frame["speed_check"] = ["ok"] * 3 + ["speed 39.90 Hz lies 33 % outside the fit's "
                                         "healthy recordings' 29.92-29.92 Hz"] * 2
    frame["trusted"] = [True, True, False, False, False]
    write_predictions(frame, tmp_path / "p.json")
    text = report_from_any_json(tmp_path / "p.json", tmp_path / "rep").read_text()
    assert ("`speed_check`: failed for 1 recording(s) (b.zip: speed 39.90 Hz lies 33 % "
            "outside") in text
    assert "Trusted segments: 2 of 5 (input, speed and path checks ok" in text
    # every recording ok: no speed line
    frame["speed_check"] = "ok"
    write_predictions(frame, tmp_path / "q.json")
    assert "speed_check" not in report_from_any_json(tmp_path / "q.json",
                                                     tmp_path / "rep2").read_text()


def test_report_reads_the_demo_ablations_csv(tmp_path):
    rows = pd.DataFrame({"variant": ["full", "full", "before_da", "before_da"],
                         "repeat": [0, 1, 0, 1], "mae_percent": [10.0, 12.0, 30.0, 34.0]})
    rows.to_csv(tmp_path / "ablations.csv", index=False)
    text = report_from_any_json(tmp_path / "ablations.csv", tmp_path / "rep").read_text()
    assert "**Full algorithm MAE: 11.0 %**" in text       # the MAE in %, one unit
    assert "| before_da | 32.0 |" in text
    assert (tmp_path / "rep" / "report.html").is_file()


def test_report_reads_the_ranking_csv(tmp_path):
    from gearshot.app.ranking import indicator_ranking

    sys.path.insert(0, str(__import__("pathlib").Path(__file__).parent))
    from test_outputs_explained import _labels, _payload

    indicator_ranking(_payload(), _labels()).to_csv(tmp_path / "ranking.csv", index=False)
    text = report_from_any_json(tmp_path / "ranking.csv", tmp_path / "rep").read_text()
    assert text.startswith("# gearshot report: indicator ranking")
    assert "separation = |2 AUC - 1|" in text and "| acc | rms |" in text
    assert (tmp_path / "rep" / "ranking.png").stat().st_size > 0


def test_report_reads_the_demo_predictions_csv(tmp_path):
    pd.DataFrame({"true": [0.32, 0.32, 0.56], "predicted": [0.30, 0.36, 0.5],
                  "variant": "full", "repeat": 0}).to_csv(tmp_path / "predictions.csv",
                                                          index=False)
    text = report_from_any_json(tmp_path / "predictions.csv", tmp_path / "rep").read_text()
    assert "**MAE 4.0 %**" in text and "| 0.320 | 2 | 0.330 |" in text
    assert (tmp_path / "rep" / "predicted_vs_true.png").is_file()


@pytest.mark.parametrize("content", [
    "sensor,indicator,auc_overall,separation,n_healthy,n_faulty\nacc,rms,1.5,0.5,2,1\n",
    "sensor,indicator,auc_overall,separation,n_healthy,n_faulty,auc[30 Hz]\n"
    "acc,rms,0.5,0.5,2,1,-1\n",
    "true,predicted\n0.3,nan\n",
    "true,predicted\n2,0.5\n",
])
def test_malformed_tables_are_refused_in_one_line(content, tmp_path):
    path = tmp_path / "t.csv"
    path.write_text(content)
    with pytest.raises(GearshotError) as info:
        read_output(path)
    assert "\n" not in str(info.value) and "t.csv" in str(info.value)


def test_a_demo_json_without_load_still_reports(tmp_path):
    (tmp_path / "d.json").write_text(json.dumps({"speed": 15, "mae": 10,
                                                 "ablations": {"full": 10.0}}))
    text = report_from_any_json(tmp_path / "d.json", tmp_path / "rep").read_text()
    assert "Condition: 15 rps; seed None." in text


def _row(**change):
    row = {"recording": "/d/a.zip", "role": "test", "segment": 0, "predicted": 0.3,
           "low": 0.1, "high": 0.5}
    row.update(change)
    return {k: v for k, v in row.items() if v is not _DROP}


_DROP = object()

#: (file content, words the one-line error names)
MALFORMED = {
    "Infinity": ('[{"recording": "a", "predicted": Infinity, "low": 0, "high": 1}]',
                 ["Infinity"]),
    "-Infinity": ('[{"recording": "a", "predicted": -Infinity, "low": 0, "high": 1}]',
                  ["-Infinity"]),
    "1e400": ('[{"recording": "a", "predicted": 1e400, "low": 0, "high": 1}]',
              ["1e400", "out of float range"]),
    "-5 in a row": (json.dumps([_row(predicted=-5)]), ["rows[0].predicted", "-5"]),
    "huge integer": (json.dumps([_row(high=10 ** 400)]), ["rows[0].high"]),
    "deep array": ("[" * 100_000 + "]" * 100_000, ["nested too deep"]),
    "recording a number": (json.dumps([_row(recording=5)]), ["rows[0].recording", "5"]),
    "recording null": (json.dumps([_row(recording=None)]), ["rows[0].recording", "None"]),
    "predicted a string": (json.dumps([_row(predicted="0.3")]), ["rows[0].predicted"]),
    "predicted null": (json.dumps([_row(predicted=None)]), ["rows[0].predicted", "null"]),
    "predicted NaN": ('[{"recording": "a", "predicted": NaN, "low": 0, "high": 1}]',
                      ["rows[0].predicted", "NaN"]),
    "low a string": (json.dumps([_row(low="x")]), ["rows[0].low", "'x'"]),
    "high null": (json.dumps([_row(high=None)]), ["rows[0].high"]),
    "row without high": (json.dumps([_row(high=_DROP)]), ["rows[0]", "'high'"]),
    "second row bad": (json.dumps([_row(), _row(segment=-1)]), ["rows[1].segment", "-1"]),
    "predicted a bool": (json.dumps([_row(predicted=True)]), ["rows[0].predicted"]),
    "role unknown": (json.dumps([_row(role="boss")]), ["rows[0].role", "boss"]),
    "new predict, rows empty": (json.dumps({"kind": "predict", "rows": []}), ["rows"]),
    "new predict, inputs a list": (json.dumps({"kind": "predict", "inputs": [1],
                                               "rows": [_row()]}), ["inputs"]),
    "kind a list": (json.dumps({"kind": ["predict"], "rows": [_row()]}),
                    ["not an output"]),
    "kind of a CSV table": (json.dumps({"kind": "ranking"}), ["not an output"]),
    "rig mae -5": (json.dumps({"experiment": "rig", "rows": [{"variant": "full",
                                                             "mae": -5}]}),
                   ["rows[0].mae", "-5"]),
    "rig mae string": (json.dumps({"experiment": "rig", "rows": [{"variant": "full",
                                                                 "mae": "0.1"}]}),
                       ["rows[0].mae"]),
    "simulated without tf": (json.dumps({"experiment": "simulated", "rows": [
        {"variant": "full", "mae": 0.1, "speed": 15, "load": 10,
         "attenuation_db": 0}]}), ["'tf'"]),
    "simulated tf a list": (json.dumps({"experiment": "simulated", "rows": [
        {"variant": "full", "mae": 0.1, "speed": 15, "load": 10, "tf": [1],
         "attenuation_db": 0}]}), ["rows[0].tf"]),
    "demo mae a string": (json.dumps({"mae": "x", "ablations": {"full": 1}}), ["mae"]),
    "demo ablation -5": (json.dumps({"mae": 10, "ablations": {"full": -5}}),
                         ["ablations.full", "-5"]),
    "demo ablation named a path": (json.dumps({"mae": 10, "ablations": {"../x": 5}}),
                                   ["ablations key", "../x"]),
    "nested 900 deep inside a valid demo": (
        '{"mae": 10, "ablations": {"full": 5}, "feature_errors": {"x": 1}, "params": '
        + "[" * 900 + "]" * 900 + "}", ["nested deeper than 16"]),
    "demo feature_errors nested": (json.dumps({"mae": 10, "ablations": {"full": 5},
                                               "feature_errors": {"x": [[1]]}}),
                                   ["feature_errors.x"]),
    "demo note a list": (json.dumps({"mae": 10, "ablations": {"full": 5},
                                     "grade_note": ["edge"]}), ["grade_note"]),
    "demo speed null": (json.dumps({"speed": None, "mae": 10, "ablations": {"full": 5}}),
                        ["speed"]),
    "family cell a string": (json.dumps({"experiment": "rig-family", "tables": {
        "condition": {"columns": ["mean"], "index": ["full"], "data": [["x"]]}}}),
        ["tables.condition.data[0][0]"]),
    "family ragged": (json.dumps({"experiment": "rig-family", "tables": {
        "condition": {"columns": ["mean"], "index": ["full"], "data": [[1, 2]]}}}),
        ["tables.condition.data[0]"]),
    "indicators value a string": (json.dumps({"kind": "indicators", "records": [
        {"file": "a", "n_cycles": 3, "indicators": {"rms": "big"}}]}),
        ["records[0].indicators.rms"]),
    "indicators name a path": (json.dumps({"kind": "indicators", "records": [
        {"file": "a", "n_cycles": 3, "indicators": {"../../x": 1.0}}]}), ["../../x"]),
    "indicators file null": (json.dumps({"kind": "indicators", "records": [
        {"file": None, "n_cycles": 3, "indicators": {"rms": 1.0}}]}), ["records[0].file"]),
    "monitor notice without a message": (json.dumps({
        "kind": "monitor", "records": [], "alarm": {"threshold": 0.2, "first_time": None},
        "forecast": {"limit": 0.6, "time": None, "low": None, "high": None, "law": None},
        "notice": {"since": "2026-01-01T00:00:00", "recordings": 3}}), ["notice", "message"]),
    "monitor law weights a list": (json.dumps({
        "kind": "monitor", "records": [], "alarm": {"threshold": 0.2, "first_time": None},
        "forecast": {"limit": 0.6, "time": None, "low": None, "high": None, "law": None,
                     "law_weights": [1]}}), ["forecast.law_weights"]),
}


@pytest.mark.parametrize("case", list(MALFORMED))
def test_malformed_outputs_are_refused_in_one_line(case, tmp_path):
    content, words = MALFORMED[case]
    path = tmp_path / "r.json"
    path.write_text(content)
    with pytest.raises(GearshotError) as info:
        read_output(path)
    text = str(info.value)
    assert "\n" not in text and "r.json" in text, text
    for word in words:
        assert word in text, (word, text)
    assert not (tmp_path / "rep").exists()


@pytest.mark.parametrize("content", [
    "recording,predicted,low,high\na.zip,inf,0,1\n",
    "recording,predicted,low,high\na.zip,-5,0,1\n",
    "recording,predicted,low,high\na.zip,abc,0,1\n",
    "recording,predicted,low\na.zip,0.3,0\n",
    "recording,predicted,low,high\n,0.3,0.1,0.5\n",
    "x,y\n1,2\n",
    "\x00\x01\x02 not a table",
])
def test_malformed_csv_is_refused_in_one_line(content, tmp_path):
    path = tmp_path / "p.csv"
    path.write_text(content)
    with pytest.raises(GearshotError) as info:
        read_output(path)
    assert "\n" not in str(info.value) and "p.csv" in str(info.value)


@pytest.mark.parametrize("case", ["Infinity", "deep array", "row without high",
                                  "recording null", "indicators name a path"])
def test_cli_report_exits_2_never_3(case, tmp_path, monkeypatch, capsys):
    path = tmp_path / "r.json"
    path.write_text(MALFORMED[case][0])
    code, err = _cli(["report", path, "--out", tmp_path / "rep"], monkeypatch, capsys)
    assert code == 2, err
    assert err.startswith("gearshot: error:") and len(err.splitlines()) == 1, err
    assert "a bug" not in err


def test_fuzzed_predict_rows_never_escape_as_another_error(tmp_path):
    """Every field of a predict row replaced by every odd value: a report or a
    GearshotError, nothing else."""
    odd = [None, "x", -5, 1e300, -1e300, True, [], {}, [1], 2 ** 70, 0.5]
    rng = np.random.default_rng(7)
    base = _row()
    for k in range(60):
        row = dict(base)
        for key in rng.choice(list(base), size=2, replace=False):
            row[str(key)] = odd[int(rng.integers(len(odd)))]
        path = tmp_path / f"r{k}.json"
        path.write_text(json.dumps([row]))
        try:
            read_output(path)
        except GearshotError as exc:
            assert "\n" not in str(exc)
