"""Compare gearshot.sim with the lab model's reference outputs; print numbers, save a figure.

    PYTHONPATH=src python benchmarks/compare_sim_reference.py

Writes benchmarks/figures/sim_vs_reference.png. Needs ../shared/reference.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from gearshot.signal import difference_signal  # noqa: E402
from gearshot.sim import Fault, GearPair, mesh_stiffness, simulate_sa  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
REF = ROOT.parent / "shared" / "reference"
N_GEARS = 8


def diff(sa):
    """Difference signal (mesh order 38, two sidebands), as in the reference."""
    return difference_signal(sa, 38, n_sidebands=2)


def rms(x):
    return np.sqrt(np.mean(x ** 2, axis=-1))


def band_spectrum(x, width=16):
    """Amplitude spectrum of the difference signal, rms per band of ``width`` orders."""
    X = np.abs(np.fft.rfft(diff(x), axis=-1))[..., 1:1025] / 1024
    return np.sqrt(np.mean(X.reshape(*X.shape[:-1], -1, width) ** 2, axis=-1))


def main():
    data = np.loadtxt(REF / "bgu_mesh_stiffness.csv", delimiter=",", skiprows=1)
    theta = data[:, 0] * 2 * np.pi
    pair = GearPair.paper()
    k = mesh_stiffness(pair, theta)
    kf = mesh_stiffness(pair, theta, fault=Fault.ftff(0.5))
    ref = data[:, 1].mean()
    print(f"mesh stiffness: mean ours {k.mean():.4g} ref {ref:.4g} "
          f"({100 * (k.mean() / ref - 1):.1f} %), RMS diff "
          f"{100 * rms(k - data[:, 1]) / ref:.1f} % of mean")

    ref = np.load(REF / "bgu_sa.npz")
    cases = [("y000_din7", 0.0, 7), ("y010_din7", 0.1, 7), ("y030_din7", 0.3, 7),
             ("y050_din7", 0.5, 7), ("y070_din7", 0.7, 7), ("y050_din3", 0.5, 3),
             ("y050_din11", 0.5, 11)]
    pairs = {"paper (0.8/3.2 kg)": pair, "geometry masses (as ref)": GearPair()}
    results = {}
    for name, p in pairs.items():
        rows = {}
        for key, y, grade in cases:
            sa = simulate_sa(p, speed=15, load=10, grade=grade, fault_sizes=[y] * N_GEARS,
                             rng=1000 + grade)
            rows[key] = sa
        results[name] = rows
    print(f"\ndiff-RMS (g), mean over {N_GEARS} gears; raw SA RMS in brackets")
    print(f"{'case':12s} {'reference':>18s} " + " ".join(f"{n:>26s}" for n in pairs))
    for key, _, _ in cases:
        line = f"{key:12s} {rms(diff(ref[key])):8.1f} [{rms(ref[key]):6.1f}]   "
        for name in pairs:
            sa = results[name][key]
            line += f"{rms(diff(sa)).mean():16.1f} [{rms(sa).mean():6.1f}] "
        print(line)
    print("\nratio diff-RMS(y)/diff-RMS(healthy), DIN 7")
    for key in ("y010_din7", "y030_din7", "y050_din7", "y070_din7"):
        line = f"{key:12s} ref {rms(diff(ref[key])) / rms(diff(ref['y000_din7'])):5.2f}"
        for name in pairs:
            r = results[name]
            line += (f" | {name}: "
                     f"{rms(diff(r[key])).mean() / rms(diff(r['y000_din7'])).mean():5.2f}")
        print(line)

    fig, axes = plt.subplots(2, 2, figsize=(13, 8.5))
    ax = axes[0, 0]
    t = data[:, 0] * 17
    sel = t < 4
    ax.plot(t[sel], data[sel, 1] / 1e6, "k", lw=1.2, label="reference healthy")
    ax.plot(t[sel], data[sel, 2] / 1e6, "k--", lw=1.2, label="reference FTFF y=0.5")
    ax.plot(t[sel], k[sel] / 1e6, "C0", lw=1, label="gearshot healthy")
    ax.plot(t[sel], kf[sel] / 1e6, "C3--", lw=1, label="gearshot FTFF y=0.5")
    ax.set(xlabel="mesh periods", ylabel="mesh stiffness (N/µm)",
           title="Mesh stiffness, paper pair")
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    ys = np.linspace(0.05, 0.95, 20)
    sa = simulate_sa(pair, speed=15, load=10, grade=7, fault_sizes=np.r_[0, ys],
                     same_gear=True, rng=3)
    ax.plot(np.r_[0, ys], rms(diff(sa)) / rms(diff(sa[:1])), "o-", label="gearshot (one gear)")
    ry = [0, 0.1, 0.3, 0.5, 0.7]
    rr = [rms(diff(ref[f"y{int(round(100 * y)):03d}_din7"])) for y in ry]
    ax.plot(ry, np.array(rr) / rr[0], "ks--", label="reference")
    ax.set(xlabel="fault size y", ylabel="diff-RMS / healthy diff-RMS",
           title="Fault signature, DIN 7, 15 rps, 10 Nm", yscale="log")
    ax.legend(fontsize=8)
    ax = axes[1, 0]
    orders = np.arange(1, 1025).reshape(-1, 16).mean(axis=1)
    for key, c in (("y000_din7", "C0"), ("y070_din7", "C3")):
        ax.semilogy(orders, band_spectrum(ref[key]), c + "--", label=f"reference {key}")
        ax.semilogy(orders, band_spectrum(results["paper (0.8/3.2 kg)"][key]).mean(0), c,
                    label=f"gearshot {key}")
    ax.set(xlabel="order (per gear revolution)", ylabel="|DFT| of diff signal (g), band rms",
           title="Difference-signal spectra")
    ax.legend(fontsize=8)
    ax = axes[1, 1]
    ang = np.arange(2048) / 2048 * 360
    ax.plot(ang, ref["y070_din7"], "k", lw=0.7, label="reference y=0.7")
    ax.plot(ang, results["paper (0.8/3.2 kg)"]["y070_din7"][0], "C3", lw=0.7, alpha=0.8,
            label="gearshot y=0.7")
    ax.set(xlabel="gear angle (deg)", ylabel="SA (g)", title="SA, DIN 7, y = 0.7")
    ax.legend(fontsize=8)
    fig.tight_layout()
    out = ROOT / "benchmarks" / "figures" / "sim_vs_reference.png"
    fig.savefig(out, dpi=110)
    print(f"\nfigure: {out.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
