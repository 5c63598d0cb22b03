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
"""

from __future__ import annotations

import hashlib
import json
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from .._atomic import atomic_path
from .._errors import GearshotError
from .._validation import check_int
from ..paper import (
    CYCLES_PER_SEGMENT,
    GEAR_TEETH,
    PINION_TEETH,
    SAMPLES_PER_CYCLE,
    TABLE1_SIZES,
)

__all__ = ["PAPER_CONDITIONS", "DEV_SEEDS", "HELDOUT_SEEDS", "SPENT_HELDOUT_SEEDS",
           "SA_PIPELINE_VERSION", "FamilyRig",
           "family_paths", "draw_family", "rig_family_experiment", "family_tables", "path_kind",
           "family_database", "parse_params", "format_family_tables", "RANGES"]

PAPER_CONDITIONS = ((15.0, 10.0), (15.0, 5.0), (30.0, 5.0), (30.0, 10.0))
DEV_SEEDS = range(100, 124)
#: The held-out range of issue #19 (fresh: never run before the decision of
#: ``benchmarks/results/family_decision_session6.md`` was committed).
HELDOUT_SEEDS = range(9500, 9524)
#: Issue #12's held-out range, evaluated twice in session 5: spent, kept for reproduction.
SPENT_HELDOUT_SEEDS = range(9000, 9024)
#: the seed ranges by name (``--range`` of the benchmark and of the CLI)
RANGES = {"dev": DEV_SEEDS, "heldout": HELDOUT_SEEDS, "spent": SPENT_HELDOUT_SEEDS}

#: Version of the recording → SA pipeline (angular resampling, SA). Part of every rig
#: cache's key and of the results' configuration key, so that SAs and rows made by an
#: older pipeline are neither reused nor counted as done. Bump it when the SAs change.
#: 2: anti-aliased angular resampling (issue #11); 1 (implicit): before it.
SA_PIPELINE_VERSION = 2


@dataclass(frozen=True)
class FamilyRig:
    """One rig of the family: what the family sets (the rest of its reality is drawn).

    Attributes
    ----------
    seed : int
        The rig's seed (``VirtualRig(seed)``).
    speed, load : float
        Operating condition, rev/s and N m.
    grade : int
        True DIN grade of the rig's wheels.
    path_index : int
        Index of the transfer path in the family's bank.
    path : str
        Its name.
    kind : str
        ``beam``, ``structure_b``, ``synthetic_rig``, ``synthetic_bank`` or ``measured``.
    attenuation_db : float
        The rig's drawn path attenuation (for the tables; not set by the family).
    """

    seed: int
    speed: float
    load: float
    grade: int
    path_index: int
    path: str
    kind: str
    attenuation_db: float


def path_kind(name: str) -> str:
    """Type of a family path from its name (for per-type tables)."""
    for prefix in ("beam", "structure_b", "synthetic_rig", "synthetic_bank"):
        if name.startswith(prefix):
            return prefix
    return "measured"


def family_paths(frf_folder=None, *, n_synthetic=4, seed=2023):
    """The family's transfer-path bank: measured FRFs, then synthetic paths.

    Parameters
    ----------
    frf_folder : path, optional
        Folder of measured FRFs (UFF58/CSV); none when omitted.
    n_synthetic : int
        Synthetic paths of each kind: the rig's default modal paths over 0–25 kHz
        (:func:`gearshot.rig.path.synthetic_path_tfs`, named ``synthetic_rig_i``) and
        hammer-test-like FRFs (:meth:`TransferFunctionBank.synthetic`, ``synthetic_bank_i``).
    seed : int
        Seed of the synthetic paths (fixed: the bank is part of the family's definition).

    Returns
    -------
    list of gearshot.transfer.TransferFunction
    """
    import dataclasses

    from ..rig.path import as_tf_list, synthetic_path_tfs
    from ..transfer import TransferFunctionBank

    n_synthetic = check_int(n_synthetic, "n_synthetic", minimum=0)
    paths = as_tf_list(str(frf_folder)) if frf_folder is not None else []
    if n_synthetic:
        for i, tf in enumerate(synthetic_path_tfs(n_synthetic,
                                                  rng=np.random.default_rng([seed, 3]))):
            paths.append(dataclasses.replace(tf, name=f"synthetic_rig_{i}"))
        bank = TransferFunctionBank.synthetic(n_synthetic, rng=np.random.default_rng([seed, 4]))
        for i, tf in enumerate(bank):
            paths.append(dataclasses.replace(tf, name=f"synthetic_bank_{i}"))
    if not paths:
        raise GearshotError("the family needs at least one path: give frf_folder or "
                            "n_synthetic > 0")
    return paths


def draw_family(seeds, paths, *, conditions=PAPER_CONDITIONS, grades=(1, 12)):
    """The family's rigs for ``seeds`` (each depends on its own seed only).

    Path ``seed % n_paths``; condition ``(seed + seed // n_paths) % n_conditions`` (so that
    consecutive seeds cover every path and every path meets several conditions); grade
    uniform in ``grades`` (inclusive) from ``default_rng([seed, 12])``.
    """
    from ..rig import VirtualRig

    n_paths = len(paths)
    conditions = [tuple(map(float, c)) for c in conditions]
    out = []
    for seed in seeds:
        seed = check_int(seed, "seeds[i]", minimum=0)
        grade = int(np.random.default_rng([seed, 12]).integers(grades[0], grades[1] + 1))
        p = seed % n_paths
        speed, load = conditions[(seed + seed // n_paths) % len(conditions)]
        rig = _rig(VirtualRig, seed, paths, grade, p)
        out.append(FamilyRig(seed=seed, speed=speed, load=load, grade=grade, path_index=p,
                             path=paths[p].name, kind=path_kind(paths[p].name),
                             attenuation_db=float(rig.reveal().attenuation_db)))
    return out


def _rig(cls, seed, paths, grade, path_index):
    return cls(seed=seed, tf_bank=paths, grade=grade,
               reality_overrides={"tf_index": int(path_index)})


# ------------------------------------------------------------------ one rig's recordings
def _rig_segments(rig: FamilyRig, paths, cache_dir: Path, campaign: dict):
    """SA segments of one rig's campaign (recorded once, cached as ``.npz``).

    Returns the campaign index (``path`` = recording key) and the segments cache
    ``{key: (sa, angle signal or None)}`` that :func:`rig_dataset` takes.
    """
    from ..rig import VirtualRig

    tag = _hash(dict(rig=asdict(rig), campaign=campaign,
                     paths=[[p.name, _tf_digest(p)] for p in paths]))
    file = cache_dir / f"rig-{rig.seed}-{tag}.npz"
    jobs = ([(0.0, r) for r in range(campaign["healthy"])]
            + [(float(y), r) for y in campaign["sizes"] for r in range(campaign["repetitions"])])
    keys = [f"s{rig.seed}_y{y:.2f}_r{r}" for y, r in jobs]
    if not file.exists():
        vr = _rig(VirtualRig, rig.seed, paths, rig.grade, rig.path_index)
        arrays = {}
        for key, (y, r) in zip(keys, jobs):
            rec = vr.record(speed=rig.speed, load=rig.load, fault_size=y,
                            duration=_duration(campaign, rig.speed), repetition=r)
            arrays[f"sa__{key}"] = rec.to_sa_segments(gear_teeth=GEAR_TEETH,
                                                      pinion_teeth=PINION_TEETH,
                                                      cycles_per_segment=CYCLES_PER_SEGMENT,
                                                      samples_per_cycle=SAMPLES_PER_CYCLE)
            if y == 0:
                arrays[f"long__{key}"] = rec.angle_domain(
                    gear_teeth=GEAR_TEETH, pinion_teeth=PINION_TEETH,
                    samples_per_cycle=SAMPLES_PER_CYCLE).astype(np.float32)
        with atomic_path(file, make_parents=True) as tmp:   # a unique temporary name
            np.savez(tmp, **arrays)
    with np.load(file) as data:
        segments = {k: (data[f"sa__{k}"].astype(float),
                        data[f"long__{k}"].astype(float) if f"long__{k}" in data else None)
                    for k in keys}
    index = pd.DataFrame({"path": keys, "speed": rig.speed, "load": rig.load,
                          "fault_size": [y for y, _ in jobs],
                          "repetition": [r for _, r in jobs]})
    return index, segments


def _duration(campaign, speed):
    """Seconds per recording: ``duration`` if set, else enough for ``segments`` SAs."""
    if campaign.get("duration"):
        return float(campaign["duration"])
    gear_revs_per_s = speed * PINION_TEETH / GEAR_TEETH
    return 1.02 * (campaign["segments"] * CYCLES_PER_SEGMENT + 1) / gear_revs_per_s


def _tf_digest(tf) -> str:
    """Content hash of a transfer function (its frequencies and values), not its name."""
    h = hashlib.sha256()
    for arr in (tf.freqs, tf.values):
        a = np.ascontiguousarray(arr)
        h.update(str(a.dtype).encode() + str(a.shape).encode() + a.tobytes())
    return h.hexdigest()[:16]


def _hash(obj) -> str:
    return hashlib.sha1(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()[:12]


# Diagnostics only (they use the rig's hidden truth or the test set): the full algorithm
# with the true transfer path instead of its blind estimate (oracle_tf), with its
# calibration chosen on every faulty test SA instead of the one example
# (oracle_calibration), with both (oracle_both), or with the rig's true grade and no
# tuning (true_grade). They make the error budget of issue #19.
DIAGNOSTIC_VARIANTS = ("oracle_tf", "true_grade", "oracle_calibration", "oracle_both")


def _calibration_oracle_class():
    from ..estimator import OneFaultShotEstimator

    class CalibrationOracle(OneFaultShotEstimator):
        """Diagnostic: the joint calibration explains every faulty SA of ``oracle_sa``
        (sizes ``oracle_size``) instead of the one example: the best calibration the
        grid can give on this target (an in-sample oracle; never a product)."""

        oracle_sa = None
        oracle_size = None

        def _calibration_examples(self, ctx):
            keep = np.asarray(self.oracle_size) > 0
            return (np.asarray(self.oracle_sa, float)[keep],
                    np.asarray(self.oracle_size, float)[keep])

    return CalibrationOracle


def true_path_on_grid(rig: FamilyRig, paths, n_points=SAMPLES_PER_CYCLE,
                      gear_teeth=GEAR_TEETH, pinion_teeth=PINION_TEETH):
    """The rig's hidden transfer path on the SA's DFT grid (order k at k × gear rev rate).

    For diagnostics: what the blind TF estimate (step 3) tries to recover.
    """
    from ..rig import VirtualRig

    _, fir = _rig(VirtualRig, rig.seed, paths, rig.grade, rig.path_index).reveal_path()
    f_gear = rig.speed * pinion_teeth / gear_teeth
    k = np.arange(n_points // 2 + 1)
    n = np.arange(fir.size)
    half = np.exp(-2j * np.pi * np.outer(k * f_gear / 50_000.0, n)) @ fir
    full = np.empty(n_points, complex)
    full[: half.size] = half
    nyq = full[n_points // 2]
    full[n_points // 2] = np.abs(nyq) * (1.0 if nyq.real >= 0 else -1.0)  # real at Nyquist
    full[half.size:] = np.conj(half[1: n_points - half.size + 1][::-1])
    return full


def _diagnostic_params(name, rig, paths):
    if name == "oracle_tf":
        return dict(transfer_function=true_path_on_grid(rig, paths))
    if name == "oracle_both":
        return dict(transfer_function=true_path_on_grid(rig, paths), calibration="joint")
    if name == "true_grade":
        return dict(calibration="nominal", nominal_grade=int(rig.grade))
    if name == "oracle_calibration":
        return dict(calibration="joint")
    raise GearshotError(f"unknown diagnostic variant {name!r}")


DISCREPANCIES = (0.0, 0.04, 0.06, 0.08, 0.10, 0.12, 0.14, 0.16, 0.20, 0.24)


def _interval_sweep(est, test_sa, test_size, coverage=0.9):
    """Coverage and mean width of the ``coverage`` intervals at several model
    discrepancies (one feature extraction; for choosing the discrepancy on the dev range),
    plus the grade weights."""
    from ..estimator.uncertainty import mixture_interval

    X = est.features_of(test_sa)
    settings, models = est.calibration_["settings"], est.setting_models_
    preds = {i: m.predict(X) for i, m in enumerate(models)}
    residuals = {i: m.validation_residuals for i, m in enumerate(models)}
    weights = {i: st["weight"] for i, st in enumerate(settings)}
    cov, width = {}, {}
    for d in DISCREPANCIES:
        low, high = mixture_interval(preds, weights, residuals, coverage, discrepancy=d)
        low, high = np.clip(low, 0, 1), np.clip(high, 0, 1)
        cov[f"{d:g}"] = float(np.mean((test_size >= low - 1e-12) & (test_size <= high + 1e-12)))
        width[f"{d:g}"] = float(np.mean(high - low))
    floor = sum(st["weight"] * float(m.validation_mae[m.n_neighbors - 1])
                for st, m in zip(settings, models))
    return {"coverage_by_discrepancy": cov, "width_by_discrepancy": width,
            "simulated_floor": floor,
            "grade_weights": {str(g): round(float(w), 4) for g, w in est.grade_weights_.items()},
            "calibration": [{k: (round(v, 4) if isinstance(v, float) else v)
                             for k, v in st.items()} for st in settings],
            "n_selected": len(est.selected_features_)}


def _family_task(spec: dict) -> list[dict]:
    """Every (draw, variant) of one rig; runs on a Dask worker or in-process."""
    import dask

    # the database's Zarr blocks are loaded here, not as tasks of the cluster whose
    # every worker thread is busy with a rig (that waits forever)
    with dask.config.set(scheduler="synchronous"):
        return _family_rows(spec)


def _family_rows(spec: dict) -> list[dict]:
    from ..sim import load_database
    from ..transfer import TransferFunctionBank
    from .rig import rig_dataset
    from .runner import evaluate_variants

    rig = FamilyRig(**spec["rig"])
    paths = family_paths(spec["frf_folder"], n_synthetic=spec["n_synthetic"],
                         seed=spec["bank_seed"])
    t0 = time.perf_counter()
    index, segments = _rig_segments(rig, paths, Path(spec["cache_dir"]), spec["campaign"])
    record_seconds = time.perf_counter() - t0
    database = load_database(spec["store"], speed=rig.speed, load=rig.load)
    selection = TransferFunctionBank.synthetic(1, rng=np.random.default_rng([rig.seed, 99]))[0]
    rows = []
    for draw in spec["draws"]:
        todo = [v for v in spec["variants"] if (draw, v) not in spec["done"]]
        if not todo:
            continue
        ds = rig_dataset(index, random_state=[rig.seed, draw], segments=segments)
        out = []
        plain = [v for v in todo if v not in DIAGNOSTIC_VARIANTS]
        if plain:
            out += evaluate_variants(ds.fit_args(database), ds.test_sa, ds.test_size,
                                     variants=plain, selection_tf=selection,
                                     fit_kwargs=ds.fit_kwargs(),
                                     random_state=1000 * rig.seed + draw,
                                     keep_estimators=True, **spec["params"])
        for name in (v for v in todo if v in DIAGNOSTIC_VARIANTS):
            extra = _diagnostic_params(name, rig, paths)
            factory = None
            if name in ("oracle_calibration", "oracle_both"):
                oracle = _calibration_oracle_class()
                oracle.oracle_sa, oracle.oracle_size = ds.test_sa, ds.test_size
                factory = oracle
            row, = evaluate_variants(ds.fit_args(database), ds.test_sa, ds.test_size,
                                     variants=["full"], selection_tf=selection,
                                     fit_kwargs=ds.fit_kwargs(),
                                     random_state=1000 * rig.seed + draw,
                                     keep_estimators=True, estimator_class=factory,
                                     **{**spec["params"], **extra})
            row["variant"] = name
            out.append(row)
        for row in out:
            pred = row.pop("prediction")
            row["fitted_grade"] = row.pop("grade")  # "grade" is the rig's true grade
            row.update(_interval_sweep(row.pop("estimator"), ds.test_sa, ds.test_size))
            by_size = {f"{y:.2f}": float(np.mean(pred[ds.test_size == y]))
                       for y in np.unique(ds.test_size)}
            rows.append(dict(config=spec["config"], **asdict(rig), draw=draw,
                             example_size=ds.faulty_size, n_test=int(ds.test_size.size),
                             mean_prediction=by_size, record_seconds=record_seconds,
                             **{k: (v if not isinstance(v, np.generic) else v.item())
                                for k, v in row.items()}))
    return rows


# ------------------------------------------------------------------ the experiment
def rig_family_experiment(store, seeds, *, results, frf_folder=None, n_synthetic=4,
                          bank_seed=2023, conditions=PAPER_CONDITIONS, n_draws=2,
                          variants=("full",), duration=None, segments=4, healthy=6,
                          sizes=TABLE1_SIZES, repetitions=2, params=None,
                          cache_dir=None, client=None, progress=True):
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
    config = _hash(dict(params=_effective_params(params), campaign=campaign,
                        store=str(store), bank=[p.name for p in paths]))
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
                          config=config, done=sorted(have)))
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


def read_family_results(results) -> pd.DataFrame:
    """All rows of a family results file (JSON lines); empty frame when absent."""
    results = Path(results)
    if not results.exists():
        return pd.DataFrame()
    rows = []
    with open(results) as fh:
        for line in fh:
            line = line.strip()
            if line:
                try:
                    rows.append(json.loads(line))
                except json.JSONDecodeError:  # a line cut by an interrupted run
                    continue
    return pd.DataFrame(rows)


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
    which the estimator's default ``simulated_reference="auto"`` uses; its SAs equal the
    plain store's).
    """
    from ..sim import GearPair, build_database

    store = Path(folder) / ("db-4conditions-h50-f350-s0" + ("-paired" if paired else ""))
    build_database(store, GearPair.paper(), speeds=[15, 30], loads=[5, 10],
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


def format_family_tables(frame: pd.DataFrame, *, rigs_table: bool = False) -> str:
    """The family's tables as text (what the benchmark and the CLI print)."""
    tables = family_tables(frame)
    with pd.option_context("display.width", 200, "display.max_columns", 50):
        parts = ["MAE % by condition (speed/load), rig mean over draws; p90/max over rigs:",
                 tables["condition"].to_string(), "", "MAE % by path type:",
                 tables["kind"].to_string(), "", "MAE % by the rig's true grade:",
                 tables["grade"].to_string(), "", "MAE % by path attenuation:",
                 tables["attenuation"].to_string(), "", "90 % interval coverage %:",
                 tables["coverage"].to_string()]
        full = frame[frame["variant"] == "full"]
        if not full.empty:
            parts += ["", f"full: fit+predict median {full['seconds'].median():.2f} s per "
                      f"dataset; recording "
                      f"{full.groupby('seed')['record_seconds'].first().median():.1f} s per "
                      f"rig (median, first run)"]
        if rigs_table:
            rigs = tables["rigs"].pivot_table(
                index=["seed", "condition", "kind", "path", "grade", "attenuation_db"],
                columns="variant", values="mae")
            parts += ["", rigs.round(1).to_string()]
    return "\n".join(parts)


# ------------------------------------------------------------------ tables
def family_tables(frame: pd.DataFrame) -> dict:
    """Summary tables of family results (MAE and coverage in %).

    Returns
    -------
    dict of pandas.DataFrame
        ``condition`` (variant × condition MAE, plus mean, rig-level p90 and max),
        ``kind`` (variant × path type), ``grade`` (× true-grade band), ``attenuation``
        (× path-attenuation band), ``coverage`` (90 % intervals, by condition),
        ``rigs`` (per-rig MAE of each variant, mean over draws).
    """
    if frame.empty:
        raise GearshotError("no family results to summarize")
    f = frame.copy()
    f["condition"] = [f"{s:g}/{ld:g}" for s, ld in zip(f["speed"], f["load"])]
    rigs = (f.groupby(["variant", "seed", "condition", "kind", "path", "grade",
                       "attenuation_db"])["mae"].mean().mul(100).reset_index())
    cond = rigs.pivot_table(index="variant", columns="condition", values="mae",
                            aggfunc="mean")
    cond["mean"] = rigs.groupby("variant")["mae"].mean()
    cond["p90 rigs"] = rigs.groupby("variant")["mae"].quantile(0.9)
    cond["max rig"] = rigs.groupby("variant")["mae"].max()
    cond["n rigs"] = rigs.groupby("variant")["seed"].nunique()
    kind = rigs.pivot_table(index="variant", columns="kind", values="mae", aggfunc="mean")
    rigs["grades"] = pd.cut(rigs["grade"], [0, 3, 6, 9, 12],
                            labels=["1-3", "4-6", "7-9", "10-12"]).astype(str)
    rigs["attenuation"] = pd.cut(rigs["attenuation_db"], [0, 17, 24, 99],
                                 labels=["<17 dB", "17-24 dB", ">24 dB"]).astype(str)
    grade = rigs.pivot_table(index="variant", columns="grades", values="mae", aggfunc="mean")
    att = rigs.pivot_table(index="variant", columns="attenuation", values="mae",
                           aggfunc="mean")
    cov = f.pivot_table(index="variant", columns="condition", values="coverage",
                        aggfunc="mean").mul(100)
    cov["pooled"] = f.groupby("variant").apply(
        lambda g: np.average(g["coverage"], weights=g["n_test"])).mul(100)
    return {"condition": cond.round(2), "kind": kind.round(2), "grade": grade.round(2),
            "attenuation": att.round(2), "coverage": cov.round(1), "rigs": rigs}
