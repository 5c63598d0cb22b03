"""The commands that make data: ``demo``, ``simulate`` (a database), ``rig`` (a campaign)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import typer

from ..._errors import GearshotError
from ..._validation import check_in_range
from ...fault_registry import FAULT_TYPE_NAMES
from ...paper import (
    RIG_DURATION,
    RIG_HEALTHY_RECORDINGS,
    RIG_LOAD,
    RIG_REPETITIONS,
    RIG_SPEED,
    TABLE1_SIZES,
)
from ._apps import app
from ._options import (
    NFaulty,
    NHealthy,
    RigGrade,
    check_condition,
    check_count,
    check_counts,
    check_duration,
    check_frf_folder,
    check_seed,
    check_store_folder,
    early,
    given,
    refuse_together,
)

__all__ = ["demo", "simulate", "rig"]

HELP_PAIRED = ("Store each signal's healthy twin (same profile errors, no fault): the "
               "estimator subtracts each signal's own twin (options.simulated_reference 'auto' -> "
               "'twin') and calibrates fault gain and width on it. Default on; --no-paired "
               "builds the old layout (half the simulation time).")
HELP_MACHINE = ("Machine description (TOML): simulate its monitored pair; --speed is then "
                "the tacho shaft's speed.")


@app.command()
def demo(
    out: Path = typer.Option(Path("gearshot-demo"), "--out", help="Folder for figures, "
                             "tables and the report."),
    seed: int = typer.Option(0, "--seed", help="Seed of the database, rig and splits."),
    draws: int = typer.Option(5, "--draws", help="Draws of the faulty example; the table "
                              "gives the mean ± std over them."),
) -> None:
    """Build a small database, record a virtual rig, fit, and report (≈ 2–3 min)."""
    check_seed(seed)
    check_count(draws, "--draws", minimum=1, maximum=1000)
    early(out, "--out", folder=True)
    from ..demo import run_demo

    run_demo(out, seed=seed, draws=draws)


@app.command()
def simulate(
    ctx: typer.Context,
    store: Path | None = typer.Option(None, "--store", help="Zarr store (default under "
                                         "gearshot's data home)."),
    speed: list[float] = typer.Option([RIG_SPEED], "--speed", help="Input speed(s), rps."),
    load: list[float] = typer.Option([RIG_LOAD], "--load", help="Load(s), Nm."),
    grade: list[int] = typer.Option(list(range(1, 13)), "--grade", help="DIN grade(s)."),
    n_healthy: NHealthy = 100,
    n_faulty: NFaulty = 700,
    seed: int = typer.Option(0, "--seed", help="Seed of the profile errors, fault sizes and "
                             "noise (each block from its own child seed)."),
    paper: bool = typer.Option(False, "--paper", help="All paper speeds (10–35 rps) and "
                               "loads (5–20 Nm)."),
    scheduler: str | None = typer.Option(None, "--scheduler", help="Address of a "
                                            "running Dask scheduler."),
    workers: int = typer.Option(2, "--workers", help="LocalCluster workers when no "
                                "--scheduler is given (builds of up to 16 blocks run "
                                "in-process, one block per core)."),
    fault_type: list[str] = typer.Option(["ftff"], "--fault-type", help="Fault type(s): "
                                         f"{', '.join(FAULT_TYPE_NAMES)}."),
    machine: Path | None = typer.Option(None, "--machine", help=HELP_MACHINE),
    paired: bool = typer.Option(True, "--paired/--no-paired", help=HELP_PAIRED),
    repair: bool = typer.Option(False, "--repair", help="Repair the store named by --store "
                                "from what its blocks record: restore a lost, empty, "
                                "invalid or edited manifest.json, check every block in "
                                "full and rebuild exactly the damaged and missing ones "
                                "(no other option)."),
) -> None:
    """Build (or finish) a simulated database; resumable. --repair: repair a store."""
    from ...paper import PAPER_LOADS, PAPER_SPEEDS
    from ..simulate import (
        default_store,
        repair_store,
        simulate_database,
        simulate_machine_database,
    )

    if repair:
        repair_store(store, _given_options(ctx, {"repair", "store", "scheduler",
                                                 "workers"}),
                     scheduler=scheduler, workers=workers, echo=typer.echo)
        return

    for other in ("--machine", "--speed", "--load"):
        refuse_together(ctx, "--paper", other, "--paper builds the paper pair at all the "
                        "paper's speeds and loads")
    if machine is not None:
        from ...machine import Machine

        Machine.from_toml(machine)       # a bad machine file first, named
    if machine is not None and not given(ctx, "--speed"):
        raise GearshotError("--machine needs --speed: the tacho shaft's speed(s) in Hz at "
                            "which the machine runs (the default, 15, is the paper rig's "
                            "input speed in rps); e.g. --speed 30 --speed 50")
    check_counts(n_healthy, n_faulty, workers)
    check_condition(speed, load)
    check_seed(seed)
    common: dict[str, Any] = dict(grades=grade, n_healthy=n_healthy, n_faulty=n_faulty, seed=seed,
                                  fault_types=fault_type, paired=bool(paired),
                                  scheduler=scheduler, workers=workers)
    if machine is not None:
        check_store_folder(store)
        early(store, "--store", folder=True)
        store, line = simulate_machine_database(machine, store, speeds=speed, loads=load,
                                                **common)
        typer.echo(line)
    else:
        store = store or default_store()
        check_store_folder(store)
        early(store, "--store", folder=True)
        speeds, loads = (PAPER_SPEEDS, PAPER_LOADS) if paper else (speed, load)
        simulate_database(store, speeds=speeds, loads=loads, **common)
    typer.echo(f"database ready: {store}")


def _given_options(ctx: typer.Context, allowed: set[str]) -> list[str]:
    """The options given on the command line other than ``allowed`` (as --names)."""
    given = []
    for param in ctx.command.params:
        name = param.name or ""
        source = ctx.get_parameter_source(name)
        if name not in allowed and source is not None and source.name not in (
                "DEFAULT", "DEFAULT_MAP"):
            given.append(max(getattr(param, "opts", [name]), key=len))
    return given


@app.command()
def rig(
    folder: Path = typer.Argument(..., help="Campaign folder (created)."),
    speed: float = typer.Option(RIG_SPEED, "--speed", help="Input (pinion) speed of the rig, "
                                "rps."),
    load: float = typer.Option(RIG_LOAD, "--load", help="Load torque of the rig, N m."),
    duration: float = typer.Option(RIG_DURATION, "--duration", help="Seconds per recording."),
    healthy: int = typer.Option(RIG_HEALTHY_RECORDINGS, "--healthy", help="Number of healthy "
                                "recordings."),
    size: list[float] = typer.Option(list(TABLE1_SIZES), "--size", help="Fault size(s)."),
    repetitions: int = typer.Option(RIG_REPETITIONS, "--repetitions", help="Recordings per "
                                    "fault size."),
    seed: int = typer.Option(0, "--seed", help="Seed of the rig's hidden reality."),
    frf_folder: Path | None = typer.Option(None, "--frf-folder", help="Measured FRFs "
                                              "for the transfer path (default synthetic)."),
    rig_grade: RigGrade = None,
    variation: float = typer.Option(0.0, "--variation", help="Run-to-run spread of speed and "
                                    "load (relative, 0 … 0.1): each recording on its own "
                                    "run, as a monitored machine's days are (0.01 in "
                                    "VirtualRig.history); 0: one run, as in the paper."),
) -> None:
    """Record a virtual-rig campaign (Table 1 of the paper) into a folder."""
    from ..campaigns import check_rig_grade, make_rig

    check_frf_folder(frf_folder)
    check_duration(duration, speed)
    check_condition([speed], [load])
    check_rig_grade(rig_grade)
    check_count(healthy, "--healthy")
    check_count(repetitions, "--repetitions")
    check_seed(seed)
    check_in_range(variation, "--variation", 0.0, 0.1)
    early(folder, "FOLDER", folder=True)
    index = make_rig(seed, frf_folder, rig_grade).campaign(
        folder, speed=speed, load=load, duration=duration, healthy=healthy,
        sizes=tuple(size), repetitions=repetitions, variation=variation)
    typer.echo(f"{len(index)} recordings written to {folder}")
