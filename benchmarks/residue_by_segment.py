"""Where a family rig's healthy residue sits and what step 6 can take off it.

Records one rig of the family (``draw_family``) anew: healthy runs 0–5 and a 0.32 fault,
4 segments of 50 gear cycles each, optionally with parts of the hidden reality set
(``OVERRIDES``, :class:`gearshot.rig.reality.RigReality` fields). Prints, per band of
orders outside the mesh bands (mesh harmonics ± 2, DC), the mean power per segment of:

* the healthy SAs;
* run 0's segments minus the best reference of runs 1–5 (run to run) and of its own
  other segments (within the run);
* run 0's segments minus the least-squares blend of their 3 best references
  (:func:`gearshot.signal.reference_blend.subtract_blend`);
* the faulty run's segments minus the best reference (fault + residue),

and the orders that hold most of the within-run residue.

    python benchmarks/residue_by_segment.py 102 '{"speed_drift": 0}'
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from gearshot.experiments import family_rigs as fr
from gearshot.paper import CYCLES_PER_SEGMENT, GEAR_TEETH, PINION_TEETH, SAMPLES_PER_CYCLE
from gearshot.signal import subtract_healthy
from gearshot.signal.orders import mesh_band_orders
from gearshot.signal.reference_blend import subtract_blend

FRF = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "frf"
BANDS = [(1, 38), (38, 152), (152, 304), (304, 608), (608, 1025)]
N = SAMPLES_PER_CYCLE


#: Orders outside the mesh bands (mesh harmonics ± 2) and DC, one-sided.
OFF_MESH = np.ones(N // 2 + 1, bool)
OFF_MESH[mesh_band_orders(N, GEAR_TEETH, 2)] = False
OFF_MESH[0] = False


def band_header() -> str:
    """The column heads of :func:`band_line`."""
    return "  ".join(f"{f'{a}-{b - 1}':>9s}" for a, b in BANDS)


def band_line(power) -> str:
    """Mean power per segment in each band of ``BANDS``, off the mesh bands (``power``:
    one-sided power spectra, segments on the leading axes)."""
    return "  ".join(f"{power[..., a:b][..., OFF_MESH[a:b]].sum(-1).mean():9.2e}"
                     for a, b in BANDS)


def run_segments(rig, vr, size, run):
    """The run's 4 SAs of 50 consecutive gear cycles."""
    rec = vr.record(speed=rig.speed, load=rig.load, fault_size=size,
                    duration=fr.campaign_duration(dict(segments=4), rig.speed),
                    repetition=run)
    return rec.to_sa_segments(gear_teeth=GEAR_TEETH, pinion_teeth=PINION_TEETH,
                              cycles_per_segment=CYCLES_PER_SEGMENT, samples_per_cycle=N)[:4]


def rig_from_argv(usage: str):
    """``SEED [OVERRIDES]`` of the command line: (seed, overrides, FamilyRig, VirtualRig)."""
    if len(sys.argv) < 2:
        sys.exit(usage)
    seed = int(sys.argv[1])
    overrides = json.loads(sys.argv[2]) if len(sys.argv) > 2 else {}
    return (seed, overrides, *fr.family_rig(seed, FRF, **overrides))


def main() -> None:
    seed, overrides, rig, vr = rig_from_argv(__doc__)
    seg = [run_segments(rig, vr, 0.0, r) for r in range(6)]
    fault = run_segments(rig, vr, 0.32, 0)

    def power(x):
        return np.abs(np.fft.rfft(x, axis=-1)) ** 2

    print(f"rig {seed}: grade {rig.grade}, path {rig.path}, {rig.speed:g} rps / "
          f"{rig.load:g} N m; overrides {overrides or 'none'}")
    print(f"{'orders':34s}" + band_header())
    refs = np.vstack(seg[1:])
    within = subtract_healthy(seg[0][:2], seg[0][2:])
    blend, _ = subtract_blend(seg[0], refs, n_blend=3)
    for label, x in (("healthy SAs", np.vstack(seg)),
                     ("run to run, best reference", subtract_healthy(seg[0], refs)),
                     ("within the run, best reference", within),
                     ("run to run, blend of 3", blend),
                     ("0.32 fault, best reference", subtract_healthy(fault, refs))):
        print(f"{label:34s}{band_line(power(x))}")
    top = np.sort(np.argsort(power(within).mean(0) * OFF_MESH)[::-1][:10])
    print("orders holding most of the within-run residue:",
          ", ".join(str(int(k)) for k in top))


if __name__ == "__main__":
    main()
