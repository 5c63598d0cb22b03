"""Condition indicators of real recordings, shaft by shaft, through a machine description."""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .._errors import GearshotError

__all__ = ["shaft_indicators", "record_indicators", "indicator_table", "indicator_figures",
           "baseline_variance", "INDICATOR_EXTRAS"]

#: Indicators added to every registered feature: RMS of the raw (mean-removed) time signal
#: and of the non-synchronous residual (angle-domain signal minus the tiled SA).
INDICATOR_EXTRAS = ("rms_raw", "rms_residual")


def _angle_and_sa(rec, machine, shaft: str, sensor):
    spc = machine.samples_per_cycle
    x = rec.angle_domain(shaft=shaft, sensor=sensor, samples_per_cycle=spc,
                         antialias=machine.antialias)
    n_cycles = x.shape[-1] // spc
    if n_cycles < 1:
        raise GearshotError(f"{rec.origin or 'recording'} holds no whole revolution of shaft "
                            f"{shaft!r}")
    blocks = x[..., : n_cycles * spc].reshape(*x.shape[:-1], n_cycles, spc)
    return blocks, blocks.mean(axis=-2), n_cycles


def baseline_variance(recordings: Sequence[Any], machine, *, shaft: str,
                      sensor: str | None = None) -> float:
    """NA4's healthy baseline: mean residual variance of the SAs of healthy recordings."""
    from ..features import na4_baseline_variance

    sas = []
    for rec in recordings:
        _, sa, _ = _angle_and_sa(rec, machine, shaft, machine.sensor(sensor).name)
        sas.append(sa)
    return na4_baseline_variance(np.stack(sas), list(machine.mesh_orders(shaft)),
                                 shaft_orders=machine.shaft_orders)


def shaft_indicators(rec, machine, *, shaft: str, sensors: Sequence[str] | None = None,
                     baseline: float | None = None) -> dict[str, dict[str, Any]]:
    """Every indicator of one shaft for several sensors of one recording.

    Parameters
    ----------
    rec : gearshot.io.Recording
        Read with ``machine`` (multi-channel).
    machine : gearshot.Machine
    shaft : str
        The shaft whose revolution is the SA cycle; its mesh orders are all removed.
    sensors : sequence of str, optional
        Default: every sensor of the machine.
    baseline : float, optional
        Healthy residual variance for NA4 (:func:`baseline_variance`).

    Returns
    -------
    dict
        sensor name -> ``{"n_cycles": int, "indicators": {name: float}}``.
    """
    from ..features import available_features, extract_features

    machine.check_shaft(shaft, "--shaft")
    names = [machine.sensor(s).name for s in (sensors or [s.name for s in machine.sensors])]
    idx = [rec.channel_names.index(n) for n in names]
    acc = rec.acceleration if rec.acceleration.ndim == 2 else rec.acceleration[None]
    raw = acc[idx]
    if len(names) == 1:
        blocks, sa, n_cycles = _angle_and_sa(rec, machine, shaft, names[0])
        blocks, sa = blocks[None], sa[None]
    else:
        blocks, sa, n_cycles = _angle_and_sa(rec, machine, shaft, None)
        if blocks.ndim == 2:
            blocks, sa = blocks[None], sa[None]
        blocks, sa = blocks[idx], sa[idx]
    feats = available_features()
    values = extract_features(sa, list(machine.mesh_orders(shaft)), names=feats,
                              n_sidebands=machine.n_sidebands, baseline_variance=baseline,
                              shaft_orders=machine.shaft_orders)
    centred = raw - raw.mean(axis=-1, keepdims=True)
    rms_raw = np.sqrt(np.mean(centred ** 2, axis=-1))
    resid = blocks - sa[:, None, :]
    rms_res = np.sqrt(np.mean(resid ** 2, axis=(-2, -1)))
    out = {}
    for i, name in enumerate(names):
        ind = {f: float(values[i, j]) for j, f in enumerate(feats)}
        ind["rms_raw"] = float(rms_raw[i])
        ind["rms_residual"] = float(rms_res[i])
        out[name] = {"n_cycles": int(n_cycles), "indicators": ind}
    return out


