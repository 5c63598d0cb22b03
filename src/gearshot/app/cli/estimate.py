"""The commands on a user's recordings: ``predict``, ``indicators`` and ``report``.

``indicators`` is the light path (issue #20: one record in ≤ 0.8 s as a whole process):
this module imports nothing heavy; each command imports what it needs when it runs.
"""

from __future__ import annotations

import json
from pathlib import Path

import typer

from ..._errors import GearshotError
from ._apps import app
from ._options import check_seed, early, only_with, refuse_together

__all__ = ["predict", "indicators", "report", "FAULTY_SIZE_HELP"]

FAULTY_SIZE_HELP = (
    "Declared size of the faulty recording's fault, in (0, 1], in the units of the "
    "database's fault type (--fault-type of gearshot simulate): ftff (default): width of "
    "the cut along the active profile / the active profile's width (1: the whole profile); "
    "partial_face: the cut band's width / the face width; breakage: lost tooth height / "
    "the height above the lowest contact point, the break spanning that share of the face "
    "(1: a missing tooth); destruction: the pitted band's width / the active profile's. "
    "An ordinal label (chipped, broken) has no size: give your best measure of it (the "
    "estimates are on the same scale).")
_HELP = {
    "database": "Simulated database store (gearshot simulate; with --machine, gearshot "
                "simulate --machine).",
    "healthy": "Healthy recordings of the machine: any number of files, folders or glob "
               "patterns after one --healthy.",
    "faulty": "The one faulty recording; its first segment is the example.",
    "recordings": "Recordings to estimate: any number of files, folders (their recording "
                  "files) or glob patterns after one --recordings.",
    "speed": "Database condition. With --machine: the tacho shaft's speed in Hz (default: "
             "the database speed nearest to the healthy recordings' tacho); without: the "
             "database's speed in rps (required).",
    "load": "Database load, N m (default: the database's only load; with --machine and a "
            "database over several loads, the one the healthy recordings pick, refused when "
            "ambiguous).",
    "out": "Output table, CSV or (by suffix .json) JSON; one row per SA segment with its "
           "role, estimate and interval.",
    "gear_teeth": "Without --machine: teeth of the monitored (faulty) gear, whose revolution "
                  "is the SA cycle (default: the database's gear pair; another count is "
                  "refused).",
    "pinion_teeth": "Without --machine: teeth of its pinion, whose speed is --speed "
                    "(default: the database's).",
    "seed": "Random state of the fit (splits, step 1's held-out TF).",
    "machine": "Machine description (TOML): SAs of the monitored gear's shaft through its "
               "gear train; speeds in tacho-shaft Hz.",
    "cycles": "With --machine: revolutions per SA segment (default: the machine's).",
    "sensor": ("With --machine: sensor name (default the first, or the next whose fit "
               "passes when the first cannot read its own example)."),
    "holdout": "Fraction of each healthy recording's segments (the last ones) kept out of "
               "the fit and estimated; with the example record's other segments they check "
               "the fit (the fit_check column: 'passed' or the reason) and calibrate the "
               "intervals.",
    "tolerance": "With --machine: largest relative distance between a recording's tacho "
                 "speed and the database condition (beyond it the recording is refused; "
                 "within it, a recording whose speed lies outside the fit's recordings' "
                 "speeds by more than their run-to-run spread, at least 0.3 %, is "
                 "estimated but not trusted: speed_check).",
    "speed_hint": "Nominal speed (Hz) of the machine's reference shaft for every record "
                  "without a tacho and without its own FILE@HZ: the speed is searched "
                  "within ±10 % of it (instead of the machine file's [speed] range_hz), so "
                  "that records at several nominal speeds need no machine file each.",
    "labels": "CSV with columns file, label (and optionally cell): rank the indicators by "
              "how well they separate healthy (label 0, healthy or good) from the other "
              "labels, AUC per cell and overall.",
}


