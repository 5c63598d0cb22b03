"""The family's results file (JSON lines) and its summary tables."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from .._errors import GearshotError

__all__ = ["read_family_results", "family_tables", "format_family_tables"]


def read_family_results(results) -> pd.DataFrame:
    """All rows of a family results file (JSON lines); empty frame when absent."""
    results = Path(results)
    if not results.exists():
        return pd.DataFrame()
    rows = []
    with open(results) as fh:
        for line in fh:
            line = line.strip()
            if line:
                try:
                    rows.append(json.loads(line))
                except json.JSONDecodeError:  # a line cut by an interrupted run
                    continue
    return pd.DataFrame(rows)



def format_family_tables(frame: pd.DataFrame, *, rigs_table: bool = False) -> str:
    """The family's tables as text (what the benchmark and the CLI print)."""
    tables = family_tables(frame)
    with pd.option_context("display.width", 200, "display.max_columns", 50):
        parts = ["MAE % by condition (speed/load), rig mean over draws; p90/max over rigs:",
                 tables["condition"].to_string(), "", "MAE % by path type:",
                 tables["kind"].to_string(), "", "MAE % by the rig's true grade:",
                 tables["grade"].to_string(), "", "MAE % by path attenuation:",
                 tables["attenuation"].to_string(), "", "90 % interval coverage %:",
                 tables["coverage"].to_string()]
        if "check" in tables:
            parts += ["", "The fits' own check (passed / refused: MAE % of each; the passed "
                      "fits' 90 % coverage % and width):", tables["check"].to_string()]
        full = frame[frame["variant"] == "full"]
        if not full.empty:
            parts += ["", f"full: fit+predict median {full['seconds'].median():.2f} s per "
                      f"dataset; recording "
                      f"{full.groupby('seed')['record_seconds'].first().median():.1f} s per "
                      f"rig (median, first run)"]
        if rigs_table:
            rigs = tables["rigs"].pivot_table(
                index=["seed", "condition", "kind", "path", "grade", "attenuation_db"],
                columns="variant", values="mae")
            parts += ["", rigs.round(1).to_string()]
    return "\n".join(parts)



# ------------------------------------------------------------------ tables
def family_tables(frame: pd.DataFrame) -> dict:
    """Summary tables of family results (MAE and coverage in %).

    Returns
    -------
    dict of pandas.DataFrame
        ``condition`` (variant × condition MAE, plus mean, rig-level p90 and max),
        ``kind`` (variant × path type), ``grade`` (× true-grade band), ``attenuation``
        (× path-attenuation band), ``coverage`` (90 % intervals, by condition),
        ``rigs`` (per-rig MAE of each variant, mean over draws).
    """
    if frame.empty:
        raise GearshotError("no family results to summarize")
    f = frame.copy()
    f["condition"] = [f"{s:g}/{ld:g}" for s, ld in zip(f["speed"], f["load"])]
    rigs = (f.groupby(["variant", "seed", "condition", "kind", "path", "grade",
                       "attenuation_db"])["mae"].mean().mul(100).reset_index())
    cond = rigs.pivot_table(index="variant", columns="condition", values="mae",
                            aggfunc="mean")
    cond["mean"] = rigs.groupby("variant")["mae"].mean()
    cond["p90 rigs"] = rigs.groupby("variant")["mae"].quantile(0.9)
    cond["max rig"] = rigs.groupby("variant")["mae"].max()
    cond["n rigs"] = rigs.groupby("variant")["seed"].nunique()
    kind = rigs.pivot_table(index="variant", columns="kind", values="mae", aggfunc="mean")
    rigs["grades"] = pd.cut(rigs["grade"], [0, 3, 6, 9, 12],
                            labels=["1-3", "4-6", "7-9", "10-12"]).astype(str)
    rigs["attenuation"] = pd.cut(rigs["attenuation_db"], [0, 17, 24, 99],
                                 labels=["<17 dB", "17-24 dB", ">24 dB"]).astype(str)
    grade = rigs.pivot_table(index="variant", columns="grades", values="mae", aggfunc="mean")
    att = rigs.pivot_table(index="variant", columns="attenuation", values="mae",
                           aggfunc="mean")
    cov = f.pivot_table(index="variant", columns="condition", values="coverage",
                        aggfunc="mean").mul(100)
    cov["pooled"] = f.groupby("variant").apply(
        lambda g: np.average(g["coverage"], weights=g["n_test"])).mul(100)
    out = {"condition": cond.round(2), "kind": kind.round(2), "grade": grade.round(2),
           "attenuation": att.round(2), "coverage": cov.round(1), "rigs": rigs}
    if "fit_check" in f and not f["fit_check"].astype(str).str.startswith("unchecked").all():
        out["check"] = _check_table(f)
    return out


def _check_table(f: pd.DataFrame) -> pd.DataFrame:
    """Per variant, the fits that passed their own check against those that refused
    themselves: how many, their MAE %, and the passed fits' coverage % and width."""
    passed = f["fit_check"].astype(str) == "passed"
    rows = {}
    for variant, g in f.groupby("variant"):
        ok = passed.loc[g.index]
        yes, no = g[ok], g[~ok]
        rows[variant] = {
            "fits": len(g), "passed %": 100.0 * ok.mean(),
            "MAE passed": 100.0 * yes["mae"].mean() if len(yes) else np.nan,
            "MAE refused": 100.0 * no["mae"].mean() if len(no) else np.nan,
            "coverage passed": 100.0 * np.average(yes["coverage"], weights=yes["n_test"])
            if len(yes) else np.nan,
            "width passed": yes["width"].mean() if len(yes) else np.nan}
    return pd.DataFrame.from_dict(rows, orient="index").round(3)

