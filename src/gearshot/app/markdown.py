"""The Markdown of a report: ``report.md`` from a results summary and its figures, and
beside it ``report.html``, the same report self-contained (figures embedded as base64 PNG).

Written by the demo, the experiments' ``--out`` and ``gearshot report``
(:mod:`gearshot.app.report` chooses what goes in; this module only writes it).
"""

from __future__ import annotations

import base64
import html
import re
from pathlib import Path

from .._atomic import write_text_atomic

__all__ = ["write_report", "write_markdown", "markdown_to_html", "md_table"]


def write_report(folder, summary: dict, figures: dict) -> Path:
    """Write ``report.md`` in ``folder`` from a results summary and {caption: png path}."""
    folder = Path(folder)
    lines = ["# gearshot report", ""]
    if "speed" in summary:
        load = f", {summary['load']:g} Nm" if summary.get("load") is not None else ""
        lines += [f"Condition: {summary['speed']:g} rps{load}; seed {summary.get('seed')}.",
                  ""]
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
    for key in ("ablation_note", "grade_note"):
        if summary.get(key):
            lines += [str(summary[key]).replace("\n", "\n\n"), ""]
    for key in ("grade", "rig_grade", "selected_features", "n_neighbors", "feature_errors"):
        if key in summary:
            lines.append(f"* {key.replace('_', ' ')}: {summary[key]}")
    lines.append("")
    for caption, path in figures.items():
        rel = Path(path).relative_to(folder) if Path(path).is_relative_to(folder) else path
        lines += [f"## {caption}", "", f"![{caption}]({rel})", ""]
    return write_markdown(folder, lines)


def write_markdown(folder, lines: list[str]) -> Path:
    """Write ``report.md`` (the lines) and ``report.html`` (the same, self-contained) in
    ``folder``; returns the Markdown's path."""
    folder = Path(folder)
    text = "\n".join(lines)
    write_text_atomic(folder / "report.html", markdown_to_html(text, folder),
                      make_parents=True)
    path = folder / "report.md"
    write_text_atomic(path, text, make_parents=True)
    return path


_IMAGE = re.compile(r"^!\[(?P<alt>[^\]]*)\]\((?P<src>[^)]+)\)$")


def _inline(text: str) -> str:
    """Escape, then the inline marks reports use: ``**bold**`` and ```code```."""
    text = html.escape(text)
    text = re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", text)
    return re.sub(r"`([^`]+)`", r"<code>\1</code>", text)


def _image(alt: str, src: str, folder: Path) -> str:
    """An ``<img>`` with the PNG inside (a missing or non-PNG file: its alt text only)."""
    path = Path(src) if Path(src).is_absolute() else folder / src
    if path.suffix.lower() != ".png" or not path.is_file():
        return f"<p>[figure {html.escape(src)} not found]</p>"
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return (f'<figure><img alt="{html.escape(alt, quote=True)}" '
            f'src="data:image/png;base64,{data}"></figure>')


def markdown_to_html(text: str, folder) -> str:
    """A self-contained HTML page from a report's Markdown (the subset reports write:
    headings, paragraphs, bullet lists, pipe tables, images of PNG files in ``folder``)."""
    folder = Path(folder)
    body: list[str] = []
    title = "gearshot report"
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        line = lines[i].rstrip()
        if not line:
            i += 1
            continue
        if line.startswith("#"):
            level = min(len(line) - len(line.lstrip("#")), 6)
            content = line[level:].strip()
            if level == 1:
                title = content
            body.append(f"<h{level}>{_inline(content)}</h{level}>")
            i += 1
        elif (m := _IMAGE.match(line)) is not None:
            body.append(_image(m["alt"], m["src"], folder))
            i += 1
        elif line.startswith("|"):
            rows = []
            while i < len(lines) and lines[i].startswith("|"):
                rows.append([c.strip() for c in lines[i].strip().strip("|").split("|")])
                i += 1
            head, rest = rows[0], [r for r in rows[1:] if not set("".join(r)) <= set("-: ")]
            body.append("<table><thead><tr>" + "".join(f"<th>{_inline(c)}</th>" for c in head)
                        + "</tr></thead><tbody>" + "".join(
                            "<tr>" + "".join(f"<td>{_inline(c)}</td>" for c in r) + "</tr>"
                            for r in rest) + "</tbody></table>")
        elif line.startswith(("* ", "- ")):
            items = []
            while i < len(lines) and lines[i].startswith(("* ", "- ")):
                items.append(f"<li>{_inline(lines[i][2:])}</li>")
                i += 1
            body.append("<ul>" + "".join(items) + "</ul>")
        else:
            para = [line.strip()]
            i += 1
            while i < len(lines) and lines[i].strip() and not lines[i].startswith(
                    ("#", "|", "* ", "- ", "![")):
                para.append(lines[i].strip())
                i += 1
            body.append(f"<p>{_inline(' '.join(para))}</p>")
    style = ("body{font-family:sans-serif;max-width:60em;margin:2em auto;padding:0 1em}"
             "table{border-collapse:collapse;font-size:90%}td,th{border:1px solid #bbb;"
             "padding:2px 6px;text-align:right}img{max-width:100%}")
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>{html.escape(title)}</title><style>{style}</style></head><body>\n"
            + "\n".join(body) + "\n</body></html>\n")


def md_table(frame, floats: str = "{:.3g}") -> list[str]:
    """A pandas DataFrame as Markdown table lines (index dropped)."""
    cols = [str(c) for c in frame.columns]
    lines = ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for row in frame.itertuples(index=False):
        cells = [floats.format(v) if isinstance(v, float) else str(v) for v in row]
        lines.append("| " + " | ".join(cells) + " |")
    return lines + [""]
