"""Markdown report gathering an experiment's tables and figures."""

from __future__ import annotations

from pathlib import Path

from .._atomic import write_text_atomic
from .markdown import md_table as _md_table
from .markdown import write_report

__all__ = ["write_report", "json_kind", "report_from_any_json"]


def json_kind(payload) -> str | None:
    """Which gearshot JSON ``payload`` is: ``"demo"``, ``"simulated"``, ``"rig"``,
    ``"rig-family"``, ``"predict"``, ``"indicators"``, or None."""
    if isinstance(payload, list):
        if payload and all(isinstance(r, dict) and {"recording", "predicted"} <= set(r)
                           for r in payload):
            return "predict"
        return None
    if not isinstance(payload, dict):
        return None
    if payload.get("experiment") in ("simulated", "rig") and isinstance(payload.get("rows"),
                                                                       list):
        return str(payload["experiment"])
    if payload.get("experiment") == "rig-family" and isinstance(payload.get("tables"), dict):
        return "rig-family"
    if payload.get("kind") == "indicators" or (
            isinstance(payload.get("records"), list) and payload["records"]
            and all(isinstance(r, dict) and "indicators" in r for r in payload["records"])):
        return "indicators"
    if "ablations" in payload and "mae" in payload:
        return "demo"
    return None


KINDS_TEXT = ("demo results.json, experiment simulated/rig --json, experiment rig-family "
              "--json, predict --out X.json, indicators --json, monitor --json")


def report_from_any_json(path, out) -> Path:
    """``gearshot report``: figures and ``report.md`` from any JSON gearshot writes.

    Raises
    ------
    GearshotError
        One line naming the file when it is not such a JSON.
    """
    import json

    from .._errors import GearshotError

    path, out = Path(path), Path(out)
    try:
        payload = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise GearshotError(f"{str(path)!r} is not a JSON file ({type(exc).__name__}: "
                            f"{str(exc).splitlines()[0][:80]})") from None
    from .monitor_report import is_monitor_payload, monitor_report

    if is_monitor_payload(payload):
        out.mkdir(parents=True, exist_ok=True)
        return monitor_report(payload, out, source=path)
    kind = json_kind(payload)
    if kind is None:
        raise GearshotError(f"{str(path)!r} is not a JSON that gearshot writes (one of: "
                            f"{KINDS_TEXT})")
    out.mkdir(parents=True, exist_ok=True)
    if kind in ("simulated", "rig"):
        from .figures import report_from_json

        return report_from_json(path, out)
    if kind == "demo":
        return _demo_report(payload, out)
    if kind == "rig-family":
        return _family_report(payload, out)
    if kind == "predict":
        return _predict_report(payload, out, source=path)
    return _indicators_report(payload, out, source=path)


def _demo_report(payload, out: Path) -> Path:
    from .figures import ablation_figure

    figs = {"Mean MAE of the ablations over the example draws (bars: ± 1 std), Fig. 14b":
            ablation_figure({k: v / 100 for k, v in payload["ablations"].items()}, out,
                            spread={k: v / 100 for k, v in
                                    (payload.get("ablations_std") or {}).items()},
                            draws=payload.get("draws"))}
    return write_report(out, payload, figs)


def _family_report(payload, out: Path) -> Path:
    import pandas as pd

    lines = ["# gearshot report: rig family", "",
             f"Range {payload.get('range')}, {len(payload.get('seeds', []))} rigs x "
             f"{payload.get('draws')} draws; parameters {payload.get('params') or 'defaults'}.",
             "MAE and coverage in %.", ""]
    tables = {name: pd.DataFrame(split.get("data", []), columns=split.get("columns"),
                                 index=split.get("index"))
              for name, split in payload["tables"].items()}
    for name, frame in tables.items():
        lines += [f"## {name}", ""] + _md_table(frame.reset_index(names=""), "{:.1f}")
    cond = tables.get("condition")
    if cond is not None and len(cond.columns):
        from .figures import ablation_figure

        col = "mean" if "mean" in cond else cond.columns[0]
        fig = ablation_figure({str(k): float(v) / 100 for k, v in cond[col].items()}, out,
                              name="family_mae")
        lines += ["## MAE by variant over the rigs", "", f"![MAE by variant]({fig.name})", ""]
    target = out / "report.md"
    write_text_atomic(target, "\n".join(lines), make_parents=True)
    return target


def _predict_report(rows, out: Path, *, source: Path) -> Path:
    import pandas as pd

    from .predict import summary_table

    frame = pd.DataFrame(rows)
    if "low" not in frame:
        frame["low"] = frame["high"] = frame["predicted"]
    table = summary_table(frame)
    figs = {"Estimated size per segment and its interval, by recording":
            _predict_figure(frame, out / "estimates.png")}
    lines = ["# gearshot report: fault-size estimates", "", f"From `{source.name}`: "
             f"{len(frame)} SA segments of {frame['recording'].nunique()} recording(s). "
             "Role: what a segment was to the fit (healthy_fitted and example were fitted "
             "on; healthy_holdout, faulty_rest and test were not).", ""]
    if "comparable" in frame:
        lines += [f"Comparable segments: {int(frame['comparable'].astype(bool).sum())} of "
                  f"{len(frame)}.", ""]
    lines += _md_table(table)
    for caption, fig in figs.items():
        lines += [f"## {caption}", "", f"![{caption}]({fig.name})", ""]
    target = out / "report.md"
    write_text_atomic(target, "\n".join(lines), make_parents=True)
    return target


def _predict_figure(frame, path: Path) -> Path:
    from matplotlib.figure import Figure

    from .._atomic import atomic_path

    names = list(dict.fromkeys(frame["recording"]))
    fig = Figure(figsize=(7, 1.4 + 0.35 * len(names)), layout="constrained")
    ax = fig.subplots()
    roles = list(dict.fromkeys(frame["role"])) if "role" in frame else [None]
    for k, role in enumerate(roles):
        part = frame if role is None else frame[frame["role"] == role]
        y = [names.index(r) + 0.12 * (k - (len(roles) - 1) / 2) for r in part["recording"]]
        ax.errorbar(part["predicted"], y,
                    xerr=[part["predicted"] - part["low"], part["high"] - part["predicted"]],
                    fmt="o", ms=3, lw=0.6, color=f"C{k}", label=role)
    ax.set_yticks(range(len(names)), [Path(n).name for n in names], fontsize=7)
    ax.set_xlim(-0.02, 1.02)
    ax.set_xlabel("estimated fault size y (0 healthy ... 1), bars: prediction interval")
    if roles != [None]:
        ax.legend(fontsize=7, title="role", title_fontsize=7, loc="lower right")
    with atomic_path(path, make_parents=True) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    return path


def _indicators_report(payload, out: Path, *, source: Path) -> Path:
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

        lines += ["## Indicator ranking (AUC, healthy vs faulty)", ""]
        lines += _md_table(pd.DataFrame(payload["ranking"]), "{:.2f}")
    for p in paths:
        lines += [f"## {p.stem}", "", f"![{p.stem}]({p.name})", ""]
    target = out / "report.md"
    write_text_atomic(target, "\n".join(lines), make_parents=True)
    return target
