"""The machine file verified against the signal: the mesh orders it declares must stand
where it says in the healthy recordings' order spectrum.

A machine file turns a recording into the angle of every shaft: the tacho's pulses per
revolution and the sampling rate make the reference shaft's speed, the tooth counts every
other shaft's. A mistake in any of them moves every gear mesh away from the order the file
declares for it, and the estimates built on that angle are wrong without looking wrong.
Each stage's mesh is a line at order ``driver_teeth * speed_ratio(driver)`` of the reference
shaft (with harmonics). :func:`check_recording` reads the whole-record order spectrum of
that shaft (along the tacho's angle, or the angle tracked from the vibration) and tests,
in this order:

1. without a tacho, the tracked speed (:func:`speed_check`): the record's whole orders
   must stand best at the tracked speed, not at another within 15 % (a comb locked on a
   mesh sideband or on a ratio of the speed is named with its size and the speed found);
2. the declared comb must stand out (:data:`MIN_COMB_DB`); where it does not, the scale
   ``k`` of the orders that a nameable mistake makes is tried (:data:`MIN_GAIN_DB`):
   ``k = p / P`` with the speed off the declared range: ``pulses_per_rev`` looks like
   ``P``, not ``p``; ``k`` the speed ratio of two shafts: the tacho (or ``[speed]``)
   watches the other shaft; none: a tooth count (one mesh missing, the others standing)
   or another gear train;
3. the odd harmonics of the lowest declared mesh must stand out (:data:`MIN_ODD_DB`;
   tested by :func:`verify_machine` on the mean over its recordings): otherwise that mesh
   is not there and the train found has twice the declared orders (the PHM09 helical
   file on spur records: 16, 8 declared, 32, 16 found);
4. the speed must lie in the declared ``[speed] range_hz`` (or within 10 % of the
   recording's nominal ``speed``): otherwise, with the orders where declared, ``fs`` is
   off (the tacho and the vibration are stretched alike, so the orders cannot show it).

Level of a line: its peak in the Hann-windowed order spectrum of the whole record, in dB
above the median of the spectrum over the surrounding whole order. *Prominence* of a line:
its level minus the median level at the eight neighbouring whole-order offsets
(``±1 … ±4`` shaft orders): a mesh stands above the shaft's own harmonics and sidebands
around it, which every healthy gearbox shows at almost every whole order.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from .._errors import GearshotError

__all__ = ["MeshLine", "MachineCheck", "verify_machine", "check_recording", "speed_check",
           "MIN_COMB_DB", "MIN_ODD_DB", "MIN_GAIN_DB", "MAX_WHOLE_GAIN_DB",
           "MIN_PROMINENCE_DB", "SPEED_RANGE_MARGIN"]

#: The declared comb (every stage's mesh, harmonics 1-3, clipped to -10...20 dB, mean over
#: lines and sensors) must stand this many dB above the neighbouring whole orders.
MIN_COMB_DB = 1.0
#: The odd harmonics of the lowest declared mesh (up to order 125) must stand this many dB
#: above their neighbouring whole orders (mean over the recordings checked together):
#: otherwise that mesh is not there and the train found meshes at twice its orders.
MIN_ODD_DB = 2.0
#: A nameable mistake's scale of the orders must put the comb's lines this many dB higher
#: over the floor than the declared scale before it is named.
MIN_GAIN_DB = 3.0
#: Along a tracked angle, the record's whole orders 1-100 (median level over the half
#: orders between them) must not stand this many dB better at another speed within 15 %:
#: otherwise the mesh comb locked on a sideband or a ratio of the speed.
MAX_WHOLE_GAIN_DB = 1.0
#: A declared mesh whose harmonics 1-3 stand this many dB out counts as found.
MIN_PROMINENCE_DB = 3.0
#: Relative margin around ``[speed] range_hz`` (and around a nominal speed) within which
#: the measured reference speed is plausible.
SPEED_RANGE_MARGIN = 0.10
_HARMONICS = 3
_NEIGHBOURS = 4
_SAMPLES_PER_REV = 1024
_CLIP = (-10.0, 20.0)
_ODD_TOP = 125.0
_WHOLE_TOP = 100.0
_WHOLE_SEARCH = 0.15
_MIN_SHIFT_BINS = 5.0


@dataclass(frozen=True)
class MeshLine:
    """One declared gear mesh in the order spectrum of the reference shaft.

    Attributes
    ----------
    stage : str
        The stage, e.g. ``"input 32T -> idler 96T"``.
    order : float
        Declared mesh order of the reference shaft.
    prominence_db : float
        Mean over the first three harmonics (and the sensors) of the line's level minus
        the median level of its neighbouring whole orders, dB.
    """

    stage: str
    order: float
    prominence_db: float

    @property
    def stands(self) -> bool:
        """Whether the mesh stands out (:data:`MIN_PROMINENCE_DB`)."""
        return self.prominence_db >= MIN_PROMINENCE_DB


@dataclass(frozen=True)
class MachineCheck:
    """What :func:`verify_machine` found for one recording.

    Attributes
    ----------
    recording : str
        The recording's origin.
    passed : bool
    mistake : str
        ``""`` when passed, else the likely mistake in one line.
    scale : float
        Orders found / orders declared (1 when the declared comb stands best).
    speed_hz : float
        Mean reference-shaft speed the file gives, rev/s.
    speed_source : str
        ``"tacho"`` or ``"vibration"``.
    lines : tuple of MeshLine
    score_db, best_score_db : float
        Mean clipped prominence of every declared line at scale 1 and at ``scale``.
    odd_db : float
        Mean prominence of the odd harmonics of the lowest declared mesh.
    whole_db : float
        Median level of the whole orders 1-100 over the half orders, dB (tracked speed
        only; 0 with a tacho).
    speed_ratio : float
        True / used speed at which the whole orders stand best (within 15 %).
    """

    recording: str
    passed: bool
    mistake: str
    scale: float
    speed_hz: float
    speed_source: str
    lines: tuple[MeshLine, ...] = field(default=())
    score_db: float = 0.0
    best_score_db: float = 0.0
    odd_db: float = 0.0
    whole_db: float = 0.0
    speed_ratio: float = 1.0

    def describe(self) -> str:
        """One line: the file, the verdict, the mistake."""
        found = ", ".join(f"{ln.order:g} ({ln.prominence_db:+.1f} dB)" for ln in self.lines)
        if self.passed:
            return (f"{self.recording}: machine file verified (mesh orders {found} of the "
                    f"{self.speed_source} shaft at {self.speed_hz:.4g} Hz)")
        return f"{self.recording}: {self.mistake}"

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready summary."""
        return {"recording": self.recording, "passed": self.passed, "mistake": self.mistake,
                "scale": self.scale, "speed_hz": self.speed_hz,
                "speed_source": self.speed_source,
                "mesh_orders": [ln.order for ln in self.lines],
                "prominence_db": [ln.prominence_db for ln in self.lines]}


