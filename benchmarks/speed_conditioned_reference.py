"""Does a cycle's own speed explain a rough beam rig's residue? (issue #30 item 4)

Records one rig of the family (``draw_family``) anew, as ``residue_by_segment.py`` does:
healthy runs 0–5, 4 segments of 50 gear cycles each, optionally with parts of the hidden
reality set (``OVERRIDES``). Run 0's segments are the target; runs 1–5 the healthy
references. Prints, per band of orders outside the mesh bands, the mean power per segment
of run 0 minus:

* the best delay-aligned reference SA and the blend of 3 (step 6 as the library runs it);
* a model of each healthy *cycle's* order spectrum as a function of that cycle's speed
  (tacho), fitted on every cycle of runs 1–5 (1000 cycles) and averaged over the target
  segment's own cycles: a polynomial of degree 1–3 in the speed, a Gaussian kernel
  over the speed (bandwidth 0.02 % and 0.1 %), and the 10 nearest cycles in speed of the
  same pinion phase (the pinion's orders are not whole orders of the gear's cycle).

A cycle-level model sees the speed the SA averages away; if the residue were the mean
response of each order at the cycle's speed, it would leave far less than the blend.

    python benchmarks/speed_conditioned_reference.py 102 ['{"tacho_jitter": 0}']
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
from residue_by_segment import band_header, band_line, rig_from_argv

from gearshot.experiments import family_rigs as fr
from gearshot.paper import GEAR_TEETH, PINION_TEETH, SAMPLES_PER_CYCLE
from gearshot.signal import subtract_healthy
from gearshot.signal.reference_blend import subtract_blend
from gearshot.signal.trains import shaft_cycle_times

N = SAMPLES_PER_CYCLE
CYCLES = 200  # 4 segments of 50
ORDERS = np.arange(N // 2 + 1)


def _cycles(rig, vr, run):
    """The run's first 200 gear cycles: order spectra (200, N/2+1) and speeds (rev/s)."""
    rec = vr.record(speed=rig.speed, load=rig.load, fault_size=0.0,
                    duration=fr.campaign_duration(dict(segments=4), rig.speed), repetition=run)
    times = shaft_cycle_times(rec.pulse_times(), revs_per_cycle=Fraction(GEAR_TEETH, PINION_TEETH),
                              pulses_per_rev=rec.resolved_pulses_per_rev())
    x = rec.angle_domain(gear_teeth=GEAR_TEETH, pinion_teeth=PINION_TEETH, samples_per_cycle=N)
    spectra = np.fft.rfft(x[: CYCLES * N].reshape(CYCLES, N), axis=-1)
    return spectra, 1.0 / np.diff(times)[:CYCLES]


def _segments(spectra):
    return spectra.reshape(4, CYCLES // 4, -1).mean(1)


def _aligned(runs):
    """Every run advanced by its delay against run 1 (whole-run SAs, step 6's lag search)."""
    ref = np.fft.irfft(runs[1][0].mean(0), n=N)
    out = []
    for spectra, speed in runs:
        _, _, delay = subtract_healthy(np.fft.irfft(spectra.mean(0), n=N), ref,
                                       return_details=True)
        out.append((spectra * np.exp(2j * np.pi * ORDERS * float(delay) / N), speed))
    return out


def _models(train):
    """name -> function(target spectra, target speeds) -> predicted segment spectra."""
    spectra = np.concatenate([s for s, _ in train])
    speed = np.concatenate([f for _, f in train])
    phase = np.concatenate([np.arange(CYCLES) % PINION_TEETH for _ in train])
    mean = speed.mean()

    def poly(deg):
        design = np.vander(100 * (speed / mean - 1), deg + 1)
        beta = np.linalg.lstsq(design, spectra, rcond=None)[0]
        return lambda f: np.vander(100 * (f / mean - 1), deg + 1) @ beta

    def kernel(h):
        def predict(f):
            w = np.exp(-0.5 * ((speed[None] - f[:, None]) / (h * mean)) ** 2)
            return (w @ spectra) / w.sum(1, keepdims=True)
        return predict

    def nearest(f, k=10):
        out = np.empty((f.size, spectra.shape[1]), complex)
        for c, fc in enumerate(f):
            idx = np.flatnonzero(phase == c % PINION_TEETH)
            out[c] = spectra[idx[np.argsort(np.abs(speed[idx] - fc))[:k]]].mean(0)
        return out

    return {**{f"speed polynomial, degree {d}": poly(d) for d in (1, 2, 3)},
            "speed kernel, 0.02 %": kernel(2e-4), "speed kernel, 0.1 %": kernel(1e-3),
            "10 nearest in speed, same pinion phase": nearest}


def main() -> None:
    seed, overrides, rig, vr = rig_from_argv(__doc__)
    runs = _aligned([_cycles(rig, vr, r) for r in range(6)])
    target, speed = runs[0]
    sa = _segments(target)
    refs = np.fft.irfft(np.concatenate([_segments(s) for s, _ in runs[1:]]), n=N)
    blend, _ = subtract_blend(np.fft.irfft(sa, n=N), refs, n_blend=3)
    print(f"rig {seed}: grade {rig.grade}, path {rig.path}, {rig.speed:g} rps / "
          f"{rig.load:g} N m; overrides {overrides or 'none'}; cycle speeds "
          f"{speed.min():.3f}-{speed.max():.3f} rev/s (run 0)")
    print(f"{'run 0 minus':42s}" + band_header())
    rows = {"nothing (the healthy SAs)": sa,
            "the best reference (step 6, one)": np.fft.rfft(
                subtract_healthy(np.fft.irfft(sa, n=N), refs), axis=-1),
            "the blend of 3 (step 6, the default)": np.fft.rfft(blend, axis=-1)}
    for name, model in _models(runs[1:]).items():
        rows[name] = sa - _segments(model(speed))
    for name, spectra in rows.items():
        print(f"{name:42s}{band_line(np.abs(spectra) ** 2)}")


if __name__ == "__main__":
    main()
