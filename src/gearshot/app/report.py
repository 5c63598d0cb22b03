"""``gearshot report``: figures, ``report.md`` and a self-contained ``report.html`` from
any output gearshot writes.

One kind of output = one entry of :data:`KINDS`: a check against its declared schema
(:mod:`gearshot.app.report_schema`) and one small function that writes its report. A new
kind adds a detection line in :func:`json_kind` and one entry.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

from .._errors import GearshotError
from . import report_schema as schema
from . import report_tables
from .markdown import md_table as _md_table
from .markdown import write_markdown, write_report
from .monitor_report import check_monitor, monitor_report
from .report_predict import predict_report, predict_rows, short_value

__all__ = ["write_report", "json_kind", "report_from_any_json", "read_output", "KINDS",
           "predict_rows"]

KINDS_TEXT = ("predict --out X.csv or X.json, demo results.json, ablations.csv or "
              "predictions.csv, experiment simulated/rig --json, experiment rig-family "
              "--json, indicators --json or its ranking.csv, monitor --json")
#: The kinds a JSON declares (``kind`` or ``experiment``); the others are CSV tables.
JSON_KINDS = ("predict", "demo", "simulated", "rig", "rig-family", "indicators", "monitor")
#: The deepest nesting of lists and objects an output may have (gearshot writes at most 5).
MAX_DEPTH = 16
#: The largest output file ``report`` reads (bytes).
MAX_BYTES = 512 * 1024 * 1024


def json_kind(payload: Any) -> str | None:
    """Which gearshot output ``payload`` is: ``"demo"``, ``"simulated"``, ``"rig"``,
    ``"rig-family"``, ``"predict"``, ``"indicators"``, or None. A declared ``kind`` (or
    ``experiment``) wins; the older predict JSON (a bare list of rows) is recognised by
    its rows' keys."""
    if isinstance(payload, list):
        if payload and all(isinstance(r, dict) and {"recording", "predicted"} <= set(r)
                           for r in payload):
            return "predict"
        return None
    if not isinstance(payload, dict):
        return None
    declared = payload.get("kind", payload.get("experiment"))
    if isinstance(declared, str) and declared in JSON_KINDS:
        return str(declared)
    if isinstance(payload.get("records"), list) and payload["records"] and all(
            isinstance(r, dict) and "indicators" in r for r in payload["records"]):
        return "indicators"
    if "ablations" in payload and "mae" in payload:
        return "demo"
    return None


def _load_json(path: Path) -> Any:
    """The JSON of ``path``; a non-finite number (``Infinity``, ``1e400``) or a nesting
    too deep for Python is refused in one line. ``NaN`` (as gearshot writes a missing
    value) reads as NaN and is refused later where the schema wants a number."""

    def finite(text: str) -> float:
        value = float(text)
        if not math.isfinite(value):
            raise GearshotError(f"{str(path)!r}: the number {text[:30]} is out of float "
                                f"range (gearshot writes only finite numbers)")
        return value

    def constant(name: str) -> float:
        if name == "NaN":
            return math.nan
        raise GearshotError(f"{str(path)!r}: {name} is not a number gearshot writes")

    try:
        text = path.read_text(encoding="utf-8")
        payload = json.loads(text, parse_float=finite, parse_constant=constant)
    except RecursionError:
        raise GearshotError(f"{str(path)!r}: its JSON is nested too deep to be an output "
                            f"of gearshot") from None
    except (UnicodeDecodeError, ValueError) as exc:
        if isinstance(exc, GearshotError):
            raise
        raise GearshotError(f"{str(path)!r} is not a JSON file ({type(exc).__name__}: "
                            f"{str(exc).splitlines()[0][:80]})") from None
    if _depth(payload) > MAX_DEPTH:
        raise GearshotError(f"{str(path)!r}: its JSON is nested deeper than {MAX_DEPTH} "
                            f"levels; no output of gearshot is")
    return payload


def _depth(value: Any) -> int:
    """How deeply lists and objects nest in a parsed JSON value (iteratively)."""
    deepest, stack = 0, [(value, 1)]
    while stack:
        item, level = stack.pop()
        if isinstance(item, (list, dict)):
            deepest = max(deepest, level)
            stack.extend((v, level + 1) for v in (item.values() if isinstance(item, dict)
                                                  else item))
    return deepest


