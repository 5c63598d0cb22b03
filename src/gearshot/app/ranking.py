"""Which indicator tells this machine's conditions apart: a ranking from labelled records.

``gearshot indicators ... --labels LABELS.csv`` reads a table with columns ``file`` and
``label`` (and optionally ``cell``): ``label`` 0, ``healthy`` or ``good`` (any case) marks
the healthy class, every other label a fault. For every sensor and indicator the ranking
gives the area under the ROC curve (AUC, scikit-learn's :func:`~sklearn.metrics.roc_auc_score`)
of healthy against faulty records within each cell (an operating condition: the ``cell``
column, or else the tacho speed rounded to whole Hz) and over all records together, and
whether the indicator rises or falls with the fault. ``separation`` = ``|2 AUC - 1|``,
the overall AUC folded onto [0, 1] (0: no better than chance; 1: a threshold separates the
classes perfectly), orders the table.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .._errors import GearshotError

__all__ = ["read_labels", "indicator_ranking", "format_ranking", "ranking_figure",
           "HEALTHY_LABELS", "RANKING_NOTE"]

#: What the ranking's columns mean and how far its AUCs can be trusted (printed with it
#: and written in its report).
RANKING_NOTE = (
    "separation = |2 AUC - 1|: the overall AUC folded onto [0, 1] (0: the indicator does no "
    "better than chance; 1: one threshold separates healthy from faulty records, whichever "
    "way the indicator moves). An AUC from few records is weak evidence: with n_healthy "
    "and n_faulty records in a cell there are only n_healthy x n_faulty comparisons, and "
    "with one faulty record per cell an AUC of 1.00 means only that this one record lies "
    "beyond every healthy one; the columns n_healthy and n_faulty give the counts.")

#: Labels of the healthy class (compared without case)
HEALTHY_LABELS = ("0", "healthy", "good")


def read_labels(path: str | Path, files: Sequence[str] = ()) -> pd.DataFrame:
    """The labels table: ``file`` (a file name), ``label``, ``faulty`` (bool), ``cell``
    (str, or missing).

    Raises
    ------
    GearshotError
        Missing columns, a file of ``files`` without a label, or only one class.
    """
    path = Path(path)
    try:
        table = pd.read_csv(path, dtype=str, skipinitialspace=True)
    except (OSError, ValueError) as exc:
        raise GearshotError(f"--labels {str(path)!r} is not a readable CSV ({exc})") from None
    table.columns = [str(c).strip().lower() for c in table.columns]
    missing = {"file", "label"} - set(table.columns)
    if missing:
        raise GearshotError(f"--labels {str(path)!r} needs columns file and label; it lacks "
                            f"{sorted(missing)} (has {list(table.columns)})")
    table["file"] = [Path(str(f).strip()).name for f in table["file"]]
    table["label"] = [str(v).strip() for v in table["label"]]
    table["faulty"] = ~table["label"].str.lower().isin(HEALTHY_LABELS)
    unlabelled = [f for f in files if f not in set(table["file"])]
    if unlabelled:
        raise GearshotError(f"--labels {str(path)!r} has no label for {unlabelled[:3]}"
                            + (f" and {len(unlabelled) - 3} more" if len(unlabelled) > 3
                               else ""))
    used = table[table["file"].isin(files)] if files else table
    if used["faulty"].nunique() < 2:
        raise GearshotError(f"--labels {str(path)!r}: the records need both classes, healthy "
                            f"(label 0, healthy or good) and faulty; got labels "
                            f"{sorted(set(used['label']))}")
    return table


def _auc(values: np.ndarray, faulty: np.ndarray) -> float:
    from sklearn.metrics import roc_auc_score

    ok = np.isfinite(values)
    if len(set(faulty[ok])) < 2:
        return float("nan")
    return float(roc_auc_score(faulty[ok], values[ok]))


def indicator_ranking(payload: dict[str, Any], labels: pd.DataFrame) -> pd.DataFrame:
    """AUC of every (sensor, indicator), per cell and overall.

    Parameters
    ----------
    payload : dict
        :func:`gearshot.app.indicators.record_indicators`'s output.
    labels : pandas.DataFrame
        :func:`read_labels`'s output.

    Returns
    -------
    pandas.DataFrame
        ``sensor, indicator, direction, separation, auc_overall, auc[<cell>]...,
        n_healthy, n_faulty``, best first. ``auc`` is P(indicator of a faulty record >
        that of a healthy one); ``direction`` says which way the indicator moves.
    """
    from .indicators import _META, indicator_table

    table = indicator_table(payload)
    if "input_check" in table:   # a channel that failed its input check has no indicator
        table = table[table["input_check"] == "ok"]
    merged = table.merge(labels.drop(columns=[c for c in ("case", "condition")
                                              if c in labels]), on="file", how="inner")
    if "cell" in merged and merged["cell"].notna().all():
        merged["cell"] = merged["cell"].astype(str)
    else:
        merged["cell"] = [f"{round(v):d} Hz" for v in merged["tacho_speed_hz"]]
    cells = sorted(merged["cell"].unique())
    cols = [c for c in table.columns if c not in _META]
    rows = []
    for sensor, part in merged.groupby("sensor", sort=False):
        y = part["faulty"].to_numpy(bool)
        for col in cols:
            x = part[col].to_numpy(float)
            overall = _auc(x, y)
            row = {"sensor": sensor, "indicator": col,
                   "direction": "rises with fault" if overall >= 0.5 else "falls with fault",
                   "separation": abs(2 * overall - 1), "auc_overall": overall}
            for cell in cells:
                inside = (part["cell"] == cell).to_numpy()
                row[f"auc[{cell}]"] = _auc(x[inside], y[inside])
            row["n_healthy"], row["n_faulty"] = int((~y).sum()), int(y.sum())
            rows.append(row)
    out = pd.DataFrame(rows)
    out = out.sort_values(["separation", "indicator"], ascending=[False, True],
                          kind="stable", ignore_index=True)
    first = merged[merged["sensor"] == merged["sensor"].iloc[0]]
    out.attrs["cells"] = {cell: (int((~part["faulty"]).sum()), int(part["faulty"].sum()))
                          for cell, part in first.groupby("cell", sort=True)}
    return out


def format_ranking(ranking: pd.DataFrame) -> str:
    """The ranking as printed by ``gearshot indicators --labels``."""
    head = ("indicator ranking: AUC of healthy vs faulty records (1 or 0: a threshold "
            "separates them; 0.5: chance), per cell and overall")
    lines = [head, ranking.to_string(index=False, float_format=lambda v: f"{v:.2f}",
                                     line_width=None)]
    cells = ranking.attrs.get("cells")
    if cells:
        lines.append("records per cell (healthy/faulty): " + ", ".join(
            f"{cell} {h}/{f}" for cell, (h, f) in cells.items()))
    lines.append(RANKING_NOTE)
    return "\n".join(lines)


def ranking_figure(ranking: pd.DataFrame, path: str | Path, *, title: str = "") -> Path:
    """A heat map of the AUC (rows: sensor/indicator, best first; columns: cells and
    overall), written atomically as PNG."""
    from matplotlib.figure import Figure

    from .._atomic import atomic_path

    cells = [c for c in ranking.columns if c.startswith("auc[")] + ["auc_overall"]
    values = ranking[cells].to_numpy(float)
    names = [f"{s} / {i}" for s, i in zip(ranking["sensor"], ranking["indicator"])]
    fig = Figure(figsize=(2.2 + 1.1 * len(cells), 1.2 + 0.24 * len(names)),
                 layout="constrained")
    ax = fig.subplots()
    image = ax.imshow(values, cmap="RdBu_r", vmin=0.0, vmax=1.0, aspect="auto")
    ax.set_xticks(range(len(cells)), [c[4:-1] if c.startswith("auc[") else "overall"
                                      for c in cells], fontsize=8)
    ax.set_yticks(range(len(names)), names, fontsize=7)
    for (i, j), v in np.ndenumerate(values):
        if np.isfinite(v):
            ax.text(j, i, f"{v:.2f}", ha="center", va="center", fontsize=6)
    fig.colorbar(image, ax=ax, label="AUC (faulty > healthy)")
    ax.set_xlabel("cell (operating condition)")
    ax.set_title(f"{title}\nindicator ranking, best first".strip(), fontsize=9)
    path = Path(path)
    with atomic_path(path, make_parents=True) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    return path