# ---------------------------------------------------------------- order spectrum
@dataclass(frozen=True)
class _Spectrum:
    level: np.ndarray   # (n_sensors, n_bins) dB above the local floor, max over +-2 bins
    n_revs: int         # bins per order

    @property
    def max_order(self) -> float:
        return float((self.level.shape[-1] - 3) / self.n_revs)

    def at(self, orders: np.ndarray) -> np.ndarray:
        """Level at ``orders`` (any shape), per sensor: shape (n_sensors, *orders.shape)."""
        b = np.clip(np.rint(np.asarray(orders) * self.n_revs).astype(np.int64), 0,
                    self.level.shape[-1] - 1)
        return self.level[:, b]

    def prominence(self, orders: np.ndarray, unit: float = 1.0) -> np.ndarray:
        """Level at ``orders`` minus the median level at the neighbouring whole orders
        (of a shaft turning ``unit`` times as fast), mean over sensors: shape of
        ``orders``."""
        orders = np.asarray(orders, dtype=float)
        offsets = unit * np.array([j for j in range(-_NEIGHBOURS, _NEIGHBOURS + 1) if j])
        around = self.at(orders[..., None] + offsets)       # (s, ..., 8)
        return np.asarray(np.mean(self.at(orders) - np.median(around, axis=-1), axis=0))


