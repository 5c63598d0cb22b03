"""Batched gear-pair dynamics: Newmark integration of the lumped-parameter model.

Degrees of freedom (``q``, 7 of the 13 of DESIGN.md section 2)::

    [x1, y1, phi1, x2, y2, phi2, phib]

lateral bearing motions of pinion (1) and gear (2), their rotations about the nominal
rigid motion driven by the motor angle theta_m(t), and the brake rotation. The axial
and tilt DOFs of the 13-DOF model are left out: for a spur mesh whose load acts at
mid-face the line-of-action vector has no axial or tilt terms, so those DOFs decouple
exactly (K, M and C are block-diagonal) and do not reach the vertical acceleration.

Mesh: ``K(t) = K0 + k_m(t) v v^T``; excitation ``v * sum_pairs k_pair e_pair``.
Newmark beta = 1/4, gamma = 1/2. The effective-stiffness inverse for any k_m follows
exactly from one precomputed inverse by the Sherman-Morrison formula (rank-one update),
which replaces the angle-grid table of inverses. Modal damping (``pair.damping_ratio`` on
every mode of the mean-stiffness system). Output: vertical acceleration ``y1'' + y2''``
in g.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np
import scipy.fft as sp_fft

from .._errors import GearshotError
from .._validation import check_finite, check_int, check_positive, describe
from .faults import FullToothFaceFault, ToothFault
from .geometry import GearPair
from .profile_errors import ToothProfileErrors, draw_profile_errors
from .stiffness import _N_TABLE, _pair_table

__all__ = ["SimulationResult", "simulate", "simulate_sa", "system_matrices",
           "DEFAULT_MIN_FS"]

_G0 = 9.80665  # m/s^2 per g
#: internal integration rate floor, Hz (see benchmarks/RESULTS.md, gearshot.sim section: dt convergence)
DEFAULT_MIN_FS = 100e3
_BATCH_CHUNK = 64


# ----------------------------------------------------------------------------- model
def system_matrices(pair: GearPair):
    """Mass, constant stiffness, damping and line-of-action vector of the 7-DOF model.

    Returns
    -------
    M, K0, C : ndarray (7, 7)
        Mass (kg, kg m^2), stiffness without the mesh, modal damping.
    v : ndarray (7,)
        Mesh deflection along the line of action = v . q (m).
    omega : ndarray (7,)
        Natural angular frequencies (rad/s) of the mean-mesh-stiffness system.
    """
    m1, m2 = pair.masses
    j1, j2 = pair.inertias
    kt1, kt2 = pair.shaft_torsional_stiffness
    kb = pair.bearing_stiffness
    a = pair.pressure_angle
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
    k_mean = float(np.mean(_pair_table(pair, None))) * pair.contact_ratio
    K = K0 + k_mean * np.outer(v, v)
    # modal damping on the mean system
    L = np.linalg.cholesky(M)
    Li = np.linalg.inv(L)
    w2, psi = np.linalg.eigh(Li @ K @ Li.T)
    phi = Li.T @ psi                          # mass-normalised modes
    omega = np.sqrt(np.maximum(w2, 0.0))
    C = M @ phi @ np.diag(2 * pair.damping_ratio * omega) @ phi.T @ M
    return M, K0, C, v, omega


@dataclass(frozen=True)
class _Integrator:
    B1: np.ndarray
    B2: np.ndarray
    B3: np.ndarray
    w: np.ndarray
    s: float
    v: np.ndarray
    c_load: np.ndarray
    c_motor: np.ndarray
    x_static: np.ndarray
    coef: np.ndarray      # a0, a2, a3, a6, a7
    omega_min: float


def _integrator(pair: GearPair, dt: float, load0: float) -> _Integrator:
    M, K0, C, v, omega = system_matrices(pair)
    beta, gamma = 0.25, 0.5
    a0 = 1 / (beta * dt ** 2)
    a1 = gamma / (beta * dt)
    a2 = 1 / (beta * dt)
    a3 = 1 / (2 * beta) - 1
    a4 = gamma / beta - 1
    a5 = dt / 2 * (gamma / beta - 2)
    a6 = dt * (1 - gamma)
    a7 = gamma * dt
    A = K0 + a0 * M + a1 * C
    Ai = np.linalg.inv(A)
    Ai = 0.5 * (Ai + Ai.T)
    B1 = Ai @ (a0 * M + a1 * C)
    B2 = Ai @ (a2 * M + a4 * C)
    B3 = Ai @ (a3 * M + a5 * C)
    w = Ai @ v
    f_load = np.zeros(7)
    f_load[6] = -1.0                      # brake torque opposes rotation (per N m)
    ratio = pair.z_pinion / pair.z_gear
    f_motor = -np.array([0, 0, M[2, 2], 0, 0, M[5, 5] * ratio, M[6, 6] * ratio])
    k_mean = float(np.mean(_pair_table(pair, None))) * pair.contact_ratio
    x_static = np.linalg.solve(K0 + k_mean * np.outer(v, v), f_load * load0)
    return _Integrator(B1, B2, B3, w, float(v @ w), v, Ai @ f_load, Ai @ f_motor, x_static,
                       np.array([a0, a2, a3, a6, a7]), float(omega[omega > 0].min()))


@nb.njit(cache=True, fastmath=False)
def _interp_table(tab, u):
    n = tab.shape[0] - 1
    p = u * n
    i = int(p)
    if i >= n:
        return tab[n]
    f = p - i
    return tab[i] * (1.0 - f) + tab[i + 1] * f


@nb.njit(cache=True)
def _tooth_error(slope, wav, phase, noise, nwaves, t, s):
    knots = noise.shape[1]
    p = s * (knots - 1)
    i = int(p)
    if i > knots - 2:
        i = knots - 2
    f = p - i
    return (slope[t] * s + 0.5 * wav[t] * math.sin(2.0 * math.pi * nwaves * s + phase[t])
            + noise[t, i] * (1.0 - f) + noise[t, i + 1] * f)


@nb.njit(cache=True, parallel=True, fastmath=True)
def _newmark_batch(mesh_pos, motor_acc, load, k_tab, kf_tab, ef_tab, f_tooth,
                   g_slope, g_wav, g_phase, g_noise, g_nw,
                   p_slope, p_wav, p_phase, p_noise, p_nw,
                   eps, z_gear, B1, B2, B3, w, s, v, c_load, c_motor, X, V, A, coef,
                   rec_start, out):
    n_batch = out.shape[0]
    n_steps = mesh_pos.shape[0]
    n_rec = out.shape[1]
    ndof = X.shape[1]
    a0, a2, a3, a6, a7 = coef[0], coef[1], coef[2], coef[3], coef[4]
    n_pairs = int(math.ceil(eps)) + 1
    z_pin = p_slope.shape[1]
    for b in nb.prange(n_batch):
        x = X[b].copy()
        vel = V[b].copy()
        acc = A[b].copy()
        xb = np.zeros(ndof)
        for n in range(n_steps):
            tm = mesh_pos[n]
            # a pair's entry/exit is anti-aliased: its contribution is weighted by the
            # fraction of a step-wide window around tm that lies inside its contact
            if n > 0:
                half = 0.5 * abs(tm - mesh_pos[n - 1])
            else:
                half = 0.5 * abs(mesh_pos[min(1, n_steps - 1)] - tm)
            base = math.floor(tm)
            kk = 0.0
            fex = 0.0
            for j in range(-1, n_pairs):
                nn = base - j
                lo = tm - half - nn
                hi = tm + half - nn
                if hi <= 0.0 or lo >= eps:
                    continue
                if hi > lo:
                    wgt = (min(hi, eps) - max(lo, 0.0)) / (hi - lo)
                else:
                    wgt = 1.0
                u = (tm - nn) / eps
                if u < 0.0:
                    u = 0.0
                elif u > 1.0:
                    u = 1.0
                gt = int(nn % z_gear)
                pt = int(nn % z_pin)
                faulty = gt == f_tooth[b]
                if faulty:
                    k = _interp_table(kf_tab[b], u)
                else:
                    k = _interp_table(k_tab, u)
                # both wheels' errors run along the path of contact (as in the lab's
                # model): their slope terms add into a mesh-periodic sawtooth
                e = (_tooth_error(g_slope[b], g_wav[b], g_phase[b], g_noise[b], g_nw, gt, u)
                     + _tooth_error(p_slope[b], p_wav[b], p_phase[b], p_noise[b], p_nw, pt,
                                    u))
                if faulty:
                    e += _interp_table(ef_tab[b], u)
                kk += wgt * k
                fex += wgt * k * e
            ld = load[n]
            ma = motor_acc[n]
            for i in range(ndof):
                acc_i = w[i] * fex + c_load[i] * ld + c_motor[i] * ma
                for jj in range(ndof):
                    acc_i += B1[i, jj] * x[jj] + B2[i, jj] * vel[jj] + B3[i, jj] * acc[jj]
                xb[i] = acc_i
            proj = 0.0
            for i in range(ndof):
                proj += v[i] * xb[i]
            corr = kk * proj / (1.0 + kk * s)
            for i in range(ndof):
                xn = xb[i] - corr * w[i]
                an = a0 * (xn - x[i]) - a2 * vel[i] - a3 * acc[i]
                vel[i] = vel[i] + a6 * acc[i] + a7 * an
                acc[i] = an
                x[i] = xn
            r = n - rec_start
            if r >= 0 and r < n_rec:
                out[b, r] = (acc[1] + acc[4]) / _G0
        X[b] = x
        V[b] = vel
        A[b] = acc


# ----------------------------------------------------------------------------- inputs
def _check_pair(pair):
    if not isinstance(pair, GearPair):
        raise GearshotError(f"pair must be a GearPair (e.g. GearPair.paper()); got "
                            f"{describe(pair)}")


def _check_grade(grade):
    return check_int(grade, "grade", minimum=1, maximum=12)


def _check_sizes(fault_sizes):
    try:
        arr = (None if isinstance(fault_sizes, str)
               else np.atleast_1d(np.asarray(fault_sizes, dtype=float)))
    except (TypeError, ValueError):
        arr = None
    if arr is None or arr.ndim != 1 or arr.size == 0:
        raise GearshotError(f"fault_sizes must be a non-empty 1-D sequence; got "
                            f"{describe(fault_sizes)}")
    check_finite(arr, "fault_sizes")
    bad = (arr < 0) | (arr > 1)
    if bad.any():
        raise GearshotError(f"fault_sizes must lie in [0, 1]; got {arr[bad][0]!r} "
                            f"at index {int(np.flatnonzero(bad)[0])}")
    return arr


def _as_rng(rng, n=None):
    if isinstance(rng, (list, tuple)):
        if n is not None and len(rng) != n:
            raise GearshotError(f"rng must hold one seed per signal ({n}); got {len(rng)}")
        return [_as_rng(r) for r in rng]
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None or isinstance(rng, (int, np.integer, np.random.SeedSequence)):
        return np.random.default_rng(rng)
    raise GearshotError(f"rng must be a numpy Generator, a seed or None; got {describe(rng)}")


def _profile(value, name, times):
    """Constant, callable f(t) or array (resampled onto ``times``) -> array over times."""
    if callable(value):
        arr = np.asarray(value(times), dtype=float)
        if arr.shape == ():
            arr = np.full(times.shape, float(arr))
        if arr.shape != times.shape:
            raise GearshotError(f"{name}(t) must return an array shaped like t {times.shape};"
                                f" got shape {arr.shape}")
    elif np.ndim(value) == 0:
        arr = np.full(times.shape, check_positive(value, name))
    else:
        src = np.asarray(value, dtype=float)
        if src.ndim != 1 or src.size < 2:
            raise GearshotError(f"{name} must be a scalar, a callable or a 1-D array of "
                                f">= 2 samples; got {describe(value)}")
        arr = src
    check_finite(arr, name)
    if np.any(arr <= 0):
        raise GearshotError(f"{name} must be > 0 everywhere; got minimum {arr.min()!r}")
    return arr


def _resolve_faults(fault_sizes, faults, center, depth) -> list[ToothFault]:
    """One fault object per signal, from FTFF sizes or from given fault objects."""
    if faults is not None:
        if fault_sizes is not None:
            raise GearshotError("give fault_sizes or faults, not both")
        faults = list(faults) if not isinstance(faults, ToothFault) else [faults]
        if not faults:
            raise GearshotError("faults must not be empty")
        for i, f in enumerate(faults):
            if f is not None and not isinstance(f, ToothFault):
                raise GearshotError(f"faults[{i}] must be a ToothFault (e.g. Fault.ftff(0.3))"
                                    f" or None; got {describe(f)}")
        return [f if f is not None else ToothFault() for f in faults]
    if fault_sizes is None:
        raise GearshotError("give fault_sizes (FTFF sizes) or faults (fault objects)")
    sizes = _check_sizes(fault_sizes)
    return [FullToothFaceFault(size=float(y), center=center, depth=depth) for y in sizes]


def _fault_arrays(pair: GearPair, faults: list[ToothFault]):
    """Per-signal tables over the contact position u of the faulty pair's stiffness and
    displacement excitation (from the fault's hooks), and the faulty tooth index."""
    n = len(faults)
    kf = np.empty((n, _N_TABLE))
    ef = np.zeros((n, _N_TABLE))
    tooth = np.full(n, -1, dtype=np.int64)
    healthy = _pair_table(pair, None)
    u = np.linspace(0.0, 1.0, _N_TABLE)
    for i, f in enumerate(faults):
        if f is None or f.is_healthy:
            kf[i] = healthy
            continue
        kf[i] = _pair_table(pair, f)
        ef[i] = f.displacement(pair, 1.0 - u)
        tooth[i] = f.tooth % pair.z_gear
    return kf, ef, tooth


def _stack_errors(errs: list[ToothProfileErrors]):
    return (np.stack([e.slope for e in errs]), np.stack([e.waviness for e in errs]),
            np.stack([e.phase for e in errs]), np.stack([e.noise for e in errs]),
            float(errs[0].n_waves))


class _Batch:
    """Prepared per-signal tables and the integration state of a batch of signals."""

    def __init__(self, pair, integ, faults, gear_errs, pin_errs):
        self.pair, self.integ = pair, integ
        self.kf, self.ef, self.tooth = _fault_arrays(pair, faults)
        self.g = _stack_errors(gear_errs)
        self.p = _stack_errors(pin_errs)
        n = len(faults)
        self.X = np.tile(integ.x_static, (n, 1))
        self.V = np.zeros((n, integ.x_static.size))
        self.A = np.zeros((n, integ.x_static.size))

    def run(self, mesh_pos, motor_acc, load, rec_start, n_rec):
        """Advance over the given steps; return the vertical acceleration (g) of steps
        ``rec_start ... rec_start + n_rec - 1``."""
        pair, integ = self.pair, self.integ
        out = np.empty((self.X.shape[0], n_rec))
        _newmark_batch(np.ascontiguousarray(mesh_pos), np.ascontiguousarray(motor_acc),
                       np.ascontiguousarray(load), _pair_table(pair, None), self.kf,
                       self.ef, self.tooth, *self.g, *self.p, pair.contact_ratio,
                       pair.z_gear, integ.B1, integ.B2, integ.B3, integ.w, integ.s, integ.v,
                       integ.c_load, integ.c_motor, self.X, self.V, self.A, integ.coef,
                       rec_start, out)
        return out


def _run(pair, integ, mesh_pos, motor_acc, load, faults, gear_errs, pin_errs, rec_start,
         n_rec):
    return _Batch(pair, integ, faults, gear_errs, pin_errs).run(mesh_pos, motor_acc, load,
                                                              rec_start, n_rec)


def _draw_errors(pair, grade, n, rng, same_gear, average_pinion):
    if isinstance(rng, list):          # one generator per signal
        ge = [draw_profile_errors(pair.z_gear, grade, r) for r in rng]
        pe = [draw_profile_errors(pair.z_pinion, grade, r) for r in rng]
        if average_pinion:
            pe = [e.mean_tooth() for e in pe]
        return ge, pe
    if same_gear:
        ge = [draw_profile_errors(pair.z_gear, grade, rng)] * n
        pe = [draw_profile_errors(pair.z_pinion, grade, rng)] * n
    else:
        ge, pe = [], []
        for _ in range(n):
            ge.append(draw_profile_errors(pair.z_gear, grade, rng))
            pe.append(draw_profile_errors(pair.z_pinion, grade, rng))
    if average_pinion:
        pe = [e.mean_tooth() for e in pe]
    return ge, pe


def _warmup_time(pair: GearPair, integ: _Integrator) -> float:
    # the start transient (from the static state under the mean mesh stiffness; small)
    # of the slowest mode decays to 1 % of its start: SA error ~2e-5 relative for the
    # paper pair (benchmarks/RESULTS.md, gearshot.sim section)
    return 4.6 / (pair.damping_ratio * integ.omega_min)


# ----------------------------------------------------------------------------- public API
def simulate_sa(pair: GearPair, *, speed: float, load: float, grade: int, fault_sizes=None,
                n_points: int = 2048, same_gear: bool = False, rng=None,
                fault_center: float = 0.5, fault_depth: float = 0.5, faults=None,
                min_fs: float = DEFAULT_MIN_FS) -> np.ndarray:
    """Synchronous averages over one revolution of the driven gear, steady state.

    The SA of the vertical acceleration over the hunting period averages the pinion's
    tooth-to-tooth errors to its mean tooth; the model is linear with gear-periodic
    stiffness, so the SA equals the steady-state response of one gear revolution to
    the gear's own errors plus the pinion's mean-tooth errors. That response is what is
    integrated here (after a warm-up that damps the start transient to 1 %), then
    resampled to ``n_points`` by ideal FFT resampling (orders >= n_points/2 dropped).

    Parameters
    ----------
    pair : GearPair
    speed : float
        Input (pinion) shaft speed, rev/s.
    load : float
        Load torque on the output shaft, N m.
    grade : int
        DIN 3962 quality grade 1 ... 12.
    fault_sizes : sequence of float
        FTFF sizes y in [0, 1] (0 = healthy), one signal each.
    n_points : int
        Points per SA cycle.
    same_gear : bool
        One gear pair (one draw of profile errors) for every signal, whose fault grows;
        otherwise each signal draws its own.
    rng : numpy.random.Generator, int, None, or a list of those (one per signal)
        Source of the profile errors; a list gives each signal its own stream (a signal
        is then reproducible alone from its seed).
    fault_center, fault_depth : float
        FTFF placement and depth coefficient.
    faults : sequence of ToothFault, optional
        Instead of ``fault_sizes``: one fault object per signal (any fault type; None =
        healthy).
    min_fs : float
        Lowest internal integration rate, Hz.

    Returns
    -------
    ndarray (n_signals, n_points)
        Vertical acceleration SAs, g.
    """
    _check_pair(pair)
    speed = check_positive(speed, "speed")
    load = check_positive(load, "load")
    grade = _check_grade(grade)
    faults = _resolve_faults(fault_sizes, faults, fault_center, fault_depth)
    n_sig = len(faults)
    n_points = check_int(n_points, "n_points", minimum=16)
    min_fs = check_positive(min_fs, "min_fs")
    rng = _as_rng(rng, n_sig)
    t_rev = pair.z_gear / (pair.z_pinion * speed)
    n_rev = sp_fft.next_fast_len(max(2 * n_points, int(math.ceil(t_rev * min_fs))), real=True)
    dt = t_rev / n_rev
    integ = _integrator(pair, dt, load)
    n_warm = int(math.ceil(_warmup_time(pair, integ) / dt))
    n_steps = n_warm + n_rev
    tau = (np.arange(n_steps) + 1 - n_warm) * dt        # record: tau = 0 ... t_rev - dt
    mesh_pos = tau * speed * pair.z_pinion
    zeros = np.zeros(n_steps)
    loads = np.full(n_steps, load)
    ge, pe = _draw_errors(pair, grade, n_sig, rng, same_gear, average_pinion=True)
    out = np.empty((n_sig, n_points))
    for start in range(0, n_sig, _BATCH_CHUNK):
        sl = slice(start, start + _BATCH_CHUNK)
        acc = _run(pair, integ, mesh_pos, zeros, loads, faults[sl], ge[sl], pe[sl],
                   n_warm - 1, n_rev)
        out[sl] = _fft_resample(acc, n_points)
    return out


def _fft_resample(x: np.ndarray, n_out: int) -> np.ndarray:
    n = x.shape[-1]
    X = sp_fft.rfft(x, axis=-1, workers=-1)
    Y = np.zeros(x.shape[:-1] + (n_out // 2 + 1,), dtype=complex)
    keep = min(n_out // 2, X.shape[-1] - 1)
    Y[..., :keep] = X[..., :keep]
    if n_out % 2 == 0 and keep == n_out // 2:
        Y[..., keep] = X[..., keep].real
    return sp_fft.irfft(Y, n=n_out, axis=-1, workers=-1) * (n_out / n)


@dataclass(frozen=True)
class SimulationResult:
    """Time signals of :func:`simulate`.

    Attributes
    ----------
    acceleration : ndarray (n_signals, n_samples)
        Vertical acceleration (sum of both bearings), g.
    pinion_angle : ndarray (n_samples,)
        Motor / pinion nominal rotation angle, rad (0 at the first sample).
    time : ndarray (n_samples,)
        s.
    fs : float
        Sampling rate, Hz.
    """

    acceleration: np.ndarray
    pinion_angle: np.ndarray
    time: np.ndarray
    fs: float


def simulate(pair: GearPair, *, speed, load, grade: int, fault_sizes=None, fs: float,
             duration: float | None = None, n_revs: float | None = None, rng=None,
             same_gear: bool = False, fault_center: float = 0.5, fault_depth: float = 0.5,
             faults=None, min_fs: float = DEFAULT_MIN_FS) -> SimulationResult:
    """Vertical-acceleration time signals, steady state from the first sample.

    The run is integrated in chunks (memory stays bounded for long recordings) at an
    integer multiple of ``fs`` that is >= ``min_fs``, after a warm-up at the initial speed
    and load, and decimated by a Kaiser-windowed FIR (as :func:`scipy.signal.resample_poly`)
    fed with real samples on both sides, so there are no edge effects.

    Parameters
    ----------
    pair : GearPair
    speed : float, callable or 1-D array
        Input shaft speed, rev/s: a constant, ``speed(t)`` (t in s, vectorised) or samples
        at ``fs`` covering the output duration.
    load : float, callable or 1-D array
        Output load torque, N m, same forms as ``speed``.
    grade : int
        DIN grade 1 ... 12.
    fault_sizes : sequence of float
        FTFF sizes, one signal each.
    fs : float
        Output sampling rate, Hz; the integration runs at an integer multiple >= min_fs
        and is decimated with an anti-aliasing filter.
    duration, n_revs : float
        Signal length in seconds, or in input-shaft revolutions (one of the two).
    rng, same_gear, fault_center, fault_depth, faults, min_fs
        As in :func:`simulate_sa`.

    Returns
    -------
    SimulationResult
    """
    from scipy.signal import firwin, oaconvolve

    _check_pair(pair)
    fs = check_positive(fs, "fs")
    grade = _check_grade(grade)
    faults = _resolve_faults(fault_sizes, faults, fault_center, fault_depth)
    n_sig = len(faults)
    min_fs = check_positive(min_fs, "min_fs")
    rng = _as_rng(rng, n_sig)
    if (duration is None) == (n_revs is None):
        raise GearshotError("give exactly one of duration and n_revs; got "
                            f"duration={duration!r}, n_revs={n_revs!r}")
    up = max(1, int(math.ceil(min_fs / fs)))
    dt = 1.0 / (fs * up)
    speed_fn = _profile_fn(speed, "speed", fs)
    load_fn = _profile_fn(load, "load", fs)
    if duration is None:
        n_revs = check_positive(n_revs, "n_revs")
        if callable(speed) or np.ndim(speed):
            raise GearshotError("n_revs needs a constant speed; give duration instead")
        duration = n_revs / float(speed)
    duration = check_positive(duration, "duration")
    n_out = int(round(duration * fs))
    if n_out < 2:
        raise GearshotError(f"duration must span >= 2 samples at fs; got {duration!r} s")
    if not callable(speed) and np.ndim(speed) and np.size(speed) < n_out:
        raise GearshotError(f"speed holds {np.size(speed)} samples; the duration needs "
                            f"{n_out} at fs")
    if not callable(load) and np.ndim(load) and np.size(load) < n_out:
        raise GearshotError(f"load holds {np.size(load)} samples; the duration needs "
                            f"{n_out} at fs")
    n_fine = n_out * up
    sp0 = float(speed_fn(np.zeros(1))[0])
    ld0 = float(load_fn(np.zeros(1))[0])
    integ = _integrator(pair, dt, ld0)
    # anti-aliasing FIR (Kaiser, like scipy's resample_poly), centred: half length D
    half = 10 * up if up > 1 else 0
    h = firwin(2 * half + 1, 1.0 / up, window=("kaiser", 5.0)) if up > 1 else np.ones(1)
    n_warm = max(int(math.ceil(_warmup_time(pair, integ) / dt)), half + 1)
    ge, pe = _draw_errors(pair, grade, n_sig, rng, same_gear, average_pinion=False)
    acc = np.empty((n_sig, n_out))
    angle = np.zeros(n_out)
    z1 = pair.z_pinion
    chunk = 1 << 16
    for start in range(0, n_sig, _BATCH_CHUNK):
        sl = slice(start, start + _BATCH_CHUNK)
        batch = _Batch(pair, integ, faults[sl], ge[sl], pe[sl])
        # warm-up at the initial speed and load, t = -(n_warm - 1) dt ... 0; keep the
        # samples from t = -half dt to 0 (the filter's history and the first sample)
        tau = (np.arange(n_warm) - (n_warm - 1)) * dt
        zero = np.zeros(n_warm)
        tail = batch.run(sp0 * z1 * tau, zero, np.full(n_warm, ld0), n_warm - 1 - half,
                         half + 1)
        theta = 0.0
        k_next = 0
        g0 = -half              # fine time index of tail[:, 0]
        n_total = n_fine + half
        for c0 in range(1, n_total, chunk):
            c1 = min(c0 + chunk, n_total)
            t = np.arange(c0 - 1, c1 + 1) * dt          # one step of margin each side
            sp = speed_fn(t)
            omega = 2 * np.pi * sp
            inc = np.pi * (sp[1:-1] + sp[:-2]) * dt      # trapezoid, steps c0 ... c1-1
            th = theta + np.cumsum(inc)
            theta = th[-1]
            if start == 0:                               # the motor angle at output times
                fidx = np.arange(c0, c1)
                sel = (fidx % up == 0) & (fidx // up < n_out)
                angle[fidx[sel] // up] = th[sel]
            motor_acc = (omega[2:] - omega[:-2]) / (2 * dt)
            fine = batch.run(th * z1 / (2 * np.pi), motor_acc, load_fn(t[1:-1]), 0,
                             c1 - c0)
            zz = np.concatenate([tail, fine], axis=1)
            if up == 1:
                idx = np.arange(zz.shape[1]) + g0
                keep = (idx >= 0) & (idx < n_out)
                acc[sl, idx[keep]] = zz[:, keep]
                tail = zz[:, :0]
                g0 += zz.shape[1]
                continue
            conv = oaconvolve(zz, h[None, :], mode="valid", axes=-1)
            centre = g0 + half + np.arange(conv.shape[1])  # fine index of each output
            pick = (centre % up == 0) & (centre // up >= k_next) & (centre // up < n_out)
            ks = centre[pick] // up
            acc[sl, ks] = conv[:, pick]
            if ks.size:
                k_next = int(ks[-1]) + 1
            tail = zz[:, -(2 * half):]
            g0 += zz.shape[1] - 2 * half
    return SimulationResult(acceleration=acc, pinion_angle=angle,
                            time=np.arange(n_out) / fs, fs=fs)


def _profile_fn(value, name, fs):
    """A vectorised f(t) for a constant, a callable or samples at ``fs``."""
    if callable(value):
        return lambda t: _profile(value, name, t)
    if np.ndim(value) == 0:
        v = check_positive(value, name)
        return lambda t: np.full(np.shape(t), v)
    src = _profile(value, name, np.zeros(1))
    t_src = np.arange(src.size) / fs
    return lambda t: np.interp(t, t_src, src)
