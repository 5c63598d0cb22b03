"""The Dask cluster of a long job (a command, a database build): a running scheduler, a
LocalCluster, or none.

Examples
--------
>>> from gearshot._cluster import dask_client
>>> with dask_client(None, workers=1) as client:   # one worker: work runs in-process
...     print(client)
None
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from ._errors import GearshotError

__all__ = ["dask_client", "WORKER_MALLOC", "IN_PROCESS_BLOCKS"]

#: Database builds of at most this many blocks run in-process (one block per core on
#: threads, :mod:`gearshot.sim._block_threads`): a LocalCluster's start-up and its workers'
#: separate writes cost more than they save there (one paper condition, 12 blocks: 10.8 s
#: in-process against 20 s on a 2-worker LocalCluster, measured with issue #23).
IN_PROCESS_BLOCKS = 16

#: glibc allocator settings of the LocalCluster's workers (set before they start). Dask's
#: own ``MALLOC_TRIM_THRESHOLD_=65536`` also pins the mmap threshold at 128 KiB: every
#: array above it (an SA batch, a spectrum) is then mapped afresh and page-faulted in on
#: each use, which cost a Sec. 4.1 dataset 1.18 s of CPU instead of 0.52 s with these
#: (measured with issue #23). Arrays up to 32 MiB come from the heap,
#: and up to 128 MiB of freed heap is kept for reuse.
WORKER_MALLOC = {"MALLOC_TRIM_THRESHOLD_": 128 << 20, "MALLOC_MMAP_THRESHOLD_": 32 << 20}


@contextmanager
def dask_client(scheduler: str | None = None, workers: int = 2, *,
                needed: bool = True) -> Iterator[Any]:
    """A Dask client for the ``with`` block, closed (with its LocalCluster) on exit.

    Parameters
    ----------
    scheduler : str, optional
        Address of a running Dask scheduler (``--scheduler``); it is left running. Its
        workers keep the environment they were started with: start them with
        :data:`WORKER_MALLOC` in it (``MALLOC_TRIM_THRESHOLD_=134217728
        MALLOC_MMAP_THRESHOLD_=33554432 dask worker ADDRESS``) for the LocalCluster's speed.
    workers : int
        Workers of the LocalCluster started when no ``scheduler`` is given (one thread
        each); with 1 worker no cluster is started and the client is None (in-process).
    needed : bool
        Whether the work has more than one task; when False and no ``scheduler`` is given,
        no cluster is started (its start-up would cost more than it saves).

    Yields
    ------
    dask.distributed.Client or None
        None: run in-process.

    Raises
    ------
    GearshotError
        The scheduler cannot be reached (the message names ``--scheduler`` and the address).
    """
    client, cluster = _start(scheduler, workers, needed=needed)
    try:
        yield client
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()


def _start(scheduler: str | None, workers: int, *, needed: bool) -> tuple[Any, Any]:
    """(client, the LocalCluster this started or None); (None, None) to run in-process."""
    if scheduler:
        from dask.distributed import Client

        try:
            return Client(scheduler, timeout="10s"), None
        except Exception as exc:
            raise GearshotError(f"cannot reach the Dask scheduler at --scheduler "
                                f"{scheduler!r}: {exc}") from None
    if needed and workers > 1:
        import dask
        from dask.distributed import Client, LocalCluster

        key = "distributed.nanny.pre-spawn-environ"
        with dask.config.set({key: {**dask.config.get(key), **WORKER_MALLOC}}):
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1,
                                   dashboard_address=":0")
        return Client(cluster), cluster
    return None, None
