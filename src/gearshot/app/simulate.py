"""``gearshot simulate``: a simulated database of the paper's pair or of a machine's pair.

:func:`simulate_database` builds (or finishes: the build is resumable) the database of the
paper's test-rig pair; :func:`simulate_machine_database` the database of the monitored
pair of a machine file, its speeds given as the machine's tacho-shaft speeds.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from .._cluster import IN_PROCESS_BLOCKS, dask_client

__all__ = ["default_store", "simulate_database", "simulate_machine_database",
           "repair_store"]


def default_store() -> Path:
    """Where ``gearshot simulate`` keeps the paper pair's database by default."""
    from .._paths import data_home

    return data_home(create=False) / "databases" / "sim-db"


def simulate_database(store: Path, *, speeds: Sequence[float], loads: Sequence[float],
                      grades: Sequence[int], n_healthy: int, n_faulty: int, seed: int,
                      fault_types: Sequence[str] = ("ftff",), paired: bool = True,
                      scheduler: str | None = None, workers: int = 2) -> Path:
    """The paper pair's database over ``speeds`` × ``loads`` × ``grades`` × ``fault_types``
    (more than :data:`gearshot._cluster.IN_PROCESS_BLOCKS` blocks on a Dask cluster, see
    :func:`gearshot._cluster.dask_client`; fewer in-process, one block per core);
    returns ``store``."""
    from ..sim import GearPair, build_database

    n_blocks = len(speeds) * len(loads) * len(grades) * len(fault_types)
    with dask_client(scheduler, workers, needed=n_blocks > IN_PROCESS_BLOCKS) as client:
        build_database(store, GearPair.paper(), speeds=speeds, loads=loads, grades=grades,
                       n_healthy=n_healthy, n_faulty=n_faulty, seed=seed, client=client,
                       fault_types=list(fault_types), paired=paired)
    return store


def repair_store(store: Path | None, others: Sequence[str], *, scheduler: str | None = None,
                 workers: int = 2, echo=print) -> Path:
    """``gearshot simulate --repair --store S``: :func:`gearshot.sim.repair_database` on
    ``S`` (the store's own build arguments, read from its blocks); ``others``: the other
    build options given, refused (the repair takes its arguments from the store)."""
    from .._errors import GearshotError
    from ..sim import repair_database

    if store is None:
        raise GearshotError("--repair needs --store: the store to repair")
    if others:
        raise GearshotError(f"--repair takes the build's arguments from the store; do not "
                            f"give {', '.join(others)} with it")
    with dask_client(scheduler, workers, needed=False) as client:
        done = repair_database(store, client=client)
    echo(f"repaired: {'; '.join(done)}" if done else "nothing to repair: manifest and "
         "blocks whole")
    echo(f"database ready: {store}")
    return store


def simulate_machine_database(machine_file: Path, store: Path | None, *,
                              speeds: Sequence[float], loads: Sequence[float],
                              grades: Sequence[int], n_healthy: int, n_faulty: int,
                              seed: int, fault_types: Sequence[str] = ("ftff",),
                              paired: bool = True, scheduler: str | None = None,
                              workers: int = 2) -> tuple[Path, str]:
    """``simulate --machine``: a database of the machine's monitored pair (paired by
    default: on a real machine the target's step 6 subtracts the same gear's healthy SA,
    and so does the simulated side with twins).

    ``speeds`` are the machine's reference (tacho) shaft speeds, Hz; ``store`` defaults to
    :func:`gearshot.app.predict_machine.machine_database_path`.

    Returns
    -------
    store : Path
    description : str
        One line naming the pair and the conditions, in the machine's terms.
    """
    from ..machine import Machine
    from ..sim import build_database
    from .predict_machine import machine_database_path

    mach = Machine.from_toml(machine_file)
    pair = mach.gear_pair()
    store = store or machine_database_path(machine_file, n_healthy=n_healthy,
                                           n_faulty=n_faulty, seed=seed, paired=paired)
    sim_speeds = [mach.sim_speed(s) for s in speeds]
    n_blocks = len(sim_speeds) * len(loads) * len(grades) * len(fault_types)
    with dask_client(scheduler, workers, needed=n_blocks > IN_PROCESS_BLOCKS) as client:
        build_database(store, pair, speeds=sim_speeds, loads=loads, grades=grades,
                       n_healthy=n_healthy, n_faulty=n_faulty, seed=seed, client=client,
                       fault_types=list(fault_types), paired=paired)
    mate_shaft, _ = mach.mate()
    ref_kind = "tacho" if mach.tacho is not None else "reference"
    shaft = mach.monitored.shaft if mach.monitored is not None else "monitored"
    line = (f"monitored gear {pair.z_gear} teeth on the {shaft} shaft (the "
            f"fault's gear) meshing with {pair.z_pinion} teeth on the {mate_shaft} shaft; "
            f"conditions: {mach.reference_shaft} "
            f"({ref_kind}) shaft {', '.join(f'{s:g}' for s in speeds)} Hz x load "
            f"{', '.join(f'{x:g}' for x in loads)} N m")
    return store, line