@app.command()
def predict(
    ctx: typer.Context,
    database: Path = typer.Option(..., "--database", help=_HELP["database"]),
    healthy: list[str] = typer.Option(..., "--healthy", help=_HELP["healthy"]),
    faulty: Path = typer.Option(..., "--faulty", help=_HELP["faulty"]),
    faulty_size: float = typer.Option(..., "--faulty-size", help=FAULTY_SIZE_HELP),
    recordings: list[str] = typer.Option([], "--recordings", help=_HELP["recordings"]),
    speed: float | None = typer.Option(None, "--speed", help=_HELP["speed"]),
    load: float | None = typer.Option(None, "--load", help=_HELP["load"]),
    out: Path = typer.Option(Path("predictions.csv"), "--out", help=_HELP["out"]),
    coverage: float = typer.Option(0.9, "--coverage", help="Prediction-interval coverage."),
    gear_teeth: int | None = typer.Option(None, "--gear-teeth", help=_HELP["gear_teeth"]),
    pinion_teeth: int | None = typer.Option(None, "--pinion-teeth",
                                               help=_HELP["pinion_teeth"]),
    seed: int = typer.Option(0, "--seed", help=_HELP["seed"]),
    machine: Path | None = typer.Option(None, "--machine", help=_HELP["machine"]),
    cycles_per_segment: int | None = typer.Option(None, "--cycles-per-segment",
                                                     help=_HELP["cycles"]),
    sensor: str | None = typer.Option(None, "--sensor", help=_HELP["sensor"]),
    holdout: float = typer.Option(0.25, "--holdout", help=_HELP["holdout"]),
    speed_tolerance: float = typer.Option(0.05, "--speed-tolerance", help=_HELP["tolerance"]),
) -> None:
    """Fit from a database + healthy recordings + one faulty recording; estimate sizes."""
    for teeth in ("--gear-teeth", "--pinion-teeth"):
        refuse_together(ctx, "--machine", teeth, "the machine file gives the monitored "
                        "gear's teeth and its train")
    for option in ("--cycles-per-segment", "--sensor", "--speed-tolerance"):
        only_with(ctx, option, "--machine", "recordings without a machine file are the "
                  "paper rig's, one sensor, every segment estimated")
    if out.suffix.lower() not in (".csv", ".json"):
        raise GearshotError(f"--out {str(out)!r} must end in .csv or .json (the formats "
                            f"predict writes); got suffix {out.suffix!r}")
    check_seed(seed)
    from ..files import expand_recordings
    from ..predict import format_predictions, predict_recordings, write_predictions

    early(out, "--out")
    healthy_files = expand_recordings(healthy, "--healthy")
    if not 0 < speed_tolerance < 1:
        raise GearshotError(f"--speed-tolerance must lie in (0, 1); got {speed_tolerance!r}")
    frame, where = predict_recordings(
        database, healthy_files, faulty, faulty_size, recordings, machine=machine, speed=speed,
        load=load, coverage=coverage, gear_teeth=gear_teeth, pinion_teeth=pinion_teeth,
        seed=seed, cycles_per_segment=cycles_per_segment, sensor=sensor, holdout=holdout,
        speed_tolerance=speed_tolerance)
    write_predictions(frame, out)
    typer.echo(format_predictions(frame, where))
    typer.echo(f"predictions written to {out}")


@app.command()
def indicators(
    recordings: list[str] = typer.Argument(..., help="Recording files, folders or glob "
                                           "patterns (the original zips are fine); "
                                           "FILE@HZ gives a record without a tacho its "
                                           "nominal reference-shaft speed (a speed hint)."),
    machine: Path = typer.Option(..., "--machine", help="Machine description (TOML)."),
    shaft: str = typer.Option(..., "--shaft", help="Shaft whose revolution is the SA cycle."),
    sensor: list[str] = typer.Option([], "--sensor", help="Sensor name(s), repeat the "
                                     "option for several (default: every sensor of the "
                                     "machine file)."),
    json_out: Path | None = typer.Option(None, "--json", help="Write the indicators as JSON "
                                            "(machine, shaft, speeds, sensor, units)."),
    out: Path | None = typer.Option(None, "--out", help="Folder for one figure per "
                                       "indicator (and the ranking with --labels)."),
    baseline: list[str] = typer.Option([], "--baseline", help="Healthy recording(s): NA4 "
                                       "against their residual variance (files up to the "
                                       "next option)."),
    labels: Path | None = typer.Option(None, "--labels", help=_HELP["labels"]),
    speed_hint: float | None = typer.Option(None, "--speed-hint", help=_HELP["speed_hint"]),
) -> None:
    """Condition indicators of one shaft per recording and sensor (--labels: a ranking).

    A batch goes on past a record that fails (each failure one line); the others are
    written and the exit status is 2 at the end. The outputs (--json, --out) are written
    all or none.
    """
    from ...machine import Machine
    from ..files import expand_recordings
    from ..indicators import check_speed_hints, format_indicators, record_indicators

    mach = Machine.from_toml(machine)
    early(json_out, "--json")
    early(out, "--out", folder=True)
    files, hints = _with_speed_hints(recordings, speed_hint)
    check_speed_hints(hints, mach)
    base = expand_recordings(baseline, "--baseline")
    label_table = None
    if labels is not None:
        from ..ranking import read_labels

        label_table = read_labels(labels, [f.name for f in files])
    payload = record_indicators(files, mach, shaft=shaft, sensors=sensor or None,
                                baseline_paths=base, machine_file=machine, speed_hints=hints,
                                errors="collect")
    failures = payload.pop("failures")
    if len(files) == 1 and failures:     # one record: its error is the one line
        raise GearshotError(failures[0]["error"])
    for failure in failures:
        name = Path(failure["file"]).name
        text = failure["error"] if name in failure["error"] else f"{name}: {failure['error']}"
        typer.secho(f"gearshot: error: {text}", err=True, fg="red")
    if not payload["records"]:
        raise GearshotError(f"none of the {len(files)} recording(s) could be analysed "
                            f"(each failure above); nothing written")
    if failures:
        payload["failures"] = failures
    typer.echo(format_indicators(payload))
    _write_indicator_outputs(payload, label_table, json_out, out,
                             f"{mach.name}, shaft {shaft}")
    if failures:
        raise GearshotError(f"{len(failures)} of {len(files)} recording(s) failed (each "
                            f"above); the other {len(files) - len(failures)} written")


