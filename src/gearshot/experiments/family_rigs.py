"""The rigs of the virtual-rig family (issue #12) and their recordings, reduced to SAs.

:func:`family_paths` is the family's transfer-path bank, :func:`draw_family` the rigs of
a range of seeds (each set by its seed alone), :func:`true_path_on_grid` a rig's hidden
path for the diagnostics; a rig's campaign is recorded once and cached as SA segments
(``.npz``). The experiment over the family is :mod:`gearshot.experiments.family`.
"""

from __future__ import annotations

import hashlib
import json
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
    RIG_CONDITIONS,
    SAMPLES_PER_CYCLE,
)

__all__ = ["PAPER_CONDITIONS", "DEV_SEEDS", "HELDOUT_SEEDS", "SPENT_HELDOUT_SEEDS", "RANGES",
           "SA_PIPELINE_VERSION", "FamilyRig", "path_kind", "family_paths", "draw_family",
           "true_path_on_grid", "rig_segments", "campaign_duration", "tf_digest", "config_hash",
           "cached_family_fits", "family_rig"]

#: The paper's four rig conditions (speed rev/s, load N m), :data:`gearshot.paper.RIG_CONDITIONS`
PAPER_CONDITIONS = RIG_CONDITIONS
DEV_SEEDS = range(100, 124)
#: The held-out range of issue #19 (fresh: never run before the decision of
#: ``benchmarks/results/family_configuration_grade_calibration.md`` was committed).
HELDOUT_SEEDS = range(9500, 9524)
#: Issue #12's held-out range, evaluated twice: spent, kept for reproduction.
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


def family_rig(seed: int, frf_folder=None, **overrides):
    """One rig of the family to record anew: ``(FamilyRig, VirtualRig)``, the rig's hidden
    reality with ``overrides`` set (:class:`gearshot.rig.reality.RigReality` fields, e.g.
    ``speed_drift=0``). For the benchmarks and tests that record a rig themselves."""
    from ..rig import VirtualRig

    paths = family_paths(frf_folder, n_synthetic=4, seed=2023)
    rig = draw_family([int(seed)], paths)[0]
    virtual = _rig(VirtualRig, int(seed), paths, rig.grade, rig.path_index)
    return rig, (virtual.with_reality(**overrides) if overrides else virtual)


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


# ------------------------------------------------------------------ one rig's recordings
def rig_segments(rig: FamilyRig, paths, cache_dir: Path, campaign: dict):
    """SA segments of one rig's campaign (recorded once, cached as ``.npz``).

    Returns the campaign index (``path`` = recording key) and the segments cache
    ``{key: (sa, angle signal or None)}`` that :func:`rig_dataset` takes.
    """
    from ..rig import VirtualRig

    tag = config_hash(dict(rig=asdict(rig), campaign=campaign,
                     paths=[[p.name, tf_digest(p)] for p in paths]))
    file = cache_dir / f"rig-{rig.seed}-{tag}.npz"
    jobs = ([(0.0, r) for r in range(campaign["healthy"])]
            + [(float(y), r) for y in campaign["sizes"] for r in range(campaign["repetitions"])])
    keys = [f"s{rig.seed}_y{y:.2f}_r{r}" for y, r in jobs]
    if not file.exists():
        vr = _rig(VirtualRig, rig.seed, paths, rig.grade, rig.path_index)
        arrays = {}
        for key, (y, r) in zip(keys, jobs):
            rec = vr.record(speed=rig.speed, load=rig.load, fault_size=y,
                            duration=campaign_duration(campaign, rig.speed), repetition=r)
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


def campaign_duration(campaign, speed):
    """Seconds per recording: ``duration`` if set, else enough for ``segments`` SAs."""
    if campaign.get("duration"):
        return float(campaign["duration"])
    gear_revs_per_s = speed * PINION_TEETH / GEAR_TEETH
    return 1.02 * (campaign["segments"] * CYCLES_PER_SEGMENT + 1) / gear_revs_per_s


def tf_digest(tf) -> str:
    """Content hash of a transfer function (its frequencies and values), not its name."""
    h = hashlib.sha256()
    for arr in (tf.freqs, tf.values):
        a = np.ascontiguousarray(arr)
        h.update(str(a.dtype).encode() + str(a.shape).encode() + a.tobytes())
    return h.hexdigest()[:16]


def config_hash(obj) -> str:
    """A short hash of a JSON-able configuration (keys sorted)."""
    return hashlib.sha1(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()[:12]


def cached_family_fits(seeds, data, frf_folder=None, *, draws: int = 2):
    """Each (rig, draw) of the family over its cached segments, fitted with the library
    defaults as ``benchmarks/rig_family.py`` fits it: yields ``(rig, draw, dataset,
    database, estimator)`` (the paired family database under ``data/family``). For the
    benchmarks that look inside those fits."""
    from ..estimator import OneFaultShotEstimator
    from ..paper import RIG_HEALTHY_RECORDINGS, TABLE1_SIZES
    from ..sim import load_database
    from ..transfer import TransferFunctionBank
    from .rig import rig_dataset

    paths = family_paths(frf_folder, n_synthetic=4, seed=2023)
    store = next((Path(data) / "family").glob("db-4conditions-*-paired"))
    campaign = dict(duration=None, segments=4, healthy=int(RIG_HEALTHY_RECORDINGS),
                    sizes=[float(y) for y in TABLE1_SIZES], repetitions=2,
                    sa_pipeline=SA_PIPELINE_VERSION)
    for rig in draw_family(seeds, paths):
        index, segments = rig_segments(rig, paths, Path(data) / "family" / "rigs", campaign)
        database = load_database(store, speed=rig.speed, load=rig.load)
        selection = TransferFunctionBank.synthetic(
            1, rng=np.random.default_rng([rig.seed, 99]))[0]
        for draw in range(draws):
            ds = rig_dataset(index, random_state=[rig.seed, draw], segments=segments)
            est = OneFaultShotEstimator(random_state=1000 * rig.seed + draw).fit(
                *ds.fit_args(database), selection_tf=selection, **ds.fit_kwargs())
            yield rig, draw, ds, database, est
