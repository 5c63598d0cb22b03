"""``gearshot experiment``: the paper's experiments (Sec. 4.1, 4.2) and the rig family.

Each command checks its options, calls its service in :mod:`gearshot.app.experiment_runs`
and prints (and writes) what the service returns.
"""

from __future__ import annotations

from pathlib import Path

import typer

from ..._errors import GearshotError
from ...paper import RIG_DURATION, RIG_LOAD, RIG_SPEED
from ._apps import experiment_app
from ._options import (
    HELP_PARAM,
    FiguresOut,
    NFaulty,
    NHealthy,
    ResultsJson,
    RigGrade,
    Scheduler,
    Workers,
    check_attenuations,
    check_condition,
    check_count,
    check_counts,
    check_duration,
    check_frf_folder,
    check_seed,
    check_store_folder,
    early,
    refuse_together,
    write_json,
)

__all__ = ["experiment_simulated", "experiment_rig", "experiment_rig_family"]

HELP_RANGE = ("Seed range: dev (100–123; every choice is made here), heldout (9500–9523; "
              "evaluate once, at the end) or spent (9000–9023, issue #12's held-out range, "
              "evaluated twice).")
HELP_VARIANT = ("Estimator variant(s): full, no_feature_selection, no_tuning, before_da, "
                "rms_only, zero_shot (repeat the option).")
HELP_FAMILY_FRF = ("Measured FRFs of the path bank (the family of issue #12 uses the 12 real "
                   "ones); synthetic paths only when omitted.")
HELP_RIG_PAIRED = ("Build and use the database with healthy twins (default): the estimator's "
                   "options.simulated_reference='auto' then subtracts each signal's own "
                   "twin (steps 1 and 6). --no-paired: the old layout.")
HELP_FAMILY_PAIRED = ("Use the database with healthy twins (default; the estimator's "
                      "options.simulated_reference='auto' then uses them). --no-paired: the old "
                      "layout.")


