"""How much of the rig family's error is the simulator's physics? Two databases that
differ from the library's only in the physics of the simulated faults and gear pair.

* ``--mode oracle``: each rig is estimated against a database of its own: the gear pair
  with the rig's hidden mass, inertia, stiffness and damping factors
  (:func:`gearshot.rig.sim_engine.perturbed_pair`) and every simulated fault cut as the
  rig cuts it (:func:`gearshot.rig.sim_engine.physical_fault`: its centre, depth and edge
  offsets, the depth varying along the cut by its roughness); grades 1-12, the family's
  counts (50 healthy + 350 faulty per grade, paired, seed 0), the rig's condition only.
  Library defaults otherwise. What is left is everything but the physics: the path and
  its estimate, noise, interference, speed and load ripple, the one example and the
  estimator. A diagnostic: it reads the rig's hidden truth (``VirtualRig.reveal``).
* ``--mode prior``: one family database (4 conditions, the family's counts) whose faults
  draw their shape per signal from a stated prior (centre U(0.4, 0.6), depth U(0.3, 0.7),
  edge offsets U(-0.15, 0.15), roughness U(-0.3, 0.3) per cosine term) instead of the
  nominal cut (centre 0.5, depth 0.5, no offsets, no roughness): the fault's shape treated
  as unknown and marginalised (domain randomisation), no hidden truth read.

* ``--mode factors --setting S``: the rigs recorded again with parts of their hidden
  reality switched off (``SETTINGS``: "clean" none of noise, interference, ripple, drift,
  tacho jitter; "noise", "interference", "load", "jitter", "sripple" (the once-per-rev
  speed ripple), "drift" (the slow speed drift), "speed" (both) each alone; the drift
  beside one other part: "drift_noise", "drift_interf", "drift_jitter", "drift_load";
  "all_but_load" everything but the load ripple; their own cache ``WORK/rigs_S``),
  estimated against the family database and against the rig's
  own-physics database of ``--mode oracle`` (run it first, same ``--work``).

The oracle and prior modes replace, for the build only, the fault objects the database
builder makes from its sizes (``gearshot.sim.dynamics.resolve_faults``); the stored labels
stay the nominal sizes, as a rig's labels are. The rigs' SA segments come from the family's cache.

    GEARSHOT_DATA=DATA OMP_NUM_THREADS=1 python benchmarks/physics_budget.py --mode oracle \
        --work WORK --seeds 100 ... 123
    GEARSHOT_DATA=DATA OMP_NUM_THREADS=1 python benchmarks/physics_budget.py --mode prior \
        --work WORK --range dev
    GEARSHOT_DATA=DATA OMP_NUM_THREADS=1 python benchmarks/physics_budget.py --mode factors \
        --setting drift --work WORK --seeds 100 ... 111

Rows go to ``WORK/<mode>.jsonl`` (the family's row format); the family's tables are
printed at the end.
"""

from __future__ import annotations

import argparse
import time
import zlib
from pathlib import Path
from types import SimpleNamespace

import numpy as np

import gearshot.sim.dynamics as dynamics
from gearshot import data_home
from gearshot.experiments import family
from gearshot.experiments.family_rigs import _rig, draw_family, family_paths
from gearshot.rig import VirtualRig
from gearshot.rig.irregular import IrregularFaceFault
from gearshot.rig.sim_engine import perturbed_pair, physical_fault
from gearshot.sim import GearPair, build_database
from gearshot.sim._inputs import check_sizes

PRIOR = dict(center=(0.4, 0.6), depth=(0.3, 0.7), edges=0.15, roughness=0.3)
_NOMINAL = dynamics.resolve_faults
_STATE: dict = {"reality": None, "prior": False}


def _faults(fault_sizes, faults, center, depth, fault_type="ftff"):
    """The builder's fault objects: the rig's cut, a cut drawn from the prior, or nominal."""
    reality, prior = _STATE["reality"], _STATE["prior"]
    if (reality is None and not prior) or fault_type != "ftff" or faults is not None:
        return _NOMINAL(fault_sizes, faults, center, depth, fault_type)
    sizes = check_sizes(fault_sizes)
    rng = np.random.default_rng(zlib.crc32(np.asarray(sizes).tobytes()))
    out = []
    for y in sizes:
        if prior:   # drawn for every signal, healthy ones too, so draws follow the seeds
            c, d = rng.uniform(*PRIOR["center"]), rng.uniform(*PRIOR["depth"])
            e = rng.uniform(-PRIOR["edges"], PRIOR["edges"], 2)
            r = rng.uniform(-PRIOR["roughness"], PRIOR["roughness"], 3)
            reality = SimpleNamespace(fault_center=c, fault_depth=d, fault_edges=tuple(e),
                                      fault_roughness=tuple(r))
        if y <= 0:
            out.extend(_NOMINAL([0.0], None, 0.5, 0.5))
        else:   # the cut the rig (or the drawn shape) makes for a label y
            s, c, d = physical_fault(float(y), reality)
            out.append(IrregularFaceFault(size=s, center=c, depth=d,
                                          roughness=tuple(reality.fault_roughness)))
    return out


