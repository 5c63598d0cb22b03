"""Modal synthesis of realistic FRFs and a seeded synthetic bank of them.

Accelerance of a structure with N modes (modal constants A_r in 1/kg, natural frequencies
ω_r, damping ratios ζ_r) plus an optional rigid-body term R₀ (a free structure)::

    H(ω) = R₀ − ω² Σ_r A_r / (ω_r² − ω² + 2i ζ_r ω_r ω)

Residues of equal sign on neighbouring modes put an antiresonance between them; a sign change
removes it. Non-minimum-phase behaviour is added by a pure delay exp(−iωτ) and/or all-pass
factors (ω₀² − ω² − 2iζω₀ω) / (ω₀² − ω² + 2iζω₀ω), i.e. a zero pair in the right half plane
mirrored by a pole pair in the left one (magnitude 1, extra phase lag).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .._errors import GearshotError
from .._validation import as_signal_array, check_in_range, check_int, check_positive, describe
from .function import TransferFunction

__all__ = ["Mode", "modal_frf", "synthetic_tfs", "attenuation_db", "antiresonances"]

_QUANTITIES = {"accelerance": "acceleration", "mobility": "velocity",
               "receptance": "displacement"}


@dataclass(frozen=True)
class Mode:
    """One structural mode.

    Parameters
    ----------
    frequency : float
        Undamped natural frequency in Hz (> 0).
    damping : float
        Viscous damping ratio ζ in [0, 1).
    residue : float
        Modal constant A_r in 1/kg (product of the mass-normalized mode shape at response and
        reference; its sign decides whether an antiresonance follows the mode).
    """

    frequency: float
    damping: float
    residue: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "frequency", check_positive(self.frequency, "frequency"))
        object.__setattr__(self, "damping", check_in_range(self.damping, "damping", 0.0, 1.0,
                                                           high_inclusive=False))
        r = self.residue
        if isinstance(r, bool) or not isinstance(r, (int, float, np.floating, np.integer)) \
                or not np.isfinite(r):
            raise GearshotError(f"residue must be a finite real number; got {describe(r)}")
        object.__setattr__(self, "residue", float(r))


def modal_frf(freqs, modes: Sequence[Mode], *, quantity: str = "accelerance",
              rigid_body: float = 0.0, delay: float = 0.0,
              allpass: Sequence[tuple[float, float]] = (), name: str = "") -> TransferFunction:
    """FRF of a modal model at the given frequencies.

    Parameters
    ----------
    freqs : array_like, shape (n_lines,)
        Strictly increasing frequencies in Hz (>= 0).
    modes : sequence of Mode
        The modes (at least one).
    quantity : {"accelerance", "mobility", "receptance"}
        Response per unit force: acceleration, velocity or displacement.
    rigid_body : float
        Rigid-body modal constant R₀ in 1/kg (accelerance term R₀, i.e. a free structure's
        mass line). Only allowed for ``"accelerance"`` when ``freqs`` contains 0 Hz.
    delay : float
        Pure delay τ in s (>= 0) multiplying the FRF by exp(−iωτ).
    allpass : sequence of (frequency_hz, damping)
        Right-half-plane zero pairs (each with its mirrored stable pole pair).
    name : str
        Name of the returned function.

    Returns
    -------
    TransferFunction
        ``metadata`` holds the model (``modes``, ``rigid_body``, ``delay_s``, ``allpass``).

    Examples
    --------
    Two modes of the same sign: two resonances with an antiresonance between them.

    >>> import numpy as np
    >>> from gearshot.transfer import Mode, antiresonances, modal_frf
    >>> tf = modal_frf(np.linspace(0.0, 1000.0, 1001),
    ...                [Mode(200.0, 0.02, 1.0), Mode(600.0, 0.02, 1.0)])
    >>> tf.n_lines
    1001
    >>> print(float(tf.freqs[np.argmax(np.abs(tf.values))]))     # the accelerance peaks high
    601.0
    >>> print(antiresonances(tf))
    [447.]
    """
    f = as_signal_array(freqs, "freqs", min_ndim=1, max_ndim=1, min_length=2)
    if quantity not in _QUANTITIES:
        raise GearshotError(f"quantity must be one of {tuple(_QUANTITIES)}; got {quantity!r}")
    modes = list(modes)
    if not modes or not all(isinstance(m, Mode) for m in modes):
        raise GearshotError(f"modes must be a non-empty sequence of Mode; got {describe(modes)}")
    delay = check_positive(delay, "delay", allow_zero=True)
    if isinstance(rigid_body, bool) or not isinstance(rigid_body, (int, float, np.number)) \
            or not np.isfinite(rigid_body):
        raise GearshotError(f"rigid_body must be a finite real number; got {describe(rigid_body)}")
    rigid_body = float(rigid_body)
    if rigid_body != 0.0 and quantity != "accelerance" and np.any(f == 0):
        raise GearshotError(f"rigid_body={rigid_body} makes the {quantity} infinite at 0 Hz")
    w = 2 * np.pi * f
    h, pairs = _with_allpass(_modal_response(w, modes, quantity, rigid_body), w, allpass)
    if delay:
        h = h * np.exp(-1j * w * delay)
    meta = {"modes": tuple((m.frequency, m.damping, m.residue) for m in modes),
            "rigid_body": rigid_body, "delay_s": delay, "allpass": tuple(pairs),
            "model": f"modal {quantity}"}
    return TransferFunction(freqs=f, values=h, name=name, response_quantity=_QUANTITIES[quantity],
                            reference_quantity="force", metadata=meta)


def _modal_response(w: np.ndarray, modes: Sequence[Mode], quantity: str,
                    rigid_body: float) -> np.ndarray:
    """Sum of the modes' receptances at angular frequencies ``w``, as ``quantity``, with the
    rigid-body term."""
    receptance = np.zeros(w.shape, dtype=np.complex128)
    for m in modes:
        wr = 2 * np.pi * m.frequency
        receptance += m.residue / (wr**2 - w**2 + 2j * m.damping * wr * w)
    if quantity == "accelerance":
        h = -(w**2) * receptance + rigid_body
    elif quantity == "mobility":
        with np.errstate(divide="ignore", invalid="ignore"):
            h = 1j * w * receptance + (rigid_body / (1j * w) if rigid_body else 0.0)
    else:
        with np.errstate(divide="ignore", invalid="ignore"):
            h = receptance - (rigid_body / w**2 if rigid_body else 0.0)
    return h


def _with_allpass(h: np.ndarray, w: np.ndarray, allpass: Sequence[tuple[float, float]]
                  ) -> tuple[np.ndarray, list[tuple[float, float]]]:
    """``h`` times each all-pass section (a right-half-plane zero pair over its mirrored
    stable pole pair), and the checked ``(frequency_hz, damping)`` pairs."""
    pairs = []
    for item in allpass:
        try:
            f0, z0 = item
        except (TypeError, ValueError):
            raise GearshotError(f"allpass entries must be (frequency_hz, damping); "
                                f"got {describe(item)}") from None
        f0 = check_positive(f0, "allpass frequency")
        z0 = check_in_range(z0, "allpass damping", 0.0, 1.0, low_inclusive=False,
                            high_inclusive=False)
        w0 = 2 * np.pi * f0
        h = h * (w0**2 - w**2 - 2j * z0 * w0 * w) / (w0**2 - w**2 + 2j * z0 * w0 * w)
        pairs.append((f0, z0))
    return h, pairs


def attenuation_db(tf: TransferFunction) -> float:
    """Overall attenuation of a TF across its band in dB: −20·log10(RMS of |H| over the lines).

    This is the level drop that white noise suffers through the TF (10 dB or more for the
    paper's measured TFs together with their attenuation factor α).

    Examples
    --------
    A flat gain of 0.5 attenuates by 20·log10(2) dB:

    >>> import numpy as np
    >>> from gearshot.transfer import TransferFunction, attenuation_db
    >>> flat = TransferFunction(np.linspace(0.0, 500.0, 501), np.full(501, 0.5 + 0j))
    >>> print(round(attenuation_db(flat), 3))
    6.021
    """
    rms = float(np.sqrt(np.mean(tf.magnitude**2)))
    return float(-20 * np.log10(rms)) if rms > 0 else float("inf")


def antiresonances(tf: TransferFunction, *, min_depth_db: float = 10.0) -> np.ndarray:
    """Frequencies (Hz) of the antiresonances of an FRF.

    An antiresonance is a notch made by a lightly damped zero pair: a local minimum of |H|
    that lies at least ``min_depth_db`` below the smaller of the highest levels reached on
    either side before the curve drops below the notch again, and across which the phase
    *rises* (by more than π/4 between the lines where |H| is back 3 dB above the minimum).
    The phase rise tells a zero from a mere trough between two resonances whose residues
    change sign (there the phase keeps falling).

    Examples
    --------
    >>> import numpy as np
    >>> from gearshot.transfer import Mode, antiresonances, modal_frf
    >>> freqs = np.linspace(0.0, 1000.0, 1001)
    >>> same_sign = modal_frf(freqs, [Mode(200.0, 0.02, 1.0), Mode(600.0, 0.02, 1.0)])
    >>> print(antiresonances(same_sign))
    [447.]
    >>> opposite = modal_frf(freqs, [Mode(200.0, 0.02, 1.0), Mode(600.0, 0.02, -1.0)])
    >>> print(antiresonances(opposite))     # a trough between the modes, not a zero
    []
    """
    min_depth_db = check_positive(min_depth_db, "min_depth_db", allow_zero=True)
    mag = 20 * np.log10(np.maximum(tf.magnitude, np.finfo(float).tiny))
    phase = tf.phase
    inner = np.arange(1, mag.size - 1)
    cand = inner[(mag[inner] < mag[inner - 1]) & (mag[inner] <= mag[inner + 1])]
    found = []
    for k in cand:
        left = mag[:k][::-1]
        right = mag[k + 1:]
        if min(_peak_until_lower(left, mag[k]), _peak_until_lower(right, mag[k])) \
                - mag[k] < min_depth_db:
            continue
        lo = k - 1 - _first_at_least(left, mag[k] + 3.0)
        hi = k + 1 + _first_at_least(right, mag[k] + 3.0)
        if phase[hi] - phase[lo] > np.pi / 4:
            found.append(tf.freqs[k])
    return np.asarray(found, dtype=float)


def _first_at_least(side: np.ndarray, level: float) -> int:
    above = np.flatnonzero(side >= level)
    return int(above[0]) if above.size else side.size - 1


def _peak_until_lower(side: np.ndarray, level: float) -> float:
    below = np.flatnonzero(side < level)
    seg = side[: below[0]] if below.size else side
    return float(seg.max()) if seg.size else -np.inf


def synthetic_tfs(n: int, *, band: tuple[float, float] = (0.0, 1000.0), n_lines: int = 1001,
                   rng: np.random.Generator | int | None = None,
                   n_modes: tuple[int, int] = (4, 12),
                   damping: tuple[float, float] = (0.01, 0.05),
                   attenuation: tuple[float, float] = (10.0, 20.0),
                   nonminimum_fraction: float = 0.5) -> list[TransferFunction]:
    """A seeded bank of realistic accelerance FRFs (stand-ins for measured hammer-test TFs).

    Each FRF is a free structure (rigid-body mass line, so |H(0)| > 0) with
    ``n_modes`` (uniform integer in the inclusive range) modes spread over the band's inner
    94 %, damping ratios uniform in ``damping``, log-normal residue magnitudes with random sign
    changes (at least one pair of neighbouring modes keeps its sign, so antiresonances
    appear), scaled so that its overall attenuation (:func:`attenuation_db`) is uniform in
    ``attenuation`` dB. A fraction ``nonminimum_fraction`` is made non-minimum-phase with a
    pure delay (0.2–2 ms) and, for half of those, an all-pass zero pair.

    Parameters
    ----------
    n : int
        Number of FRFs.
    band : (float, float)
        First and last line in Hz.
    n_lines : int
        Lines per FRF (evenly spaced).
    rng : numpy.random.Generator or int
        Seed or generator (required: the bank must be reproducible).
    n_modes, damping, attenuation, nonminimum_fraction
        Ranges of the random model, see above.

    Returns
    -------
    list of TransferFunction

    Examples
    --------
    >>> from gearshot.transfer import attenuation_db, synthetic_tfs
    >>> tfs = synthetic_tfs(2, rng=0)
    >>> len(tfs), tfs[0].n_lines
    (2, 1001)
    >>> all(10.0 <= attenuation_db(tf) <= 20.0 for tf in tfs)
    True
    """
    n = check_int(n, "n", minimum=1)
    n_lines = check_int(n_lines, "n_lines", minimum=16)
    if rng is None:
        raise GearshotError("rng must be given (an int seed or a numpy.random.Generator) so "
                            "that the bank is reproducible")
    rng = np.random.default_rng(rng)
    lo, hi = (float(b) for b in band)
    if not (np.isfinite(lo) and np.isfinite(hi) and 0 <= lo < hi):
        raise GearshotError(f"band must be (low, high) Hz with 0 <= low < high; got {band!r}")
    m_lo, m_hi = (check_int(v, "n_modes", minimum=1) for v in n_modes)
    if m_lo > m_hi:
        raise GearshotError(f"n_modes must be (min, max) with min <= max; got {n_modes!r}")
    z_lo, z_hi = (check_in_range(v, "damping", 0.0, 1.0, low_inclusive=False,
                                 high_inclusive=False) for v in damping)
    a_lo, a_hi = (check_positive(v, "attenuation", allow_zero=True) for v in attenuation)
    nonminimum_fraction = check_in_range(nonminimum_fraction, "nonminimum_fraction", 0.0, 1.0)
    freqs = np.linspace(lo, hi, n_lines)
    n_nmp = int(round(nonminimum_fraction * n))
    nmp_flags = np.zeros(n, bool)
    nmp_flags[rng.permutation(n)[:n_nmp]] = True
    return [_random_accelerance(rng, freqs, f"synthetic_{i:03d}", band=(lo, hi),
                                n_modes=(m_lo, m_hi),
                                damping=(min(z_lo, z_hi), max(z_lo, z_hi)),
                                attenuation=(min(a_lo, a_hi), max(a_lo, a_hi)),
                                nonminimum=bool(nmp_flags[i]))
            for i in range(n)]


def _random_accelerance(rng: np.random.Generator, freqs: np.ndarray, name: str, *,
                        band: tuple[float, float], n_modes: tuple[int, int],
                        damping: tuple[float, float], attenuation: tuple[float, float],
                        nonminimum: bool) -> TransferFunction:
    """One FRF of :func:`synthetic_tfs`' random model, its draws taken from ``rng`` in a
    fixed order (modes, damping, frequencies, residues, rigid body, delay/all-pass, level)."""
    lo, hi = band
    k = int(rng.integers(n_modes[0], n_modes[1] + 1))
    zeta = rng.uniform(damping[0], damping[1], size=k)
    fr = _spread_modes(rng, k, lo + 0.03 * (hi - lo), lo + 0.97 * (hi - lo))
    mags = rng.lognormal(0.0, 0.6, size=k)
    flips = rng.random(k - 1) < 0.35
    if k > 1 and flips.all():
        flips[rng.integers(k - 1)] = False  # keep one same-sign pair -> antiresonance
    signs = np.concatenate([[1.0], np.where(np.cumsum(flips) % 2 == 1, -1.0, 1.0)])
    modes = [Mode(float(a), float(b), float(c)) for a, b, c in zip(fr, zeta, signs * mags)]
    rigid = float(rng.uniform(0.2, 1.0) * mags.mean())
    delay = 0.0
    allp: tuple[tuple[float, float], ...] = ()
    if nonminimum:
        delay = float(rng.uniform(0.2e-3, 2e-3))
        if rng.random() < 0.5:
            allp = ((float(rng.uniform(lo + 0.2 * (hi - lo), lo + 0.8 * (hi - lo))),
                     float(rng.uniform(0.05, 0.3))),)
    tf = modal_frf(freqs, modes, rigid_body=rigid, delay=delay, allpass=allp, name=name)
    target = rng.uniform(attenuation[0], attenuation[1])
    gain = 10 ** (-target / 20) / np.sqrt(np.mean(tf.magnitude**2))
    meta = dict(tf.metadata, scale=float(gain), attenuation_db=float(target),
                nonminimum_phase_added=nonminimum)
    return TransferFunction(freqs=freqs, values=tf.values * gain, name=tf.name,
                            response_quantity="acceleration", metadata=meta)


def _spread_modes(rng: np.random.Generator, k: int, lo: float, hi: float) -> np.ndarray:
    """k sorted frequencies in [lo, hi], random but at least half the mean spacing apart."""
    gap = 0.5 * (hi - lo) / k
    # k uniform points in an interval shortened by the k-1 gaps, then the gaps added back
    base = np.sort(rng.uniform(0.0, (hi - lo) - gap * (k - 1), size=k))
    return lo + base + gap * np.arange(k)
