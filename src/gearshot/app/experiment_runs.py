"""The paper's experiments as the command line runs them: database, data, fit, results.

Each function does one ``gearshot experiment`` command's work (build the simulated
database it needs, record or reuse the rig campaign, run the sweep on a Dask cluster) and
returns what the command prints and writes, so that the command only parses its options.

* :func:`run_simulated_experiment`: Sec. 4.1 (``experiment simulated``);
* :func:`run_rig_experiment`: Sec. 4.2 on one virtual rig (``experiment rig``);
* :func:`run_rig_family`: issue #12's family of rigs (``experiment rig-family``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .._cluster import dask_client
from ..paper import (
    PAPER_LOADS,
    PAPER_SPEEDS,
    RIG_HEALTHY_RECORDINGS,
    RIG_REPETITIONS,
    TABLE1_SIZES,
)

__all__ = ["ExperimentRun", "run_simulated_experiment", "run_rig_experiment",
           "run_rig_family", "family_results_file", "simulated_store_tag"]


@dataclass
class ExperimentRun:
    """What an experiment command prints and writes.

    Attributes
    ----------
    table : pandas.DataFrame or dict
        The summary printed (mean MAE % per variant; the family: its dict of tables,
        :func:`gearshot.experiments.family.family_tables`).
    payload : dict
        The ``--json`` document.
    results : pandas.DataFrame
        One row per dataset (and variant).
    predictions : pandas.DataFrame or None
        Per-segment predictions (``experiment rig``).
    estimator : OneFaultShotEstimator or None
        The first draw's fitted full estimator (``experiment rig`` with figures).
    extra : dict
        Anything else the command reports (the family: its ``results`` file).
    """

    table: Any
    payload: dict
    results: Any
    predictions: Any = None
    estimator: Any = None
    extra: dict = field(default_factory=dict)


def simulated_store_tag(speeds, loads, *, paper: bool) -> str:
    """The part of a default database name that says its conditions."""
    if paper:
        return "paper"
    return ("-".join(f"{s:g}" for s in speeds) + "rps-"
            + "-".join(f"{ld:g}" for ld in loads) + "Nm")


def run_simulated_experiment(store: Path | None, *, speeds, loads, grade: int,
                             attenuations_db, frf_folder: Path | None,
                             selection_tf: str | None, seed: int, n_healthy: int,
                             n_faulty: int, paper: bool = False, scheduler: str | None = None,
                             workers: int = 2) -> ExperimentRun:
    """Sec. 4.1: build the database (if missing) and run the sweep over TFs × conditions.

    ``paper=True`` is the paper's grid (:data:`gearshot.paper.PAPER_SPEEDS` ×
    :data:`~gearshot.paper.PAPER_LOADS`) instead of ``speeds`` × ``loads``; ``store``
    defaults to a database under the data home named after the conditions, grade,
    counts and seed.
    """
    from ..experiments import SIMULATED_VARIANTS, simulated_experiment, summarize
    from ..sim import GearPair, build_database, default_database_path

    if paper:
        speeds, loads = PAPER_SPEEDS, PAPER_LOADS
    tag = simulated_store_tag(speeds, loads, paper=paper)
    store = store or default_database_path(
        f"sim-db-{tag}-grade{grade}-h{n_healthy}-f{n_faulty}-s{seed}")
    with dask_client(scheduler, workers, needed=len(speeds) * len(loads) > 1) as client:
        build_database(store, GearPair.paper(), speeds=speeds, loads=loads, grades=[grade],
                       n_healthy=n_healthy, n_faulty=n_faulty, seed=seed, client=client)
        results = simulated_experiment(store, speeds=speeds, loads=loads, grade=grade,
                                       frf_folder=frf_folder, selection_tf=selection_tf,
                                       attenuations_db=attenuations_db, seed=seed,
                                       client=client)
    table = summarize(results)
    by_variant = dict(zip(table["variant"], table["mae_percent"]))
    payload = {"experiment": "simulated", "mae": by_variant.get("full"),
               "ablations": by_variant, "n_datasets": int(len(results) / len(SIMULATED_VARIANTS)),
               "rows": results.to_dict(orient="records")}
    return ExperimentRun(table=table, payload=payload, results=results)


def _rig_campaign(campaign: Path | None, *, seed: int, speed: float, load: float,
                  duration: float, frf_folder: Path | None, rig_grade: int | None,
                  attenuation_db: float | None) -> Path:
    """The Table-1 campaign of the rig ``seed`` at one condition (recorded once, cached)."""
    from .campaigns import cached_campaign, folder_digest, make_rig

    rig = make_rig(seed, frf_folder, rig_grade)
    inputs: dict[str, Any] = {
        "seed": seed, "speed": speed, "load": load, "rig_grade": rig_grade,
        "attenuation_db": attenuation_db, "duration": duration,
        "frf_sha256": folder_digest(frf_folder), "healthy": RIG_HEALTHY_RECORDINGS,
        "sizes": list(TABLE1_SIZES), "repetitions": RIG_REPETITIONS, "fs": float(rig.fs)}

    def record(folder: Path) -> None:
        real = rig if attenuation_db is None else rig.with_reality(
            attenuation_db=attenuation_db)
        real.campaign(folder, speed=speed, load=load, duration=duration,
                      healthy=inputs["healthy"], sizes=tuple(inputs["sizes"]),
                      repetitions=inputs["repetitions"])

    return cached_campaign(campaign, inputs, record)


def run_rig_experiment(campaign: Path | None, store: Path | None, *, speed: float,
                       load: float, seed: int, duration: float, repeats: int, n_healthy: int,
                       n_faulty: int, params: dict, frf_folder: Path | None = None,
                       rig_grade: int | None = None, attenuation_db: float | None = None,
                       paired: bool = True, keep_estimator: bool = False,
                       scheduler: str | None = None, workers: int = 2) -> ExperimentRun:
    """Sec. 4.2 on one virtual rig: the database (grades 1–12 at the condition), the rig's
    campaign (:func:`gearshot.app.campaigns.cached_campaign`) and the five variants of
    Fig. 14 over ``repeats`` draws of the example; ``keep_estimator``: keep the first
    draw's full estimator (for the figures)."""
    import numpy as np

    from ..experiments import RIG_VARIANTS, rig_experiment, summarize
    from ..sim import GearPair, build_database, default_database_path, load_database
    from ..transfer import TransferFunctionBank

    store = store or default_database_path(
        f"sim-db-{speed:g}rps-{load:g}Nm-h{n_healthy}-f{n_faulty}-s{seed}"
        + ("-paired" if paired else ""))
    with dask_client(scheduler, workers, needed=True) as client:
        build_database(store, GearPair.paper(), speeds=[speed], loads=[load],
                       grades=range(1, 13), n_healthy=n_healthy, n_faulty=n_faulty,
                       seed=seed, client=client, paired=paired)
    database = load_database(store, speed=speed, load=load)
    campaign = _rig_campaign(campaign, seed=seed, speed=speed, load=load, duration=duration,
                             frf_folder=frf_folder, rig_grade=rig_grade,
                             attenuation_db=attenuation_db)
    selection = TransferFunctionBank.synthetic(1, rng=np.random.default_rng([seed, 99]))[0]
    results, predictions = rig_experiment(campaign, database, speed=speed, load=load,
                                          selection_tf=selection, variants=RIG_VARIANTS,
                                          n_repeats=repeats, seed=seed,
                                          keep_estimators="first" if keep_estimator else False,
                                          params=params)
    estimator = None
    if "estimator" in results:
        estimator = results.loc[results["variant"] == "full", "estimator"].dropna().iloc[0]
        results = results.drop(columns="estimator")
    table = summarize(results)
    by_variant = dict(zip(table["variant"], table["mae_percent"]))
    payload = {"experiment": "rig", "speed": speed, "load": load, "params": params,
               "mae": by_variant.get("full"), "ablations": by_variant,
               "rows": results.to_dict(orient="records")}
    return ExperimentRun(table=table, payload=payload, results=results,
                         predictions=predictions, estimator=estimator)


