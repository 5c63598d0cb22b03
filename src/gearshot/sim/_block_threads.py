"""In-process database builds of several blocks: one block per core side by side.

A block's serial steps (profile-error draws, fault objects, the Zarr write, the
checksums) leave the second core idle when the blocks run one after another with numba
threads over each batch. Here each of ``n_threads`` Python threads builds whole blocks
with its kernels on one numba thread; the kernels, the FFTs, the CRCs and the file writes
release the GIL, so the threads overlap as a LocalCluster's worker processes do, without
their start-up. Every signal's numbers are those of a one-thread build (each signal is
integrated on its own: the thread count changes no arithmetic).

BLAS runs on one thread meanwhile (its thread count is process-wide).

Only with a thread-safe numba threading layer (OpenMP or TBB): numba's ``workqueue``
layer aborts the process when two threads launch parallel kernels at once, so with it the
blocks run one after another as before.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_EXCEPTION, ThreadPoolExecutor, wait

import numba as nb
import numpy as np
from threadpoolctl import threadpool_limits

__all__ = ["block_threads", "run_blocks"]

_SAFE_LAYERS = ("omp", "tbb")


@nb.njit(cache=True, nogil=True, parallel=True)
def _touch(x):       # any parallel kernel: starts numba's threading layer
    for i in nb.prange(x.shape[0]):
        x[i] += 1.0
    return x


def block_threads(n_blocks: int) -> int:
    """Threads for an in-process build of ``n_blocks`` blocks: one per core (at most one
    per block), 1 when the machine has one core or numba's threading layer is not
    thread-safe."""
    n = min(n_blocks, os.cpu_count() or 1)
    if n < 2:
        return 1
    _touch(np.zeros(2))
    try:
        layer = nb.threading_layer()
    except ValueError:       # not started (cannot happen after _touch): be careful
        return 1
    return n if layer in _SAFE_LAYERS else 1


def run_blocks(build: Callable[..., object], tasks: Sequence[tuple], n_threads: int,
               done: Callable[[], None]) -> None:
    """``build(*task)`` for every task on ``n_threads`` threads (each with one numba
    thread), ``done()`` after each; a failure cancels the blocks not started and, once
    the running ones have finished (their temporaries removed), the failure of the
    first failed task in task order is raised."""

    def one(task):
        nb.set_num_threads(1)        # thread-local: the caller's setting is kept
        return build(*task)

    # BLAS on one thread for the whole build, as in a Dask worker: its thread count is
    # process-wide, and one block's threadpool_limits (sim._helical) must not restore a
    # threaded BLAS under the other's products (their sums would change in the last bits)
    with threadpool_limits(1, user_api="blas"), ThreadPoolExecutor(
            max_workers=n_threads, thread_name_prefix="gearshot-block") as pool:
        futures = [pool.submit(one, t) for t in tasks]
        pending = set(futures)
        while pending:
            finished, pending = wait(pending, return_when=FIRST_EXCEPTION)
            if any(f.exception() is not None for f in finished):
                for other in pending:
                    other.cancel()
                wait(pending)
                break
            for _ in finished:
                done()
    for fut in futures:      # the first failed block in task order (as one by one)
        if not fut.cancelled() and fut.exception() is not None:
            fut.result()
