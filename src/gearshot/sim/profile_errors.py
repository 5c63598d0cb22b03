"""Tooth-profile errors per tooth from the DIN 3962 quality grade.

Along the roll length of the active profile (s in [0, 1]) tooth i deviates by
``e_i(s) = fHa_i s + 0.5 ffa_i sin(2 pi n s + phi_i) + noise_i(s)`` with fHa_i, ffa_i drawn
within +-10 % of the grade's values, n = 2.5 waves (z < 20) or 3.5, phi_i ~ U(-pi, pi) and
noise_i piecewise linear between knots drawn from U(-c, c) (DESIGN.md section 2).

In the dynamics, s is the position along the path of contact (0 at the start of the
pair's contact, 1 at its end) for both wheels, as in the lab's model; the two wheels'
slope terms then add into a mesh-periodic sawtooth (measuring each wheel's s from its own
root instead would let equal slopes cancel and lowers the mesh harmonics about 4-fold,
far below the reference SAs).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import check_int

__all__ = ["DIN_PROFILE_TOLERANCES", "ToothProfileErrors", "draw_profile_errors",
           "tooth_error", "noise_cell", "wave_amplitudes", "waves_per_profile"]

#: grade -> (fHa, ffa, c) in micrometres, DIN 3962 grades 1..12.
DIN_PROFILE_TOLERANCES = {
    g: (fh, ff, c) for g, fh, ff, c in zip(
        range(1, 13),
        (1, 1.5, 2, 3, 4.5, 6, 9, 12, 18, 28, 45, 71),
        (1.5, 2, 3, 4, 6, 8, 11, 16, 22, 36, 56, 90),
        (0.02, 0.04, 0.06, 0.08, 0.1, 0.2, 0.3, 0.4, 0.6, 1.0, 1.5, 2.3))
}

N_NOISE_KNOTS = 16


def tooth_error(x, slope, wa, wb, sin_w, cos_w, knot_lo, knot_hi, frac):
    """The profile error of a tooth, the one formula of the package.

    ``slope x + wa sin(2 pi n s) + wb cos(2 pi n s) + noise(s)``: ``x`` is the roll
    fraction measured from the slope's origin (``s`` in the simulator), ``sin_w, cos_w``
    the sine and cosine of the waviness angle ``2 pi n s``, ``wa, wb`` the waviness's
    amplitudes (:func:`wave_amplitudes`), and the noise is interpolated linearly between
    ``knot_lo`` and ``knot_hi`` at fraction ``frac`` (:func:`noise_cell`). Plain
    arithmetic on numpy arrays or scalars; the integration kernel compiles it inline
    (:mod:`gearshot.sim._kernel`).
    """
    return slope * x + wa * sin_w + wb * cos_w + (knot_lo * (1.0 - frac) + knot_hi * frac)


def noise_cell(s, n_knots: int):
    """Knot cell and fraction of roll fractions ``s`` in [0, 1] on ``n_knots`` equally
    spaced noise knots (``s = 1`` is the end of the last cell)."""
    pos = np.asarray(s) * (n_knots - 1)
    i0 = np.minimum(pos.astype(int), n_knots - 2)
    return i0, pos - i0


def wave_amplitudes(waviness, phase):
    """Sine and cosine amplitudes ``wa, wb`` of the waviness term ``0.5 ffa sin(2 pi n s
    + phi) = wa sin(2 pi n s) + wb cos(2 pi n s)``."""
    half = 0.5 * np.asarray(waviness)
    return half * np.cos(phase), half * np.sin(phase)


@dataclass(frozen=True)
class ToothProfileErrors:
    """Profile errors of every tooth of one wheel (arrays over teeth; metres).

    Attributes
    ----------
    slope : ndarray (z,)
        fHa_i, m.
    waviness : ndarray (z,)
        ffa_i, m (peak-to-peak of the sine term).
    phase : ndarray (z,)
        phi_i, rad.
    noise : ndarray (z, n_knots)
        Noise knots, m, equally spaced over s in [0, 1].
    n_waves : float
        Waves per active profile.
    """

    slope: np.ndarray
    waviness: np.ndarray
    phase: np.ndarray
    noise: np.ndarray
    n_waves: float

    def __call__(self, tooth, s) -> np.ndarray:
        """Deviation (m) of tooth ``tooth`` at roll fractions ``s`` (broadcast)."""
        tooth = np.asarray(tooth) % self.slope.size
        s = np.clip(np.asarray(s, dtype=float), 0.0, 1.0)
        i0, frac = noise_cell(s, self.noise.shape[1])
        wa, wb = wave_amplitudes(self.waviness[tooth], self.phase[tooth])
        angle = 2 * np.pi * self.n_waves * s
        return tooth_error(s, self.slope[tooth], wa, wb, np.sin(angle), np.cos(angle),
                           self.noise[tooth, i0], self.noise[tooth, i0 + 1], frac)

    def mean_tooth(self) -> ToothProfileErrors:
        """The average over teeth as a one-tooth wheel (exact: the sine terms share one
        frequency, so their mean is a sine)."""
        # np.mean's own steps (a sum, then divided by the count), without its overhead
        z = self.slope.size
        phasor = np.add.reduce(self.waviness * np.exp(1j * self.phase)) / z
        return ToothProfileErrors(
            slope=np.add.reduce(self.slope, keepdims=True) / z,
            waviness=np.array([np.abs(phasor)]), phase=np.array([np.angle(phasor)]),
            noise=np.add.reduce(self.noise, axis=0, keepdims=True) / z,
            n_waves=self.n_waves)


def draw_profile_errors(z: int, grade: int, rng: np.random.Generator) -> ToothProfileErrors:
    """Draw the profile errors of a ``z``-tooth wheel of DIN grade ``grade`` (1 ... 12)."""
    z = check_int(z, "z", minimum=1)
    grade = check_int(grade, "grade", minimum=1, maximum=12)
    fh, ff, c = (v * 1e-6 for v in DIN_PROFILE_TOLERANCES[grade])
    slope = fh * rng.uniform(0.9, 1.1, z)
    waviness = ff * rng.uniform(0.9, 1.1, z)
    phase = rng.uniform(-np.pi, np.pi, z)
    noise = rng.uniform(-c, c, (z, N_NOISE_KNOTS))
    return ToothProfileErrors(slope, waviness, phase, noise, waves_per_profile(z))


def waves_per_profile(z: int) -> float:
    """Waviness waves per active profile of a ``z``-tooth wheel (DESIGN.md section 2)."""
    return 2.5 if z < 20 else 3.5
