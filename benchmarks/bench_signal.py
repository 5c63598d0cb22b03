"""Speed of the signal core (issue: foundation). Prints numbers; asserts nothing.

Run:  python benchmarks/bench_signal.py
Targets: features of 10,000 SAs (2048 points) < 2 s; TF estimate from 60 s at 50 kHz < 1 s;
angular resampling of 60 s at 50 kHz < 2 s; subtract_healthy (shown for the estimator).
"""

from __future__ import annotations

import os
import time

import numpy as np

from gearshot import features, signal, transfer
from gearshot.paper import GEAR_TEETH


def best_of(func, repeat=3):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        func()
        times.append(time.perf_counter() - t0)
    return min(times)


def main():
    rng = np.random.default_rng(0)
    sa = rng.normal(size=(10_000, 2048))
    fs, duration = 50_000.0, 60.0
    n = int(fs * duration)
    t = np.arange(n) / fs
    speed = 15.0 * (1 + 0.01 * np.sin(2 * np.pi * t / 10))
    theta = np.cumsum(speed) / fs
    x = np.cos(2 * np.pi * 17 * theta) + 0.1 * rng.normal(size=n)
    tacho = (np.mod(theta, 1.0) < 0.2) * 5.0
    pulses = signal.pulse_times(tacho, fs)
    refs = rng.normal(size=(8, 2048))

    rows = [
        ("features, 10,000 SAs x 2048 (paper's four)", "< 2 s",
         best_of(lambda: features.extract_features(sa, GEAR_TEETH))),
        ("features, 10,000 SAs x 2048 (all ten)", "-",
         best_of(lambda: features.extract_features(sa, GEAR_TEETH,
                                                   names=features.available_features()))),
        ("TF estimate, 60 s at 50 kHz (3e6 samples)", "< 1 s",
         best_of(lambda: transfer.estimate_transfer_function(x, 2048))),
        ("pulse_times, 60 s at 50 kHz", "-", best_of(lambda: signal.pulse_times(tacho, fs))),
        ("angular resampling, 60 s at 50 kHz (x2, cubic)", "< 2 s",
         best_of(lambda: signal.angular_resample(x, fs, pulses, samples_per_rev=1024))),
        ("subtract_healthy, 100 SAs vs 8 refs (x100)", "-",
         best_of(lambda: signal.subtract_healthy(sa[:100], refs), repeat=1)),
    ]
    print(f"load average: {os.getloadavg()}")
    print(f"{'task':55s} {'target':>8s} {'seconds':>9s}")
    for name, target, sec in rows:
        print(f"{name:55s} {target:>8s} {sec:9.3f}")


if __name__ == "__main__":
    main()
