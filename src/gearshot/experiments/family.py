"""A family of virtual rigs (issue #12): accuracy on machines the method was not tuned on.

Every rig is a :class:`~gearshot.rig.VirtualRig` whose hidden reality is drawn from its
seed, with three fields set by the family so that the family spans the whole reality
distribution in a balanced way:

* the true DIN grade, uniform 1 … 12 (drawn from the seed; a plain rig draws 4 … 8);
* the transfer path, one of a fixed bank: the measured FRFs of a folder (the 12 real ones
  by default) plus synthetic paths of the rig's own kind and of
  :meth:`gearshot.transfer.TransferFunctionBank.synthetic` (path ``seed % n_paths``);
* the operating condition, one of the paper's four, balanced over seeds and paths.

The attenuation (10–30 dB), sensor SNR, interference, fault shape and every other hidden
field keep the rig's own draw. Each rig records a short campaign (healthy recordings and
a few recordings per fault size) that is reduced at once to SA segments and cached as one
``.npz`` per rig; then several example draws (Sec. 4.2 splits) are evaluated for every
estimator variant. One simulated database per condition serves every rig.

Results are appended, one JSON line per (rig, draw, variant), to a results file; rows
already there (same rig, draw, variant and estimator configuration) are skipped, so a run
resumes where it stopped. Rigs run as Dask tasks when a client is given.

Choices (defaults, thresholds, …) are to be made on :data:`DEV_SEEDS` only;
:data:`HELDOUT_SEEDS` is evaluated once, at the end, and reported.

The rigs and their recordings are in :mod:`~gearshot.experiments.family_rigs`, one rig's
evaluation in :mod:`~gearshot.experiments.family_eval`, the results file's tables in
:mod:`~gearshot.experiments.family_tables`; their public names are importable from here.
"""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path

import numpy as np

from .._errors import GearshotError
from .._validation import check_int
from ..paper import RIG_HEALTHY_RECORDINGS, TABLE1_SIZES
from .family_eval import DIAGNOSTIC_VARIANTS, DISCREPANCIES
from .family_eval import family_task as _family_task
from .family_rigs import (
    DEV_SEEDS,
    HELDOUT_SEEDS,
    PAPER_CONDITIONS,
    RANGES,
    SA_PIPELINE_VERSION,
    SPENT_HELDOUT_SEEDS,
    FamilyRig,
    config_hash,
    draw_family,
    family_paths,
    path_kind,
    true_path_on_grid,
)
from .family_rigs import campaign_duration as _duration  # noqa: F401  (tests use it)
from .family_rigs import tf_digest as _tf_digest  # noqa: F401  (tests use it)
from .family_tables import family_tables, format_family_tables, read_family_results

__all__ = ["PAPER_CONDITIONS", "DEV_SEEDS", "HELDOUT_SEEDS", "SPENT_HELDOUT_SEEDS",
           "SA_PIPELINE_VERSION", "FamilyRig", "DIAGNOSTIC_VARIANTS", "DISCREPANCIES",
           "family_paths", "draw_family", "rig_family_experiment", "family_tables", "path_kind",
           "family_database", "parse_params", "format_family_tables", "RANGES",
           "read_family_results", "true_path_on_grid"]


# ------------------------------------------------------------------ the experiment
def rig_family_experiment(store, seeds, *, results, frf_folder=None, n_synthetic=4,
                          bank_seed=2023, conditions=PAPER_CONDITIONS, n_draws=2,
                          variants=("full",), duration=None, segments=4,
                          healthy=RIG_HEALTHY_RECORDINGS,
                          sizes=TABLE1_SIZES, repetitions=2, params=None,
                          cache_dir=None, client=None, progress=True, checked=False):
    """Evaluate the estimator variants on a family of virtual rigs; resumable.

    Parameters
    ----------
    store : path
        Simulated database holding every condition of ``conditions`` at grades 1–12
        (:func:`gearshot.sim.build_database`); one database serves every rig.
    seeds : iterable of int
        Rig seeds (e.g. :data:`DEV_SEEDS` or :data:`HELDOUT_SEEDS`).
    results : path
        JSON-lines results file (appended; rows already there are not recomputed).
    frf_folder : path, optional
        Measured FRFs for the path bank (see :func:`family_paths`).
    n_synthetic, bank_seed : int
        Synthetic paths of each kind in the bank, and their seed.
    conditions : sequence of (speed, load)
    n_draws : int
        Example draws (Sec. 4.2 splits) per rig.
    variants : sequence of str
        Estimator variants (:data:`gearshot.experiments.VARIANTS`).
    duration, segments, healthy, sizes, repetitions
        Each rig's campaign: ``healthy`` healthy recordings and ``repetitions`` per fault
        size, each ``duration`` s or, by default, long enough for ``segments`` 50-cycle
        SAs at the rig's speed (4: 30.5 s at 15 rps, 15.3 s at 30 rps).
    params : dict, optional
        Estimator parameters applied to every variant (a variant's own settings win).
        Part of the configuration key: other ``params`` give new rows.
    checked : bool, default False
        Fit as ``gearshot predict`` does, checking itself: the last quarter of each
        training healthy recording's segments and the example recording's other
        segments are held out (:meth:`~gearshot.experiments.RigDataset.fit_kwargs`), so
        every row's ``fit_check`` is a verdict; a new configuration (part of the key).
    cache_dir : path, optional
        Where rigs' SA segments are cached (default ``<results>.rigs/``).
    client : dask.distributed.Client, optional
        Run rigs as Dask tasks; in-process when None.

    Returns
    -------
    pandas.DataFrame
        Rows of this configuration for ``seeds`` (``mae``, ``coverage``, ``grade`` …, with
        the rig's ``seed, speed, load, grade, path, kind, attenuation_db`` and ``draw``).
    """
    results = Path(results)
    params = dict(params or {})
    n_draws = check_int(n_draws, "n_draws", minimum=1)
    campaign = dict(duration=None if duration is None else float(duration),
                    segments=check_int(segments, "segments", minimum=1), healthy=int(healthy),
                    sizes=[float(y) for y in sizes], repetitions=int(repetitions),
                    sa_pipeline=SA_PIPELINE_VERSION)
    paths = family_paths(frf_folder, n_synthetic=n_synthetic, seed=bank_seed)
    # the key holds every estimator parameter in effect (explicit ones and the library's
    # defaults, so that a changed default is a new configuration) and the path bank
    # (another bank is another family)
    key = dict(params=_effective_params(params), campaign=campaign, store=str(store),
               bank=[p.name for p in paths])
    if checked:   # only then: the key of every earlier configuration stays as it was
        key["checked"] = True
    config = config_hash(key)
    rigs = draw_family(seeds, paths, conditions=conditions)
    cache_dir = Path(cache_dir) if cache_dir else results.with_name(results.name + ".rigs")
    done = _done_rows(results, config)
    specs = []
    for rig in rigs:
        have = done.get(rig.seed, set())
        draws = list(range(n_draws))
        if all((d, v) in have for d in draws for v in variants):
            continue
        specs.append(dict(rig=asdict(rig), frf_folder=None if frf_folder is None
                          else str(frf_folder), n_synthetic=n_synthetic, bank_seed=bank_seed,
                          cache_dir=str(cache_dir), campaign=campaign, store=str(store),
                          draws=draws, variants=list(variants), params=params,
                          config=config, done=sorted(have), checked=bool(checked)))
    for spec in specs:
        spec["done"] = {tuple(x) for x in spec["done"]}
    results.parent.mkdir(parents=True, exist_ok=True)
    _run(specs, results, client, progress, total=len(rigs))
    frame = read_family_results(results)
    if frame.empty:
        return frame
    wanted = set(int(s) for s in seeds)
    keep = (frame["config"] == config) & frame["seed"].isin(wanted) \
        & frame["variant"].isin(list(variants)) & (frame["draw"] < n_draws)
    return frame[keep].reset_index(drop=True)