def _order_spectrum(x: np.ndarray, spc: int) -> _Spectrum:
    """Level of the whole record's order spectrum, per sensor row of ``x``."""
    x = np.atleast_2d(np.asarray(x, dtype=float))
    n_revs = x.shape[-1] // spc
    if n_revs < 2 * _NEIGHBOURS + 2:
        raise GearshotError(f"the recording holds {n_revs} revolution(s) of the reference "
                            f"shaft; verifying the machine file needs at least "
                            f"{2 * _NEIGHBOURS + 2}")
    x = x[:, : n_revs * spc]
    x = (x - x.mean(axis=-1, keepdims=True)) * np.hanning(x.shape[-1])
    power = np.abs(np.fft.rfft(x, axis=-1)) ** 2
    db = 10.0 * np.log10(power + np.finfo(float).tiny)
    n_blocks = db.shape[-1] // n_revs
    floor = np.median(db[:, : n_blocks * n_revs].reshape(x.shape[0], n_blocks, n_revs),
                      axis=-1)
    centres = (np.arange(n_blocks) + 0.5) * n_revs
    bins = np.arange(db.shape[-1])
    level = db - np.stack([np.interp(bins, centres, f) for f in floor])
    # a line may spread over a bin either side (speed drift, a tracked angle)
    padded = np.pad(level, ((0, 0), (2, 2)), mode="edge")
    level = np.max(np.stack([padded[:, i: i + level.shape[-1]] for i in range(5)]), axis=0)
    return _Spectrum(level, n_revs)


# ---------------------------------------------------------------- the check
def _whole_order_db(spec: _Spectrum, r: np.ndarray, top: float = _WHOLE_TOP) -> np.ndarray:
    """Median level at the orders ``j * r`` (``j`` = 1 ... ``top``) minus the median level
    half-way between them, dB, for every ratio ``r``: every whole order of the true shaft
    carries a line (its harmonics, the meshes and their sidebands: every shaft of a train
    turns a whole number of times per revolution of the train's common period), so this
    peaks at the ratio of the true speed to the speed of the angle used."""
    r = np.atleast_1d(np.asarray(r, dtype=float))
    j = np.arange(1, int(min(top, (spec.max_order - 1) / r.max())) + 1, dtype=float)
    on = spec.at(np.multiply.outer(r, j)).mean(axis=0)
    off = spec.at(np.multiply.outer(r, j + 0.5)).mean(axis=0)
    return np.asarray(np.median(on, axis=-1) - np.median(off, axis=-1))


def _speed_ratio_found(spec: _Spectrum) -> tuple[float, float, float]:
    """(level at ratio 1, best level, its ratio) of the whole-order comb over true/used
    speed ratios within :data:`_WHOLE_SEARCH`."""
    top = min(_WHOLE_TOP, spec.max_order / (1 + _WHOLE_SEARCH) - 1)
    step = 0.5 / (top * spec.n_revs)
    r = np.arange(1 - _WHOLE_SEARCH, 1 + _WHOLE_SEARCH + step, step)
    w = _whole_order_db(spec, r, top)
    w1 = float(_whole_order_db(spec, np.array([1.0]), top)[0])
    i = int(np.argmax(w))
    return w1, float(w[i]), float(r[i])