@experiment_app.command("simulated")
def experiment_simulated(
    ctx: typer.Context,
    store: Path | None = typer.Option(None, "--store", help="Database store (built if "
                                         "missing)."),
    speed: list[float] = typer.Option([RIG_SPEED], "--speed", help="Input speed(s), rps "
                                      "(repeat the option)."),
    load: list[float] = typer.Option([RIG_LOAD], "--load", help="Load(s), N m (repeat the "
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
    n_healthy: NHealthy = 100,
    n_faulty: NFaulty = 700,
    json_out: ResultsJson = None,
    out: FiguresOut = None,
    scheduler: Scheduler = None,
    workers: Workers = 2,
) -> None:
    """Sec. 4.1: simulated signals through measured TFs; before DA / RMS only / full."""
    for other in ("--speed", "--load"):
        refuse_together(ctx, "--full", other, "--full runs the paper's 26 speeds × 4 loads")
    check_frf_folder(frf_folder, minimum=2)      # one held out for selection, one to test
    if not full:
        check_condition(speed, load)
    if not 1 <= grade <= 12:
        raise GearshotError(f"--grade must be 1 … 12; got {grade}")
    check_attenuations(attenuation_db)
    check_seed(seed)
    check_counts(n_healthy, n_faulty, workers)
    # each dataset splits the healthy signals (training, target, test) and the faulty
    # ones (training, test and the example): gearshot.experiments.simulated_dataset
    check_count(n_healthy, "--n-healthy", minimum=8, maximum=100_000)
    check_count(n_faulty, "--n-faulty", minimum=4, maximum=100_000)
    check_store_folder(store)
    early(json_out, "--json")
    early(out, "--out", folder=True)
    early(store, "--store", folder=True)
    from ...experiments import check_selection_tf
    from ..experiment_runs import run_simulated_experiment

    try:
        check_selection_tf(frf_folder, selection_tf, seed=seed)
    except GearshotError as exc:
        raise GearshotError(f"--selection-tf: {exc}") from None

    run = run_simulated_experiment(store, speeds=speed, loads=load, grade=grade,
                                   attenuations_db=attenuation_db, frf_folder=frf_folder,
                                   selection_tf=selection_tf, seed=seed, n_healthy=n_healthy,
                                   n_faulty=n_faulty, paper=full, scheduler=scheduler,
                                   workers=workers)
    typer.echo(run.table.to_string(index=False))
    write_json(json_out, run.payload)
    if out is not None:
        from ..figures import simulated_figures

        simulated_figures(run.results, out)


@experiment_app.command("rig")
def experiment_rig(
    campaign: Path | None = typer.Option(None, "--campaign", help="Campaign folder "
                                            "(recorded if missing)."),
    store: Path | None = typer.Option(None, "--store", help="Database store (built if "
                                         "missing; default under gearshot's data home)."),
    speed: float = typer.Option(RIG_SPEED, "--speed", help="Input speed, rps."),
    load: float = typer.Option(RIG_LOAD, "--load", help="Load, N m."),
    seed: int = typer.Option(0, "--seed", help="Seed of the database, rig and splits."),
    frf_folder: Path | None = typer.Option(None, "--frf-folder", help="Measured FRFs for "
                                              "the rig's path (default synthetic)."),
    rig_grade: RigGrade = None,
    attenuation_db: float | None = typer.Option(None, "--attenuation-db",
                                                   help="Rig path attenuation (default "
                                                   "hidden, 10–30 dB)."),
    duration: float = typer.Option(RIG_DURATION, "--duration", help="Seconds per recording."),
    repeats: int = typer.Option(5, "--repeats", help="Random example draws."),
    n_healthy: NHealthy = 100,
    n_faulty: NFaulty = 700,
    json_out: ResultsJson = None,
    out: FiguresOut = None,
    param: list[str] = typer.Option([], "--param", help=HELP_PARAM),
    paired: bool = typer.Option(True, "--paired/--no-paired", help=HELP_RIG_PAIRED),
    scheduler: Scheduler = None,
    workers: Workers = 2,
) -> None:
    """Sec. 4.2: virtual-rig recordings; the five variants of Fig. 14 (the paper's KNN;
    --param 'estimator="boosting"' for the library's default regressor)."""
    from ..campaigns import check_rig_grade

    check_frf_folder(frf_folder)
    check_duration(duration, speed)
    check_condition([speed], [load])
    check_rig_grade(rig_grade)
    check_seed(seed)
    if attenuation_db is not None:
        check_attenuations([attenuation_db])
    check_count(repeats, "--repeats", minimum=1, maximum=1000)
    check_counts(n_healthy, n_faulty, workers)
    check_store_folder(store)
    for path, option in ((json_out, "--json"), (out, "--out"), (store, "--store"),
                         (campaign, "--campaign")):
        early(path, option, folder=option != "--json")
    from ...experiments.family import parse_params
    from ..experiment_runs import run_rig_experiment

    run = run_rig_experiment(campaign, store, speed=speed, load=load, seed=seed,
                             duration=duration, repeats=repeats, n_healthy=n_healthy,
                             n_faulty=n_faulty,   # Fig. 14 is the paper's estimator's
                             params={"estimator": "paper", **parse_params(param)},
                             frf_folder=frf_folder, rig_grade=rig_grade,
                             attenuation_db=attenuation_db, paired=paired,
                             keep_estimator=out is not None, scheduler=scheduler,
                             workers=workers)
    typer.echo(run.table.to_string(index=False))
    write_json(json_out, run.payload)
    if out is not None:
        from ..figures import rig_figures

        rig_figures(run.results, run.predictions, out, estimator=run.estimator)


@experiment_app.command("rig-family")
def experiment_rig_family(
    ctx: typer.Context,
    seed_range: str = typer.Option("dev", "--range", help=HELP_RANGE),
    seeds: list[int] = typer.Option([], "--seed", help="Explicit rig seed(s) instead of "
                                    "--range (results file 'seeds.jsonl')."),
    n_rigs: int | None = typer.Option(None, "--n-rigs", help="The first N seeds only."),
    draws: int = typer.Option(2, "--draws", help="Example draws (Sec. 4.2 splits) per rig."),
    variants: list[str] = typer.Option(["full"], "--variant", help=HELP_VARIANT),
    frf_folder: Path | None = typer.Option(None, "--frf-folder", help=HELP_FAMILY_FRF),
    segments: int = typer.Option(4, "--segments", help="50-cycle SAs per recording."),
    repetitions: int = typer.Option(2, "--repetitions", help="Recordings per fault size."),
    param: list[str] = typer.Option([], "--param", help=HELP_PARAM),
    paired: bool = typer.Option(True, "--paired/--no-paired", help=HELP_FAMILY_PAIRED),
    results: Path | None = typer.Option(None, "--results", help="JSON-lines results file "
                                           "(appended, resumable; default "
                                           "DATA_HOME/family/RANGE.jsonl)."),
    rigs_cache: Path | None = typer.Option(None, "--rigs-cache", help="Folder of the rigs' "
                                              "cached SA segments (default "
                                              "DATA_HOME/family/rigs, shared by all runs)."),
    json_out: Path | None = typer.Option(None, "--json", help="Write the summary tables "
                                            "as JSON."),
    rigs_table: bool = typer.Option(False, "--rigs-table", help="Print the per-rig table."),
    checked: bool = typer.Option(False, "--checked", help="Fit as 'gearshot predict' "
                                 "does, checking itself on held-out healthy segments and "
                                 "the example recording's other segments (a new "
                                 "configuration; the tables add the fits' verdicts)."),
    scheduler: Scheduler = None,
    workers: int = typer.Option(1, "--workers", help="LocalCluster workers (rigs in "
                                "parallel) when no --scheduler is given."),
) -> None:
    """Issue #12: accuracy over a family of virtual rigs never used for tuning; resumable."""
    from ...experiments import family
    from ..experiment_runs import family_results_file, run_rig_family

    refuse_together(ctx, "--range", "--seed", "--seed names the rigs instead of a range")
    pool = _family_seeds(seed_range, seeds, n_rigs, frf_folder, variants)
    for value, option in ((draws, "--draws"), (segments, "--segments"),
                          (repetitions, "--repetitions")):
        check_count(value, option, minimum=1, maximum=100)
    check_count(workers, "--workers", minimum=1, maximum=256)
    params = family.parse_params(param)
    name = None if seeds else seed_range
    results = results or family_results_file(name)
    early(results, "--results")
    early(rigs_cache, "--rigs-cache", folder=True)
    early(json_out, "--json")
    run = run_rig_family(pool, seed_range=name, results=results, draws=draws,
                         variants=variants, frf_folder=frf_folder, segments=segments,
                         repetitions=repetitions, params=params, paired=paired,
                         rigs_cache=rigs_cache, scheduler=scheduler, workers=workers,
                         checked=checked)
    typer.echo(f"{len(pool)} rigs × {draws} draws, {len(run.results)} rows in {results}")
    typer.echo(family.format_family_tables(run.results, rigs_table=rigs_table))
    write_json(json_out, run.payload)


def _family_seeds(seed_range: str, seeds: list[int], n_rigs: int | None,
                  frf_folder: Path | None, variants: list[str]) -> list[int]:
    """The rig seeds of a family run (``--seed`` or ``--range``, the first ``--n-rigs``),
    after checking ``--range``, ``--frf-folder`` and ``--variant``."""
    from ...experiments import VARIANTS, family

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
        check_count(s, "--seed", maximum=2**31 - 1)
    pool = list(seeds) if seeds else list(family.RANGES[seed_range])
    if n_rigs is not None:
        check_count(n_rigs, "--n-rigs", minimum=1, maximum=len(pool))
        pool = pool[:n_rigs]
    return pool
