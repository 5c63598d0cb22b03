"""The ``gearshot`` command line."""

from __future__ import annotations

import hashlib
import json
import os
import sys
from pathlib import Path
from typing import Any

import typer

from .. import __version__
from .._atomic import atomic_path, check_writable, os_error_text, write_json_atomic
from .._errors import GearshotError
from .._validation import check_load, check_speed
from ..fault_registry import FAULT_TYPE_NAMES
from ..paper import (
    CYCLES_PER_SEGMENT,
    GEAR_TEETH,
    PAPER_LOADS,
    PAPER_SPEEDS,
    PINION_TEETH,
    TABLE1_SIZES,
)

app = typer.Typer(
    name="gearshot",
    help="One-fault-shot gear tooth-fault size estimation (Matania et al., 2023).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
experiment_app = typer.Typer(help="Run the paper's experiments (Sec. 4.1 and 4.2).",
                             no_args_is_help=True)
app.add_typer(experiment_app, name="experiment")

HELP_N_HEALTHY = "Simulated healthy signals per grade and condition."
HELP_N_FAULTY = ("Simulated faulty signals per grade and condition (sizes drawn uniformly "
                 "in (0, 1]).")
HELP_SCHEDULER = "Address of a running Dask scheduler (default: a LocalCluster of --workers)."
HELP_WORKERS = "LocalCluster workers when no --scheduler is given."


def _version_callback(value: bool) -> None:
    if value:
        typer.echo(f"gearshot {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(False, "--version", callback=_version_callback,
                                 is_eager=True, help="Print the version and exit."),
) -> None:
    """One-fault-shot gear tooth-fault size estimation."""


def _client(scheduler: str | None, workers: int, *, needed: bool):
    """A Dask client: the given scheduler, a LocalCluster when useful, or None."""
    if scheduler:
        from dask.distributed import Client

        try:
            return Client(scheduler, timeout="10s")
        except Exception as exc:
            raise GearshotError(f"cannot reach the Dask scheduler at --scheduler "
                                f"{scheduler!r}: {exc}") from None
    if needed and workers > 1:
        from dask.distributed import Client, LocalCluster

        return Client(LocalCluster(n_workers=workers, threads_per_worker=1,
                                   dashboard_address=":0"))
    return None


def _write_json(path: Path | None, payload: dict) -> None:
    if path is None:
        return
    write_json_atomic(payload, path, make_parents=True, indent=2, sort_keys=False,
                      default=float)


def _early(path: Path | None, option: str, *, folder: bool = False) -> None:
    """Fail now, before the long work, if an output cannot be written."""
    if path is not None:
        check_writable(path, option, folder=folder)


#: Gear revolutions averaged per SA segment by the experiments and ``predict`` (the paper's 50)
SEGMENT_REVOLUTIONS = CYCLES_PER_SEGMENT
MAX_DURATION = 1200.0   # s per recording (60 s in the paper)
MAX_COUNT = 10_000      # recordings per campaign size / simulated signals are bounded below


def _check_duration(duration: float, speed: float, *, option: str = "--duration",
                    gear_teeth: int = GEAR_TEETH,
                    pinion_teeth: int = PINION_TEETH) -> None:
    """A recording must hold one SA segment (50 gear revolutions) at this speed."""
    check_speed(speed, "--speed")
    if not (0 < duration <= MAX_DURATION):
        raise GearshotError(f"{option} must lie in (0, {MAX_DURATION:g}] s; got {duration!r}")
    revs = duration * speed * pinion_teeth / gear_teeth
    need = SEGMENT_REVOLUTIONS * gear_teeth / (pinion_teeth * speed)
    if revs < SEGMENT_REVOLUTIONS:
        raise GearshotError(
            f"{option} {duration:g} s holds {revs:.3g} gear revolution(s) at --speed "
            f"{speed:g} rps; one SA segment needs {SEGMENT_REVOLUTIONS} "
            f"(--duration >= {need:.3g} s)")


def _check_condition(speeds, loads) -> None:
    """Physical bounds on the --speed / --load values (rev/s, N m)."""
    for v in speeds:
        check_speed(v, "--speed")
    for v in loads:
        check_load(v, "--load")


def _check_frf_folder(folder: Path | None, *, minimum: int = 1) -> None:
    """The FRF folder exists and holds at least ``minimum`` readable FRFs (checked now,
    before any database is built)."""
    if folder is None:
        return
    if not folder.is_dir():
        raise GearshotError(f"--frf-folder {str(folder)!r} is not a folder")
    from ..transfer import TransferFunctionBank

    try:
        bank = TransferFunctionBank.from_folder(folder)
    except GearshotError as exc:
        raise GearshotError(f"--frf-folder: {exc}") from None
    if len(bank) < minimum:
        raise GearshotError(f"--frf-folder {str(folder)!r} holds {len(bank)} FRF(s); "
                            f"this needs at least {minimum}")


def _check_rig_grade(rig_grade: int | None) -> None:
    if rig_grade is not None and not 1 <= rig_grade <= 12:
        raise GearshotError(f"--rig-grade must be 1 … 12; got {rig_grade}")


