"""The 7-DOF lumped-parameter model, its Newmark integrator and a prepared batch.

Degrees of freedom (``q``, 7 of the 13 of DESIGN.md section 2)::

    [x1, y1, phi1, x2, y2, phi2, phib]

lateral bearing motions of pinion (1) and gear (2), their rotations about the nominal
rigid motion driven by the motor angle theta_m(t), and the brake rotation. The axial
and tilt DOFs of the 13-DOF model are left out: for a spur mesh whose load acts at
mid-face the line-of-action vector has no axial or tilt terms, so those DOFs decouple
exactly (K, M and C are block-diagonal) and do not reach the vertical acceleration.

A helical pair adds the axial motions ``z1, z2`` (9 DOFs; axial bearing stiffness
``pair.bearing_stiffness``): the mesh deflection is taken along the tooth normal,
``cos(beta_b) (transverse deflection) + sin(beta_b) (z1 - z2)``, so the mesh force has the
axial component ``F_n sin(beta_b)`` that loads the axial bearings, and the transverse
component ``F_n cos(beta_b)``. (The tilts the axial force excites through its lever arm
are left out.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ._ftff_batch import ftff_cached
from ._helical import helical_batch_tables
from ._kernel import (
    G0,
    contact_slots,
    newmark_spur,
    newmark_tables,
    spur_shared,
    table_shared,
)
from .faults import ToothFault, is_ftff
from .geometry import GearPair
from .profile_errors import ToothProfileErrors, wave_amplitudes
from .stiffness import _N_TABLE, _pair_table, face_bands, fault_tables

__all__ = ["system_matrices", "Integrator", "integrator", "Batch", "HelicalBatch",
           "make_batch", "warmup_time"]


def system_matrices(pair: GearPair):
    """Mass, constant stiffness, damping and line-of-action vector of the 7-DOF model.

    Returns
    -------
    M, K0, C : ndarray (7, 7), or (9, 9) for a helical pair
        Mass (kg, kg m^2), stiffness without the mesh, modal damping.
    v : ndarray (7,) or (9,)
        Mesh deflection along the line of action (the tooth normal) = v . q (m).
    omega : ndarray (7,)
        Natural angular frequencies (rad/s) of the mean-mesh-stiffness system.
    """
    return _modal_system(pair)[:5]


def _modal_system(pair: GearPair):
    """:func:`system_matrices` plus the mean system's squared natural frequencies and
    mass-normalised modes (columns)."""
    m1, m2 = pair.masses
    j1, j2 = pair.inertias
    kt1, kt2 = pair.shaft_torsional_stiffness
    kb = pair.bearing_stiffness
    a = pair.transverse_pressure_angle
    rb1, rb2 = pair.base_radius(pair.z_pinion), pair.base_radius(pair.z_gear)
    M = np.diag([m1, m1, j1, m2, m2, j2, pair.inertia_brake])
    K0 = np.zeros((7, 7))
    for i in (0, 1, 3, 4):
        K0[i, i] = kb
    K0[2, 2] = kt1
    K0[5, 5] += kt2
    K0[6, 6] += kt2
    K0[5, 6] = K0[6, 5] = -kt2
    v = np.array([math.sin(a), math.cos(a), rb1, -math.sin(a), -math.cos(a), -rb2, 0.0])
    if pair.is_helical:
        bb = pair.base_helix_angle
        M = np.diag(np.concatenate([np.diag(M), [m1, m2]]))
        K0 = np.pad(K0, (0, 2))
        K0[7, 7] = K0[8, 8] = kb
        v = np.concatenate([math.cos(bb) * v, [math.sin(bb), -math.sin(bb)]])
    # the mean mesh stiffness (slices keep the spur mean: the face average preserves it)
    k_mean = float(np.mean(_pair_table(pair, None))) * pair.contact_ratio
    K = K0 + k_mean * np.outer(v, v)
    # modal damping on the mean system
    L = np.linalg.cholesky(M)
    Li = np.linalg.inv(L)
    w2, psi = np.linalg.eigh(Li @ K @ Li.T)
    phi = Li.T @ psi                          # mass-normalised modes
    omega = np.sqrt(np.maximum(w2, 0.0))
    C = M @ phi @ np.diag(2 * pair.damping_ratio * omega) @ phi.T @ M
    return M, K0, C, v, omega, w2, phi


@dataclass(frozen=True)
class Integrator:
    """Newmark (beta 1/4, gamma 1/2) coefficients for one pair and time step, in the
    mass-normalised modal coordinates of the mean-stiffness system.

    ``mc`` (ndof, 9) per mode: the factors of displacement, velocity and acceleration in
    the right-hand side, the modal line-of-action, load and motor vectors, 1/D (D: the
    diagonal effective stiffness), line-of-action / D and the output factor (g per modal
    acceleration); ``sc`` = (a0, a2, a3, a6, a7, k_mean, sum vt^2 / D); ``to_modal``
    maps a physical state to modal coordinates (Phi^T M); ``x_static`` is the static
    state under the mean mesh stiffness (modal).
    """

    mc: np.ndarray
    sc: np.ndarray
    to_modal: np.ndarray
    x_static: np.ndarray
    omega_min: float


def integrator(pair: GearPair, dt: float, load0: float) -> Integrator:
    M, K0, C, v, omega, w2, phi = _modal_system(pair)
    beta, gamma = 0.25, 0.5
    a0 = 1 / (beta * dt ** 2)
    a1 = gamma / (beta * dt)
    a2 = 1 / (beta * dt)
    a3 = 1 / (2 * beta) - 1
    a4 = gamma / beta - 1
    a5 = dt / 2 * (gamma / beta - 2)
    a6 = dt * (1 - gamma)
    a7 = gamma * dt
    damp = 2 * pair.damping_ratio * omega          # modal damping, diagonal
    f_load = np.zeros(v.size)
    f_load[6] = -1.0                      # brake torque opposes rotation (per N m)
    ratio = pair.z_pinion / pair.z_gear
    f_motor = np.zeros(v.size)
    f_motor[:7] = -np.array([0, 0, M[2, 2], 0, 0, M[5, 5] * ratio, M[6, 6] * ratio])
    k_mean = float(np.mean(_pair_table(pair, None))) * pair.contact_ratio
    x_static = np.linalg.solve(K0 + k_mean * np.outer(v, v), f_load * load0)
    # Phi^T (K0 + a0 M + a1 C) Phi = diag(w2 + a0 + a1 damp) - k_mean vt vt^T: the mesh
    # stiffness k_m enters as the rank-one term (k_m - k_mean) vt vt^T
    d = w2 + a0 + a1 * damp
    vt = phi.T @ v
    mc = np.column_stack([a0 + a1 * damp, a2 + a4 * damp, a3 + a5 * damp, vt,
                          phi.T @ f_load, phi.T @ f_motor, 1.0 / d, vt / d,
                          (phi[1] + phi[4]) / G0])
    sc = np.array([a0, a2, a3, a6, a7, k_mean, float(np.sum(vt * vt / d))])
    to_modal = phi.T @ M
    return Integrator(np.ascontiguousarray(mc), sc, to_modal, to_modal @ x_static,
                      float(omega[omega > 0].min()))


def warmup_time(pair: GearPair, integ: Integrator) -> float:
    """Time (s) for the start transient of the slowest mode to decay to 1 %."""
    # the start transient (from the static state under the mean mesh stiffness; small)
    # of the slowest mode decays to 1 % of its start: SA error ~2e-5 relative for the
    # paper pair (benchmarks/RESULTS.md, gearshot.sim section)
    return 4.6 / (pair.damping_ratio * integ.omega_min)


def _fault_arrays(pair: GearPair, faults: list[ToothFault]):
    """Per-signal tables over the contact position u of the faulty pair's stiffness and
    displacement excitation (from the fault's hooks), and the faulty tooth index."""
    n = len(faults)
    prefetch_ftff(pair, faults)
    kf = np.empty((n, _N_TABLE))
    ef = np.zeros((n, _N_TABLE))
    tooth = np.full(n, -1, dtype=np.int64)
    healthy = _pair_table(pair, None)
    for i, f in enumerate(faults):
        if f is None or f.is_healthy:
            kf[i] = healthy
            continue
        kf[i], ef[i] = fault_tables(pair, f)
        tooth[i] = f.tooth % pair.z_gear
    return kf, ef, tooth


def prefetch_ftff(pair: GearPair, faults) -> None:
    """Compute the tables of every FTFF among ``faults`` (and their face bands) in one
    batch (:func:`._ftff_batch.ftff_cached`)."""
    todo = [band for f in faults if f is not None and not f.is_healthy
            for _, _, band in face_bands(pair, f) if is_ftff(band)]
    if todo:
        ftff_cached(pair, todo)


def _stack_errors(errs: list[ToothProfileErrors]):
    """Slope, the waviness as sine/cosine amplitudes (half the waviness times cos/sin of
    each tooth's phase) and noise knots of every signal; the waves per profile."""
    wa, wb = wave_amplitudes(np.stack([e.waviness for e in errs]),
                             np.stack([e.phase for e in errs]))
    return ((np.stack([e.slope for e in errs]), wa, wb,
             np.ascontiguousarray(np.stack([e.noise for e in errs]))),
            float(errs[0].n_waves))


LANES = 32     # signals integrated side by side by one thread (_kernel._modal_step); 8 -> 32
#                halves the kernel time per SA (measured with issue #23)


def _lanes(n: int) -> tuple[int, int]:
    """(lanes, padded batch size) for ``n`` signals."""
    lanes = min(LANES, n)
    return lanes, -(-n // lanes) * lanes


def _pad(a: np.ndarray, n_pad: int) -> np.ndarray:
    """``a`` with its first axis padded to ``n_pad`` by repeating the last row."""
    if a.shape[0] == n_pad:
        return a
    return np.concatenate([a, np.repeat(a[-1:], n_pad - a.shape[0], axis=0)])


def _signals_last(a: np.ndarray, n_pad: int) -> np.ndarray:
    """Per-signal array (n, ...) padded and moved to (..., n_pad), contiguous."""
    return np.ascontiguousarray(np.moveaxis(_pad(a, n_pad), 0, -1))


def _contacts(mesh_pos, span, k_tab):
    """The batch-shared contact data of :func:`._kernel.contact_slots` and
    :func:`._kernel.table_shared`."""
    pair_id, wgt, pos, count = contact_slots(np.ascontiguousarray(mesh_pos, dtype=float),
                                             float(span))
    cell, frac, k_h = table_shared(pos, count, k_tab)
    return pair_id, wgt, pos, count, cell, frac, k_h


class Batch:
    """Prepared per-signal tables and the integration state of a batch of signals."""

    def __init__(self, pair, integ, faults, gear_errs, pin_errs):
        self.pair, self.integ = pair, integ
        self.kf, self.ef, self.tooth = _fault_arrays(pair, faults)
        n = len(faults)
        self.lanes, n_pad = _lanes(n)
        tooth = np.full(n_pad, -1, dtype=np.int64)
        tooth[:n] = self.tooth
        self.tooth = tooth
        self.kf, self.ef = _pad(self.kf, n_pad), _pad(self.ef, n_pad)
        g, self.g_nw = _stack_errors(gear_errs)
        p, self.p_nw = _stack_errors(pin_errs)
        self.g = tuple(_signals_last(a, n_pad) for a in g)
        self.p = tuple(_signals_last(a, n_pad) for a in p)
        self._init_state(n)

    def _init_state(self, n):
        x0 = self.integ.x_static
        self.n = n
        n_pad = _lanes(n)[1]
        self.X = np.tile(x0, (n_pad, 1))          # modal coordinates
        self.V = np.zeros((n_pad, x0.size))
        self.A = np.zeros((n_pad, x0.size))

    def shared(self, mesh_pos):
        """What every signal shares at the steps' mesh positions ``mesh_pos``
        (:func:`._kernel.contact_slots`, :func:`._kernel.table_shared`,
        :func:`._kernel.spur_shared`); the same for every batch of a pair, so batches
        run over the same steps compute it once (:meth:`run`'s ``shared``)."""
        pair_id, wgt, pos, count, _, _, k_h = _contacts(mesh_pos, self.pair.contact_ratio,
                                                        _pair_table(self.pair, None))
        return (pair_id, wgt, pos, count, k_h,
                *spur_shared(pos, count, self.g[3].shape[1], self.g_nw, self.p_nw))

    def run(self, mesh_pos, motor_acc, load, rec_start, n_rec, shared=None):
        """Advance over the given steps; return the vertical acceleration (g) of steps
        ``rec_start ... rec_start + n_rec - 1`` (``shared``: :meth:`shared` of
        ``mesh_pos``, computed here when not given)."""
        integ = self.integ
        pair_id, wgt, pos, count, k_h, n_cell, n_frac, trig = (
            self.shared(mesh_pos) if shared is None else shared)
        out = np.empty((self.X.shape[0], n_rec))
        newmark_spur(np.ascontiguousarray(load, dtype=float),
                     np.ascontiguousarray(motor_acc, dtype=float), count, wgt, pos,
                     pair_id % self.g[0].shape[0], pair_id % self.p[0].shape[0], k_h,
                     n_cell, n_frac, trig, self.kf, self.ef, self.tooth, *self.g, *self.p,
                     integ.mc, integ.sc, self.X, self.V, self.A, self.lanes, rec_start, out)
        return out[:self.n]


class HelicalBatch(Batch):
    """A batch of a helical pair: per-tooth tables of stiffness and error force over the
    delay since a tooth pair's first contact (slice method, :mod:`._slices`)."""

    def __init__(self, pair, integ, faults, gear_errs, pin_errs):
        self.pair, self.integ = pair, integ
        n = len(faults)
        self.lanes, n_pad = _lanes(n)
        prefetch_ftff(pair, faults)
        (self.span, self.k, self.kf, tooth, self.fg, self.fp,
         self.fpf) = helical_batch_tables(pair, faults, gear_errs, pin_errs, n_pad)
        self.tooth = np.full(n_pad, -1, dtype=np.int64)
        self.tooth[:n] = tooth
        self.kf, self.fpf = _pad(self.kf, n_pad), _pad(self.fpf, n_pad)
        self._init_state(n)

    def shared(self, mesh_pos):
        return _contacts(mesh_pos, self.span, self.k)

    def run(self, mesh_pos, motor_acc, load, rec_start, n_rec, shared=None):
        integ = self.integ
        pair_id, wgt, _, count, cell, frac, k_h = (
            self.shared(mesh_pos) if shared is None else shared)
        out = np.empty((self.X.shape[0], n_rec))
        newmark_tables(
            np.ascontiguousarray(load, dtype=float),
            np.ascontiguousarray(motor_acc, dtype=float), count, wgt,
            pair_id % self.fg.shape[0], pair_id % self.fp.shape[0], k_h, cell, frac,
            self.kf, self.tooth, self.fg, self.fp, self.fpf, integ.mc, integ.sc, self.X,
            self.V, self.A, self.lanes, rec_start, out)
        return out[:self.n]


def make_batch(pair, integ, faults, gear_errs, pin_errs) -> Batch:
    """A :class:`Batch` (spur) or :class:`HelicalBatch` for ``pair``."""
    cls = HelicalBatch if pair.is_helical else Batch
    return cls(pair, integ, faults, gear_errs, pin_errs)