def _tracked_off(spec: _Spectrum, speed: float, whole: float, whole_best: float,
                 ratio: float) -> str:
    """Why a tracked speed is off (``""`` when it is not): the record's whole orders stand
    best at another speed, farther than the comb's resolution (5 bins at order 100)."""
    def far(r: float, top: float) -> bool:   # beyond the comb's resolution
        return abs(r - 1.0) * top * spec.n_revs > _MIN_SHIFT_BINS

    if whole_best - whole > MAX_WHOLE_GAIN_DB and far(ratio, _WHOLE_TOP):
        return (f"the speed tracked in the vibration ({speed:.4g} Hz) looks "
                f"{100 * (1 / ratio - 1):+.2f} % off: the record's whole orders stand "
                f"best at {speed * ratio:.4g} Hz ({whole_best:+.1f} against {whole:+.1f} "
                f"dB over the half orders at the tracked speed): the mesh comb locked on "
                f"a sideband or a ratio of the speed (check [speed] range_hz or the "
                f"nominal speed)")
    return ""


def _stage_lines(machine: Any) -> list[tuple[str, Fraction]]:
    ref = machine.reference_shaft
    return [(f"{st.driver} {st.driver_teeth}T -> {st.driven} {st.driven_teeth}T",
             st.driver_teeth * machine.speed_ratio(st.driver, relative_to=ref))
            for st in machine.stages]


def _candidates(machine: Any, speed: float, source: str,
                plausible: tuple[float, float] | None) -> list[tuple[float, str]]:
    """Scales of the orders that a nameable mistake makes, with its name: another
    ``pulses_per_rev``, the tacho on another shaft, a comb locked on a ratio."""
    out: list[tuple[float, str]] = []
    ref = machine.reference_shaft
    # a wrong tacho shaft or pulse count shows in the speed too, where a range says so
    off = plausible is not None and not plausible[0] <= speed <= plausible[1]
    key = "tacho.shaft" if source == "tacho" else "speed.shaft"
    for other in machine.shafts:
        if other != ref and (off or plausible is None):
            # the file's reference angle is really ``other``'s: orders scale by ref / other
            r = float(machine.speed_ratio(ref, relative_to=other))
            out.append((r, f"{key} looks like {other!r}, not {ref!r}"))
    if source == "tacho" and machine.tacho is not None:
        p = machine.tacho.pulses_per_rev
        for big_p in range(1, 4 * p + 11):
            if big_p == p:
                continue
            true = speed * p / big_p
            if plausible is None or (off and plausible[0] <= true <= plausible[1]):
                out.append((p / big_p, f"pulses_per_rev looks like {big_p}, not {p}"))
    if source == "vibration":
        for r in (0.5, 2.0 / 3.0, 1.5, 2.0):
            out.append((r, f"the speed tracked in the vibration is {1 / r:.3g} x the true one"))
    return out


def _comb_score(spec: _Spectrum, orders: np.ndarray, unit: float) -> float:
    """The comb score of mesh ``orders`` of a shaft turning ``unit`` times as fast as the
    spectrum's."""
    if (orders.max() * _HARMONICS + (_NEIGHBOURS + 1) * unit > spec.max_order
            or orders.min() < (_NEIGHBOURS + 1) * unit
            or unit * spec.n_revs < 4):
        return -np.inf
    # the level over the floor, not the prominence: a wrong scale's neighbours fall
    # between the true whole orders and would flatter any line
    lv = spec.at(orders[:, None] * np.arange(1, _HARMONICS + 1))
    return float(np.mean(np.clip(lv, 0.0, 40.0)))


def _best_candidate(spec: _Spectrum, declared: np.ndarray,
                    candidates: list[tuple[float, str]]) -> tuple[float, float, str]:
    """(scale, score, name) of the candidate whose comb stands best (nearby scales within
    half a percent searched: a tracked or drifting speed)."""
    scored = []
    for k, name in candidates:
        ks = k * (1.0 + np.linspace(-0.005, 0.005, 21))
        sc = [_comb_score(spec, declared * kk, k) for kk in ks]
        i = int(np.argmax(sc))
        scored.append((float(ks[i]), float(sc[i]), name))
    if not scored:
        return 1.0, -np.inf, ""
    top = max(sc for _, sc, _ in scored)
    # ties (the same scale, two explanations): the first in the list
    return next(c for c in scored if c[1] >= top - 0.5)