def family_results_file(seed_range: str | None) -> Path:
    """The default results file of a family run: ``DATA_HOME/family/<range>.jsonl``
    (``seeds.jsonl`` for explicit seeds, ``seed_range`` None)."""
    from .. import data_home

    return data_home() / "family" / f"{seed_range or 'seeds'}.jsonl"


def run_rig_family(seeds, *, seed_range: str | None, results: Path | None, draws: int,
                   variants, frf_folder: Path | None, segments: int, repetitions: int,
                   params: dict, paired: bool = True, rigs_cache: Path | None = None,
                   scheduler: str | None = None, workers: int = 1,
                   checked: bool = False) -> ExperimentRun:
    """Issue #12's family of virtual rigs ``seeds`` (resumable): the family's database
    under ``DATA_HOME/family``, the rows of this configuration and the summary tables.

    ``seed_range`` names the range the seeds come from (None: explicit seeds); ``results``
    defaults to :func:`family_results_file`. The run's ``results`` are the rows of this
    configuration (print them with :func:`gearshot.experiments.family.format_family_tables`)
    and its ``extra["results"]`` the file.
    """
    from .. import data_home
    from ..experiments import family

    home = data_home()
    results = results or family_results_file(seed_range)
    store = family.family_database(home / "family", paired=paired)
    with dask_client(scheduler, workers, needed=len(seeds) > 1) as client:
        frame = family.rig_family_experiment(
            store, seeds, results=results, frf_folder=frf_folder, n_draws=draws,
            variants=variants, segments=segments, repetitions=repetitions, params=params,
            cache_dir=rigs_cache or home / "family" / "rigs", client=client,
            checked=checked)
    tables = family.family_tables(frame)
    payload = {"experiment": "rig-family", "range": seed_range, "seeds": list(seeds),
               "draws": draws, "params": params, "results": str(results),
               "checked": bool(checked),
               "tables": {name: json.loads(t.to_json(orient="split"))
                          for name, t in tables.items() if name != "rigs"}}
    return ExperimentRun(table=tables, payload=payload, results=frame,
                         extra={"results": results})