def _check_count(value: int, option: str, *, minimum: int = 0,
                 maximum: int = MAX_COUNT) -> None:
    if not minimum <= value <= maximum:
        raise GearshotError(f"{option} must lie in {minimum} … {maximum}; got {value}")


def _folder_digest(folder: Path | None) -> str | None:
    """Content hash of every file of an FRF folder (names and bytes), or None."""
    if folder is None:
        return None
    h = hashlib.sha256()
    for path in sorted(p for p in folder.rglob("*") if p.is_file()):
        h.update(path.relative_to(folder).as_posix().encode() + b"\0")
        with open(path, "rb") as fh:
            while chunk := fh.read(1 << 20):
                h.update(chunk)
        h.update(b"\0")
    return h.hexdigest()


CACHE_MANIFEST = "gearshot-cache.json"


def _cached_campaign(campaign: Path | None, inputs: dict, record) -> Path:
    """The campaign for ``inputs``: reuse one recorded from exactly these inputs, else record.

    The default folder's name carries a hash of every input (seed, condition, grade,
    attenuation, the FRF files' content, duration, counts) and the folder holds those
    inputs in ``gearshot-cache.json``, checked on every reuse.
    """
    from .. import data_home

    key = hashlib.sha256(json.dumps(inputs, sort_keys=True).encode()).hexdigest()[:16]
    if campaign is None:
        campaign = data_home() / (f"campaign-s{inputs['seed']}-{inputs['speed']:g}rps-"
                                  f"{inputs['load']:g}Nm-{key}")
    manifest = campaign / CACHE_MANIFEST
    if (campaign / "index.csv").is_file():
        if not manifest.exists():
            return campaign   # a campaign the user recorded (gearshot rig): theirs to vouch for
        try:
            old = json.loads(manifest.read_text())
        except (OSError, ValueError) as exc:
            raise GearshotError(f"--campaign {str(campaign)!r}: {CACHE_MANIFEST} is "
                                f"unreadable ({exc}); delete the folder to record it again") \
                from None
        if old == inputs:
            return campaign
        diff = sorted(k for k in set(old) | set(inputs) if old.get(k) != inputs.get(k))
        raise GearshotError(f"--campaign {str(campaign)!r} was recorded from other inputs "
                            f"(differs in {', '.join(diff)}); pass another --campaign or "
                            f"delete it")
    check_writable(campaign, "--campaign", folder=True)
    record(campaign)
    write_json_atomic(inputs, manifest)
    return campaign


@app.command()
def demo(
    out: Path = typer.Option(Path("gearshot-demo"), "--out", help="Folder for figures, "
                             "tables and the report."),
    seed: int = typer.Option(0, "--seed", help="Seed of the database, rig and splits."),
    draws: int = typer.Option(5, "--draws", help="Draws of the faulty example; the table "
                              "gives the mean ± std over them."),
) -> None:
    """Build a small database, record a virtual rig, fit, and report (≈ 2–3 min)."""
    _early(out, "--out", folder=True)
    from .demo import run_demo

    run_demo(out, seed=seed, draws=draws)


@app.command()
def simulate(
    store: Path | None = typer.Option(None, "--store", help="Zarr store (default under "
                                         "gearshot's data home)."),
    speed: list[float] = typer.Option([15.0], "--speed", help="Input speed(s), rps."),
    load: list[float] = typer.Option([10.0], "--load", help="Load(s), Nm."),
    grade: list[int] = typer.Option(list(range(1, 13)), "--grade", help="DIN grade(s)."),
    n_healthy: int = typer.Option(100, "--n-healthy", help=HELP_N_HEALTHY),
    n_faulty: int = typer.Option(700, "--n-faulty", help=HELP_N_FAULTY),
    seed: int = typer.Option(0, "--seed", help="Seed of the profile errors, fault sizes and "
                             "noise (each block from its own child seed)."),
    paper: bool = typer.Option(False, "--paper", help="All paper speeds (10–35 rps) and "
                               "loads (5–20 Nm)."),
    scheduler: str | None = typer.Option(None, "--scheduler", help="Address of a "
                                            "running Dask scheduler."),
    workers: int = typer.Option(2, "--workers", help="LocalCluster workers when no "
                                "--scheduler is given."),
    fault_type: list[str] = typer.Option(["ftff"], "--fault-type", help="Fault type(s): "
                                         f"{', '.join(FAULT_TYPE_NAMES)}."),
    machine: Path | None = typer.Option(None, "--machine", help="Machine description "
                                           "(TOML): simulate its monitored pair; --speed is "
                                           "then the tacho shaft's speed."),
    paired: bool = typer.Option(True, "--paired/--no-paired", help="Store each signal's "
                                "healthy twin (same profile errors, no fault): the "
                                "estimator subtracts each signal's own twin "
                                "(simulated_reference 'auto' -> 'twin') and calibrates "
                                "fault gain and width on it. Default on; --no-paired "
                                "builds the old layout (half the simulation time)."),
) -> None:
    """Build (or finish) a simulated database; resumable."""
    from .._paths import data_home

    _check_count(n_healthy, "--n-healthy", maximum=100_000)
    _check_count(n_faulty, "--n-faulty", maximum=100_000)
    _check_count(workers, "--workers", minimum=1, maximum=256)
    _check_condition(speed, load)
    if machine is not None:
        _early(store, "--store", folder=True)
        _simulate_machine(machine, store, speed, load, grade, n_healthy, n_faulty, seed,
                          scheduler, workers, fault_type, paired=bool(paired))
        return
    store = store or data_home(create=False) / "databases" / "sim-db"  # default_database_path
    _early(store, "--store", folder=True)
    from ..sim import GearPair, build_database
    speeds, loads = (PAPER_SPEEDS, PAPER_LOADS) if paper else (speed, load)
    n_blocks = len(speeds) * len(loads) * len(grade) * len(fault_type)
    client = _client(scheduler, workers, needed=n_blocks > 1)
    try:
        build_database(store, GearPair.paper(), speeds=speeds, loads=loads, grades=grade,
                       n_healthy=n_healthy, n_faulty=n_faulty, seed=seed, client=client,
                       fault_types=fault_type, paired=bool(paired))
    finally:
        if client is not None:
            client.close()
    typer.echo(f"database ready: {store}")