def _plausible_speeds(machine: Any, rec: Any) -> tuple[float, float] | None:
    """Reference-shaft speeds the machine file or the recording declare plausible."""
    vs = machine.vibration_speed
    if vs is not None and vs.speed_range is not None:
        r = float(machine.speed_ratio(machine.reference_shaft, relative_to=vs.shaft))
        lo, hi = vs.speed_range[0] * r, vs.speed_range[1] * r
    elif getattr(rec, "speed", None) is not None:
        r = float(machine.speed_ratio(machine.reference_shaft, relative_to=machine.shafts[0]))
        lo = hi = float(rec.speed) * r
    else:
        return None
    return lo * (1 - SPEED_RANGE_MARGIN), hi * (1 + SPEED_RANGE_MARGIN)


def _name_mistake(machine: Any, spec: _Spectrum, speed: float, source: str,
                  plausible: tuple[float, float] | None, lines: list[MeshLine],
                  declared: np.ndarray, s1: float) -> tuple[float, float, str]:
    """(scale, its score, the likely mistake in one line) when the declared comb does not
    stand where declared."""
    decl = ", ".join(f"{o:.4g}" for o in declared)
    k, score, name = _best_candidate(spec, declared,
                                     _candidates(machine, speed, source, plausible))
    at_one = _comb_score(spec, declared, 1.0)
    if name and score - at_one >= MIN_GAIN_DB:
        found = ", ".join(f"{o * k:.4g}" for o in declared)
        return k, score, (f"{name}: the mesh orders stand at {k:.4g} x the declared "
                          f"({found} instead of {decl}; lines {score:.1f} dB over the "
                          f"floor against {at_one:.1f} where declared) "
                          f"and the {source} gives {speed:.4g} Hz, i.e. "
                          f"{speed * k:.4g} Hz")
    tooth = _tooth_mistake(lines)
    if tooth:
        return 1.0, s1, tooth
    if source == "vibration":
        return 1.0, s1, (f"the speed tracked in the vibration ({speed:.4g} Hz) does not put "
                         f"the declared mesh orders ({decl}) on lines ({s1:+.1f} dB): the "
                         f"tracking locked on something else, or the train is not this "
                         f"machine's (check [speed] range_hz, fs, the tooth counts)")
    return 1.0, s1, (f"the declared mesh orders ({decl}) of {machine.name!r} do not stand in "
                     f"the order spectrum ({s1:+.1f} dB over their neighbours, at least "
                     f"{MIN_COMB_DB:g} needed): another gear train (another gearbox's "
                     f"machine file), wrong tooth counts, or a wrong tacho")


def _tooth_mistake(lines: list[MeshLine], half: bool = False) -> str:
    """One mesh missing while the others stand: a tooth count (``half``: not where the
    missing mesh is half of a declared one -- that is another train at twice the
    orders)."""
    standing = [ln for ln in lines if ln.stands]
    absent = [ln for ln in lines if ln.prominence_db < 0.0]
    if half:
        orders = [ln.order for ln in lines]
        absent = [ln for ln in absent
                  if not any(abs(2 * ln.order - o) < 1e-6 for o in orders)]
    if standing and absent:
        missing = ", ".join(f"{ln.stage} at order {ln.order:.4g} ({ln.prominence_db:+.1f} dB)"
                            for ln in absent)
        return (f"a tooth count looks wrong: the mesh of {missing} does not stand out where "
                f"declared while the others do")
    return ""


