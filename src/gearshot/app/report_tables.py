"""Reports of the tables gearshot writes beside its figures: the indicator ranking
(``indicators --labels --out F``: ``F/ranking.csv``) and the demo's per-segment sizes
(``gearshot demo``: ``predictions.csv``). One check and one report writer per kind, as
:data:`gearshot.app.report.KINDS` dispatches them."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from . import report_schema as schema
from .markdown import md_table, write_markdown

__all__ = ["RANKING_ROW", "SIZES_ROW", "check_ranking", "ranking_report", "check_sizes",
           "sizes_report"]

#: One row of ``ranking.csv`` (its ``auc[<cell>]`` columns are checked as AUCs too).
RANKING_ROW = {
    "sensor": schema.Field("str"), "indicator": schema.Field("str"),
    "direction": schema.Field("str", required=False),
    "separation": schema.Field("number", nullable=True, low=0.0, high=1.0),
    "auc_overall": schema.Field("number", nullable=True, low=0.0, high=1.0),
    "n_healthy": schema.Field("int", low=0), "n_faulty": schema.Field("int", low=0),
}

#: One row of the demo's ``predictions.csv``: a test segment's true and estimated size.
SIZES_ROW = {
    "true": schema.Field("number", low=0.0, high=1.0),
    "predicted": schema.Field("number", low=0.0, high=1.0),
    "low": schema.Field("number", required=False, low=0.0, high=1.0),
    "high": schema.Field("number", required=False, low=0.0, high=1.0),
}


def check_ranking(payload: Any, where: str) -> None:
    rows = payload.get("rows")
    schema.check_rows(rows, RANKING_ROW, where)
    auc = schema.Field("number", nullable=True, low=0.0, high=1.0)
    for i, row in enumerate(rows):
        for key, value in row.items():
            if str(key).startswith("auc["):
                schema.check_fields({key: value}, {key: auc}, where, f"rows[{i}]")


def ranking_report(payload: Any, out: Path, source: Path) -> Path:
    import pandas as pd

    from .ranking import RANKING_NOTE, ranking_figure

    frame = pd.DataFrame(payload["rows"])
    fig = ranking_figure(frame, out / "ranking.png")
    lines = ["# gearshot report: indicator ranking", "",
             f"From `{source.name}`: {len(frame)} sensor × indicator rows, "
             f"{int(frame['n_healthy'].max())} healthy and {int(frame['n_faulty'].max())} "
             f"faulty records.", "", RANKING_NOTE, ""]
    lines += md_table(frame, "{:.2f}")
    lines += ["## AUC per cell and overall", "", f"![AUC per cell]({fig.name})", ""]
    return write_markdown(out, lines)


def check_sizes(payload: Any, where: str) -> None:
    schema.check_rows(payload.get("rows"), SIZES_ROW, where)


def sizes_report(payload: Any, out: Path, source: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import pandas as pd

    from .. import plotting

    frame = pd.DataFrame(payload["rows"])
    table = frame.groupby("true").agg(segments=("predicted", "size"),
                                      mean_predicted=("predicted", "mean"),
                                      std=("predicted", "std")).reset_index()
    table = table.rename(columns={"true": "true size", "mean_predicted": "mean predicted"})
    mae = 100 * float((frame["predicted"] - frame["true"]).abs().mean())
    fig, ax = plt.subplots(figsize=(4.5, 4.5))
    plotting.plot_predicted_vs_true(frame["true"], frame["predicted"], ax=ax,
                                    low=frame.get("low"), high=frame.get("high"))
    png = plotting.save_figure(fig, out / "predicted_vs_true")[0]
    plt.close(fig)
    lines = ["# gearshot report: estimated against true sizes", "",
             f"From `{source.name}`: {len(frame)} test segments; **MAE {mae:.1f} %**.", ""]
    lines += md_table(table, "{:.3f}")
    lines += ["## Predicted vs true size", "", f"![Predicted vs true]({Path(png).name})", ""]
    return write_markdown(out, lines)
