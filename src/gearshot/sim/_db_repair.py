"""Repairing a database store from what its blocks record: ``gearshot simulate --repair``.

Every block records the manifest of the build that made it (with its digest) and the size
and CRC-32 of its files (with the list's digest). :func:`repair_database` restores a lost,
empty, invalid or edited ``manifest.json`` from the blocks' copies, checks every block in
full (every chunk's CRC-32, not only sizes and times as a resuming build does), removes the
damaged ones and rebuilds exactly those and the missing ones with the manifest's own
arguments, so the store it leaves loads.
"""

from __future__ import annotations

import json
from pathlib import Path

from .._atomic import remove_tree, write_json_atomic
from .._errors import GearshotError
from ._db_checksums import block_problem
from ._db_manifest import block_name, blocks_manifest, pair_from_manifest
from ._integrity import manifest_diff, store_lock

__all__ = ["repair_database"]


def _file_manifest(store: Path) -> dict | None:
    """``manifest.json`` as a dict, or None when it is missing, empty or invalid."""
    try:
        man = json.loads((store / "manifest.json").read_text())
    except (OSError, ValueError):
        return None
    return man if isinstance(man, dict) and {"speeds", "loads", "grades"} <= set(man) else None


def _chosen_manifest(store: Path) -> tuple[dict, str | None]:
    """The build's manifest and what was wrong with ``manifest.json`` (None: nothing)."""
    found = _file_manifest(store)
    theirs, n_vouch, n_blocks = blocks_manifest(store)
    if theirs is None and n_vouch:
        raise GearshotError(f"store {str(store)!r}: its blocks record different builds; it "
                            f"cannot be repaired as one store: move the blocks you want "
                            f"into a new store or rebuild it (gearshot simulate --store NEW)")
    if theirs is None:
        if found is None:
            raise GearshotError(f"store {str(store)!r}: manifest.json is missing or damaged "
                                f"and none of its {n_blocks} block(s) records a build to "
                                f"restore it from; remove the store and build it again "
                                f"(gearshot simulate)")
        return found, None
    if found is None:
        state = ("is missing" if not (store / "manifest.json").exists() else
                 "is empty or not a gearshot manifest")
        return theirs, f"manifest.json {state}"
    if found != theirs:
        return theirs, (f"manifest.json was changed after the build (differs from its "
                        f"blocks' record in {manifest_diff(found, theirs)})")
    return found, None


def repair_database(store, *, client=None, progress: bool = True) -> list[str]:
    """Repair ``store`` so that it loads: restore ``manifest.json`` from the blocks,
    remove every block that fails a full check, rebuild those and the missing ones.

    Parameters
    ----------
    store : str or Path
        A database store (``gearshot simulate``, ``build_database``).
    client : dask.distributed.Client, optional
        Where the rebuilt blocks are simulated (default: as ``build_database``).
    progress : bool
        Print the rebuild's progress (stderr).

    Returns
    -------
    list of str
        One line per repair made (empty: the store was whole).

    Raises
    ------
    GearshotError
        The store is not a folder, or nothing records its build (no valid manifest and no
        block vouching for one), or its blocks record different builds.
    """
    from .database import build_database

    store = Path(store).expanduser()
    if not store.is_dir():
        raise GearshotError(f"--store {str(store)!r} is not a database store (no such "
                            f"folder)")
    done: list[str] = []
    man, wrong = _chosen_manifest(store)
    pair = pair_from_manifest(man)
    if pair is None:
        raise GearshotError(f"store {str(store)!r}: the gear pair its build records "
                            f"({man.get('pair')!r}) cannot be read; rebuild it into a new "
                            f"store (gearshot simulate)")
    with store_lock(store, man, progress=progress):
        if wrong is not None:
            write_json_atomic(man, store / "manifest.json", sort_keys=False)
            done.append(f"{wrong}: restored from the blocks' copies")
        damaged, missing = [], []
        for i in range(len(man["speeds"])):
            for j in range(len(man["loads"])):
                for k in range(len(man["grades"])):
                    for ft in man.get("fault_types", ["ftff"]):
                        path = store / "blocks" / block_name(i, j, k, ft)
                        if not path.exists():
                            missing.append(path.name)
                            continue
                        problem = block_problem(path)
                        if problem is not None:
                            damaged.append(f"{path.name} ({problem})")
                            remove_tree(path)
        if damaged:
            done.append(f"removed {len(damaged)} damaged block(s) to rebuild: "
                        + "; ".join(damaged))
        if missing:
            done.append(f"{len(missing)} missing block(s) to build: {', '.join(missing)}")
    build_database(store, pair, speeds=man["speeds"], loads=man["loads"],
                   grades=man["grades"], n_healthy=man["n_healthy"],
                   n_faulty=man["n_faulty"], seed=man["seed"], n_points=man["n_points"],
                   client=client, progress=progress,
                   fault_types=man.get("fault_types", ["ftff"]),
                   paired=bool(man.get("paired", False)))
    return done
