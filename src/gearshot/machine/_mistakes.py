"""Naming the likely mistake of a machine file from the order spectrum
(:mod:`gearshot.machine.signal_check`): the scales of the orders that a wrong pulse count or
tacho shaft make, a missing mesh (a tooth count), another gear train, a wrong ``fs``."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ._order_spectrum import HARMONICS, NEIGHBOURS, Spectrum

__all__ = ["MIN_COMB_DB", "MIN_ODD_DB", "MIN_GAIN_DB", "MIN_PROMINENCE_DB",
           "SPEED_RANGE_MARGIN", "MeshLine", "name_mistake", "tooth_mistake", "half_mistake",
           "fs_mistake", "plausible_speeds"]

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
#: A declared mesh whose harmonics 1-3 stand this many dB out counts as found.
MIN_PROMINENCE_DB = 3.0
#: Relative margin around ``[speed] range_hz`` (and around a nominal speed) within which
#: the measured reference speed is plausible.
SPEED_RANGE_MARGIN = 0.10
_CLIP = (-10.0, 20.0)



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


def _comb_score(spec: Spectrum, orders: np.ndarray, unit: float) -> float:
    """The comb score of mesh ``orders`` of a shaft turning ``unit`` times as fast as the
    spectrum's."""
    if (orders.max() * HARMONICS + (NEIGHBOURS + 1) * unit > spec.max_order
            or orders.min() < (NEIGHBOURS + 1) * unit
            or unit * spec.n_revs < 4):
        return -np.inf
    # the level over the floor, not the prominence: a wrong scale's neighbours fall
    # between the true whole orders and would flatter any line
    lv = spec.at(orders[:, None] * np.arange(1, HARMONICS + 1))
    return float(np.mean(np.clip(lv, 0.0, 40.0)))


def _best_candidate(spec: Spectrum, declared: np.ndarray,
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


def plausible_speeds(machine: Any, rec: Any) -> tuple[float, float] | None:
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


def name_mistake(machine: Any, spec: Spectrum, speed: float, source: str,
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
    tooth = tooth_mistake(lines)
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


def tooth_mistake(lines: list[MeshLine], half: bool = False) -> str:
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


def half_mistake(machine: Any, declared: np.ndarray, low: float, odd: float) -> str:
    found = ", ".join(f"{2 * o:.4g}" for o in declared)
    decl = ", ".join(f"{o:.4g}" for o in declared)
    return (f"the mesh orders found ({found}) match another gear train than the declared "
            f"({decl}) of {machine.name!r}: the odd harmonics of the lowest declared mesh "
            f"(order {low:.4g}) stand {odd:+.1f} dB over their neighbours (another "
            f"gearbox's machine file, or tooth counts half the true ones)")


def fs_mistake(rec: Any, speed: float, plausible: tuple[float, float]) -> str:
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


