"""Numerical checks of simulate_sa: time-step convergence and the one-revolution shortcut.

    PYTHONPATH=src python benchmarks/check_sim_convergence.py
"""

from __future__ import annotations

import numpy as np

from gearshot.signal import difference_signal
from gearshot.sim import GearPair, simulate, simulate_sa


def diff(sa):
    """Difference signal (mesh order 38, two sidebands), as in the reference."""
    return difference_signal(sa, 38, n_sidebands=2)


def rms(x):
    return np.sqrt(np.mean(x ** 2, axis=-1))


def main():
    pair = GearPair.paper()
    sizes = [0.0, 0.3, 0.7]
    print("diff-RMS (g) at internal rate min_fs; relative change when dt is halved")
    for speed in (10, 15, 35):
        r = {fs: rms(diff(simulate_sa(pair, speed=speed, load=10, grade=7, fault_sizes=sizes,
                                      same_gear=True, rng=5, min_fs=fs)))
             for fs in (50e3, 100e3, 200e3)}
        for lo, hi in ((50e3, 100e3), (100e3, 200e3)):
            ch = 100 * np.abs(r[lo] / r[hi] - 1)
            print(f"  {speed:2d} rps, {lo / 1e3:.0f} -> {hi / 1e3:.0f} kHz: y={sizes}: "
                  f"{np.round(r[hi], 2)} g, change {np.round(ch, 3)} %")
    speed = 15.0
    t_rev = 38 / (17 * speed)
    fs = 2048 * 8 / t_rev
    res = simulate(pair, speed=speed, load=10, grade=7, fault_sizes=[0.0, 0.5], fs=fs,
                   duration=17 * t_rev, rng=5, min_fs=fs)
    x = res.acceleration.reshape(2, 17, -1).mean(axis=1)
    X = np.fft.rfft(x, axis=-1)
    sa_long = np.fft.irfft(X[:, :1025] * np.r_[np.ones(1024), 1.0], n=2048) * 2048 / x.shape[-1]
    sa = simulate_sa(pair, speed=speed, load=10, grade=7, fault_sizes=[0.0, 0.5], rng=5,
                     min_fs=fs)
    print("simulate_sa (one revolution, mean pinion tooth) vs SA of 17 gear revolutions "
          "(hunting period) of simulate(): relative RMS difference",
          np.round(rms(sa - sa_long) / rms(sa), 5))


if __name__ == "__main__":
    main()