def _simulate_machine(machine_file, store, speeds, loads, grades, n_healthy, n_faulty, seed,
                      scheduler, workers, fault_types=("ftff",), paired=True):
    """``simulate --machine``: a database of the machine's monitored pair (paired by
    default: on a real machine the target's step 6 subtracts the same gear's healthy SA,
    and so does the simulated side with twins)."""
    from ..machine import Machine
    from ..sim import build_database
    from .predict_machine import machine_database_path

    mach = Machine.from_toml(machine_file)
    pair = mach.gear_pair()
    store = store or machine_database_path(machine_file, n_healthy=n_healthy,
                                           n_faulty=n_faulty, seed=seed, paired=paired)
    sim_speeds = [mach.sim_speed(s) for s in speeds]
    n_blocks = len(sim_speeds) * len(loads) * len(grades) * len(fault_types)
    client = _client(scheduler, workers, needed=n_blocks > 1)
    try:
        build_database(store, pair, speeds=sim_speeds, loads=loads, grades=grades,
                       n_healthy=n_healthy, n_faulty=n_faulty, seed=seed, client=client,
                       fault_types=list(fault_types), paired=paired)
    finally:
        if client is not None:
            client.close()
    mate_shaft, _ = mach.mate()
    ref_kind = "tacho" if mach.tacho is not None else "reference"
    typer.echo(f"pair {pair.z_pinion} -> {pair.z_gear} teeth (fault on the {pair.z_gear}-tooth "
               f"gear, its mate on the {mate_shaft} shaft); conditions: {mach.reference_shaft} "
               f"({ref_kind}) shaft {', '.join(f'{s:g}' for s in speeds)} Hz x load "
               f"{', '.join(f'{x:g}' for x in loads)} N m")
    typer.echo(f"database ready: {store}")


@app.command()
def rig(
    folder: Path = typer.Argument(..., help="Campaign folder (created)."),
    speed: float = typer.Option(15.0, "--speed", help="Input (pinion) speed of the rig, "
                                "rps."),
    load: float = typer.Option(10.0, "--load", help="Load torque of the rig, N m."),
    duration: float = typer.Option(60.0, "--duration", help="Seconds per recording."),
    healthy: int = typer.Option(6, "--healthy", help="Number of healthy recordings."),
    size: list[float] = typer.Option(list(TABLE1_SIZES), "--size", help="Fault size(s)."),
    repetitions: int = typer.Option(6, "--repetitions", help="Recordings per fault size."),
    seed: int = typer.Option(0, "--seed", help="Seed of the rig's hidden reality."),
    frf_folder: Path | None = typer.Option(None, "--frf-folder", help="Measured FRFs "
                                              "for the transfer path (default synthetic)."),
    rig_grade: int | None = typer.Option(None, "--rig-grade", help="Force the rig's true "
                                            "surface grade (default: hidden, drawn)."),
) -> None:
    """Record a virtual-rig campaign (Table 1 of the paper) into a folder."""
    _check_frf_folder(frf_folder)
    _check_duration(duration, speed)
    _check_condition([speed], [load])
    _check_rig_grade(rig_grade)
    _check_count(healthy, "--healthy")
    _check_count(repetitions, "--repetitions")
    _early(folder, "FOLDER", folder=True)
    rig_obj = _make_rig(seed, frf_folder, rig_grade)
    index = rig_obj.campaign(folder, speed=speed, load=load, duration=duration,
                             healthy=healthy, sizes=tuple(size), repetitions=repetitions)
    typer.echo(f"{len(index)} recordings written to {folder}")


def _make_rig(seed, frf_folder, rig_grade):
    from ..rig import VirtualRig

    kwargs = {}
    if frf_folder is not None:
        kwargs["tf_bank"] = str(frf_folder)
    if rig_grade is not None:
        _check_rig_grade(rig_grade)
        kwargs["grade"] = rig_grade
    return VirtualRig(seed=seed, **kwargs)


