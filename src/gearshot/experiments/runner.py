"""Running the paper's experiments: many datasets × estimator variants, resumably, on Dask."""

from __future__ import annotations

import hashlib
import json
import time
from pathlib import Path

import numpy as np
import pandas as pd

from .._atomic import atomic_path
from .._errors import GearshotError
from .._validation import check_attenuation
from .variants import RIG_VARIANTS, SIMULATED_VARIANTS, variant_params

__all__ = ["evaluate_variants", "simulated_experiment", "rig_experiment", "summarize",
           "check_selection_tf"]


def evaluate_variants(fit_args, test_sa, test_size, *, variants, selection_tf,
                      random_state=0, keep_estimators=False, coverage=0.9,
                      estimator_class=None, fit_kwargs=None, **params):
    """Fit every variant on one dataset and score it on its test set.

    ``estimator_class`` (default :class:`OneFaultShotEstimator`) is what is fitted; the
    family's diagnostics pass a subclass. ``fit_args`` (and ``fit_kwargs``, e.g. the SAs'
    tooth counts) go to every ``fit``; ``params`` to every estimator. The variants share
    their target-side work (:func:`gearshot.estimator._shared_work.shared_target_work`:
    step 6's alignment and step 7's target features are done once per distinct input;
    the numbers are those of separate fits, bit for bit), so a variant's ``seconds`` is
    shorter when an earlier one did that work.

    Returns
    -------
    list of dict
        One row per variant: ``variant``, ``mae``, ``grade``, ``selected``, ``n_neighbors``,
        ``coverage`` (share of test sizes inside the ``coverage`` prediction interval),
        ``width`` (the mean width of those intervals),
        ``seconds``, plus ``prediction`` (array) and, with ``keep_estimators``, ``estimator``.
    """
    from ..estimator import OneFaultShotEstimator
    from ..estimator._shared_work import shared_target_work

    rows = []
    with shared_target_work():   # the variants share the target-side work on one dataset
        for name in variants:
            rows.append(_evaluate_one(
                (estimator_class or OneFaultShotEstimator)(
                    random_state=random_state, **{**params, **variant_params(name)}),
                name, fit_args, fit_kwargs, test_sa, test_size, selection_tf, coverage,
                keep_estimators))
    return rows


def _evaluate_one(est, name, fit_args, fit_kwargs, test_sa, test_size, selection_tf,
                  coverage, keep_estimators):
    """Fit one variant's estimator and score it (one row of :func:`evaluate_variants`)."""
    t0 = time.perf_counter()
    est.fit(*fit_args, selection_tf=selection_tf, **dict(fit_kwargs or {}))
    pred = est.predict(test_sa)
    seconds = time.perf_counter() - t0
    low, high = est.predict_interval(test_sa, coverage=coverage)
    inside = (test_size >= low - 1e-12) & (test_size <= high + 1e-12)
    row = dict(variant=name, mae=float(np.mean(np.abs(pred - test_size))),
               grade=est.grade_, selected=",".join(est.selected_features_),
               n_neighbors=est.n_neighbors_, coverage=float(np.mean(inside)),
               width=float(np.mean(high - low)), seconds=seconds, prediction=pred)
    if keep_estimators:
        row["estimator"] = est
    return row


# ------------------------------------------------------------------ resumable result store
def _task_key(spec: dict) -> str:
    text = json.dumps(spec, sort_keys=True, default=str)
    return hashlib.sha1(text.encode()).hexdigest()[:16]


def _write_parquet_atomic(frame: pd.DataFrame, path: Path) -> None:
    with atomic_path(path) as tmp:
        frame.to_parquet(tmp, index=False)


def _simulated_task(spec: dict) -> pd.DataFrame:
    """One (speed, load, attenuation): every test TF × variant. Runs on a Dask worker."""
    from ..sim import load_database
    from .simulated import simulated_dataset

    db = load_database(spec["store"], speed=spec["speed"], load=spec["load"],
                       grade=spec["grade"])
    sa = db["sa"].values
    y = db["fault_size"].values
    bank = _bank(spec)
    selection = bank[spec["selection_tf"]]
    rows = []
    for name in spec["tfs"]:
        ds = simulated_dataset(sa, y, bank[name], grade=spec["grade"],
                               attenuation_db=spec["attenuation_db"],
                               random_state=[spec["seed"], spec["tfs"].index(name)],
                               attrs=db.attrs)
        for row in evaluate_variants(ds.fit_args(), ds.test_sa, ds.test_size,
                                     variants=spec["variants"], selection_tf=selection,
                                     random_state=spec["seed"], nominal_grade=spec["grade"],
                                     estimator="paper"):   # the paper's sweep: its KNN
            row.pop("prediction")
            rows.append(dict(speed=spec["speed"], load=spec["load"], tf=name,
                             attenuation_db=spec["attenuation_db"], seed=spec["seed"], **row))
    return pd.DataFrame(rows)


def _bank(spec):
    from ..transfer import TransferFunctionBank

    if spec.get("frf_folder"):
        return TransferFunctionBank.from_folder(spec["frf_folder"])
    return TransferFunctionBank.synthetic(spec.get("n_synthetic", 24),
                                          rng=np.random.default_rng(spec["seed"]))


def _run_specs(specs, task, results_dir: Path, client, description: str) -> pd.DataFrame:
    """Run tasks whose result file is missing; return all results. Resumable."""
    from .._progress import progress

    results_dir.mkdir(parents=True, exist_ok=True)
    todo = []
    for spec in specs:
        path = results_dir / f"{_task_key(spec)}.parquet"
        if not path.exists():
            todo.append((spec, path))
    with progress(description, len(specs), completed=len(specs) - len(todo)) as bar:
        if client is None:
            for spec, path in todo:
                _write_parquet_atomic(task(spec), path)
                bar.advance()
        else:
            from dask.distributed import as_completed

            futures = {client.submit(task, spec, pure=False): path for spec, path in todo}
            for fut in as_completed(futures):
                _write_parquet_atomic(fut.result(), futures[fut])
                bar.advance()
    frames = [pd.read_parquet(results_dir / f"{_task_key(s)}.parquet") for s in specs]
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()


