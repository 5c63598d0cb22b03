"""The demo's and the ranking's outputs say what their numbers mean (issue #32): the grade
at the edge of the search, an ablation below the full algorithm against the spread over
draws, one MAE unit, rounded numbers, the ranking's caveat and counts, points coloured by
label."""

from __future__ import annotations

import pandas as pd
import pytest

from gearshot.app.demo import ablation_spread_note, edge_grade_note


@pytest.mark.parametrize("grade, edge", [(1, "smoothest"), (12, "roughest"), (6, None),
                                         (2, None)])
def test_a_grade_at_the_edge_of_the_search_is_said(grade, edge):
    note = edge_grade_note(grade, list(range(1, 13)))
    if edge is None:
        assert note == ""
    else:
        assert f"the {edge} grade of the database's range 1-12" in note
        assert "edge of the search" in note and "extrapolated" in note


def _stats(full, full_std, other, other_std, draws=5):
    stats = pd.DataFrame({"mean": [full, other, 30.0], "std": [full_std, other_std, 1.0]},
                         index=["full", "no_feature_selection", "before_da"])
    stats.attrs["draws"] = draws
    return stats


def test_an_ablation_below_full_within_the_spread_is_no_evidence():
    note = ablation_spread_note(_stats(12.0, 3.0, 10.5, 2.0))
    assert note.startswith("note: no_feature_selection (10.5 ± 2.0 %)")
    assert "by 1.5 points over 5 draw(s)" in note and "no evidence" in note
    assert "before_da" not in note          # above full: no comment


def test_an_ablation_below_full_beyond_the_spread_is_said_so():
    note = ablation_spread_note(_stats(12.0, 1.0, 8.0, 1.5))
    assert "by 4.0 points" in note and "larger than the spread" in note


def test_no_comment_when_full_is_best():
    assert ablation_spread_note(_stats(8.0, 1.0, 10.0, 1.0)) == ""


def _payload():
    recs = []
    for k, (name, value) in enumerate([("spur1_30hz_High_1.zip", 1.0),
                                       ("spur3_30hz_High_1.zip", 1.2),
                                       ("spur2_30hz_High_1.zip", 3.0),
                                       ("spur1_40hz_High_1.zip", 1.1),
                                       ("spur2_40hz_High_1.zip", 2.5)]):
        recs.append({"file": name, "sensor": "acc", "tacho_speed_hz": 30.0 if "30hz" in name
                     else 40.0, "shaft_speed_hz": 30.0, "n_cycles": 10,
                     "indicators": {"rms": value, "kurtosis": 3.0 + 0.1 * k}})
    return {"kind": "indicators", "machine": "m", "shaft": "input",
            "units": {"indicators": {"acc": {"rms": "g", "kurtosis": "1"}}}, "records": recs}


def _labels():
    return pd.DataFrame({"file": [r["file"] for r in _payload()["records"]],
                         "label": ["healthy", "healthy", "chipped", "healthy", "chipped"],
                         "faulty": [False, False, True, False, True]})


def test_ranking_states_counts_per_cell_and_the_caveat():
    from gearshot.app.ranking import format_ranking, indicator_ranking

    ranking = indicator_ranking(_payload(), _labels())
    assert ranking.attrs["cells"] == {"30 Hz": (2, 1), "40 Hz": (1, 1)}
    text = format_ranking(ranking)
    assert "records per cell (healthy/faulty): 30 Hz 2/1, 40 Hz 1/1" in text
    assert "separation = |2 AUC - 1|" in text
    assert "with one faulty record per cell an AUC of 1.00" in text


def test_indicator_points_are_coloured_by_label(tmp_path, monkeypatch):
    from matplotlib.figure import Figure

    from gearshot.app.indicators import indicator_figures

    seen = []
    original = Figure.legend

    def spy(self, *args, **kw):
        seen.append([h.get_label() for h in kw.get("handles", [])])
        return original(self, *args, **kw)

    monkeypatch.setattr(Figure, "legend", spy)
    labels = dict(zip(_labels()["file"], _labels()["label"]))
    indicator_figures(_payload(), tmp_path, labels=labels)
    assert seen and all({"label chipped", "label healthy"} <= set(s) for s in seen)
    assert not any("spur1" in h for s in seen for h in s)
    seen.clear()
    indicator_figures(_payload(), tmp_path)                # without labels: by case
    assert {"spur1", "spur2", "spur3"} <= set(seen[0])


def test_ranking_json_report_carries_the_note(tmp_path):
    import json

    from gearshot.app.ranking import indicator_ranking
    from gearshot.app.report import report_from_any_json

    payload = _payload()
    ranking = indicator_ranking(payload, _labels())
    payload["ranking"] = json.loads(ranking.to_json(orient="records"))
    payload["ranking_cells"] = {c: {"healthy": h, "faulty": f}
                                for c, (h, f) in ranking.attrs["cells"].items()}
    (tmp_path / "i.json").write_text(json.dumps(payload))
    text = report_from_any_json(tmp_path / "i.json", tmp_path / "rep").read_text()
    assert "separation = |2 AUC - 1|" in text
    assert "Records per cell (healthy/faulty): 30 Hz 2/1, 40 Hz 1/1." in text


def test_demo_outputs_give_the_mae_in_percent_everywhere(tmp_path):
    import json

    from gearshot.app.demo import _write_outputs
    from gearshot.app.report import report_from_any_json

    results = pd.DataFrame({"variant": ["full", "full", "rms_only", "rms_only"],
                            "repeat": [0, 1, 0, 1], "mae": [0.0512345678, 0.0612, 0.08, 0.1],
                            "grade": [6, 7, 6, 7], "estimator": [None] * 4})
    full_pred = pd.DataFrame({"true": [0.32, 0.56], "predicted": [0.312345678901, 0.5]})
    summary = {"speed": 15.0, "load": 10.0, "seed": 0, "draws": 2, "mae_unit": "%",
               "mae": 5.62, "mae_std": 0.71, "ablations": {"full": 5.62, "rms_only": 9.0},
               "ablations_std": {"full": 0.71, "rms_only": 1.41}, "grade": 1,
               "grade_note": "grade 1 is the smoothest grade ... edge of the search"}
    _write_outputs(tmp_path, summary, {}, results, full_pred)
    table = pd.read_csv(tmp_path / "ablations.csv")
    assert "mae" not in table and list(table["mae_percent"]) == [5.123, 6.12, 8.0, 10.0]
    assert "0.3123" in (tmp_path / "predictions.csv").read_text()
    assert "0.312345678901" not in (tmp_path / "predictions.csv").read_text()
    report = (tmp_path / "report.md").read_text()
    assert "**Full algorithm MAE: 5.6 ± 0.7 %**" in report and "edge of the search" in report
    assert json.loads((tmp_path / "results.json").read_text())["mae_unit"] == "%"
    # the report command reads the same ablations.csv back, in %
    text = report_from_any_json(tmp_path / "ablations.csv", tmp_path / "rep").read_text()
    assert "| rms_only | 9.0 |" in text
