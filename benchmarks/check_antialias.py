"""What the anti-alias low-pass changes in synchronous averages.

1. Analytic: idler orders 5, 96, 700 (below the angular Nyquist 1024) plus 10x stronger
   orders 1500 and 2600, 10-pulse tacho on the input shaft (3:1), speed +-1 %: SA error
   against the analytic SA, with and without the low-pass.
2. The paper's virtual rig (15 rps, 10 Nm, 20 s): relative change of the SA's orders below
   0.9 x Nyquist when the low-pass is switched on (what aliasing was adding).
3. PHM09 spur2 30 Hz High, every shaft: the same relative change (the issue's 3-13 %).

    PYTHONPATH=src python benchmarks/check_antialias.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gearshot import Machine
from gearshot.io import Recording
from gearshot.paper import GEAR_TEETH, PINION_TEETH
from gearshot.rig import VirtualRig
from gearshot.signal import angular_resample, pulse_times, synchronous_average
from gearshot.signal.trains import shaft_cycle_times

ROOT = Path(__file__).resolve().parents[1]
SPR = 2048


def below(sa_on, sa_off):
    keep = slice(1, int(0.9 * SPR / 2))
    a = np.fft.rfft(sa_on, axis=-1)[..., keep]
    b = np.fft.rfft(sa_off, axis=-1)[..., keep]
    return float(np.linalg.norm(a - b) / np.linalg.norm(a))


def analytic():
    fs = 200_000 / 3
    t = np.arange(int(fs * 4)) / fs
    theta = 30 * t + 0.01 * 30 * 3 / (2 * np.pi) * np.sin(2 * np.pi * t / 3)
    idler = theta / 3
    low, high = {5: 1.0, 96: 0.5, 700: 0.3}, {1500: 3.0, 2600: 3.0}
    x = sum(a * np.cos(2 * np.pi * o * idler + 0.3 * o) for o, a in {**low, **high}.items())
    pulses = pulse_times(np.sin(2 * np.pi * 10 * theta), fs, threshold=0.0)
    cyc = shaft_cycle_times(pulses, revs_per_cycle=3, pulses_per_rev=10)
    grid = np.interp(cyc[0], t, idler) + np.arange(SPR) / SPR
    ref = sum(a * np.cos(2 * np.pi * o * grid + 0.3 * o) for o, a in low.items())
    for aa in (True, False):
        sa = synchronous_average(angular_resample(x, fs, cyc, samples_per_rev=SPR,
                                                  antialias=aa), SPR)
        err = np.linalg.norm(sa - ref) / np.linalg.norm(ref)
        print(f"analytic, antialias={aa}: SA error {err:.2e}")


def rig():
    rec = VirtualRig(seed=0).record(speed=15.0, load=10.0, duration=20.0)
    on = rec.to_sa_segments(gear_teeth=GEAR_TEETH, pinion_teeth=PINION_TEETH)
    off = rec.to_sa_segments(gear_teeth=GEAR_TEETH, pinion_teeth=PINION_TEETH,
                              antialias=False)
    print(f"virtual rig 15 rps: orders < 0.9 Nyquist change by {below(on, off):.2%} "
          f"(fs {rec.fs:g} Hz, angular Nyquist {1024 * 15 * 17 / 38:.0f} Hz)")


def phm():
    path = ROOT.parent / "shared" / "data" / "phm09" / "spur2_30hz_High_1.zip"
    m = Machine.from_toml(ROOT / "examples" / "machines" / "phm09_spur.toml")
    rec = Recording.read(path, machine=m)
    for shaft in m.shafts:
        on = rec.to_sa_segments(shaft=shaft, cycles_per_segment=None)
        off = rec.to_sa_segments(shaft=shaft, cycles_per_segment=None, antialias=False)
        print(f"phm09 spur2 30hz High, shaft {shaft}: orders < 0.9 Nyquist change by "
              f"{below(on[0], off[0]):.2%} (acc_input), {below(on[1], off[1]):.2%} "
              f"(acc_output)")


if __name__ == "__main__":
    analytic()
    rig()
    phm()