@experiment_app.command("simulated")
def experiment_simulated(
    store: Path | None = typer.Option(None, "--store", help="Database store (built if "
                                         "missing)."),
    speed: list[float] = typer.Option([15.0], "--speed", help="Input speed(s), rps "
                                      "(repeat the option)."),
    load: list[float] = typer.Option([10.0], "--load", help="Load(s), N m (repeat the "
                                     "option)."),
    grade: int = typer.Option(7, "--grade", help="Grade of the simulated signals."),
    attenuation_db: list[float] = typer.Option([10.0], "--attenuation-db", help="Path "
                                               "attenuation(s) of the measured TFs, dB."),
    frf_folder: Path | None = typer.Option(None, "--frf-folder", help="Measured FRFs "
                                              "(default: a synthetic bank of 24)."),
    selection_tf: str | None = typer.Option(None, "--selection-tf", help="Name of the "
                                               "held-out TF (default the bank's last)."),
    seed: int = typer.Option(0, "--seed", help="Seed of the database and the splits."),
    full: bool = typer.Option(False, "--full", help="The paper's sweep: 26 speeds × 4 loads "
                              "× 23 TFs."),
    n_healthy: int = typer.Option(100, "--n-healthy", help=HELP_N_HEALTHY),
    n_faulty: int = typer.Option(700, "--n-faulty", help=HELP_N_FAULTY),
    json_out: Path | None = typer.Option(None, "--json", help="Write results as JSON."),
    out: Path | None = typer.Option(None, "--out", help="Folder for figures and report."),
    scheduler: str | None = typer.Option(None, "--scheduler", help=HELP_SCHEDULER),
    workers: int = typer.Option(2, "--workers", help=HELP_WORKERS),
) -> None:
    """Sec. 4.1: simulated signals through measured TFs; before DA / RMS only / full."""
    _check_frf_folder(frf_folder, minimum=2)      # one held out for selection, one to test
    if not full:
        _check_condition(speed, load)
    if not 1 <= grade <= 12:
        raise GearshotError(f"--grade must be 1 … 12; got {grade}")
    _early(json_out, "--json")
    _early(out, "--out", folder=True)
    _early(store, "--store", folder=True)
    _check_count(n_healthy, "--n-healthy", maximum=100_000)
    _check_count(n_faulty, "--n-faulty", maximum=100_000)
    _check_count(workers, "--workers", minimum=1, maximum=256)
    from ..experiments import SIMULATED_VARIANTS, simulated_experiment, summarize
    from ..sim import GearPair, build_database, default_database_path

    speeds, loads = (PAPER_SPEEDS, PAPER_LOADS) if full else (speed, load)
    tag = "paper" if full else "-".join(f"{s:g}" for s in speeds) + "rps-" + \
        "-".join(f"{ld:g}" for ld in loads) + "Nm"
    store = store or default_database_path(
        f"sim-db-{tag}-grade{grade}-h{n_healthy}-f{n_faulty}-s{seed}")
    client = _client(scheduler, workers, needed=len(speeds) * len(loads) > 1)
    try:
        build_database(store, GearPair.paper(), speeds=speeds, loads=loads, grades=[grade],
                       n_healthy=n_healthy, n_faulty=n_faulty, seed=seed, client=client)
        results = simulated_experiment(store, speeds=speeds, loads=loads, grade=grade,
                                       frf_folder=frf_folder, selection_tf=selection_tf,
                                       attenuations_db=attenuation_db, seed=seed,
                                       client=client)
    finally:
        if client is not None:
            client.close()
    table = summarize(results)
    typer.echo(table.to_string(index=False))
    by_variant = dict(zip(table["variant"], table["mae_percent"]))
    payload = {"experiment": "simulated", "mae": by_variant.get("full"),
               "ablations": by_variant, "n_datasets": int(len(results) / len(SIMULATED_VARIANTS)),
               "rows": results.to_dict(orient="records")}
    _write_json(json_out, payload)
    if out is not None:
        from .figures import simulated_figures

        simulated_figures(results, out)


