"""The commands that watch a machine over time: ``fit`` (a model file) and ``monitor``."""

from __future__ import annotations

from pathlib import Path

import typer

from ..._errors import GearshotError
from ._apps import app
from ._options import check_seed, early, write_json
from .estimate import _HELP, FAULTY_SIZE_HELP

__all__ = ["fit", "monitor"]

_MODEL_HELP = ("Model file to write (skops): the fitted estimator, the machine file, the "
               "database identity, the fit check and the healthy baseline.")


@app.command()
def fit(
    database: Path = typer.Option(..., "--database", help=_HELP["database"]),
    healthy: list[str] = typer.Option(..., "--healthy", help=_HELP["healthy"] + " At least "
                                      "two: the last quarter (at least one; with --machine, "
                                      "the last quarter of each one's segments) is kept out "
                                      "of the fit as the alarm's healthy baseline."),
    model: Path = typer.Option(..., "--model", help=_MODEL_HELP),
    faulty: Path | None = typer.Option(None, "--faulty", help="The one faulty recording "
                                          "(e.g. a recording of the history whose size an "
                                          "inspection measured). Without it: zero-shot."),
    faulty_size: float | None = typer.Option(None, "--faulty-size", help=FAULTY_SIZE_HELP),
    speed: float | None = typer.Option(None, "--speed", help=_HELP["speed"]),
    load: float | None = typer.Option(None, "--load", help=_HELP["load"]),
    coverage: float = typer.Option(0.9, "--coverage", help="Prediction-interval coverage."),
    gear_teeth: int | None = typer.Option(None, "--gear-teeth", help=_HELP["gear_teeth"]),
    pinion_teeth: int | None = typer.Option(None, "--pinion-teeth",
                                               help=_HELP["pinion_teeth"]),
    seed: int = typer.Option(0, "--seed", help=_HELP["seed"]),
    machine: Path | None = typer.Option(None, "--machine", help=_HELP["machine"]),
    cycles_per_segment: int | None = typer.Option(None, "--cycles-per-segment",
                                                     help=_HELP["cycles"]),
    sensor: str | None = typer.Option(None, "--sensor", help=_HELP["sensor"]),
    speed_tolerance: float = typer.Option(0.05, "--speed-tolerance", help=_HELP["tolerance"]),
    false_alarm_rate: float | None = typer.Option(
        None, "--false-alarm-rate", help="Probability that a healthy recording exceeds the "
        "alarm threshold, in (0, 0.5) (default 0.02: gearshot.monitor.FALSE_ALARM_RATE)."),
    sustain: int | None = typer.Option(
        None, "--sustain", help="Consecutive trusted recordings over the threshold that "
        "raise the alarm (and under it that clear it), at least 1 (default 2)."),
) -> None:
    """Fit once and write a model file for gearshot monitor (zero-shot without --faulty)."""
    check_seed(seed)
    if model.suffix.lower() != ".skops":
        raise GearshotError(f"--model {str(model)!r} must end in .skops; got suffix "
                            f"{model.suffix!r}")
    if not 0 < speed_tolerance < 1:
        raise GearshotError(f"--speed-tolerance must lie in (0, 1); got {speed_tolerance!r}")
    from ..files import expand_recordings
    from ..monitor import fit_model

    early(model, "--model")
    healthy_files = expand_recordings(healthy, "--healthy")
    result = fit_model(database, healthy_files, faulty, faulty_size, model=model,
                       machine=machine, speed=speed, load=load, coverage=coverage,
                       gear_teeth=gear_teeth, pinion_teeth=pinion_teeth, seed=seed,
                       cycles_per_segment=cycles_per_segment, sensor=sensor,
                       speed_tolerance=speed_tolerance, false_alarm_rate=false_alarm_rate,
                       sustain=sustain)
    from ...monitor.trust import model_warning

    typer.echo(result.describe())
    if result.extras.get("sensor_note"):
        typer.echo(result.extras["sensor_note"])
    warning = model_warning(result)
    if warning:
        typer.echo(f"warning: {warning}")
    if result.calibration == "zero_shot":
        typer.echo("zero-shot: no faulty example; refit with --faulty/--faulty-size when an "
                   "inspection measures a size")
    typer.echo(f"model written to {model} (digest {result.digest})")


@app.command()
def monitor(
    model: list[Path] = typer.Option(..., "--model", help="Model file(s) (gearshot fit "
                                     "--model): one, or one per --index."),
    index: list[Path] = typer.Option(..., "--index", help="CSV of recordings: columns file "
                                     "(or path) and time (ISO 8601), optional speed, load; "
                                     "or a folder (its index.csv, else its recordings) or a "
                                     "quoted glob, times from the file names or time stamps. "
                                     "Repeat with --history for several machines."),
    history: list[Path] = typer.Option(..., "--history", help="Parquet history of the "
                                       "estimates (created; one per --index)."),
    json_out: Path | None = typer.Option(None, "--json", help="Write records, alarm and "
                                            "forecast as JSON."),
    out: Path | None = typer.Option(None, "--out", help="Folder for the trend figure and "
                                       "the records as CSV."),
    limit: float = typer.Option(0.6, "--limit", help="Fault size whose crossing is "
                                "forecast."),
    scheduler: str | None = typer.Option(None, "--scheduler", help="Address of a running "
                                            "Dask scheduler (estimates spread over its "
                                            "workers)."),
    workers: int = typer.Option(1, "--workers", help="LocalCluster workers when no "
                                "--scheduler is given (1: in-process)."),
) -> None:
    """Estimate the new recordings of an index, append them to the history, alarm and
    forecast."""
    if len(index) != len(history):
        raise GearshotError(f"give one --history per --index; got {len(index)} --index and "
                            f"{len(history)} --history")
    if len(model) not in (1, len(index)):
        raise GearshotError(f"give one --model, or one per --index; got {len(model)} for "
                            f"{len(index)} --index")
    if len(index) > 1 and (json_out is not None or out is not None):
        raise GearshotError("--json and --out take one machine; with several --index, run "
                            "gearshot monitor once more per machine for its outputs")
    if not 0 < limit <= 1:
        raise GearshotError(f"--limit must lie in (0, 1]; got {limit!r}")
    early(json_out, "--json")
    early(out, "--out", folder=True)
    for h in history:
        early(h, "--history")
    from ..monitor import monitor_fleet, write_monitor_outputs
    from ..monitor_report import format_monitor

    models = model * len(index) if len(model) == 1 else model
    payloads = monitor_fleet(list(zip(models, index, history, strict=True)), limit=limit,
                             scheduler=scheduler, workers=workers)
    for i, payload in enumerate(payloads):
        if len(payloads) > 1:
            typer.echo(f"== {index[i]}")
        typer.echo(format_monitor(payload))
    if json_out is not None:
        write_json(json_out, payloads[0])
        typer.echo(f"monitor results written to {json_out}")
    if out is not None:
        write_monitor_outputs(payloads[0], out=out)
        typer.echo(f"trend figure written to {out / 'trend.png'}")