def _effective_params(params: dict) -> dict:
    """Every estimator parameter in effect with ``params`` (defaults filled in)."""
    from ..estimator import OneFaultShotEstimator

    full = OneFaultShotEstimator(**params).get_params(deep=False)
    full.pop("random_state", None)   # set per (rig, draw) by the experiment
    return {k: (list(v) if isinstance(v, range) else v) for k, v in full.items()}


def _run(specs, results: Path, client, progress, total):
    from .._progress import progress as progress_of

    def append(rows):
        with open(results, "a") as fh:
            for row in rows:
                fh.write(json.dumps(row, default=_json_default) + "\n")

    with progress_of("rig family", total, completed=total - len(specs),
                     enabled=progress) as bar:
        if client is None:
            for spec in specs:
                append(_family_task(spec))
                bar.advance()
        else:
            from dask.distributed import as_completed

            futures = [client.submit(_family_task, spec, pure=False) for spec in specs]
            for fut in as_completed(futures):
                append(fut.result())
                bar.advance()


def _json_default(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return str(value)



def _done_rows(results: Path, config: str) -> dict:
    frame = read_family_results(results)
    done: dict = {}
    if frame.empty:
        return done
    frame = frame[frame["config"] == config]
    for seed, draw, variant in zip(frame["seed"], frame["draw"], frame["variant"]):
        done.setdefault(int(seed), set()).add((int(draw), str(variant)))
    return done


# ------------------------------------------------------------------ shared by the CLI
def family_database(folder, *, paired=True, client=False, progress=True) -> Path:
    """The family's simulated database (built if missing; resumable).

    Grades 1–12 at the four paper conditions, 50 healthy + 350 faulty signals per block,
    seed 0, in ``folder/db-4conditions-h50-f350-s0`` (``-paired`` with the healthy twins,
    which the estimator's default ``EstimatorOptions.simulated_reference="auto"`` uses; its
    SAs equal the plain store's).
    """
    from ..sim import GearPair, build_database

    store = Path(folder) / ("db-4conditions-h50-f350-s0" + ("-paired" if paired else ""))
    build_database(store, GearPair.paper(), speeds=sorted({s for s, _ in PAPER_CONDITIONS}),
                   loads=sorted({ld for _, ld in PAPER_CONDITIONS}),
                   grades=range(1, 13), n_healthy=50, n_faulty=350, seed=0, client=client,
                   progress=progress, paired=bool(paired))
    return store


def parse_params(items, *, option="--param") -> dict:
    """Estimator parameters from ``NAME=VALUE`` strings (VALUE as JSON when it parses).

    Unknown names and values the estimator refuses raise a :class:`GearshotError` that
    names ``option`` and quotes the item.
    """
    from ..estimator import OneFaultShotEstimator, check_estimator_params

    known = OneFaultShotEstimator().get_params(deep=False)
    params = {}
    for item in items:
        name, sep, value = str(item).partition("=")
        if not sep or not name:
            raise GearshotError(f"{option} must be NAME=VALUE; got {item!r}")
        if name not in known:
            raise GearshotError(f"{option} {item!r}: {name!r} is not an estimator parameter "
                                f"(they are {sorted(known)})")
        try:
            params[name] = json.loads(value)
        except json.JSONDecodeError:
            params[name] = value
    est = OneFaultShotEstimator(**params)
    try:
        check_estimator_params(est)
    except GearshotError as exc:
        raise GearshotError(f"{option}: {exc}") from None
    return params

