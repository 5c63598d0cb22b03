"""Condition indicators of real recordings, shaft by shaft, through a machine description."""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .._atomic import atomic_path
from .._errors import GearshotError
from .._validation import check_speed

__all__ = ["shaft_indicators", "record_indicators", "indicator_table", "indicator_figures",
           "format_indicators", "indicator_units", "check_speed_hints",
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
    from ..features import CONDITION_INDICATORS, extract_features

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
    feats = CONDITION_INDICATORS
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


#: Units of every indicator: the RMS values are in the sensor's physical unit (``{unit}``),
#: the rest are ratios or moments without a unit.
_UNIT_OF = {"rms_diff": "{unit}", "rms_env_diff": "{unit}", "rms_raw": "{unit}",
            "rms_residual": "{unit}"}


def indicator_units(machine, sensor: str) -> dict[str, str]:
    """{indicator: unit} for one sensor (``"g"`` for the RMS values of a 10 mV/g
    accelerometer, ``"1"`` for the dimensionless ones)."""
    from ..features import CONDITION_INDICATORS

    unit = machine.sensor(sensor).unit
    return {f: _UNIT_OF.get(f, "1").format(unit=unit)
            for f in (*CONDITION_INDICATORS, *INDICATOR_EXTRAS)}


def record_indicators(paths: Sequence[str | Path], machine, *, shaft: str,
                      sensors: Sequence[str] | str | None = None,
                      baseline_paths: Sequence[str | Path] = (),
                      machine_file: str | Path | None = None, sensor: str | None = None,
                      speed_hints: Mapping[str, float] | None = None,
                      errors: str = "raise") -> dict[str, Any]:
    """The ``gearshot indicators`` payload for recording files.

    Parameters
    ----------
    paths : sequence of path
        Recording files.
    machine : gearshot.Machine
    shaft : str
        The shaft whose revolution is the SA cycle.
    sensors : sequence of str, optional
        Default: every sensor of the machine (``sensor``, one name, is kept for callers
        of old).
    baseline_paths : sequence of path
        Healthy recordings: NA4's baseline variance, per sensor.
    machine_file : path, optional
        Recorded in the payload.
    speed_hints : mapping of str to float, optional
        Nominal speed (Hz) of the machine's reference shaft per file (``str(path)``), for
        records without a tacho: the speed is searched within ±10 % of it (before the
        machine file's ``[speed] range_hz``). A machine with a tacho takes none.
    errors : {"raise", "collect"}
        A file that cannot be read or analysed (no tacho, unreadable, too short): raise its
        :class:`~gearshot.GearshotError` (default), or ``"collect"`` it -- one
        ``{"file", "error"}`` entry in the payload's ``"failures"`` -- and go on with the
        other files (a batch).

    Returns
    -------
    dict
        ``{"kind": "indicators", "machine", "machine_file", "shaft", "tacho_shaft",
        "shaft_speed_ratio", "units", "records": [...]}``; one record per file and
        sensor: ``{"file", "sensor", "tacho_speed_hz", "shaft_speed_hz", "speed_source",
        "speed_uncertainty_hz", "n_cycles", "indicators", "input_check"}``;
        ``input_check`` is ``"ok"`` or the failed check of
        :mod:`gearshot.io.input_health` (a dead, constant, clipped or implausible
        channel), whose ``indicators`` are then all null and ``n_cycles`` null.
        ``tacho_speed_hz`` is the mean
        speed of the machine's reference (tacho) shaft, read from the tacho
        (``speed_source="tacho"``) or, for a machine without ``[tacho]``, estimated from the
        vibration (``"vibration"``, with the standard uncertainty of the instantaneous
        speed, rev/s; ``null`` with a tacho); ``shaft_speed_hz`` that of ``shaft`` (through
        the gear train). With ``errors="collect"``, also ``"failures"``.
    """
    from ..io import Recording
    from ..machine.signal_check import verify_machine

    machine.check_shaft(shaft, "--shaft")
    if errors not in ("raise", "collect"):
        raise GearshotError(f"errors must be 'raise' or 'collect'; got {errors!r}")
    hints = check_speed_hints(speed_hints, machine)
    if isinstance(sensors, str):
        sensors = [sensors]
    names = [machine.sensor(s).name for s in
             (sensors or ([sensor] if sensor else [s.name for s in machine.sensors]))]
    ratio = float(machine.speed_ratio(shaft))
    failures: list[dict[str, str]] = []

    def attempt(path, work):
        """``work()``, or None with the failure collected (``errors="collect"``)."""
        try:
            return work()
        except GearshotError as exc:
            if errors == "raise":
                raise
            failures.append({"file": str(path), "error": " ".join(str(exc).split())})
            return None

    reads = {str(p): attempt(p, lambda p=p: _read(p, machine, names, hints.get(str(p))))
             for p in paths}
    good = [r for r in reads.values() if r is not None]
    # the machine file must put its mesh orders where the recordings have them (the
    # healthy baseline recordings where given)
    base_recs = [Recording.read(p, machine=machine) for p in baseline_paths]
    if base_recs or good:
        verify_machine(machine, base_recs or [rec for rec, _ in good])
    baselines = _baselines(base_recs, machine, shaft, names)
    records: list[dict[str, Any]] = []
    for path in paths:
        read = reads[str(path)]
        if read is not None:
            records += attempt(path, lambda p=path, r=read: _record_rows(
                p, machine, shaft, names, baselines, ratio, *r)) or []
    units = {n: indicator_units(machine, n) for n in names}
    payload = {"kind": "indicators", "machine": machine.name,
               "machine_file": None if machine_file is None else str(machine_file),
               "shaft": shaft, "tacho_shaft": machine.reference_shaft,
               "shaft_speed_ratio": ratio,
               "units": {"speeds": "Hz (revolutions per second)", "indicators": units},
               "records": records}
    if errors == "collect":
        payload["failures"] = failures
    return payload


def check_speed_hints(speed_hints: Mapping[str, float] | None, machine) -> dict[str, float]:
    """``speed_hints`` checked: speeds within the physical bounds, and none for a machine
    with a tacho (its speed is read, never searched)."""
    if not speed_hints:
        return {}
    if machine.tacho is not None:
        raise GearshotError(f"a speed hint is for records without a tacho; machine "
                            f"{machine.name!r} has one (its [tacho] gives the speed)")
    return {str(k): check_speed(v, f"speed hint of {str(k)!r}") for k, v in
            speed_hints.items()}


def _baselines(recs: Sequence[Any], machine, shaft: str,
               names: Sequence[str]) -> dict[str, float | None]:
    """NA4's baseline variance per sensor from healthy recordings (read with ``machine``;
    None without any)."""
    if not recs:
        return {n: None for n in names}
    return {n: baseline_variance(recs, machine, shaft=shaft, sensor=n) for n in names}


def _read(path: str | Path, machine, names: Sequence[str],
          hint: float | None = None) -> tuple[Any, dict]:
    """One file read with ``machine`` (``hint``: its speed hint, no tacho), the input
    checks of its sensors ``names`` and its speed (read or tracked now: a record whose
    speed cannot be found fails here, naming a failed sensor where that is why)."""
    from ..io import Recording
    from ..io._vibration import SPEED_HINT_KEY
    from ..io.input_health import check_input

    rec = Recording.read(path, machine=machine,
                         metadata=None if hint is None else {SPEED_HINT_KEY: hint})
    checks = {n: check_input(rec.channel(n).acceleration, units=machine.sensor(n).unit)
              for n in names}
    try:
        rec.shaft_speed()
    except GearshotError as exc:   # no tacho: the speed comes from a failed sensor?
        bad = [f"{n}: {c.failed} ({c.reason})" for n, c in checks.items() if not c.ok]
        if bad:
            raise GearshotError(f"{str(path)!r} fails the input check of "
                                f"{'; '.join(bad)}; {exc}") from None
        raise
    return rec, checks


def _record_rows(path: str | Path, machine, shaft: str, names: Sequence[str],
                 baselines: dict[str, float | None], ratio: float,
                 rec: Any, checks: dict) -> list[dict[str, Any]]:
    """The payload records of one file (``rec``, ``checks``: :func:`_read`'s): one per
    sensor."""
    from ..features import CONDITION_INDICATORS

    tacho = float(rec.shaft_speed())
    rows = []
    for name in names:
        if checks[name].ok:
            res = shaft_indicators(rec, machine, shaft=shaft, sensors=[name],
                                   baseline=baselines[name])[name]
        else:   # no indicator of a failed channel: null, with the check named
            res = {"n_cycles": None, "indicators": dict.fromkeys(
                (*CONDITION_INDICATORS, *INDICATOR_EXTRAS))}
        rows.append({"file": Path(path).name, "sensor": name,
                     "tacho_speed_hz": tacho, "shaft_speed_hz": tacho * ratio,
                     "speed_source": rec.speed_source,
                     "speed_uncertainty_hz": rec.speed_uncertainty,
                     "n_cycles": res["n_cycles"], "indicators": res["indicators"],
                     "input_check": checks[name].label})
    return rows


def _case_of(file_name: str) -> tuple[str, str]:
    """(case, condition) from a file name such as ``spur2_30hz_High_1.zip``."""
    stem = re.sub(r"(\.[A-Za-z0-9]+)+$", "", file_name)
    case, _, rest = stem.partition("_")
    return case, rest


def format_indicators(payload: dict[str, Any]) -> str:
    """The payload as the aligned text table ``gearshot indicators`` prints (one row per
    record and sensor; plain Python, so that a one-record call does not import pandas)."""
    head = ["file", "sensor", "tacho_hz", "shaft_hz", "n_cycles", "input_check"]
    rows = []
    for r in payload["records"]:
        rows.append([r["file"], r.get("sensor", ""), f"{r['tacho_speed_hz']:.4g}",
                     f"{r['shaft_speed_hz']:.4g}", str(r["n_cycles"]),
                     r.get("input_check", "ok")]
                    + ["null" if v is None else f"{v:.4g}" for v in r["indicators"].values()])
    if payload["records"]:
        head += list(payload["records"][0]["indicators"])
    widths = [max(len(str(c)) for c in col) for col in zip(head, *rows)]
    lines = [" ".join(str(c).rjust(w) for c, w in zip(line, widths)) for line in [head, *rows]]
    return "\n".join(lines)


def indicator_table(payload: dict[str, Any]):
    """The payload as a pandas DataFrame: one row per record, one column per indicator."""
    import pandas as pd

    rows = []
    for r in payload["records"]:
        case, cond = _case_of(r["file"])
        extra = {k: r[k] for k in ("speed_source", "speed_uncertainty_hz", "input_check")
                 if k in r}
        rows.append({"file": r["file"], "case": case, "condition": cond,
                     "sensor": r.get("sensor", ""),
                     "tacho_speed_hz": r.get("tacho_speed_hz", r.get("speed_hz")),
                     "shaft_speed_hz": r.get("shaft_speed_hz", r.get("speed_hz")),
                     **extra, "n_cycles": r["n_cycles"], **r["indicators"]})
    return pd.DataFrame(rows)


_META = ("file", "case", "condition", "sensor", "tacho_speed_hz", "shaft_speed_hz",
         "speed_source", "speed_uncertainty_hz",
         "n_cycles", "input_check")


def indicator_figures(payload: dict[str, Any], folder: str | Path, *,
                      title: str = "", labels: dict[str, str] | None = None) -> list[Path]:
    """One figure per indicator (``<name>.png``): value against the tacho-shaft speed, one
    panel per sensor, one colour per label (``labels``: {file name: label}, as
    ``--labels`` gives them) or, without labels, per case (the file-name prefix before the
    first ``_``), one marker per remaining condition; the unit on the axis. Written
    atomically."""
    from matplotlib.figure import Figure

    table = indicator_table(payload)
    if labels:
        table["case"] = [f"label {labels.get(Path(f).name, '?')}" for f in table["file"]]
    units = payload.get("units", {}).get("indicators", {})
    folder = Path(folder)
    cols = [c for c in table.columns if c not in _META]
    cases = sorted(table["case"].unique())
    sensors = list(dict.fromkeys(table["sensor"]))
    conds = sorted({re.sub(r"^\d+hz_?", "", c, flags=re.I) for c in table["condition"]})
    markers = "osD^v<>pP*X"
    paths = []
    for col in cols:
        source = (table["speed_source"].iloc[0] if "speed_source" in table.columns
                  and table["speed_source"].nunique() == 1 else "tacho")
        fig = Figure(figsize=(4.2 * len(sensors) + 1.3, 3.8), layout="constrained")
        axes = fig.subplots(1, len(sensors), squeeze=False)[0]
        for ax, sensor in zip(axes, sensors):
            sub_s = table[table["sensor"] == sensor]
            for ci, case in enumerate(cases):
                for _, row in sub_s[sub_s["case"] == case].iterrows():
                    cond = re.sub(r"^\d+hz_?", "", row["condition"], flags=re.I)
                    ax.plot(row["tacho_speed_hz"], row[col],
                            markers[conds.index(cond) % len(markers)],
                            color=f"C{ci % 10}", ms=6)
            unit = units.get(sensor, {}).get(col, "")
            ax.set_xlabel("tacho-shaft speed (Hz), read from the tacho" if source == "tacho"
                          else "reference-shaft speed (Hz), estimated from the vibration")
            ax.set_ylabel(f"{col} [{unit}]" if unit and unit != "1" else f"{col} (ratio)")
            ax.set_title(f"sensor {sensor}" if sensor else "", fontsize=9)
        handles = [axes[0].plot([], [], "o", color=f"C{ci % 10}", label=case)[0]
                   for ci, case in enumerate(cases)]
        handles += [axes[0].plot([], [], markers[k % len(markers)], color="0.4",
                                 label=cond)[0] for k, cond in enumerate(conds) if cond]
        fig.legend(handles=handles, loc="outside right upper", fontsize=7)
        fig.suptitle(f"{title}: {col}".strip(": "), fontsize=10)
        path = folder / f"{col}.png"
        with atomic_path(path, make_parents=True) as tmp:
            fig.savefig(tmp, dpi=110, format="png")
        paths.append(path)
    return paths
