"""The Markdown of a report: ``report.md`` from a results summary and its figures.

Written by the demo, the experiments' ``--out`` and ``gearshot report``
(:mod:`gearshot.app.report` chooses what goes in; this module only writes it).
"""

from __future__ import annotations

from pathlib import Path

from .._atomic import write_text_atomic

__all__ = ["write_report", "md_table"]


def write_report(folder, summary: dict, figures: dict) -> Path:
    """Write ``report.md`` in ``folder`` from a results summary and {caption: png path}."""
    folder = Path(folder)
    lines = ["# gearshot report", ""]
    if "speed" in summary:
        lines += [f"Condition: {summary['speed']:g} rps, {summary['load']:g} Nm; "
                  f"seed {summary.get('seed')}.", ""]
    spread = summary.get("ablations_std")
    over = f" (mean ± std over {summary['draws']} example draws)" if spread else ""
    if "mae" in summary:
        pm = f" ± {summary['mae_std']:.1f}" if "mae_std" in summary else ""
        lines += [f"**Full algorithm MAE: {summary['mae']:.1f}{pm} %**{over}", ""]
    if summary.get("ablations"):
        if spread:
            lines += ["| variant | MAE mean [%] | std [%] |", "|---|---|---|"]
            lines += [f"| {k} | {v:.1f} | {spread.get(k, 0.0):.1f} |"
                      for k, v in summary["ablations"].items()]
        else:
            lines += ["| variant | MAE [%] |", "|---|---|"]
            lines += [f"| {k} | {v:.1f} |" for k, v in summary["ablations"].items()]
        lines.append("")
    for key in ("grade", "rig_grade", "selected_features", "n_neighbors", "feature_errors"):
        if key in summary:
            lines.append(f"* {key.replace('_', ' ')}: {summary[key]}")
    lines.append("")
    for caption, path in figures.items():
        rel = Path(path).relative_to(folder) if Path(path).is_relative_to(folder) else path
        lines += [f"## {caption}", "", f"![{caption}]({rel})", ""]
    path = folder / "report.md"
    write_text_atomic(path, "\n".join(lines), make_parents=True)
    return path


def md_table(frame, floats: str = "{:.3g}") -> list[str]:
    """A pandas DataFrame as Markdown table lines (index dropped)."""
    cols = [str(c) for c in frame.columns]
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for row in frame.itertuples(index=False):
        cells = [floats.format(v) if isinstance(v, float) else str(v) for v in row]
        lines.append("| " + " | ".join(cells) + " |")
    return lines + [""]
