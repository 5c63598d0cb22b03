"""A fast stand-in physics engine for the virtual rig (used until/unless the full simulator
is plugged in).

It is *not* the 13-DOF simulator. It keeps the features the rig's tests need:

* a geometric transmission error (TE) of the meshing teeth, tabulated over one full
  hunting period of the pair (lcm(z_gear, z_pinion) mesh cycles): tooth-profile errors of
  both wheels from their DIN 3962 grade (slope fHa, waviness ffa, random roughness c), a
  load-proportional mesh-compliance ripple and, on gear tooth 0, a full-face fault whose
  width grows with the fault size y (an arc-shaped cut, optionally irregular);
* load sharing between tooth pairs (contact ratio > 1) as a smoothing of the TE over a
  mesh cycle;
* the structure's response, integrated in *time* over the whole run: the TE at the
  instantaneous angle drives three lightly damped modes (a base-excited modal model), so
  speed and load variations act as in a real run (no time-warping of one cycle).

Output: vertical acceleration in g.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.signal

from .._validation import check_in_range, check_int
from ..paper import GEAR_TEETH, PINION_TEETH
from ..sim.profile_errors import (
    DIN_PROFILE_TOLERANCES,
    noise_cell,
    tooth_error,
    wave_amplitudes,
    waves_per_profile,
)
from .reality import RigReality

__all__ = ["SurrogateEngine", "DIN_PROFILE_TOLERANCES_UM"]

#: grade -> (fHa, ffa, c) in micrometres (DIN 3962): the simulator's table.
DIN_PROFILE_TOLERANCES_UM = DIN_PROFILE_TOLERANCES

_G = 9.80665


@dataclass(frozen=True)
class SurrogateEngine:
    """Stand-in physics engine: ``engine(motor_revs=..., load_torque=..., fs=...,
    fault_size=..., reality=..., rng=...) -> acceleration (g)``.

    Parameters
    ----------
    gear_teeth, pinion_teeth : int
        Tooth counts (driven gear, pinion).
    nominal_grade : int
        DIN grade used when ``reality`` is None (the nominal model).
    modes_hz : tuple of float
        Nominal natural frequencies of the three structural modes, Hz.
    damping : float
        Nominal modal damping ratio.
    points_per_mesh : int
        Resolution of the TE table per mesh cycle.
    fault_um, fault_compliance_um : float
        TE where the cut tooth has lost contact: geometric (um) and extra compliance
        (um per 10 N m).
    fault_impact_um : float
        Re-engagement impact (a short TE pulse, um per 10 N m) per mesh cycle of lost
        contact.
    contact_loss_size : float
        Fault size at which a nominal-depth cut makes its tooth lose contact at the cut's
        centre; larger faults lose contact over a wider part of the mesh cycle.
    """

    gear_teeth: int = GEAR_TEETH
    pinion_teeth: int = PINION_TEETH
    nominal_grade: int = 7
    modes_hz: tuple[float, float, float] = (2800.0, 6300.0, 9700.0)
    damping: float = 0.05
    points_per_mesh: int = 128
    fault_um: float = 2.0
    fault_compliance_um: float = 2.0
    fault_impact_um: float = 4.0
    contact_loss_size: float = 0.3

    def __post_init__(self) -> None:
        check_int(self.gear_teeth, "gear_teeth", minimum=2)
        check_int(self.pinion_teeth, "pinion_teeth", minimum=2)
        check_int(self.nominal_grade, "nominal_grade", minimum=1, maximum=12)
        check_in_range(self.damping, "damping", 0.0, 1.0, low_inclusive=False)

    # -- tooth profile errors ---------------------------------------------------------
    @staticmethod
    def _profile(z: int, grade: int, s: np.ndarray, tooth: np.ndarray,
                 rng: np.random.Generator) -> np.ndarray:
        fh, ff, c = DIN_PROFILE_TOLERANCES_UM[grade]
        slope = fh * rng.uniform(0.9, 1.1, z) * rng.choice([-1.0, 1.0], z)
        wav = ff * rng.uniform(0.9, 1.1, z)
        phase = rng.uniform(-np.pi, np.pi, z)
        knots = rng.uniform(-c, c, (z, 16))
        i0, fr = noise_cell(s, knots.shape[1])
        wa, wb = wave_amplitudes(wav[tooth], phase[tooth])
        angle = 2 * np.pi * waves_per_profile(z) * s
        # the slope measured from mid-profile
        return tooth_error(s - 0.5, slope[tooth], wa, wb, np.sin(angle), np.cos(angle),
                           knots[tooth, i0], knots[tooth, i0 + 1], fr)

    def _fault(self, s: np.ndarray, size: float, reality: RigReality | None) -> np.ndarray:
        """Relative cut depth (0 ... ~1) along the mesh cycle of the faulty tooth."""
        if size <= 0:
            return np.zeros_like(s)
        if reality is None:
            center, depth, edges, rough = 0.5, 0.5, (0.0, 0.0), (0.0, 0.0, 0.0)
        else:
            center, depth = reality.fault_center, reality.fault_depth
            edges, rough = reality.fault_edges, reality.fault_roughness
        lo = center - 0.5 * size * (1 + edges[0])
        hi = center + 0.5 * size * (1 + edges[1])
        x = (s - lo) / (hi - lo)  # 0 ... 1 across the cut
        arc = np.sqrt(np.clip(1 - (2 * x - 1) ** 2, 0.0, None))
        shape = 1 + sum(r * np.cos((k + 1) * np.pi * x) for k, r in enumerate(rough))
        # cut depth relative to the depth at which the tooth loses contact altogether
        # (cut depth ~ depth * chord ~ depth * size): saturates -> contact-loss plateau
        rel = depth / 0.5 * size / self.contact_loss_size * arc * shape
        return np.where((x > 0) & (x < 1), np.clip(rel, 0.0, 1.0), 0.0)

    def tables(self, *, fault_size: float, reality: RigReality | None,
               rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """TE tables over one hunting period: geometric (um) and compliance (um per 10 N m).

        Returns arrays of shape (lcm * points_per_mesh,), sampled at mesh-cycle positions
        ``u = i / points_per_mesh``.
        """
        zg, zp = self.gear_teeth, self.pinion_teeth
        period = zg * zp // math.gcd(zg, zp)
        u = np.arange(period * self.points_per_mesh) / self.points_per_mesh
        n = np.floor(u).astype(np.int64)
        s = u - n
        if reality is None:
            grade, prng, kfac = self.nominal_grade, rng, 1.0
        else:
            grade = reality.grade
            prng = np.random.default_rng(reality.profile_seed)
            kfac = reality.mesh_stiffness_factor
        geom = (self._profile(zg, grade, s, n % zg, prng)
                + self._profile(zp, grade, s, n % zp, prng))
        compl = (4.0 * (1 + 0.25 * np.cos(2 * np.pi * s) + 0.08 * np.cos(4 * np.pi * s + 0.5))
                 / kfac)
        # load sharing over a contact ratio ~1.6: smooth over 0.6 mesh cycle (circular)
        geom, compl = self._smooth(geom, 0.6), self._smooth(compl, 0.6)
        # the cut tooth loses contact inside the window: a sharper, load-dependent event
        raw_cut = self._fault(s, fault_size, reality) * (n % zg == 0)
        cut = self._smooth(raw_cut, 0.15)
        geom = geom - self.fault_um * cut
        compl = compl + self.fault_compliance_um * cut / kfac
        # re-engagement impact at the end of the contact-loss span: the wheels run free
        # across it, so the impact grows with its length (and with load, see __call__)
        lost = np.flatnonzero(raw_cut >= 1.0)
        impact = np.zeros_like(u)
        if lost.size:
            span = lost.size / self.points_per_mesh  # mesh cycles without contact
            d = (u - u[lost[-1]]) * self.points_per_mesh
            impact = self.fault_impact_um * span * np.exp(-0.5 * (d / 2.0) ** 2) / kfac
        return geom, compl + impact

    def _smooth(self, x: np.ndarray, cycles: float) -> np.ndarray:
        width = max(int(cycles * self.points_per_mesh), 1)
        win = np.hanning(width + 2)[1:-1]
        win /= win.sum()
        padded = np.concatenate([x[-width:], x, x[:width]])
        return scipy.signal.fftconvolve(padded, win, mode="same")[width:-width]

    def _modes(self, reality: RigReality | None) -> list[tuple[float, float, float]]:
        """(frequency Hz, damping, weight) per mode."""
        weights = (0.5, 0.3, 0.2)
        if reality is None:
            return [(f, self.damping, w) for f, w in zip(self.modes_hz, weights)]
        mp, mg = reality.mass_factor
        kb, km, ks = (reality.bearing_stiffness_factor, reality.mesh_stiffness_factor,
                      reality.shaft_stiffness_factor)
        factors = (math.sqrt(kb / mg), math.sqrt(km / mp), math.sqrt(km * ks / (mp * mg)))
        return [(f * r, self.damping * reality.damping_factor, w)
                for f, r, w in zip(self.modes_hz, factors, weights)]

    def __call__(self, *, motor_revs: np.ndarray, load_torque: np.ndarray, fs: float,
                 fault_size: float, reality: RigReality | None,
                 rng: np.random.Generator) -> np.ndarray:
        geom, compl = self.tables(fault_size=fault_size, reality=reality, rng=rng)
        n_tab = geom.size
        period = n_tab / self.points_per_mesh
        u = np.mod(np.asarray(motor_revs, dtype=np.float64) * self.pinion_teeth, period)
        idx = u * self.points_per_mesh
        grid = np.arange(n_tab + 1)
        te = (np.interp(idx, grid, np.append(geom, geom[0]))
              + np.asarray(load_torque) / 10.0 * np.interp(idx, grid, np.append(compl, compl[0])))
        te *= 1e-6  # um -> m
        acc = np.zeros_like(te)
        for f, z, w in self._modes(reality):
            wn = 2 * np.pi * f
            b, a = scipy.signal.bilinear([wn ** 2, 0.0, 0.0], [1.0, 2 * z * wn, wn ** 2], fs=fs)
            acc += w * scipy.signal.lfilter(b, a, te)
        return acc / _G