def _held_out(bank_spec: dict, selection_tf) -> tuple[str, list[str]]:
    """The held-out TF's name and the others' names of the bank of ``bank_spec``."""
    names = list(_bank(bank_spec).names)
    held = selection_tf if selection_tf is not None else names[-1]
    if held not in names:
        shown = names if len(names) <= 8 else names[:4] + ["..."] + names[-2:]
        raise GearshotError(f"selection_tf {held!r} is not in the bank {shown}")
    return held, [n for n in names if n != held]


def check_selection_tf(frf_folder=None, selection_tf=None, *, seed=0) -> str:
    """The name of the TF :func:`simulated_experiment` holds out for feature selection
    (``selection_tf``, default the bank's last), checked before any work: a
    :class:`~gearshot.GearshotError` when the bank has no TF of that name.

    Parameters
    ----------
    frf_folder : path, optional
        Folder of measured FRFs; default the synthetic bank of 24.
    selection_tf : str, optional
    seed : int
        The synthetic bank's seed (the experiment's).

    Returns
    -------
    str
    """
    spec = dict(frf_folder=str(frf_folder) if frf_folder else None, seed=seed)
    return _held_out(spec, selection_tf)[0]


def simulated_experiment(store, *, speeds, loads, grade=7, frf_folder=None,
                         selection_tf=None, attenuations_db=(10.0,), variants=SIMULATED_VARIANTS,
                         seed=0, results_dir=None, client=None):
    """The paper's Sec. 4.1 sweep: datasets over TFs × speeds × loads × attenuations.

    Parameters
    ----------
    store : path
        Simulated database (built with :func:`gearshot.sim.build_database`) holding every
        requested speed and load at ``grade``.
    speeds, loads : sequences of float
    grade : int
        Grade of the simulated signals (training and test share it in Sec. 4.1).
    frf_folder : path, optional
        Folder of measured FRFs (UFF58/CSV); default a synthetic bank of 24.
    selection_tf : str, optional
        Name of the TF held out for feature selection (default the bank's last).
    attenuations_db : sequence of float
    variants : sequence of str
    seed : int
    results_dir : path, optional
        Where per-task results are kept (resumable); default ``<store>/experiments/...``.
    client : dask.distributed.Client, optional

    Returns
    -------
    pandas.DataFrame
        One row per (speed, load, tf, attenuation, variant) with its MAE.
    """
    store = Path(store)
    for a in attenuations_db:
        check_attenuation(a, "attenuations_db[]")
    bank_spec = dict(frf_folder=str(frf_folder) if frf_folder else None, seed=seed)
    held, tfs = _held_out(bank_spec, selection_tf)
    specs = [dict(store=str(store), speed=float(s), load=float(ld), grade=int(grade),
                  attenuation_db=float(a), tfs=tfs, selection_tf=held,
                  variants=list(variants), **bank_spec)
             for s in speeds for ld in loads for a in attenuations_db]
    results_dir = Path(results_dir) if results_dir else store / "experiments" / "simulated"
    return _run_specs(specs, _simulated_task, results_dir, client,
                      "simulated datasets")


def rig_experiment(campaign, database, *, speed, load, selection_tf, variants=RIG_VARIANTS,
                   n_repeats=1, seed=0, keep_estimators=False, params=None):
    """The paper's Sec. 4.2 experiment on one condition's campaign.

    Parameters
    ----------
    params : dict, optional
        Estimator parameters for every variant (a variant's own settings win).
    keep_estimators : bool or "first"
        Keep the fitted estimators in an ``estimator`` column: of every repeat (True) or of
        the first repeat only (``"first"``, enough to draw one run's figures).

    Returns
    -------
    results : pandas.DataFrame
        One row per (repeat, variant) with the MAE and fitted grade/features.
    predictions : pandas.DataFrame
        ``repeat, variant, true, predicted, recording``.
    """
    from .rig import rig_dataset

    if keep_estimators not in (True, False, "first"):
        raise GearshotError(f"keep_estimators must be True, False or 'first'; got "
                            f"{keep_estimators!r}")
    cache: dict = {}
    rows, preds = [], []
    for r in range(int(n_repeats)):
        ds = rig_dataset(campaign, speed=speed, load=load, random_state=[seed, r],
                         segments=cache)
        for row in evaluate_variants(ds.fit_args(database), ds.test_sa, ds.test_size,
                                     variants=variants, selection_tf=selection_tf,
                                     random_state=seed + r, fit_kwargs=ds.fit_kwargs(False),
                                     keep_estimators=keep_estimators is True
                                     or (keep_estimators == "first" and r == 0),
                                     **dict(params or {})):
            pred = row.pop("prediction")
            preds.append(pd.DataFrame(dict(repeat=r, variant=row["variant"],
                                           true=ds.test_size, predicted=pred,
                                           recording=ds.test_recording)))
            rows.append(dict(repeat=r, speed=speed, load=load,
                             example_size=ds.faulty_size, **row))
    return pd.DataFrame(rows), pd.concat(preds, ignore_index=True)


def summarize(results: pd.DataFrame, by=("variant",)) -> pd.DataFrame:
    """Mean MAE (in %) grouped by ``by``."""
    out = results.groupby(list(by))["mae"].mean().mul(100).rename("mae_percent")
    return out.reset_index()