def _load_csv(path: Path) -> tuple[str, Any]:
    """A CSV gearshot writes: predict's table (one row per segment) or the demo's
    ``ablations.csv`` (one row per variant and draw)."""
    import pandas as pd

    try:
        frame = pd.read_csv(path)
    except (UnicodeDecodeError, ValueError) as exc:   # pandas' parser errors included
        raise GearshotError(f"{str(path)!r} is not a CSV table ({type(exc).__name__}: "
                            f"{str(exc).splitlines()[0][:80] if str(exc) else ''})") from None
    rows = frame.to_dict(orient="records")
    cols = set(frame.columns)
    if {"recording", "predicted"} <= cols:
        return "predict", rows
    if {"variant", "mae_percent"} <= cols and "mae" not in cols:   # the demo's, in %
        rows = [{**r, "mae": r["mae_percent"] / 100
                 if isinstance(r["mae_percent"], (int, float)) else r["mae_percent"]}
                for r in rows]
        return "rig", {"experiment": "rig", "rows": rows}
    if {"variant", "mae"} <= cols:
        return "rig", {"experiment": "rig", "rows": rows}
    if {"sensor", "indicator", "auc_overall"} <= cols:
        return "ranking", {"rows": rows}
    if {"true", "predicted"} <= cols:
        return "sizes", {"rows": rows}
    raise GearshotError(f"{str(path)!r} is not a CSV gearshot writes (predict's table: "
                        f"recording, predicted, low, high ...; the demo's ablations.csv or "
                        f"predictions.csv; indicators' ranking.csv); its columns are "
                        f"{sorted(map(str, cols))[:8]}")


def read_output(path) -> tuple[str, Any]:
    """Read and check one gearshot output: ``(kind, payload)``.

    Raises
    ------
    GearshotError
        One line naming the file: not readable, not an output gearshot writes, or a field
        outside its declared schema (:mod:`gearshot.app.report_schema`).
    """
    path = Path(path)
    if not path.is_file():
        raise GearshotError(f"results file {str(path)!r} does not exist")
    if path.stat().st_size > MAX_BYTES:
        raise GearshotError(f"{str(path)!r} is {path.stat().st_size} bytes; gearshot's "
                            f"outputs are below {MAX_BYTES}")
    if path.suffix.lower() == ".csv":
        kind, payload = _load_csv(path)
    else:
        payload = _load_json(path)
        kind = json_kind(payload)  # type: ignore[assignment]
        if kind is None:
            raise GearshotError(f"{str(path)!r} is not an output that gearshot writes (one "
                                f"of: {KINDS_TEXT})")
    KINDS[kind][0](payload, repr(str(path)))
    return kind, payload


def report_from_any_json(path, out) -> Path:
    """``gearshot report``: figures, ``report.md`` and ``report.html`` from any output
    gearshot writes (JSON or CSV); returns the Markdown's path.

    Raises
    ------
    GearshotError
        One line naming the file when it is not such an output or breaks its schema.
    """
    path, out = Path(path), Path(out)
    kind, payload = read_output(path)
    out.mkdir(parents=True, exist_ok=True)
    return KINDS[kind][1](payload, out, path)


# --- checks, one per kind ------------------------------------------------------------

def _check_predict(payload: Any, where: str) -> None:
    schema.check_predict_rows(predict_rows(payload), where)
    if isinstance(payload, dict):
        for key in ("inputs", "fit", "summary"):
            if not isinstance(payload.get(key, {}), dict):
                raise GearshotError(f"{where}: {key} must be an object; got "
                                    f"{type(payload[key]).__name__}")


def _check_experiment(payload: Any, where: str) -> None:
    row = schema.SIMULATED_ROW if payload.get("experiment") == "simulated" else \
        schema.EXPERIMENT_ROW
    schema.check_rows(payload.get("rows"), row, where)


def _check_demo(payload: Any, where: str) -> None:
    schema.check_fields(payload, schema.DEMO, where, "")
    for key in ("ablations", "ablations_std"):
        for name, value in (payload.get(key) or {}).items():
            if value is None or not 0 <= value <= 100:
                raise GearshotError(f"{where}: {key}.{name} must be an MAE in % in "
                                    f"[0, 100]; got {value!r}")
            schema.check_name(name, where, f"{key} key")


def _check_family(payload: Any, where: str) -> None:
    schema.check_fields(payload, schema.FAMILY, where, "")
    schema.check_family_tables(payload.get("tables"), where)


def _check_indicators(payload: Any, where: str) -> None:
    schema.check_indicators(payload, where)


# --- reports, one per kind -------------------------------------------------------------

def _experiment_report(payload, out: Path, source: Path) -> Path:
    import pandas as pd

    from .figures import report_from_rows

    return report_from_rows(pd.DataFrame(payload["rows"]), out,
                            simulated=payload.get("experiment") == "simulated")


