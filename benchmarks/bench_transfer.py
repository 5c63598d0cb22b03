"""Benchmarks and headline numbers for gearshot.transfer (issue #4).

Prints:
  * time to load the 12 real FRFs (UFF58) and resample each to 2048 points (target < 0.5 s);
  * H1 from the 5 real hammer impacts: main resonances, coherence there, single-impact spread;
  * the paper's premise on the 12 real FRFs (and on a synthetic bank): log-magnitude
    correlation between estimate_transfer_function and the true FRF on the 2048-point grid;
  * synthetic-bank attenuation / antiresonance counts;
and saves benchmarks/figures/transfer_real_frfs.png (magnitude/phase of the 12 real FRFs).

Run:  PYTHONPATH=src python benchmarks/bench_transfer.py [--repeat 20] [--no-figure]
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

from gearshot.transfer import (
    TransferFunctionBank,
    antiresonances,
    attenuation_db,
    estimate_transfer_function,
    frf_from_impacts,
    impact_arrays,
    read_uff_records,
    synthetic_bank,
)

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"
FRF_DIR = SHARED / "data" / "frf"
IMPACT_FILE = SHARED / "data" / "impact" / "hammer_impacts.uff"
FIG = ROOT / "benchmarks" / "figures" / "transfer_real_frfs.png"


def load_and_resample(n=2048):
    bank = TransferFunctionBank.from_folder(FRF_DIR)
    return bank, np.stack([tf.to_signal_grid(n) for tf in bank])


def bench_load(repeat):
    load_and_resample()  # warm imports (pyuff, scipy.interpolate)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        bank, grid = load_and_resample()
        times.append(time.perf_counter() - t0)
    assert grid.shape == (12, 2048)
    t = np.array(times)
    print(f"load 12 FRFs + resample to 2048: median {np.median(t) * 1e3:.1f} ms, "
          f"min {t.min() * 1e3:.1f} ms, max {t.max() * 1e3:.1f} ms over {repeat} runs "
          f"(target < 500 ms)")
    return bank


def hammer_numbers():
    from scipy.signal import find_peaks

    force, resp, fs = impact_arrays(read_uff_records(IMPACT_FILE))
    tf, coh = frf_from_impacts(force, resp, fs, estimator="H1")
    mag = np.abs(tf.values)
    pk, _ = find_peaks(mag, prominence=0.05 * mag.max())
    pk = pk[tf.freqs[pk] < 6500]
    pk = np.sort(pk[np.argsort(mag[pk])[::-1][:8]])
    print(f"H1 from {force.shape[0]} impacts, fs {fs:g} Hz, df {tf.df:g} Hz")
    print("  main resonances [Hz]:      " + " ".join(f"{tf.freqs[k]:7.0f}" for k in pk))
    print("  min coherence (±3 lines):  " + " ".join(f"{coh[k - 3:k + 4].min():7.4f}" for k in pk))
    spreads = []
    for k in pk:
        f0 = tf.freqs[k]
        fs_single = []
        for i in range(force.shape[0]):
            s, _ = frf_from_impacts(force[i], resp[i], fs)
            win = np.abs(s.freqs - f0) <= 3
            fs_single.append(s.freqs[win][np.argmax(np.abs(s.values[win]))])
        spreads.append(max(abs(np.array(fs_single) - f0)))
    print("  max single-impact offset:  " + " ".join(f"{d:7.0f}" for d in spreads) + "  (lines)")
    band = (tf.freqs > 500) & (tf.freqs < 6500)
    print(f"  median coherence 0.5-6.5 kHz: {np.median(coh[band]):.4f}")


def gear_like_signal(n_cycles, rng, n_cycle=2048, mesh=38):
    n = n_cycle * n_cycles
    t = np.arange(n) / n_cycle
    x = rng.standard_normal(n)
    for k, amp in enumerate((3.0, 1.5, 1.0, 0.5, 0.3), start=1):
        x += amp * np.cos(2 * np.pi * mesh * k * t + rng.uniform(0, 2 * np.pi))
    return x


def premise(bank, label, x, n_cycle=2048):
    half = slice(0, n_cycle // 2 + 1)
    out = {}
    for name, tf in bank.items():
        y = np.fft.ifft(np.fft.fft(x) * tf.to_signal_grid(x.size)).real
        est = estimate_transfer_function(y, n_cycle)
        true = tf.to_signal_grid(n_cycle)
        out[name] = np.corrcoef(np.log(np.abs(est[half])), np.log(np.abs(true[half])))[0, 1]
    vals = np.array(list(out.values()))
    print(f"premise ({label}): min {vals.min():.3f}, median {np.median(vals):.3f}, "
          f"all >= 0.8: {bool(np.all(vals >= 0.8))}")
    for name, v in out.items():
        print(f"  {name:16s} {v:.3f}")
    return out


def premise_per_cycle(bank, x, n_cycle=2048):
    """Variant: propagate cycle by cycle with the 2048-point grid TF (what step 4 does to SAs)."""
    half = slice(0, n_cycle // 2 + 1)
    vals = []
    for _, tf in bank.items():
        g = tf.to_signal_grid(n_cycle)
        y = np.fft.ifft(np.fft.fft(x.reshape(-1, n_cycle), axis=-1) * g, axis=-1).real.ravel()
        est = estimate_transfer_function(y, n_cycle)
        vals.append(np.corrcoef(np.log(np.abs(est[half])), np.log(np.abs(g[half])))[0, 1])
    print("premise, per-cycle circular propagation (variant): "
          + " ".join(f"{v:.3f}" for v in vals))


def synthetic_summary():
    b = synthetic_bank(24, rng=2023)
    att = np.array([attenuation_db(tf) for tf in b])
    nar = np.array([antiresonances(tf).size for tf in b])
    nmodes = np.array([len(tf.metadata["modes"]) for tf in b])
    nmp = sum(tf.metadata["nonminimum_phase_added"] for tf in b)
    print(f"synthetic bank (24, rng=2023): attenuation {att.min():.1f}-{att.max():.1f} dB, "
          f"antiresonances per FRF {nar.min()}-{nar.max()}, modes {nmodes.min()}-{nmodes.max()}, "
          f"non-minimum-phase {nmp}/24")
    return b


def figure(bank):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from gearshot.plotting import plot_transfer_function

    fig, axes = plt.subplots(2, 2, sharex="col", figsize=(13, 7),
                             gridspec_kw={"height_ratios": [2, 1]})
    for name, tf in bank.items():
        col = 0 if name.startswith("beam") else 1
        plot_transfer_function(tf, axes[:, col], label=name, lw=0.7, phase_center=90.0)
    axes[0, 0].set_title("free beam, hammer roving over 9 points (0.195 Hz lines)")
    axes[0, 1].set_title("structure B, 3 FRFs (1 Hz lines)")
    for ax in axes[0]:
        ax.legend(fontsize=7, ncol=3)
    for ax in axes[1]:
        ax.set_yticks([-90, 0, 90, 180, 270])
    for ax in axes.ravel():
        ax.grid(alpha=0.3)
    fig.suptitle("The 12 measured accelerance FRFs (../shared/data/frf/*.uff)")
    fig.tight_layout()
    FIG.parent.mkdir(parents=True, exist_ok=True)
    tmp = FIG.with_name(".tmp_" + FIG.name)
    fig.savefig(tmp, dpi=110, format="png")
    os.replace(tmp, FIG)
    plt.close(fig)
    print(f"figure written: {FIG.relative_to(ROOT)}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=20)
    ap.add_argument("--no-figure", action="store_true")
    args = ap.parse_args(argv)
    if not FRF_DIR.is_dir():
        sys.exit(f"shared data not found at {FRF_DIR}")
    print(f"load average before: {os.getloadavg()}")
    bank = bench_load(args.repeat)
    hammer_numbers()
    x = gear_like_signal(200, np.random.default_rng(0))
    premise(bank, "12 real FRFs, 200 cycles of noise + mesh tones", x)
    premise_per_cycle(bank, x)
    b = synthetic_summary()
    premise(b, "24 synthetic FRFs", x)
    if not args.no_figure:
        figure(bank)
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
