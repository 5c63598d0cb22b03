"""Can any energy of the difference signal tell a rough beam rig's faults from its healthy runs?

Records one rig of the family anew (``family_rig``): healthy runs 0–5 and the faulty
recordings 0 and 1 of sizes 0.32, 0.56 and 0.66, 4 segments of 50 gear cycles each.
Leave one healthy run out at a time: the other 5 are step 6's references (the blend of 3,
the default) and give the residue's power per order ``R`` (their blend residuals against
each other); the left-out run's segments and the faulty segments are then read by three
statistics of their blend residual, every order outside the mesh bands:

* ``raw``: the residual's energy (what an unweighted RMS feature sees);
* ``white``: the energy per order over ``R`` (the residue whitened order by order);
* ``white9``: the same over ``R`` smoothed over 9 orders in log power (the fit's
  whitening, :mod:`gearshot.estimator.whitening`).

Printed: the healthy segments' mean and standard deviation of each statistic and each
size's shift from it in healthy standard deviations (``d'``). A statistic that a fault
does not move by one or two standard deviations gives no feature to read the size from.

    python benchmarks/rough_beam_detectability.py 102
"""

from __future__ import annotations

import numpy as np
from residue_by_segment import OFF_MESH, rig_from_argv, run_segments
from scipy.ndimage import uniform_filter1d

from gearshot.estimator.steps import residue_power
from gearshot.estimator.whitening import SMOOTH_ORDERS
from gearshot.signal.reference_blend import subtract_blend

SIZES = (0.32, 0.56, 0.66)


def _power(x):
    return np.abs(np.fft.rfft(x, axis=-1)) ** 2


def main() -> None:
    seed, overrides, rig, vr = rig_from_argv(__doc__)
    healthy = [run_segments(rig, vr, 0.0, r) for r in range(6)]
    faulty = {s: [run_segments(rig, vr, s, r) for r in (0, 1)] for s in SIZES}
    stats: dict[float, dict[str, list[float]]] = {
        s: {"raw": [], "white": [], "white9": []} for s in (0.0, *SIZES)}
    for out in range(6):
        train = [q for q in range(6) if q != out]
        refs = np.vstack([healthy[q] for q in train])
        residue = np.vstack([subtract_blend(healthy[q], np.vstack(
            [healthy[p] for p in train if p != q]), n_blend=3)[0] for q in train])
        power = residue_power(residue)
        r = power[OFF_MESH]
        smooth = np.exp(uniform_filter1d(np.log(power + 1e-300), SMOOTH_ORDERS,
                                         mode="nearest"))[OFF_MESH]
        targets = [(0.0, healthy[out])]
        if out < 2:     # each faulty recording read against 5 healthy runs once
            targets += [(s, faulty[s][out]) for s in SIZES]
        for size, x in targets:
            p = _power(subtract_blend(x, refs, n_blend=3)[0])[:, OFF_MESH]
            stats[size]["raw"] += p.sum(1).tolist()
            stats[size]["white"] += (p / r).sum(1).tolist()
            stats[size]["white9"] += (p / smooth).sum(1).tolist()
    print(f"rig {seed}: grade {rig.grade}, path {rig.path}, {rig.speed:g} rps / "
          f"{rig.load:g} N m; overrides {overrides or 'none'}")
    for name in ("raw", "white", "white9"):
        h = np.array(stats[0.0][name])
        shifts = "  ".join(f"{s}: d' {(np.mean(stats[s][name]) - h.mean()) / h.std():+.2f}"
                           for s in SIZES)
        print(f"{name:7s} healthy {h.mean():9.3g} ± {h.std():8.2g}   {shifts}")


if __name__ == "__main__":
    main()