def check_recording(machine: Any, rec: Any, *, sensors: Sequence[str] | None = None,
                    odd_test: bool = True, comb_test: bool = True) -> MachineCheck:
    """Verify ``machine`` against one recording read with it (no exception).

    Parameters
    ----------
    machine : gearshot.Machine
    rec : gearshot.io.Recording
        Read with ``machine`` (healthy, steady speed).
    sensors : sequence of str, optional
        Sensors whose spectra are averaged; default: every sensor of the machine.
    odd_test : bool, default True
        Test the odd harmonics of the lowest mesh here (:data:`MIN_ODD_DB`);
        :func:`verify_machine` tests their mean over the recordings instead.
    comb_test : bool, default True
        Test the declared comb, its odd harmonics and the speed range; ``False``: only
        the tracked speed (the whole orders, :func:`speed_check`).

    Returns
    -------
    MachineCheck
    """
    label = str(rec.origin or "recording")
    names = [machine.sensor(s).name for s in (sensors or [s.name for s in machine.sensors])]
    ref = machine.reference_shaft
    speed = float(rec.shaft_speed())
    source = rec.speed_source
    x = np.stack([rec.angle_domain(shaft=ref, sensor=n, samples_per_cycle=_SAMPLES_PER_REV,
                                   antialias=machine.antialias) for n in names])
    spec = _order_spectrum(x, _SAMPLES_PER_REV)
    stages = _stage_lines(machine)
    declared = np.array([float(o) for _, o in stages])
    h = np.arange(1, _HARMONICS + 1)
    prom = spec.prominence(declared[:, None] * h)
    lines = [MeshLine(name, float(o), float(np.mean(p)))
             for (name, o), p in zip(stages, prom)]
    s1 = float(np.mean(np.clip(prom, *_CLIP)))
    low = float(declared.min())
    odd = float(np.mean(spec.prominence(low * np.arange(1, max(2, int(_ODD_TOP / low) + 1), 2))))
    # the whole-order scan only where the speed was tracked (a tacho's speed is exact)
    whole, whole_best, ratio = (_speed_ratio_found(spec) if source == "vibration"
                                else (0.0, 0.0, 1.0))
    k, best = 1.0, s1
    plausible = _plausible_speeds(machine, rec)
    moved = ""
    if source == "vibration":
        moved = _tracked_off(spec, speed, whole, whole_best, ratio)
    if moved:
        mistake = moved
    elif not comb_test:
        mistake = ""
    elif s1 < MIN_COMB_DB:
        k, best, mistake = _name_mistake(machine, spec, speed, source, plausible, lines,
                                         declared, s1)
    elif odd_test and odd < MIN_ODD_DB:
        mistake = (_tooth_mistake(lines, half=True)
                   or _half_mistake(machine, declared, low, odd))
    elif plausible is not None and not plausible[0] <= speed <= plausible[1]:
        # a wrong pulse count or tacho shaft moves the orders too; fs does not
        k, best, mistake = _name_mistake(machine, spec, speed, source, plausible, lines,
                                         declared, s1)
        if k == 1.0:
            k, best, mistake = 1.0, s1, _fs_mistake(rec, speed, plausible)
    else:
        mistake = ""
    return MachineCheck(label, not mistake, mistake, k, speed, source, tuple(lines), s1,
                        best, odd, whole, ratio)


def speed_check(machine: Any, rec: Any) -> str:
    """``"ok"``, or why a speed tracked in the vibration is not to be trusted.

    With a tacho: ``"ok"`` (the pulses are the speed). Without: the whole orders of the
    shaft in the record's order spectrum along the tracked angle must stand best at the
    tracked speed, not at another within 15 % (:data:`MAX_WHOLE_GAIN_DB`): a comb locked
    on a sideband of a mesh (e.g. 2 idler orders beside the PHM09 spur input mesh: 2.08 %
    off) or a run-up locked on another line fails here. The tracker's own refusal (no
    line stands out, an ambiguous ratio 1/2 ... 2) is returned as the reason too. The
    machine file itself is :func:`verify_machine`'s.

    Parameters
    ----------
    machine : gearshot.Machine
    rec : gearshot.io.Recording
        Read with ``machine``.

    Returns
    -------
    str
    """
    if rec.speed_source != "vibration":
        return "ok"
    try:
        check = check_recording(machine, rec, odd_test=False, comb_test=False)
    except GearshotError as exc:
        return str(exc)
    return "ok" if check.passed else check.mistake