@experiment_app.command("rig")
def experiment_rig(
    campaign: Path | None = typer.Option(None, "--campaign", help="Campaign folder "
                                            "(recorded if missing)."),
    store: Path | None = typer.Option(None, "--store", help="Database store (built if "
                                         "missing; default under gearshot's data home)."),
    speed: float = typer.Option(15.0, "--speed", help="Input speed, rps."),
    load: float = typer.Option(10.0, "--load", help="Load, N m."),
    seed: int = typer.Option(0, "--seed", help="Seed of the database, rig and splits."),
    frf_folder: Path | None = typer.Option(None, "--frf-folder", help="Measured FRFs for "
                                              "the rig's path (default synthetic)."),
    rig_grade: int | None = typer.Option(None, "--rig-grade", help="Force the rig's true "
                                            "surface grade (default: hidden, drawn)."),
    attenuation_db: float | None = typer.Option(None, "--attenuation-db",
                                                   help="Rig path attenuation (default "
                                                   "hidden, 10–30 dB)."),
    duration: float = typer.Option(60.0, "--duration", help="Seconds per recording."),
    repeats: int = typer.Option(5, "--repeats", help="Random example draws."),
    n_healthy: int = typer.Option(100, "--n-healthy", help=HELP_N_HEALTHY),
    n_faulty: int = typer.Option(700, "--n-faulty", help=HELP_N_FAULTY),
    json_out: Path | None = typer.Option(None, "--json", help="Write results as JSON."),
    out: Path | None = typer.Option(None, "--out", help="Folder for figures and report."),
    scheduler: str | None = typer.Option(None, "--scheduler", help=HELP_SCHEDULER),
    workers: int = typer.Option(2, "--workers", help=HELP_WORKERS),
    param: list[str] = typer.Option([], "--param", help="NAME=VALUE: an estimator parameter "
                                    "for every variant (VALUE as JSON when it parses)."),
    paired: bool = typer.Option(True, "--paired/--no-paired", help="Build and use the "
                                "database with healthy twins (default): the estimator's "
                                "simulated_reference='auto' then subtracts each signal's "
                                "own twin (steps 1 and 6). --no-paired: the old layout."),
) -> None:
    """Sec. 4.2: virtual-rig recordings; the five variants of Fig. 14."""
    _check_frf_folder(frf_folder)
    _check_duration(duration, speed)
    _check_condition([speed], [load])
    _check_rig_grade(rig_grade)
    _check_count(seed, "--seed", maximum=2**32 - 1)
    _check_count(repeats, "--repeats", minimum=1, maximum=1000)
    _check_count(n_healthy, "--n-healthy", maximum=100_000)
    _check_count(n_faulty, "--n-faulty", maximum=100_000)
    _check_count(workers, "--workers", minimum=1, maximum=256)
    _early(json_out, "--json")
    _early(out, "--out", folder=True)
    _early(store, "--store", folder=True)
    _early(campaign, "--campaign", folder=True)
    from ..experiments import RIG_VARIANTS, rig_experiment, summarize
    from ..experiments.family import parse_params
    from ..sim import GearPair, build_database, default_database_path, load_database
    from ..transfer import TransferFunctionBank

    params = parse_params(param)
    store = store or default_database_path(
        f"sim-db-{speed:g}rps-{load:g}Nm-h{n_healthy}-f{n_faulty}-s{seed}"
        + ("-paired" if paired else ""))
    client = _client(scheduler, workers, needed=True)
    try:
        build_database(store, GearPair.paper(), speeds=[speed], loads=[load],
                       grades=range(1, 13), n_healthy=n_healthy, n_faulty=n_faulty,
                       seed=seed, client=client, paired=paired)
    finally:
        if client is not None:
            client.close()
    database = load_database(store, speed=speed, load=load)
    inputs: dict[str, Any] = {"seed": seed, "speed": speed, "load": load, "rig_grade": rig_grade,
              "attenuation_db": attenuation_db, "duration": duration,
              "frf_sha256": _folder_digest(frf_folder), "healthy": 6,
              "sizes": list(TABLE1_SIZES), "repetitions": 6, "fs": 50_000.0}

    def record(folder: Path) -> None:
        rig_obj = _make_rig(seed, frf_folder, rig_grade)
        if attenuation_db is not None:
            rig_obj = rig_obj.with_reality(attenuation_db=attenuation_db)
        rig_obj.campaign(folder, speed=speed, load=load, duration=duration,
                         healthy=inputs["healthy"], sizes=tuple(inputs["sizes"]),
                         repetitions=inputs["repetitions"])

    campaign = _cached_campaign(campaign, inputs, record)
    import numpy as np

    selection = TransferFunctionBank.synthetic(1, rng=np.random.default_rng([seed, 99]))[0]
    results, predictions = rig_experiment(campaign, database, speed=speed, load=load,
                                          selection_tf=selection, variants=RIG_VARIANTS,
                                          n_repeats=repeats, seed=seed,
                                          keep_estimators="first" if out else False,
                                          params=params)
    estimator = None
    if "estimator" in results:
        estimator = results.loc[results["variant"] == "full", "estimator"].dropna().iloc[0]
        results = results.drop(columns="estimator")
    table = summarize(results)
    typer.echo(table.to_string(index=False))
    by_variant = dict(zip(table["variant"], table["mae_percent"]))
    payload = {"experiment": "rig", "speed": speed, "load": load, "params": params,
               "mae": by_variant.get("full"), "ablations": by_variant,
               "rows": results.to_dict(orient="records")}
    _write_json(json_out, payload)
    if out is not None:
        from .figures import rig_figures

        rig_figures(results, predictions, out, estimator=estimator)