def _demo_report(payload, out: Path, source: Path) -> Path:
    from .figures import ablation_figure

    figs = {"Mean MAE of the ablations over the example draws (bars: ± 1 std), Fig. 14b":
            ablation_figure({k: v / 100 for k, v in payload["ablations"].items()}, out,
                            spread={k: v / 100 for k, v in
                                    (payload.get("ablations_std") or {}).items()},
                            draws=payload.get("draws"))}
    return write_report(out, payload, figs)


#: Titles and number formats of a rig-family JSON's tables (others: their name, 0.1).
_FAMILY_TABLES = {
    "condition": ("MAE by condition (speed/load); mean, p90 and max over rigs", "{:.2f}"),
    "kind": ("MAE by path type", "{:.2f}"),
    "grade": ("MAE by the rig's true grade", "{:.2f}"),
    "attenuation": ("MAE by path attenuation", "{:.2f}"),
    "coverage": ("90 % interval coverage", "{:.1f}"),
    "check": ("The fits' own check (`--checked`): MAE of the fits that passed and of "
              "those that refused themselves; the passed fits' coverage and width", "{:.3g}"),
}


def _family_report(payload, out: Path, source: Path) -> Path:
    import pandas as pd

    lines = ["# gearshot report: rig family", "",
             f"Range {payload.get('range')}, {len(payload.get('seeds') or [])} rigs x "
             f"{payload.get('draws')} draws; parameters {payload.get('params') or 'defaults'}.",
             "MAE and coverage in %.", ""]
    tables = {name: pd.DataFrame(split["data"], columns=split["columns"],
                                 index=split["index"]).astype(float)
              for name, split in payload["tables"].items()}
    for name, frame in tables.items():
        title, fmt = _FAMILY_TABLES.get(name, (name, "{:.1f}"))
        lines += [f"## {title}", ""] + _md_table(frame.reset_index(names=""), fmt)
    cond = tables.get("condition")
    if cond is not None and len(cond.columns) and len(cond):
        from .figures import ablation_figure

        col = "mean" if "mean" in cond else cond.columns[0]
        fig = ablation_figure({str(k): float(v) / 100 for k, v in cond[col].items()}, out,
                              name="family_mae")
        lines += ["## MAE by variant over the rigs", "", f"![MAE by variant]({fig.name})", ""]
    return write_markdown(out, lines)


def _indicators_report(payload, out: Path, source: Path) -> Path:
    from .indicators import indicator_figures, indicator_table

    table = indicator_table(payload).drop(columns=["case", "condition"])
    shaft = payload.get("shaft", "?")
    paths = indicator_figures(payload, out, title=f"{payload.get('machine', '')}, shaft "
                                                  f"{shaft}")
    lines = ["# gearshot report: condition indicators", "",
             f"From `{source.name}`: machine {payload.get('machine', '?')!s}, shaft {shaft}, "
             f"{len(table)} record(s) x sensor(s); speeds in Hz read from the tacho.", ""]
    lines += _md_table(table)
    if payload.get("ranking"):
        import pandas as pd

        from .ranking import RANKING_NOTE

        lines += ["## Indicator ranking (AUC, healthy vs faulty)", "", RANKING_NOTE, ""]
        cells = payload.get("ranking_cells")
        if isinstance(cells, dict) and cells:
            lines += ["Records per cell (healthy/faulty): " + ", ".join(
                f"{cell} {short_value(c.get('healthy') if isinstance(c, dict) else c)}/"
                f"{short_value(c.get('faulty') if isinstance(c, dict) else c)}"
                for cell, c in cells.items()) + ".", ""]
        lines += _md_table(pd.DataFrame(payload["ranking"]), "{:.2f}")
    for p in paths:
        lines += [f"## {p.stem}", "", f"![{p.stem}]({p.name})", ""]
    return write_markdown(out, lines)


Check = Callable[[Any, str], None]
Render = Callable[[Any, Path, Path], Path]

#: Every kind ``report`` reads: its schema check and its report writer.
KINDS: dict[str, tuple[Check, Render]] = {
    "predict": (_check_predict, predict_report),
    "demo": (_check_demo, _demo_report),
    "simulated": (_check_experiment, _experiment_report),
    "rig": (_check_experiment, _experiment_report),
    "rig-family": (_check_family, _family_report),
    "indicators": (_check_indicators, _indicators_report),
    "monitor": (check_monitor, monitor_report),
    "ranking": (report_tables.check_ranking, report_tables.ranking_report),
    "sizes": (report_tables.check_sizes, report_tables.sizes_report),
}
