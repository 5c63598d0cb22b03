"""Monitoring at fleet scale (issue #31): CPU time to estimate one new 60 s recording with
a saved model, and wall/CPU time to re-report a history of 1,000 recordings.

    PYTHONPATH=src python benchmarks/bench_monitor.py --model M.skops

``--model``: a model file of the 15 rps / 10 N m condition (``gearshot fit``, e.g. one of
benchmarks/monitor_lives.py). Targets: ≤ 0.5 s CPU per new recording; ≤ 10 s to re-report
1,000 recordings (read the index and the history, alarm, forecast, JSON and figure).
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd


def _clock():
    return time.perf_counter(), time.process_time()


def _since(start):
    w, c = _clock()
    return w - start[0], c - start[1]


def main() -> None:
    from gearshot.app.monitor import estimate_recordings, monitor_history, write_monitor_outputs
    from gearshot.monitor import HISTORY_COLUMNS, append_history, load_model
    from gearshot.rig import VirtualRig

    parser = argparse.ArgumentParser()
    parser.add_argument("--model", type=Path, required=True)
    parser.add_argument("--n", type=int, default=1000)
    args = parser.parse_args()
    print(f"# loadavg before: {os.getloadavg()}")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        rec = VirtualRig(7).record(speed=15, load=10, duration=60.0, repetition=99)
        rec.write(tmp / "new.h5", dtype="float32")
        start = _clock()
        model = load_model(args.model)
        w, c = _since(start)
        print(f"load the model: {w:.3f} s wall, {c:.3f} s CPU")
        row = pd.DataFrame({"recording": [str(tmp / "new.h5")],
                            "time": [pd.Timestamp("2026-03-01")]})
        estimate_recordings(model, row)                    # warm: imports, caches
        cpu = []
        for _ in range(5):
            start = _clock()
            out = estimate_recordings(model, row)
            cpu.append(_since(start))
        walls, cpus = zip(*cpu, strict=True)
        print(f"estimate one new 60 s recording ({int(out['segments'].iloc[0])} segments): "
              f"median {np.median(walls):.3f} s wall, {np.median(cpus):.3f} s CPU over 5 "
              f"runs (target <= 0.5 s CPU): {'MET' if np.median(cpus) <= 0.5 else 'MISSED'}")

        # a history of n recordings, every one estimated by this model already
        n = args.n
        for i in range(n):
            (tmp / f"r{i:04d}.h5").write_bytes(b"")
        t = pd.date_range("2026-01-01", periods=n, freq="6h")
        life = np.linspace(0, 1, n)
        size = 0.8 * (np.maximum(life - 0.3, 0.0) / 0.7) ** 1.5
        rng = np.random.default_rng(0)
        pred = np.clip(size + 0.04 * rng.standard_normal(n), 0, 1)
        pd.DataFrame({"file": [f"r{i:04d}.h5" for i in range(n)],
                      "time": [x.isoformat() for x in t]}).to_csv(tmp / "index.csv",
                                                                  index=False)
        hist = pd.DataFrame({"recording": [str((tmp / f"r{i:04d}.h5").resolve())
                                           for i in range(n)],
                             "time": t, "predicted": pred, "low": np.clip(pred - 0.2, 0, 1),
                             "high": np.clip(pred + 0.2, 0, 1), "segments": 8,
                             "trusted_segments": 8, "trusted": rng.random(n) > 0.05,
                             "model": model.digest, "calibration": model.calibration,
                             "estimated_at": pd.Timestamp("2026-06-01"), "note": ""},
                            columns=HISTORY_COLUMNS)
        append_history(tmp / "h.parquet", hist)
        start = _clock()
        payload = monitor_history(args.model, tmp / "index.csv", tmp / "h.parquet")
        write_monitor_outputs(payload, json_out=tmp / "out.json", out=tmp / "figs")
        w, c = _since(start)
        fc = payload["forecast"]
        print(f"re-report a history of {n} recordings (0 new; alarm, forecast "
              f"[{fc['law']}, {fc['reason'] or fc['time']}], JSON, figure): {w:.2f} s wall, "
              f"{c:.2f} s CPU (target <= 10 s): {'MET' if w <= 10 else 'MISSED'}")
    print(f"# loadavg after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