def _oracle(seeds, work: Path, frf: Path, draws: int) -> Path:
    paths = family_paths(frf)
    results = work / "oracle.jsonl"
    for seed in seeds:
        t0 = time.perf_counter()
        rig = draw_family([seed], paths)[0]
        reality = _rig(VirtualRig, seed, paths, rig.grade, rig.path_index).reveal()
        store = work / f"oracle-db-{seed}"
        _STATE["reality"] = reality
        try:
            build_database(store, perturbed_pair(GearPair.paper(), reality),
                           speeds=[rig.speed], loads=[rig.load], grades=range(1, 13),
                           n_healthy=50, n_faulty=350, seed=0, client=False, paired=True,
                           progress=False)
        finally:
            _STATE["reality"] = None
        frame = family.rig_family_experiment(
            store, [seed], results=results, frf_folder=frf, n_draws=draws,
            variants=["full"], params={}, cache_dir=data_home() / "family" / "rigs",
            client=None, progress=False)
        print(f"rig {seed} (grade {rig.grade}, {rig.speed:g}/{rig.load:g}): MAE "
              + " ".join(f"{m:.3f}" for m in frame["mae"])
              + f"  ({time.perf_counter() - t0:.0f} s)", flush=True)
    return results


def _prior(seeds, work: Path, frf: Path, draws: int) -> Path:
    store = work / "prior-db"
    _STATE["prior"] = True
    try:
        build_database(store, GearPair.paper(), speeds=[15.0, 30.0], loads=[5.0, 10.0],
                       grades=range(1, 13), n_healthy=50, n_faulty=350, seed=0,
                       client=False, paired=True)
    finally:
        _STATE["prior"] = False
    results = work / "prior.jsonl"
    family.rig_family_experiment(store, seeds, results=results, frf_folder=frf,
                                 n_draws=draws, variants=["full"], params={},
                                 cache_dir=data_home() / "family" / "rigs", client=None)
    return results


_OFF = dict(snr_db=200.0, motor_level=0.0, extra_level=0.0, impact_level=0.0,
            speed_drift=0.0, speed_ripple=0.0, load_ripple=0.0, tacho_jitter=0.0)
_KEEP = {"clean": (), "noise": ("snr_db",),
         "interference": ("motor_level", "extra_level", "impact_level"),
         "load": ("load_ripple",), "jitter": ("tacho_jitter",), "sripple": ("speed_ripple",),
         "drift": ("speed_drift",), "speed": ("speed_drift", "speed_ripple"),
         "drift_noise": ("speed_drift", "snr_db"),
         "drift_interf": ("speed_drift", "motor_level", "extra_level", "impact_level"),
         "drift_jitter": ("speed_drift", "tacho_jitter"),
         "drift_load": ("speed_drift", "load_ripple"),
         "all_but_load": ("speed_drift", "speed_ripple", "snr_db", "motor_level",
                          "extra_level", "impact_level", "tacho_jitter")}
SETTINGS = {name: {k: v for k, v in _OFF.items() if k not in keep}
            for name, keep in _KEEP.items()}


def _factors(seeds, work: Path, frf: Path, draws: int, setting: str) -> Path:
    import gearshot.experiments.family_rigs as family_rigs

    off = SETTINGS[setting]

    def rig_with(cls, seed, paths, grade, path_index):
        return cls(seed=seed, tf_bank=paths, grade=grade,
                   reality_overrides={"tf_index": int(path_index), **off})

    family_rigs._rig = rig_with
    stores = {"nominal": data_home() / "family" / "db-4conditions-h50-f350-s0-paired"}
    for seed in seeds:
        stores["oracle"] = work / f"oracle-db-{seed}"
        for name, store in stores.items():
            frame = family.rig_family_experiment(
                store, [seed], results=work / f"{setting}_{name}.jsonl", frf_folder=frf,
                n_draws=draws, variants=["full"], params={},
                cache_dir=work / f"rigs_{setting}", client=None, progress=False)
            print(f"{setting} rig {seed} {name}: MAE "
                  + " ".join(f"{m:.3f}" for m in frame["mae"]), flush=True)
    return work / f"{setting}_nominal.jsonl"


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mode", choices=["oracle", "prior", "factors"], required=True)
    parser.add_argument("--setting", choices=list(SETTINGS), default="clean")
    parser.add_argument("--work", required=True, help="folder for the databases and rows")
    parser.add_argument("--range", choices=list(family.RANGES), default="dev")
    parser.add_argument("--seeds", type=int, nargs="+")
    parser.add_argument("--draws", type=int, default=2)
    parser.add_argument("--frf-folder", default=str(Path(__file__).resolve().parents[2]
                                                    / "shared" / "data" / "frf"))
    args = parser.parse_args(argv)
    seeds = list(args.seeds) if args.seeds else list(family.RANGES[args.range])
    work = Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    dynamics.resolve_faults = _faults
    frf = Path(args.frf_folder)
    if args.mode == "factors":
        results = _factors(seeds, work, frf, args.draws, args.setting)
    else:
        results = (_oracle if args.mode == "oracle" else _prior)(seeds, work, frf, args.draws)
    frame = family.read_family_results(results)
    frame = frame[frame["seed"].isin(seeds) & (frame["draw"] < args.draws)]
    print(family.format_family_tables(frame))


if __name__ == "__main__":
    main()
