"""Batched gear-pair dynamics: the public simulation functions.

Mesh: ``K(t) = K0 + k_m(t) v v^T``; excitation ``v * sum_pairs k_pair e_pair``.
Newmark beta = 1/4, gamma = 1/2. The effective-stiffness inverse for any k_m follows
exactly from one precomputed inverse by the Sherman-Morrison formula (rank-one update),
which replaces the angle-grid table of inverses. Modal damping (``pair.damping_ratio`` on
every mode of the mean-stiffness system). Output: vertical acceleration ``y1'' + y2''``
in g.

The pieces: :mod:`._system` (the 7-DOF model, integrator and prepared batches),
:mod:`._kernel` (the numba integration kernel), :mod:`._inputs` (input normalisation) and
:mod:`._decimate` (the streaming decimator of :func:`simulate`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.fft as sp_fft

from .._errors import GearshotError
from .._validation import check_int, check_load, check_positive, check_speed, describe
from ._decimate import StreamingDecimator, fir_half_length
from ._inputs import (
    as_rng,
    check_grade,
    check_pair,
    check_sizes,
    draw_errors,
    profile_fn,
    resolve_faults,
)
from ._system import integrator, make_batch, system_matrices, warmup_time
from .faults import ToothFault
from .geometry import GearPair

__all__ = ["SimulationResult", "simulate", "simulate_sa", "system_matrices",
           "DEFAULT_MIN_FS"]

#: internal integration rate floor, Hz (benchmarks/RESULTS.md, gearshot.sim: dt convergence)
DEFAULT_MIN_FS = 100e3
_BATCH_CHUNK = 64


# ----------------------------------------------------------------------------- public API
def simulate_sa(pair: GearPair, *, speed: float, load: float, grade: int, fault_sizes=None,
                n_points: int = 2048, same_gear: bool = False, rng=None,
                fault_center: float = 0.5, fault_depth: float = 0.5, faults=None,
                min_fs: float = DEFAULT_MIN_FS, fault_type: str = "ftff") -> np.ndarray:
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
        Fault sizes y in [0, 1] of ``fault_type`` (0 = healthy), one signal each.
    n_points : int
        Points per SA cycle.
    same_gear : bool
        One gear pair (one draw of profile errors) for every signal, whose fault grows;
        otherwise each signal draws its own.
    rng : numpy.random.Generator, int, None, or a list of those (one per signal)
        Source of the profile errors; a list gives each signal its own stream (a signal
        is then reproducible alone from its seed).
    fault_center, fault_depth : float
        FTFF placement and depth coefficient (also the partial-face cut's; the
        destruction band's centre).
    faults : sequence of ToothFault, optional
        Instead of ``fault_sizes``: one fault object per signal (any fault type; None =
        healthy).
    min_fs : float
        Lowest internal integration rate, Hz.
    fault_type : {"ftff", "partial_face", "breakage", "destruction"}
        Type of the faults of ``fault_sizes`` (:mod:`gearshot.sim.fault_types` says
        what a size means for each).

    Returns
    -------
    ndarray (n_signals, n_points)
        Vertical acceleration SAs, g.
    """
    run, faults, ge, pe = _prepared_run(
        pair, speed, load, grade, n_points, min_fs, rng, same_gear,
        lambda: resolve_faults(fault_sizes, faults, fault_center, fault_depth, fault_type))
    return run.sas(faults, ge, pe)


def _prepared_run(pair, speed, load, grade, n_points, min_fs, rng, same_gear, faults_of):
    """Arguments checked (in this order), then the run, the faults (``faults_of()``) and
    each signal's profile errors: what :func:`simulate_sa` and :func:`simulate_sa_paired`
    integrate."""
    check_pair(pair)
    speed = check_speed(speed)
    load = check_load(load)
    grade = check_grade(grade)
    faults = faults_of()
    n_points = check_int(n_points, "n_points", minimum=16)
    min_fs = check_positive(min_fs, "min_fs")
    rng = as_rng(rng, len(faults))
    run = _SteadyRun(pair, speed, load, n_points, min_fs)
    ge, pe = draw_errors(pair, grade, len(faults), rng, same_gear, average_pinion=True)
    return run, faults, ge, pe


