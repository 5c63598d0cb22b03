"""`VirtualRig`: recordings from a hidden "reality", and Table-1 style campaigns.

Signal chain of one recording (all at ``fs``, integrated over the whole run):

1. input-shaft angle with slow speed drift (<= 1 %) and a once-per-revolution ripple,
   starting at a random relative position of the wheels (:func:`motion.motor_angle`);
   load torque with a once-per-output-revolution ripple (:func:`motion.load_torque`);
2. the physics engine: gear vibration (g) for that angle and load history, with the
   rig's true grade, perturbed masses/stiffnesses/damping and irregular fault;
3. non-synchronous interference: motor electrical harmonics, an extra shaft at a
   non-integer order, bearing-like impacts (:mod:`.interference`);
4. the transfer path to the sensor: a TF from the bank, 10-30 dB attenuation
   (:mod:`.path`);
5. sensor noise at 20-30 dB SNR; a 1-pulse-per-revolution input-shaft tacho with jitter.

A settling time (``settle`` s) is simulated before the recorded span and dropped, so
neither the engine's nor the transfer path's start-up transient is recorded.

The physics engine is pluggable: any callable
``engine(*, motor_revs, load_torque, fs, fault_size, reality, rng) -> acceleration`` with
``motor_revs``/``load_torque`` arrays of shape (n,) (rev, N m), ``reality`` a
:class:`~gearshot.rig.reality.RigReality` (``None`` = the nominal model) and ``rng`` a
``numpy.random.Generator``, returning the vibration in g, shape (n,). The default is
:class:`~gearshot.rig.sim_engine.SimulatorEngine` (the gear-pair simulator, integrating the
whole run); :class:`~gearshot.rig.surrogate.SurrogateEngine` is a fast stand-in.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .._atomic import atomic_path, check_writable, commit_staged, staging_dir
from .._errors import GearshotError
from .._validation import check_in_range, check_int, check_load, check_positive, check_speed
from ..fault_registry import check_fault_type
from ..io import INDEX_COLUMNS, INDEX_NAME, Recording
from ..paper import GEAR_TEETH, PINION_TEETH, TABLE1_SIZES
from ..signal.level import rms
from .interference import add_noise, bearing_impacts, extra_shaft, motor_harmonics
from .motion import load_torque, motor_angle, ramp_angle
from .path import apply_path, as_tf_list, path_fir, synthetic_path_tfs
from .reality import RigReality, draw_reality, override_reality
from .sim_engine import SimulatorEngine
from .surrogate import SurrogateEngine
from .tacho import tacho_signal

__all__ = ["VirtualRig"]



def _key(value: float) -> int:
    return int(round(float(value) * 1_000_000))


class VirtualRig:
    """A virtual gear test rig with seeded hidden "reality" parameters.

    Parameters
    ----------
    seed : int
        Seeds everything: the hidden reality (drawn once) and, together with the condition
        and repetition, every recording -- the same call gives the same recording.
    engine : {"sim", "surrogate"} or callable, optional
        Physics engine (see the module docstring): ``"sim"`` (default,
        :class:`~gearshot.rig.sim_engine.SimulatorEngine`, the gear-pair simulator),
        ``"surrogate"`` (:class:`SurrogateEngine`, a fast stand-in) or any callable.
    tf_bank : folder path or sequence of TFs, optional
        Transfer-path bank (measured FRFs or TF-like objects with ``freqs``/``values``);
        default: 8 synthetic modal TFs drawn from ``seed``. The reality picks one.
    fs : float
        Sampling rate, Hz (50 kHz).
    gear_teeth, pinion_teeth : int
        Tooth counts (38, 17: the paper's pair); the tacho is on the pinion shaft.
    settle : float
        Seconds simulated before each recording and dropped.
    grade : int, optional
        Force the rig's true DIN grade (default: drawn, hidden).
    reality_overrides : mapping, optional
        Fields of the hidden :class:`RigReality` to set instead of drawing them (see
        :meth:`with_reality`).
    fault_type : str
        The fault this rig grows (``"ftff"``, default; ``"partial_face"``, ``"breakage"``,
        ``"destruction"``: :data:`gearshot.fault_registry.FAULT_TYPE_NAMES`); ``fault_size`` of
        :meth:`record` is its size label. The hidden reality makes each type irregular
        (:mod:`gearshot.rig.irregular`). The ``"sim"`` engine grows every type, the
        surrogate only the FTFF; a callable engine gets ``fault_type=`` as a keyword when
        it is not ``"ftff"``.

    Notes
    -----
    Arguments are stored as given; the reality, the TF and its FIR are built on first use.
    """

    def __init__(self, seed: int = 0, *, engine: str | Callable[..., np.ndarray] | None = None,
                 tf_bank: Any = None, fs: float = 50_000.0, gear_teeth: int = GEAR_TEETH,
                 pinion_teeth: int = PINION_TEETH, settle: float = 0.25, grade: int | None = None,
                 reality_overrides: Mapping[str, Any] | None = None,
                 fault_type: str = "ftff"):
        self.seed = seed
        self.engine = engine
        self.tf_bank = tf_bank
        self.fs = fs
        self.gear_teeth = gear_teeth
        self.pinion_teeth = pinion_teeth
        self.settle = settle
        self.grade = grade
        self.reality_overrides = reality_overrides
        self.fault_type = fault_type
        self._built: tuple[RigReality, np.ndarray, str] | None = None

    def _params(self) -> dict[str, Any]:
        return {k: getattr(self, k) for k in ("seed", "engine", "tf_bank", "fs", "gear_teeth",
                                              "pinion_teeth", "settle", "grade",
                                              "reality_overrides", "fault_type")}

    def with_reality(self, **changes: Any) -> VirtualRig:
        """A copy of this rig whose hidden reality has some fields set (e.g.
        ``attenuation_db=20``, ``grade=9``, ``snr_db=25``); everything else is unchanged.
        For controlled experiments; see :class:`RigReality` for the fields."""
        params = self._params()
        params["reality_overrides"] = {**(self.reality_overrides or {}), **changes}
        rig = VirtualRig(**params)
        rig._build()  # validate now
        return rig

    # ------------------------------------------------------------------ hidden state
    def _build(self) -> tuple[RigReality, np.ndarray, str]:
        if self._built is None:
            seed = check_int(self.seed, "seed", minimum=0)
            fs = check_positive(self.fs, "fs")
            check_int(self.gear_teeth, "gear_teeth", minimum=2)
            check_int(self.pinion_teeth, "pinion_teeth", minimum=2)
            check_positive(self.settle, "settle", allow_zero=True)
            check_fault_type(self.fault_type)
            if self.tf_bank is None:
                tfs = synthetic_path_tfs(8, rng=np.random.default_rng([seed, 3]), band=fs / 2)
            else:
                tfs = as_tf_list(self.tf_bank)
            reality = draw_reality(np.random.default_rng([seed, 1]), n_tfs=len(tfs),
                                   gear_teeth=self.gear_teeth, pinion_teeth=self.pinion_teeth)
            overrides = dict(self.reality_overrides or {})
            if self.grade is not None:
                overrides["grade"] = self.grade
            reality = override_reality(reality, overrides, n_tfs=len(tfs))
            tf = tfs[reality.tf_index]
            fir = path_fir(tf, fs, attenuation_db=reality.attenuation_db,
                           n_taps=min(2 * (tf.freqs.size - 1), 16384))
            self._built = (reality, fir, tf.name)
        return self._built

    def reveal(self) -> RigReality:
        """The hidden reality -- for validating the rig only; an estimator must not use it."""
        return self._build()[0]

    def reveal_path(self) -> tuple[str, np.ndarray]:
        """Name of the hidden transfer-path TF and its FIR (per sample) -- validation only."""
        _, fir, name = self._build()
        return name, fir.copy()

    def _engine(self) -> Callable[..., np.ndarray]:
        if self.engine is None or self.engine == "sim":
            return SimulatorEngine(fault_type=self.fault_type)
        if self.engine == "surrogate":
            if self.fault_type != "ftff":
                raise GearshotError(f"the surrogate engine models the FTFF only; "
                                    f"fault_type={self.fault_type!r} needs engine='sim'")
            return SurrogateEngine(gear_teeth=self.gear_teeth, pinion_teeth=self.pinion_teeth)
        if not callable(self.engine):
            raise GearshotError(f"engine must be 'sim', 'surrogate' or a callable; got "
                                f"{self.engine!r}")
        if self.fault_type != "ftff":
            return functools.partial(self.engine, fault_type=self.fault_type)
        return self.engine

    # ------------------------------------------------------------------ one recording
    def record(self, *, speed: float, load: float, fault_size: float = 0.0,
               duration: float = 60.0, repetition: int = 0,
               end_speed: float | None = None) -> Recording:
        """Run the rig once and record it.

        Parameters
        ----------
        speed : float
            Nominal input-shaft speed, rev/s.
        load : float
            Nominal load torque, N m.
        fault_size : float
            Fault size y in [0, 1] (0 = healthy).
        duration : float
            Recorded length, s.
        repetition : int
            Repetition number (a different run of the same condition).
        end_speed : float, optional
            A run-up (or run-down): the input speed ramps linearly from ``speed`` at the
            start of the recorded span to ``end_speed`` at its end
            (:func:`gearshot.rig.motion.ramp_angle`; the per-revolution ripple stays, the
            slow drift is replaced by the ramp). ``speed`` in the metadata is the mean.

        Returns
        -------
        Recording
            Acceleration in g, the input-shaft tacho, metadata (no hidden parameters).
        """
        reality, fir, _ = self._build()
        speed = check_speed(speed)
        load = check_load(load)
        fault_size = check_in_range(fault_size, "fault_size", 0.0, 1.0)
        duration = check_positive(duration, "duration")
        repetition = check_int(repetition, "repetition", minimum=0)
        if end_speed is not None:
            end_speed = check_positive(end_speed, "end_speed")
        fs = float(self.fs)
        rng = np.random.default_rng([int(self.seed), 2, _key(speed), _key(load),
                                     _key(fault_size), repetition])
        n_settle = int(round(self.settle * fs))
        t = np.arange(n_settle + int(round(duration * fs))) / fs
        motor = self._motor(t, speed, end_speed, reality, rng)
        torque = load_torque(motor * self.pinion_teeth / self.gear_teeth, load=load,
                             ripple=reality.load_ripple, rng=rng)
        engine = self._engine()
        vib = _engine_vibration(engine, motor, torque, fs, fault_size, reality, rng)
        vib = vib + rms(vib[n_settle:]) * _interference(t, motor, fs, speed, reality, rng)
        acc = apply_path(vib, fir)[n_settle:]
        acc = add_noise(acc, snr_db=reality.snr_db, rng=rng)
        tach = tacho_signal(motor[n_settle:], jitter=reality.tacho_jitter, rng=rng)
        extras = {}
        if end_speed is not None:
            extras = {"start_speed": speed, "end_speed": end_speed}
            speed = 0.5 * (speed + end_speed)
        return Recording(
            acc, tach, fs, speed=speed, load=load, fault_size=fault_size, units="g",
            source=f"gearshot.rig.VirtualRig(seed={int(self.seed)})",
            extras={"repetition": repetition, "rig_seed": int(self.seed),
                    "engine": type(getattr(engine, "func", engine)).__name__,
                    "fault_type": self.fault_type, **extras})

    def _motor(self, t: np.ndarray, speed: float, end_speed: float | None,
               reality: RigReality, rng: np.random.Generator) -> np.ndarray:
        """Input-shaft angle (rev) over ``t``: drifting speed, or a ramp to ``end_speed``
        over the recorded span; the per-revolution ripple either way."""
        # relative position of the wheels at the start: a whole number of pinion turns
        # (the tacho mark sits on the pinion), so SAs of different runs differ by whole teeth
        start = float(rng.integers(0, self.gear_teeth))
        if end_speed is None:
            return motor_angle(t, speed=speed, drift=reality.speed_drift,
                               ripple=reality.speed_ripple, rng=rng, start=start)
        return ramp_angle(t, speed=speed, end_speed=end_speed, t_start=self.settle,
                          t_end=float(t[-1]), ripple=reality.speed_ripple, rng=rng,
                          start=start)

    # ------------------------------------------------------------------ campaigns
    @staticmethod
    def file_name(speed: float, load: float, fault_size: float, repetition: int) -> str:
        """File name of one campaign recording, e.g. ``s15_l10_y0.56_r3.h5``."""
        return f"s{speed:g}_l{load:g}_y{fault_size:.2f}_r{repetition}.h5"

    def campaign(self, folder: str | os.PathLike, *, speed: float, load: float,
                 duration: float = 60.0, healthy: int = 6,
                 sizes: Sequence[float] = TABLE1_SIZES, repetitions: int = 6,
                 variation: float = 0.0, dtype: str = "float32",
                 progress: bool = True) -> pd.DataFrame:
        """Record one condition as in the paper's Table 1 and write it to ``folder``.

        ``healthy`` healthy recordings and ``repetitions`` recordings per fault size, each
        ``duration`` s, written as native HDF5 recordings (``dtype`` samples) plus an index
        ``index.csv`` (rows of other conditions already in the folder are kept; rows of
        this condition are replaced). ``variation`` > 0 records each at its own speed and
        load, the set-points times ``1 + variation · N(0, 1)`` (seeded by the rig, the size
        and the repetition; the run-to-run spread of :meth:`history`); the index keeps the
        set-points.

        Everything is first written to a hidden staging folder inside ``folder``
        (:func:`gearshot._atomic.staging_dir`); only when all recordings succeeded are they
        moved into place and the index replaced, last
        (:func:`gearshot._atomic.commit_staged`). A failed campaign leaves no partial file
        behind and the old index intact.

        Returns
        -------
        pandas.DataFrame
            Columns ``path`` (absolute), ``speed``, ``load``, ``fault_size``, ``repetition``;
            one row per recording of this condition.
        """
        folder = Path(folder)
        speed = check_speed(speed)
        load = check_load(load)
        jobs = _campaign_jobs(healthy, sizes, repetitions)
        check_positive(duration, "duration")
        variation = check_in_range(variation, "variation", 0.0, 0.1)
        self._build()
        if not jobs:
            raise GearshotError("the campaign holds no recording (healthy=0 and no sizes)")
        check_writable(folder, "folder", folder=True)
        with staging_dir(folder) as staging:
            new = self._record_jobs(staging, folder, jobs, speed=speed, load=load,
                                    duration=duration, dtype=dtype, progress=progress,
                                    variation=variation)
            new_index = _merged_index(folder / INDEX_NAME, new, speed, load)
            with atomic_path(staging / INDEX_NAME) as tmp:
                new_index.to_csv(tmp, index=False)
            commit_staged(staging, folder, [*new["path"], INDEX_NAME])
        out = new.copy()
        out["path"] = [str((folder / p).resolve()) for p in out["path"]]
        return out

    def history(self, folder: str | os.PathLike, **options: Any) -> pd.DataFrame:
        """Record a machine's life into ``folder``: healthy first, then a fault growing by a
        stated law, with run-to-run variation, a load change and a sensor remount partway;
        writes ``index.csv`` (``file``, ``time``, ``size``, ``event``). The options and
        defaults are :func:`gearshot.rig.history.record_history`'s."""
        from .history import record_history

        return record_history(self, folder, **options)

    def _record_jobs(self, staging: Path, folder: Path, jobs: list[tuple[float, int]], *,
                     speed: float, load: float, duration: float, dtype: str,
                     progress: bool, variation: float = 0.0) -> pd.DataFrame:
        """Record every (size, repetition) job into ``staging``; their index rows."""
        from .._progress import track

        rows = []
        for y, r in track(jobs, f"rig {speed:g} rev/s {load:g} N m", enabled=progress):
            z = (np.random.default_rng([self.seed, 43, r, int(round(y * 1e6))])
                 .standard_normal(2) * variation if variation else np.zeros(2))
            rec = self.record(speed=speed * (1 + z[0]), load=load * (1 + z[1]),
                              fault_size=y, duration=duration, repetition=r)
            name = self.file_name(speed, load, y, r)
            try:
                rec.write(staging / name, dtype=dtype)
            except GearshotError as exc:  # name the destination, not the staging copy
                raise GearshotError(str(exc).replace(str(staging / name),
                                                     str(folder / name))) from None
            rows.append({"path": name, "speed": speed, "load": load, "fault_size": y,
                         "repetition": r})
        return pd.DataFrame(rows, columns=INDEX_COLUMNS)


def _campaign_jobs(healthy: int, sizes: Sequence[float],
                   repetitions: int) -> list[tuple[float, int]]:
    """(fault size, repetition) of every recording of a campaign: healthy ones first."""
    healthy = check_int(healthy, "healthy", minimum=0)
    repetitions = check_int(repetitions, "repetitions", minimum=0)
    sizes = [check_in_range(y, "sizes[i]", 0.0, 1.0, low_inclusive=False) for y in sizes]
    return [(0.0, r) for r in range(healthy)] + [(y, r) for y in sizes
                                                 for r in range(repetitions)]


def _merged_index(index_path: Path, new: pd.DataFrame, speed: float,
                  load: float) -> pd.DataFrame:
    """The folder's index with this condition's rows replaced by ``new``."""
    if not index_path.exists():
        return new
    old = pd.read_csv(index_path)
    if list(old.columns) != INDEX_COLUMNS:
        raise GearshotError(f"{str(index_path)!r} is not a campaign index "
                            f"(columns {list(old.columns)})")
    same = np.isclose(old["speed"], speed) & np.isclose(old["load"], load)
    return pd.concat([old[~same], new], ignore_index=True)


def _engine_vibration(engine: Callable[..., np.ndarray], motor: np.ndarray,
                      torque: np.ndarray, fs: float, fault_size: float, reality: RigReality,
                      rng: np.random.Generator) -> np.ndarray:
    """The engine's gear vibration (g) for the run, checked: shaped like ``motor``, finite."""
    vib = np.asarray(engine(motor_revs=motor, load_torque=torque, fs=fs,
                            fault_size=fault_size, reality=reality, rng=rng), dtype=np.float64)
    if vib.shape != motor.shape or not np.all(np.isfinite(vib)):
        raise GearshotError(f"the physics engine returned shape {vib.shape} or non-finite "
                            f"values; expected {motor.shape} finite")
    return vib


def _interference(t: np.ndarray, motor: np.ndarray, fs: float, speed: float,
                  reality: RigReality, rng: np.random.Generator) -> np.ndarray:
    """Non-synchronous interference relative to the vibration's RMS: motor electrical
    harmonics, an extra shaft, bearing-like impacts (:mod:`.interference`)."""
    return (reality.motor_level * motor_harmonics(t, speed=speed,
                                                  pole_pairs=reality.motor_pole_pairs,
                                                  slip=reality.motor_slip, rng=rng)
            + reality.extra_level * extra_shaft(motor, order=reality.extra_order, rng=rng)
            + reality.impact_level * bearing_impacts(motor, fs, order=reality.impact_order,
                                                     frequency=reality.impact_frequency,
                                                     rng=rng))