def _with_speed_hints(items: list[str], speed_hint: float | None
                      ) -> tuple[list[Path], dict[str, float]]:
    """The recording files of ``items`` and their speed hints: ``FILE@HZ`` (a path that
    does not exist as typed, ending in ``@`` and a number) gives its files HZ; the others
    get ``--speed-hint`` (when given)."""
    from ..files import expand_recordings

    files: list[Path] = []
    hints: dict[str, float] = {}
    for item in items:
        hint = speed_hint
        base, at, hz = item.rpartition("@")
        if at and base and not Path(item).exists():
            try:
                hint = float(hz)
            except ValueError:
                raise GearshotError(f"RECORDINGS {item!r}: the speed hint after '@' must be "
                                    f"a number (Hz); got {hz!r}") from None
            item = base
        for f in expand_recordings([item], "RECORDINGS"):
            if f not in files:
                files.append(f)
                if hint is not None:
                    hints[str(f)] = hint
    return files, hints


def _write_indicator_outputs(payload: dict, label_table, json_out: Path | None,
                             out: Path | None, title: str) -> None:
    """The ranking (with --labels), the JSON and the figures, all or none: every file is
    written into a temporary first (the figures into a staging folder inside ``out``) and
    moved into place only once all are written."""
    import contextlib

    from ..._atomic import atomic_path, commit_staged, staging_dir
    from ..indicators import indicator_figures

    with contextlib.ExitStack() as stack:
        staged = None if out is None else stack.enter_context(staging_dir(out))
        if label_table is not None:
            _ranking(payload, label_table, staged, title)
        names = [] if staged is None else [
            p.name for p in indicator_figures(payload, staged, title=title)]
        if staged is not None and label_table is not None:
            names += ["ranking.csv", "ranking.png"]
        if json_out is not None:   # its rename, the last step, happens when the stack ends
            tmp = stack.enter_context(atomic_path(json_out, make_parents=True))
            tmp.write_text(json.dumps(payload, indent=2, default=float))
        if staged is not None and out is not None:
            commit_staged(staged, out, names)
    if json_out is not None:
        typer.echo(f"indicators written to {json_out}")
    if out is not None:
        indicator_figures(payload, out, title=title, labels=None if label_table is None
                          else dict(zip(label_table["file"], label_table["label"])))
        typer.echo(f"figures written to {out}")


def _ranking(payload: dict, label_table, out: Path | None, title: str) -> None:
    """``indicators --labels``: print the ranking, add it to the payload, and write its
    table and figure into ``out``."""
    from ..._atomic import atomic_path
    from ..ranking import format_ranking, indicator_ranking, ranking_figure

    ranking = indicator_ranking(payload, label_table)
    payload["ranking"] = json.loads(ranking.to_json(orient="records"))
    payload["ranking_cells"] = {cell: {"healthy": h, "faulty": f}
                                for cell, (h, f) in ranking.attrs.get("cells", {}).items()}
    typer.echo(format_ranking(ranking))
    if out is not None:
        with atomic_path(out / "ranking.csv", make_parents=True) as tmp:
            ranking.to_csv(tmp, index=False)
        ranking_figure(ranking, out / "ranking.png", title=title)


@app.command()
def report(
    results: Path = typer.Argument(..., help="An output of gearshot: predict --out X.csv "
                                   "or X.json, demo's results.json or ablations.csv, "
                                   "experiment/rig-family/indicators --json."),
    out: Path = typer.Option(Path("gearshot-report"), "--out", help="Folder for the "
                             "figures, report.md and report.html."),
) -> None:
    """Figures, report.md and a self-contained report.html from any output gearshot
    writes (JSON or CSV)."""
    if not results.is_file():
        raise GearshotError(f"results file {str(results)!r} does not exist")
    early(out, "--out", folder=True)
    from ..report import report_from_any_json

    path = report_from_any_json(results, out)
    typer.echo(f"report: {path}")