def simulate_sa_paired(pair: GearPair, *, speed: float, load: float, grade: int,
                       fault_sizes, rng: list, n_points: int = 2048,
                       fault_type: str = "ftff") -> tuple[np.ndarray, np.ndarray]:
    """SAs of :func:`simulate_sa` (one seed per signal in ``rng``) and each signal's
    healthy twin: the SA of the same gear pair (the same profile errors) without the
    fault; a healthy signal (size 0) is its own twin.

    The twins reuse the signals' profile errors, integrator and batch-shared contacts
    instead of drawing and computing them again: equal to
    ``simulate_sa(..., fault_sizes=zeros, rng=<the faulty signals' seeds>)``, bit for
    bit (the same batches of 64 faulty signals).

    Returns
    -------
    sa, twins : ndarray (n_signals, n_points)
    """
    if not isinstance(rng, (list, tuple)):
        raise GearshotError(f"rng must hold one seed per signal; got {describe(rng)}")
    run, faults, ge, pe = _prepared_run(
        pair, speed, load, grade, n_points, DEFAULT_MIN_FS, rng, False,
        lambda: resolve_faults(fault_sizes, None, 0.5, 0.5, fault_type))
    sizes = check_sizes(fault_sizes)
    sa = run.sas(faults, ge, pe)
    twins = np.array(sa, dtype=np.float64, copy=True)
    faulty = np.flatnonzero(sizes > 0)
    if faulty.size:
        healthy = [ToothFault()] * faulty.size      # what a size-0 fault of any type is
        twins[faulty] = run.sas(healthy, [ge[i] for i in faulty], [pe[i] for i in faulty])
    return sa, twins


class _SteadyRun:
    """The steady-state run of :func:`simulate_sa` for one pair and condition: time step,
    warm-up, integrator and mesh positions, and the batch-shared contact data (computed
    by the first batch, then reused by every batch of the run); arguments checked."""

    def __init__(self, pair, speed, load, n_points, min_fs):
        self.pair, self.load, self.n_points = pair, load, n_points
        t_rev = pair.z_gear / (pair.z_pinion * speed)
        self.n_rev = sp_fft.next_fast_len(max(2 * self.n_points, int(math.ceil(t_rev * min_fs))),
                                          real=True)
        dt = t_rev / self.n_rev
        self.integ = integrator(pair, dt, self.load)
        self.n_warm = int(math.ceil(warmup_time(pair, self.integ) / dt))
        n_steps = self.n_warm + self.n_rev
        tau = (np.arange(n_steps) + 1 - self.n_warm) * dt   # record: tau = 0 ... t_rev - dt
        self.mesh_pos = tau * speed * pair.z_pinion
        self.shared = None

    def sas(self, faults, ge, pe) -> np.ndarray:
        """SAs of signals with these faults and profile errors, in batches of 64."""
        n_steps = self.mesh_pos.size
        zeros = np.zeros(n_steps)
        loads = np.full(n_steps, self.load)
        out = np.empty((len(faults), self.n_points))
        for start in range(0, len(faults), _BATCH_CHUNK):
            sl = slice(start, start + _BATCH_CHUNK)
            batch = make_batch(self.pair, self.integ, faults[sl], ge[sl], pe[sl])
            if self.shared is None:
                self.shared = batch.shared(self.mesh_pos)
            acc = batch.run(self.mesh_pos, zeros, loads, self.n_warm - 1, self.n_rev,
                            self.shared)
            out[sl] = _fft_resample(acc, self.n_points)
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
             faults=None, min_fs: float = DEFAULT_MIN_FS, fault_type: str = "ftff"
             ) -> SimulationResult:
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
        Fault sizes of ``fault_type``, one signal each.
    fs : float
        Output sampling rate, Hz; the integration runs at an integer multiple >= min_fs
        and is decimated with an anti-aliasing filter.
    duration, n_revs : float
        Signal length in seconds, or in input-shaft revolutions (one of the two).
    rng, same_gear, fault_center, fault_depth, faults, min_fs, fault_type
        As in :func:`simulate_sa`.

    Returns
    -------
    SimulationResult
    """
    check_pair(pair)
    fs = check_positive(fs, "fs")
    grade = check_grade(grade)
    faults = resolve_faults(fault_sizes, faults, fault_center, fault_depth, fault_type)
    n_sig = len(faults)
    min_fs = check_positive(min_fs, "min_fs")
    rng = as_rng(rng, n_sig)
    up = max(1, int(math.ceil(min_fs / fs)))
    speed_fn, load_fn, n_out = _profiles(speed, load, fs, duration, n_revs)
    dt = 1.0 / (fs * up)
    ld0 = float(load_fn(np.zeros(1))[0])
    integ = integrator(pair, dt, ld0)
    half = fir_half_length(up)             # the anti-aliasing FIR's half length
    n_warm = max(int(math.ceil(warmup_time(pair, integ) / dt)), half + 1)
    ge, pe = draw_errors(pair, grade, n_sig, rng, same_gear, average_pinion=False)
    acc = np.empty((n_sig, n_out))
    angle = np.zeros(n_out)
    for start in range(0, n_sig, _BATCH_CHUNK):
        sl = slice(start, start + _BATCH_CHUNK)
        batch = make_batch(pair, integ, faults[sl], ge[sl], pe[sl])
        decimator = StreamingDecimator(acc[sl], up)
        _warm_up(batch, decimator, float(speed_fn(np.zeros(1))[0]) * pair.z_pinion, ld0,
                 n_warm, half, dt)
        _run_profile(batch, decimator, speed_fn, load_fn, dt, up, n_out, half,
                     angle if start == 0 else None)
    return SimulationResult(acceleration=acc, pinion_angle=angle,
                            time=np.arange(n_out) / fs, fs=fs)


def _profiles(speed, load, fs, duration, n_revs):
    """Speed and load as functions of time (s) and the output length (samples at
    ``fs``), from :func:`simulate`'s arguments (checked)."""
    if (duration is None) == (n_revs is None):
        raise GearshotError("give exactly one of duration and n_revs; got "
                            f"duration={duration!r}, n_revs={n_revs!r}")
    speed_fn = profile_fn(speed, "speed", fs)
    load_fn = profile_fn(load, "load", fs)
    if duration is None:
        n_revs = check_positive(n_revs, "n_revs")
        if callable(speed) or np.ndim(speed):
            raise GearshotError("n_revs needs a constant speed; give duration instead")
        duration = n_revs / float(speed)
    duration = check_positive(duration, "duration")
    n_out = int(round(duration * fs))
    if n_out < 2:
        raise GearshotError(f"duration must span >= 2 samples at fs; got {duration!r} s")
    for name, profile in (("speed", speed), ("load", load)):
        if not callable(profile) and np.ndim(profile) and np.size(profile) < n_out:
            raise GearshotError(f"{name} holds {np.size(profile)} samples; the duration "
                                f"needs {n_out} at fs")
    return speed_fn, load_fn, n_out