@experiment_app.command("rig-family")
def experiment_rig_family(
    seed_range: str = typer.Option("dev", "--range", help="Seed range: dev (100–123; every "
                                   "choice is made here), heldout (9500–9523; evaluate "
                                   "once, at the end) or spent (9000–9023, issue #12's "
                                   "held-out range, evaluated twice)."),
    seeds: list[int] = typer.Option([], "--seed", help="Explicit rig seed(s) instead of "
                                    "--range (results file 'seeds.jsonl')."),
    n_rigs: int | None = typer.Option(None, "--n-rigs", help="The first N seeds only."),
    draws: int = typer.Option(2, "--draws", help="Example draws (Sec. 4.2 splits) per rig."),
    variants: list[str] = typer.Option(["full"], "--variant", help="Estimator variant(s): "
                                       "full, no_feature_selection, no_tuning, before_da, "
                                       "rms_only, zero_shot (repeat the option)."),
    frf_folder: Path | None = typer.Option(None, "--frf-folder", help="Measured FRFs of the "
                                              "path bank (the family of issue #12 uses the 12 "
                                              "real ones); synthetic paths only when omitted."),
    segments: int = typer.Option(4, "--segments", help="50-cycle SAs per recording."),
    repetitions: int = typer.Option(2, "--repetitions", help="Recordings per fault size."),
    param: list[str] = typer.Option([], "--param", help="NAME=VALUE: an estimator parameter "
                                    "for every variant (VALUE as JSON when it parses)."),
    paired: bool = typer.Option(True, "--paired/--no-paired", help="Use the database with "
                                "healthy twins (default; the estimator's "
                                "simulated_reference='auto' then uses them). --no-paired: "
                                "the old layout."),
    results: Path | None = typer.Option(None, "--results", help="JSON-lines results file "
                                           "(appended, resumable; default "
                                           "DATA_HOME/family/RANGE.jsonl)."),
    rigs_cache: Path | None = typer.Option(None, "--rigs-cache", help="Folder of the rigs' "
                                              "cached SA segments (default "
                                              "DATA_HOME/family/rigs, shared by all runs)."),
    json_out: Path | None = typer.Option(None, "--json", help="Write the summary tables "
                                            "as JSON."),
    rigs_table: bool = typer.Option(False, "--rigs-table", help="Print the per-rig table."),
    scheduler: str | None = typer.Option(None, "--scheduler", help=HELP_SCHEDULER),
    workers: int = typer.Option(1, "--workers", help="LocalCluster workers (rigs in "
                                "parallel) when no --scheduler is given."),
) -> None:
    """Issue #12: accuracy over a family of virtual rigs never used for tuning; resumable."""
    from ..experiments import VARIANTS, family

    if seed_range not in family.RANGES:
        raise GearshotError(f"--range must be one of {list(family.RANGES)}; got "
                            f"{seed_range!r}")
    if frf_folder is not None and not frf_folder.is_dir():
        raise GearshotError(f"--frf-folder {str(frf_folder)!r} is not a folder")
    valid = list(VARIANTS) + list(family.DIAGNOSTIC_VARIANTS)
    for v in variants:
        if v not in valid:
            raise GearshotError(f"--variant {v!r} is not a variant; valid: {valid}")
    for s in seeds:
        _check_count(s, "--seed", maximum=2**31 - 1)
    pool = list(seeds) if seeds else list(family.RANGES[seed_range])
    if n_rigs is not None:
        _check_count(n_rigs, "--n-rigs", minimum=1, maximum=len(pool))
        pool = pool[:n_rigs]
    _check_count(draws, "--draws", minimum=1, maximum=100)
    _check_count(segments, "--segments", minimum=1, maximum=100)
    _check_count(repetitions, "--repetitions", minimum=1, maximum=100)
    _check_count(workers, "--workers", minimum=1, maximum=256)
    params = family.parse_params(param)
    from .. import data_home

    home = data_home()
    results = results or home / "family" / f"{'seeds' if seeds else seed_range}.jsonl"
    _early(results, "--results")
    _early(rigs_cache, "--rigs-cache", folder=True)
    _early(json_out, "--json")
    store = family.family_database(home / "family", paired=paired)
    client = _client(scheduler, workers, needed=len(pool) > 1)
    try:
        frame = family.rig_family_experiment(
            store, pool, results=results, frf_folder=frf_folder, n_draws=draws,
            variants=variants, segments=segments, repetitions=repetitions, params=params,
            cache_dir=rigs_cache or home / "family" / "rigs", client=client)
    finally:
        if client is not None:
            client.close()
    typer.echo(f"{len(pool)} rigs × {draws} draws, {len(frame)} rows in {results}")
    typer.echo(family.format_family_tables(frame, rigs_table=rigs_table))
    tables = family.family_tables(frame)
    payload = {"experiment": "rig-family", "range": None if seeds else seed_range,
               "seeds": pool, "draws": draws, "params": params, "results": str(results),
               "tables": {name: json.loads(t.to_json(orient="split"))
                          for name, t in tables.items() if name != "rigs"}}
    _write_json(json_out, payload)


def _comparable_summary(frame) -> str:
    """One line counting the comparable segments of a predict table (issue #19)."""
    if "comparable" not in frame or not len(frame):
        return "comparable: no segment estimated"
    n_yes = int(frame["comparable"].sum())
    n_no = len(frame) - n_yes
    line = f"comparable: {n_yes} segment(s), not comparable: {n_no}"
    if n_no:
        line += (" (they do not look like the fitted machine — another build, speed, load "
                 "or sensor? — do not act on their estimates)")
    return line


FAULTY_SIZE_HELP = (
    "Declared size of the faulty recording's fault, in (0, 1], in the units of the "
    "database's fault type (--fault-type of gearshot simulate): ftff (default): width of "
    "the cut along the active profile / the active profile's width (1: the whole profile); "
    "partial_face: the cut band's width / the face width; breakage: lost tooth height / "
    "the height above the lowest contact point, the break spanning that share of the face "
    "(1: a missing tooth); destruction: the pitted band's width / the active profile's. "
    "An ordinal label (chipped, broken) has no size: give your best measure of it (the "
    "estimates are on the same scale).")