def record_indicators(paths: Sequence[str | Path], machine, *, shaft: str,
                      sensor: str | None = None, baseline_paths: Sequence[str | Path] = ()
                      ) -> dict[str, Any]:
    """The ``gearshot indicators`` payload for recording files.

    Returns
    -------
    dict
        ``{"records": [{"file", "speed_hz", "speed_source", "speed_uncertainty_hz",
        "n_cycles", "indicators"}, ...]}``; ``speed_hz`` is the mean speed of the tacho
        shaft, read from the tacho (``speed_source="tacho"``) or, for a machine without
        ``[tacho]``, estimated from the vibration (``"vibration"``, with the standard
        uncertainty of the instantaneous speed, rev/s; ``null`` with a tacho).
    """
    from ..io import Recording

    machine.check_shaft(shaft, "--shaft")
    name = machine.sensor(sensor).name
    baseline = None
    if baseline_paths:
        recs = [Recording.read(p, machine=machine) for p in baseline_paths]
        baseline = baseline_variance(recs, machine, shaft=shaft, sensor=name)
    records = []
    for path in paths:
        rec = Recording.read(path, machine=machine)
        res = shaft_indicators(rec, machine, shaft=shaft, sensors=[name],
                               baseline=baseline)[name]
        records.append({"file": Path(path).name, "speed_hz": float(rec.shaft_speed()),
                        "speed_source": rec.speed_source,
                        "speed_uncertainty_hz": rec.speed_uncertainty,
                        "n_cycles": res["n_cycles"], "indicators": res["indicators"]})
    return {"records": records}


def _case_of(file_name: str) -> tuple[str, str]:
    """(case, condition) from a file name such as ``spur2_30hz_High_1.zip``."""
    stem = re.sub(r"(\.[A-Za-z0-9]+)+$", "", file_name)
    case, _, rest = stem.partition("_")
    return case, rest


def indicator_table(payload: dict[str, Any]):
    """The payload as a pandas DataFrame: one row per record, one column per indicator."""
    import pandas as pd

    rows = []
    for r in payload["records"]:
        case, cond = _case_of(r["file"])
        extra = {k: r[k] for k in ("speed_source", "speed_uncertainty_hz") if k in r}
        rows.append({"file": r["file"], "case": case, "condition": cond,
                     "speed_hz": r["speed_hz"], **extra, "n_cycles": r["n_cycles"],
                     **r["indicators"]})
    return pd.DataFrame(rows)


def indicator_figures(payload: dict[str, Any], folder: str | Path, *,
                      title: str = "") -> list[Path]:
    """One figure per indicator: value against the measured speed, one colour per case
    (the file-name prefix before the first ``_``), one marker per remaining condition."""
    from matplotlib.figure import Figure

    table = indicator_table(payload)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    cols = [c for c in table.columns if c not in ("file", "case", "condition", "speed_hz",
                                                  "n_cycles", "speed_source",
                                                  "speed_uncertainty_hz")]
    cases = sorted(table["case"].unique())
    conds = sorted({re.sub(r"^\d+hz_?", "", c, flags=re.I) for c in table["condition"]})
    markers = "osD^v<>pP*X"
    paths = []
    for col in cols:
        fig = Figure(figsize=(5.5, 3.6))
        ax = fig.add_subplot()
        for ci, case in enumerate(cases):
            sub = table[table["case"] == case]
            for _, row in sub.iterrows():
                cond = re.sub(r"^\d+hz_?", "", row["condition"], flags=re.I)
                ax.plot(row["speed_hz"], row[col], markers[conds.index(cond) % len(markers)],
                        color=f"C{ci % 10}", ms=6)
            ax.plot([], [], "o", color=f"C{ci % 10}", label=case)
        for k, cond in enumerate(conds):
            if cond:
                ax.plot([], [], markers[k % len(markers)], color="0.4", label=cond)
        source = (table["speed_source"].iloc[0] if "speed_source" in table.columns
                  and table["speed_source"].nunique() == 1 else "tacho")
        ax.set_xlabel("tacho-shaft speed read from the tacho (Hz)" if source == "tacho"
                      else "shaft speed estimated from the vibration (Hz)")
        ax.set_ylabel(col)
        ax.set_title(f"{title} {col}".strip(), fontsize=9)
        ax.legend(fontsize=7, ncol=2)
        fig.tight_layout()
        path = folder / f"{col}.png"
        fig.savefig(path, dpi=110)
        paths.append(path)
    return paths