def _half_mistake(machine: Any, declared: np.ndarray, low: float, odd: float) -> str:
    found = ", ".join(f"{2 * o:.4g}" for o in declared)
    decl = ", ".join(f"{o:.4g}" for o in declared)
    return (f"the mesh orders found ({found}) match another gear train than the declared "
            f"({decl}) of {machine.name!r}: the odd harmonics of the lowest declared mesh "
            f"(order {low:.4g}) stand {odd:+.1f} dB over their neighbours (another "
            f"gearbox's machine file, or tooth counts half the true ones)")


def _fs_mistake(rec: Any, speed: float, plausible: tuple[float, float]) -> str:
    lo = plausible[0] / (1 - SPEED_RANGE_MARGIN)
    hi = plausible[1] / (1 + SPEED_RANGE_MARGIN)
    if lo == hi:   # a nominal speed: the factor itself
        q = speed / lo
        return (f"fs off by factor {q:.3g}: the mesh orders stand where declared but the "
                f"{rec.speed_source} gives {speed:.4g} Hz against the nominal {lo:.4g} Hz "
                f"(the tacho and the vibration share fs: the orders cannot tell); "
                f"fs={rec.fs:g} Hz looks like {rec.fs / q:.6g} Hz")
    q = speed / lo if speed < lo else speed / hi
    side = "at most" if q < 1 else "at least"
    return (f"fs off by factor {side} {q:.3g}: the mesh orders stand where declared but the "
            f"{rec.speed_source} gives {speed:.4g} Hz, outside the declared speed range "
            f"{lo:.4g}-{hi:.4g} Hz (the tacho and the vibration share fs: the orders "
            f"cannot tell); fs={rec.fs:g} Hz looks {'high' if q < 1 else 'low'}")


def verify_machine(machine: Any, recordings: Any, *, sensors: Sequence[str] | None = None,
                   raise_on_failure: bool = True) -> list[MachineCheck]:
    """Verify a machine file against healthy recordings: its mesh orders where it says.

    Parameters
    ----------
    machine : gearshot.Machine or path
        The machine description (a TOML path is read).
    recordings : Recording, path, or sequence of them
        Healthy recordings of the machine, steady speed (paths are read with
        ``machine``).
    sensors : sequence of str, optional
        Sensors whose order spectra are averaged (default: all of the machine's).
    raise_on_failure : bool, default True
        Raise on the first recording that fails, naming it and the likely mistake.

    Returns
    -------
    list of MachineCheck
        One per recording.

    Raises
    ------
    GearshotError
        A recording's declared mesh orders do not stand where declared, or its speed is
        off the declared range by a constant factor: one line naming the file, the orders
        found and the likely mistake (``pulses_per_rev``, ``fs``, a tooth count, the
        tacho's shaft, another gear train, a tracked speed that is off).
    """
    from ..io import Recording
    from .gearbox import Machine

    if isinstance(machine, (str, Path)):
        machine = Machine.from_toml(machine)
    if isinstance(recordings, (str, Path, Recording)):
        recordings = [recordings]
    out = []
    for item in recordings:
        rec = item if isinstance(item, Recording) else Recording.read(item, machine=machine)
        # a tracker's refusal names the file itself
        check = check_recording(machine, rec, sensors=sensors, odd_test=False)
        if raise_on_failure and not check.passed:
            raise GearshotError(f"machine file {machine.name!r} does not match "
                                f"{check.describe()}")
        out.append(check)
    odd = float(np.mean([c.odd_db for c in out])) if out else MIN_ODD_DB
    if out and odd < MIN_ODD_DB:
        declared = np.array([ln.order for ln in out[0].lines])
        mistake = (_tooth_mistake(list(out[0].lines), half=True)
                   or _half_mistake(machine, declared, float(declared.min()), odd))
        out = [dataclasses.replace(c, passed=False, mistake=c.mistake or mistake)
               for c in out]
        if raise_on_failure:
            names = ", ".join(Path(c.recording).name for c in out)
            raise GearshotError(f"machine file {machine.name!r} does not match {names}: "
                                f"{mistake}")
    return out