@app.command()
def predict(
    database: Path = typer.Option(..., "--database", help="Simulated database store "
                                  "(gearshot simulate; with --machine, gearshot simulate "
                                  "--machine)."),
    healthy: list[str] = typer.Option(..., "--healthy", help="Healthy recordings of the "
                                      "machine: any number of files, folders or glob "
                                      "patterns after one --healthy."),
    faulty: Path = typer.Option(..., "--faulty", help="The one faulty recording; its first "
                                "segment is the example."),
    faulty_size: float = typer.Option(..., "--faulty-size", help=FAULTY_SIZE_HELP),
    recordings: list[str] = typer.Option([], "--recordings", help="Recordings to estimate: "
                                         "any number of files, folders (their recording "
                                         "files) or glob patterns after one --recordings."),
    speed: float | None = typer.Option(None, "--speed", help="Database condition. With "
                                          "--machine: the tacho shaft's speed in Hz "
                                          "(default: the database speed nearest to the "
                                          "healthy recordings' tacho); without: the "
                                          "database's speed in rps (required)."),
    load: float | None = typer.Option(None, "--load", help="Database load, N m (default: "
                                         "the database's only load; with --machine and a "
                                         "database over several loads, the one the healthy "
                                         "recordings pick, refused when ambiguous)."),
    out: Path = typer.Option(Path("predictions.csv"), "--out", help="Output table, CSV "
                             "or (by suffix .json) JSON; one row per SA segment with its "
                             "role, estimate and interval."),
    coverage: float = typer.Option(0.9, "--coverage", help="Prediction-interval coverage."),
    gear_teeth: int | None = typer.Option(None, "--gear-teeth", help="Without --machine: "
                                          "teeth of the monitored (faulty) gear, whose "
                                          "revolution is the SA cycle (default: the "
                                          "database's gear pair; another count is refused)."),
    pinion_teeth: int | None = typer.Option(None, "--pinion-teeth", help="Without --machine: "
                                            "teeth of its pinion, whose speed is --speed "
                                            "(default: the database's)."),
    seed: int = typer.Option(0, "--seed", help="Random state of the fit (splits, step 1's "
                             "held-out TF)."),
    machine: Path | None = typer.Option(None, "--machine", help="Machine description "
                                           "(TOML): SAs of the monitored gear's shaft through "
                                           "its gear train; speeds in tacho-shaft Hz."),
    cycles_per_segment: int | None = typer.Option(None, "--cycles-per-segment",
                                                     help="With --machine: revolutions per "
                                                     "SA segment (default: the machine's)."),
    sensor: str | None = typer.Option(None, "--sensor", help="With --machine: sensor "
                                         "name (default the first)."),
    holdout: float = typer.Option(0.25, "--holdout", help="With --machine: fraction of each "
                                  "healthy recording's segments kept out of the fit and "
                                  "estimated."),
    speed_tolerance: float = typer.Option(0.05, "--speed-tolerance", help="With --machine: "
                                          "largest relative distance between a recording's "
                                          "tacho speed and the database condition (beyond "
                                          "it the recording is refused)."),
) -> None:
    """Fit from a database + healthy recordings + one faulty recording; estimate sizes."""
    if out.suffix.lower() not in (".csv", ".json"):
        raise GearshotError(f"--out {str(out)!r} must end in .csv or .json (the formats "
                            f"predict writes); got suffix {out.suffix!r}")
    _check_count(seed, "--seed", maximum=2**32 - 1)
    from .files import expand_recordings

    _early(out, "--out")
    healthy_files = expand_recordings(healthy, "--healthy")
    if not 0 < speed_tolerance < 1:
        raise GearshotError(f"--speed-tolerance must lie in (0, 1); got {speed_tolerance!r}")
    if machine is not None:
        from ..machine import Machine
        from .predict_machine import predict_from_machine

        frame = predict_from_machine(Machine.from_toml(machine), database, healthy_files,
                                     faulty, faulty_size,
                                     expand_recordings(recordings, "--recordings"),
                                     speed=speed, load=load,
                                     cycles_per_segment=cycles_per_segment, sensor=sensor,
                                     holdout=holdout, coverage=coverage, seed=seed,
                                     speed_tolerance=speed_tolerance)
        where = (f"database condition: tacho shaft {frame.attrs['speed_hz']:.4g} Hz, load "
                 f"{frame.attrs['load']:g} N m{frame.attrs.get('load_note', '')}")
    else:
        from .predict import predict_from_files

        if speed is None:
            raise GearshotError("--speed is required without --machine (the database's "
                                "speed, rps)")
        if not recordings:
            raise GearshotError("--recordings: give at least one file or folder to estimate")
        frame = predict_from_files(database, healthy_files, faulty, faulty_size, recordings,
                                   speed=speed, load=load, coverage=coverage,
                                   gear_teeth=gear_teeth, pinion_teeth=pinion_teeth,
                                   seed=seed)
        where = (f"database condition: {frame.attrs['speed']:g} rps, load "
                 f"{frame.attrs['load']:g} N m")
    with atomic_path(out, make_parents=True) as tmp:
        if out.suffix.lower() == ".json":
            tmp.write_text(frame.to_json(orient="records", indent=2))
        else:
            frame.to_csv(tmp, index=False)
    from .predict import summary_table

    typer.echo(where)
    typer.echo(summary_table(frame).to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    typer.echo(_comparable_summary(frame))
    typer.echo(f"predictions written to {out}")


@app.command()
def indicators(
    recordings: list[str] = typer.Argument(..., help="Recording files, folders or glob "
                                           "patterns (the original zips are fine)."),
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
    labels: Path | None = typer.Option(None, "--labels", help="CSV with columns file, label "
                                          "(and optionally cell): rank the indicators by how "
                                          "well they separate healthy (label 0, healthy or "
                                          "good) from the other labels, AUC per cell and "
                                          "overall."),
) -> None:
    """Condition indicators of one shaft per recording and sensor (--labels: a ranking)."""
    from ..machine import Machine
    from .files import expand_recordings
    from .indicators import format_indicators, indicator_figures, record_indicators

    mach = Machine.from_toml(machine)
    _early(json_out, "--json")
    _early(out, "--out", folder=True)
    files = expand_recordings(recordings, "RECORDINGS")
    base = expand_recordings(baseline, "--baseline")
    label_table = None
    if labels is not None:
        from .ranking import read_labels

        label_table = read_labels(labels, [f.name for f in files])
    payload = record_indicators(files, mach, shaft=shaft, sensors=sensor or None,
                                baseline_paths=base, machine_file=machine)
    typer.echo(format_indicators(payload))
    if label_table is not None:
        from .ranking import format_ranking, indicator_ranking, ranking_figure

        ranking = indicator_ranking(payload, label_table)
        payload["ranking"] = json.loads(ranking.to_json(orient="records"))
        typer.echo(format_ranking(ranking))
        if out is not None:
            from .._atomic import atomic_path as _ap

            with _ap(out / "ranking.csv", make_parents=True) as tmp:
                ranking.to_csv(tmp, index=False)
            ranking_figure(ranking, out / "ranking.png",
                           title=f"{mach.name}, shaft {shaft}")
    if json_out is not None:
        _write_json(json_out, payload)
        typer.echo(f"indicators written to {json_out}")
    if out is not None:
        indicator_figures(payload, out, title=f"{mach.name}, shaft {shaft}")
        typer.echo(f"figures written to {out}")


@app.command()
def report(
    results: Path = typer.Argument(..., help="A JSON written by gearshot: demo's "
                                   "results.json, experiment/rig-family/indicators --json, "
                                   "predict --out X.json."),
    out: Path = typer.Option(Path("gearshot-report"), "--out", help="Folder for the "
                             "figures and report.md."),
) -> None:
    """Figures and a Markdown report from any JSON gearshot writes."""
    if not results.is_file():
        raise GearshotError(f"results file {str(results)!r} does not exist")
    _early(out, "--out", folder=True)
    from .report import report_from_any_json

    path = report_from_any_json(results, out)
    typer.echo(f"report: {path}")


def _one_line(exc: object) -> str:
    """A message on one line (libraries' messages may span several)."""
    return " ".join(str(exc).split())


def _usage_line(exc) -> str:
    """A click usage error as one line, naming the command and where its help is."""
    text = " ".join(str(exc.format_message()).split())
    ctx = getattr(exc, "ctx", None)
    command = getattr(ctx, "command_path", None) or "gearshot"
    return f"{text} (see `{command} --help`)"


def main() -> None:
    """Console entry point: user errors become one line and a non-zero exit."""
    from .files import spread_file_options

    try:
        app(args=spread_file_options(sys.argv[1:]), prog_name="gearshot",
            standalone_mode=False)
    except GearshotError as exc:
        typer.secho(f"gearshot: error: {_one_line(exc)}", err=True, fg="red")
        sys.exit(2)
    except OSError as exc:  # disk full, file too large, permission, missing file
        where = f" {exc.filename!r}" if getattr(exc, "filename", None) else ""
        typer.secho(f"gearshot: error:{where} {_one_line(os_error_text(exc))}", err=True,
                    fg="red")
        sys.exit(1)
    except MemoryError:
        typer.secho("gearshot: error: out of memory; try fewer or shorter signals (smaller "
                    "counts or sizes)", err=True, fg="red")
        sys.exit(1)
    except KeyboardInterrupt:
        typer.secho("gearshot: interrupted", err=True)
        sys.exit(130)
    except typer.Exit as exc:
        sys.exit(exc.exit_code)
    except typer.Abort:
        sys.exit(1)
    except Exception as exc:  # usage errors of typer's click: one line, exit 2
        if hasattr(exc, "show") and hasattr(exc, "exit_code"):
            if type(exc).__name__ == "NoArgsIsHelpError" or not hasattr(exc,
                                                                         "format_message"):
                exc.show()       # `gearshot` or `gearshot experiment` alone: the help
                sys.exit(exc.exit_code)
            typer.secho(f"gearshot: error: {_usage_line(exc)}", err=True, fg="red")
            sys.exit(exc.exit_code)
        if os.environ.get("GEARSHOT_DEBUG"):
            raise
        typer.secho(f"gearshot: error: unexpected {type(exc).__name__}: {exc} (a bug: please "
                    f"report it; GEARSHOT_DEBUG=1 shows the traceback)", err=True, fg="red")
        sys.exit(3)


if __name__ == "__main__":  # pragma: no cover
    main()
