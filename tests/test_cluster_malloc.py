"""The allocator settings of gearshot's LocalCluster workers (issue #23, the paper sweep)."""

import os

from gearshot._cluster import WORKER_MALLOC, dask_client


def _malloc_env():
    return {k: os.environ.get(k) for k in WORKER_MALLOC}


def test_local_cluster_workers_keep_mid_size_arrays_on_the_heap():
    # Dask's default MALLOC_TRIM_THRESHOLD_=65536 would be there without gearshot's settings
    with dask_client(None, workers=2) as client:
        seen = client.run(_malloc_env)
    assert len(seen) == 2
    want = {k: str(v) for k, v in WORKER_MALLOC.items()}
    assert all(env == want for env in seen.values()), seen
    assert int(want["MALLOC_MMAP_THRESHOLD_"]) >= 8 << 20     # an 800 x 2048 batch is 13 MB