def _warm_up(batch, decimator, mesh_rate, ld0, n_warm, half, dt):
    """Warm-up at the initial mesh rate (mesh periods per s) and load, t = -(n_warm - 1)
    dt ... 0; the samples from t = -half dt to 0 (the filter's history and the first
    sample) start ``decimator``."""
    tau = (np.arange(n_warm) - (n_warm - 1)) * dt
    decimator.start(batch.run(mesh_rate * tau, np.zeros(n_warm), np.full(n_warm, ld0),
                              n_warm - 1 - half, half + 1))


_CHUNK_STEPS = 1 << 16     # integration steps per kernel call of :func:`simulate`


def _run_profile(batch, decimator, speed_fn, load_fn, dt, up, n_out, half, angle):
    """Integrate the batch along the speed and load profiles in chunks of
    ``_CHUNK_STEPS`` steps into ``decimator``; ``angle`` (when given) receives the motor
    angle at the output times."""
    theta = 0.0
    z1 = batch.pair.z_pinion
    n_total = n_out * up + half
    for c0 in range(1, n_total, _CHUNK_STEPS):
        c1 = min(c0 + _CHUNK_STEPS, n_total)
        t = np.arange(c0 - 1, c1 + 1) * dt          # one step of margin each side
        sp = speed_fn(t)
        omega = 2 * np.pi * sp
        inc = np.pi * (sp[1:-1] + sp[:-2]) * dt      # trapezoid, steps c0 ... c1-1
        th = theta + np.cumsum(inc)
        theta = th[-1]
        if angle is not None:                        # the motor angle at output times
            fidx = np.arange(c0, c1)
            sel = (fidx % up == 0) & (fidx // up < n_out)
            angle[fidx[sel] // up] = th[sel]
        motor_acc = (omega[2:] - omega[:-2]) / (2 * dt)
        decimator.push(batch.run(th * z1 / (2 * np.pi), motor_acc, load_fn(t[1:-1]),
                                 0, c1 - c0))
