"""Fit + predict time of the library-default estimator on one rig of the family.

Run:  GEARSHOT_DATA=DIR python benchmarks/fit_speed_family.py SEED LABEL

The rig's SA segments cached by ``benchmarks/rig_family.py`` and the family database (50 +
350 paired SAs per grade, the size ``bench_speed.py estimator`` times); 5 timed fits after
one warm-up; CPU seconds are the comparable figure on a loaded box (run two trees one
after the other to compare them).
"""
import os
import sys
import time
from pathlib import Path

import numpy as np

from gearshot.estimator import OneFaultShotEstimator
from gearshot.experiments.family import (
    SA_PIPELINE_VERSION,
    draw_family,
    family_paths,
)
from gearshot.experiments.family_rigs import rig_segments
from gearshot.experiments.rig import rig_dataset
from gearshot.paper import RIG_HEALTHY_RECORDINGS, TABLE1_SIZES
from gearshot.sim import load_database
from gearshot.transfer import TransferFunctionBank

data = Path(os.environ.get("GEARSHOT_DATA", "/tmp/gearshot-bench"))
paths = family_paths(Path(__file__).resolve().parents[2] / "shared" / "data" / "frf",
                     n_synthetic=4, seed=2023)
store = data / "family" / "db-4conditions-h50-f350-s0-paired"
campaign = dict(duration=None, segments=4, healthy=int(RIG_HEALTHY_RECORDINGS),
                sizes=[float(y) for y in TABLE1_SIZES], repetitions=2,
                sa_pipeline=SA_PIPELINE_VERSION)
rig, = draw_family([int(sys.argv[1])], paths)
index, segments = rig_segments(rig, paths, data / "family" / "rigs", campaign)
db = load_database(store, speed=rig.speed, load=rig.load).load()
ds = rig_dataset(index, random_state=[rig.seed, 0], segments=segments)
sel = TransferFunctionBank.synthetic(1, rng=np.random.default_rng([rig.seed, 99]))[0]
cpu, wall = [], []
for r in range(6):
    t0, c0 = time.perf_counter(), time.process_time()
    est = OneFaultShotEstimator(random_state=r).fit(*ds.fit_args(db), selection_tf=sel,
                                                    **ds.fit_kwargs())
    pred = est.predict(ds.test_sa)
    if r:
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
t0 = time.process_time()
for _ in range(200):
    np.fft.rfft(np.ones((64, 2048)), axis=1)
ref = (time.process_time() - t0) / 200
print(f"{sys.argv[2]}: fit+predict median CPU {np.median(cpu):.3f} s, "
      f"wall {np.median(wall):.3f} s; fft_ref-like {1e3 * ref:.2f} ms; "
      f"MAE {100 * np.mean(np.abs(pred - ds.test_size)):.2f} %")
