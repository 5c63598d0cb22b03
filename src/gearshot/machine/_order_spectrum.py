"""The whole-record order spectrum of a shaft for the machine check
(:mod:`gearshot.machine.signal_check`): levels over the local floor, the prominence of a
line over its neighbouring whole orders, and the scan of the whole-order comb over speeds
near a tracked one."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._errors import GearshotError

__all__ = ["MAX_WHOLE_GAIN_DB", "HARMONICS", "NEIGHBOURS", "Spectrum", "order_spectrum",
           "speed_ratio_found", "tracked_off"]

#: Along a tracked angle, the record's whole orders 1-100 (median level over the half
#: orders between them) must not stand this many dB better at another speed within 15 %:
#: otherwise the mesh comb locked on a sideband or a ratio of the speed.
MAX_WHOLE_GAIN_DB = 1.0
HARMONICS = 3
NEIGHBOURS = 4
_WHOLE_TOP = 100.0
_WHOLE_SEARCH = 0.15
_MIN_SHIFT_BINS = 5.0


@dataclass(frozen=True)
class Spectrum:
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
        offsets = unit * np.array([j for j in range(-NEIGHBOURS, NEIGHBOURS + 1) if j])
        around = self.at(orders[..., None] + offsets)       # (s, ..., 8)
        return np.asarray(np.mean(self.at(orders) - np.median(around, axis=-1), axis=0))


def order_spectrum(x: np.ndarray, spc: int) -> Spectrum:
    """Level of the whole record's order spectrum, per sensor row of ``x``."""
    x = np.atleast_2d(np.asarray(x, dtype=float))
    n_revs = x.shape[-1] // spc
    if n_revs < 2 * NEIGHBOURS + 2:
        raise GearshotError(f"the recording holds {n_revs} revolution(s) of the reference "
                            f"shaft; verifying the machine file needs at least "
                            f"{2 * NEIGHBOURS + 2}")
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
    return Spectrum(level, n_revs)


def _whole_order_db(spec: Spectrum, r: np.ndarray, top: float = _WHOLE_TOP) -> np.ndarray:
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


def speed_ratio_found(spec: Spectrum) -> tuple[float, float, float]:
    """(level at ratio 1, best level, its ratio) of the whole-order comb over true/used
    speed ratios within :data:`_WHOLE_SEARCH`."""
    top = min(_WHOLE_TOP, spec.max_order / (1 + _WHOLE_SEARCH) - 1)
    step = 0.5 / (top * spec.n_revs)
    r = np.arange(1 - _WHOLE_SEARCH, 1 + _WHOLE_SEARCH + step, step)
    w = _whole_order_db(spec, r, top)
    w1 = float(_whole_order_db(spec, np.array([1.0]), top)[0])
    i = int(np.argmax(w))
    return w1, float(w[i]), float(r[i])


def tracked_off(spec: Spectrum, speed: float, whole: float, whole_best: float,
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
