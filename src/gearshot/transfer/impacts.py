"""FRF estimation from impact-hammer tests (H1 / H2 estimators averaged over impacts)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from .._errors import GearshotError
from .._validation import as_signal_array, check_in_range, check_positive
from .function import TransferFunction
from .uff import UffRecord

__all__ = ["ImpactFRF", "frf_from_impacts", "impact_arrays"]

_ESTIMATORS = ("H1", "H2")


class ImpactFRF(NamedTuple):
    """Result of :func:`frf_from_impacts` (unpacks as ``tf, coherence``).

    Attributes
    ----------
    tf : TransferFunction
        The averaged FRF on ``numpy.fft.rfftfreq(n_samples, 1/fs)`` (0 Hz … fs/2).
    coherence : numpy.ndarray, shape (n_lines,)
        Ordinary coherence γ² = |G_fx|² / (G_ff G_xx) in [0, 1]; identically 1 for a single
        impact.
    """

    tf: TransferFunction
    coherence: np.ndarray


def _force_window(force: np.ndarray, fs: float, duration: float) -> np.ndarray:
    """Per-impact force window: 1 from a quarter of ``duration`` before the peak to
    ``duration`` after it, with raised-cosine edges of a tenth of ``duration``; 0 elsewhere."""
    n = force.shape[-1]
    w_len = max(2, int(round(duration * fs)))
    taper = max(1, w_len // 10)
    idx = np.arange(n)
    peak = np.argmax(np.abs(force), axis=-1)[..., None]
    start = peak - w_len // 4
    stop = peak + w_len
    win = ((idx >= start) & (idx <= stop)).astype(float)
    # raised-cosine ramps just outside the flat part
    ramp_up = (idx < start) & (idx >= start - taper)
    ramp_dn = (idx > stop) & (idx <= stop + taper)
    win = np.where(ramp_up, 0.5 * (1 + np.cos(np.pi * (start - idx) / taper)), win)
    win = np.where(ramp_dn, 0.5 * (1 + np.cos(np.pi * (idx - stop) / taper)), win)
    return win


def _exp_window(force: np.ndarray, end_value: float) -> np.ndarray:
    """Exponential window from each impact's force peak (value 1) to ``end_value`` at the
    last sample; 1 before the peak."""
    n = force.shape[-1]
    idx = np.arange(n)
    peak = np.argmax(np.abs(force), axis=-1)[..., None]
    span = np.maximum(n - 1 - peak, 1)
    rel = np.clip((idx - peak) / span, 0.0, None)
    return np.exp(np.log(end_value) * rel)


def frf_from_impacts(force, response, fs: float, *, estimator: str = "H1",
                     force_window: float | None = 0.01,
                     exp_window: float | None = None) -> ImpactFRF:
    """Estimate an FRF from impact-hammer records, averaging the spectra over impacts.

    Parameters
    ----------
    force : array_like, shape (n_impacts, n_samples) or (n_samples,)
        Hammer force records (one row per impact), in N.
    response : array_like, same shape as ``force``
        Response records (e.g. acceleration in m/s²) taken with each impact.
    fs : float
        Sampling rate in Hz.
    estimator : {"H1", "H2"}
        ``"H1"`` = G_fx / G_ff (unbiased by response noise; the usual choice for hammer
        tests), ``"H2"`` = G_xx / G_xf (unbiased by force noise). G are the cross/auto
        spectra averaged over impacts.
    force_window : float or None
        Duration in s of the force window: each force record is kept
        from a quarter of this before its peak to this after it, with short raised-cosine
        edges, and zeroed elsewhere (suppresses the force channel's noise after the pulse).
        ``None`` disables. Default 0.01 s.
    exp_window : float or None
        Value in (0, 1] reached at the record's end by an exponential window that starts at
        each impact's force peak; applied to force and response alike to reduce leakage of
        responses that have not decayed. It adds apparent damping (not corrected here).
        ``None`` (default) disables.

    Returns
    -------
    ImpactFRF
        ``(tf, coherence)``; ``tf.metadata`` records the estimator and the number of impacts.

    Raises
    ------
    GearshotError
        On mismatched shapes, non-finite samples, bad options, or a force spectrum that is
        zero at some line.

    Examples
    --------
    Three hammer pulses into a single-mode system (a resonator at 300 Hz, sampled at
    4096 Hz, fully decayed within the record): H1 peaks at the mode with coherence 1.

    >>> import numpy as np
    >>> import scipy.signal
    >>> from gearshot.transfer import frf_from_impacts
    >>> fs, w0, r = 4096.0, 2 * np.pi * 300 / 4096.0, 0.99
    >>> force = np.zeros((3, 4096))
    >>> for i in range(3):
    ...     force[i, 40 + 7 * i: 46 + 7 * i] = 80.0 * np.sin(np.pi * np.arange(6) / 6)
    >>> response = scipy.signal.lfilter([0.5, 0.0, -0.5], [1, -2 * r * np.cos(w0), r**2],
    ...                                 force, axis=-1)
    >>> tf, coherence = frf_from_impacts(force, response, fs, force_window=None)
    >>> print(round(float(tf.freqs[np.argmax(np.abs(tf.values))]), 1))
    300.0
    >>> print(round(float(np.median(coherence)), 3))
    1.0
    """
    fs = check_positive(fs, "fs")
    if estimator not in _ESTIMATORS:
        raise GearshotError(f"estimator must be one of {_ESTIMATORS}; got {estimator!r}")
    f = as_signal_array(force, "force", min_ndim=1, max_ndim=2, min_length=4)
    x = as_signal_array(response, "response", min_ndim=1, max_ndim=2, min_length=4)
    if f.shape != x.shape:
        raise GearshotError(f"response must have the shape of force {f.shape}; got {x.shape}")
    f, x, force_window, exp_window = _windowed(np.atleast_2d(f), np.atleast_2d(x), fs,
                                               force_window, exp_window)
    freqs = np.fft.rfftfreq(f.shape[-1], 1.0 / fs)
    h, coh = _h_and_coherence(np.fft.rfft(f, axis=-1), np.fft.rfft(x, axis=-1), freqs,
                              estimator)
    tf = TransferFunction(freqs=freqs, values=h, name=f"{estimator} from {f.shape[0]} impact(s)",
                          metadata={"estimator": estimator, "n_impacts": int(f.shape[0]),
                                    "force_window_s": force_window,
                                    "exp_window_end": exp_window, "fs_hz": fs})
    return ImpactFRF(tf, coh)


def _windowed(f: np.ndarray, x: np.ndarray, fs: float, force_window: float | None,
              exp_window: float | None
              ) -> tuple[np.ndarray, np.ndarray, float | None, float | None]:
    """Force (and, with ``exp_window``, response) records windowed per impact; the checked
    window parameters."""
    if force_window is not None:
        force_window = check_positive(force_window, "force_window")
        f = f * _force_window(f, fs, force_window)
    if exp_window is not None:
        exp_window = check_in_range(exp_window, "exp_window", 0.0, 1.0, low_inclusive=False)
        e = _exp_window(f, exp_window)
        f = f * e
        x = x * e
    return f, x, force_window, exp_window


def _h_and_coherence(F: np.ndarray, X: np.ndarray, freqs: np.ndarray,
                     estimator: str) -> tuple[np.ndarray, np.ndarray]:
    """H1 or H2 from the impacts' spectra (averaged over the first axis), and the ordinary
    coherence; refuses lines where the estimator is undefined."""
    g_ff = np.mean(np.abs(F) ** 2, axis=0)
    g_xx = np.mean(np.abs(X) ** 2, axis=0)
    g_fx = np.mean(np.conj(F) * X, axis=0)
    tiny = np.finfo(float).tiny
    if np.any(g_ff <= tiny):
        k = int(np.flatnonzero(g_ff <= tiny)[0])
        raise GearshotError(f"force has no energy at {freqs[k]:g} Hz (line {k}); "
                            "the FRF is undefined there")
    if estimator == "H1":
        h = g_fx / g_ff
    else:
        if np.any(np.abs(g_fx) <= tiny):
            k = int(np.flatnonzero(np.abs(g_fx) <= tiny)[0])
            raise GearshotError(f"response is uncorrelated with force at {freqs[k]:g} Hz "
                                f"(line {k}); H2 is undefined there")
        h = g_xx / np.conj(g_fx)
    with np.errstate(divide="ignore", invalid="ignore"):
        coh = np.where(g_xx > tiny, np.abs(g_fx) ** 2 / (g_ff * g_xx), 0.0)
    return h, np.clip(coh, 0.0, 1.0)


def impact_arrays(records: Sequence[UffRecord], *, response_quantity: str | None = None
                  ) -> tuple[np.ndarray, np.ndarray, float]:
    """Stack impact-test time records into force and response arrays.

    Parameters
    ----------
    records : sequence of UffRecord
        As returned by :func:`read_uff_records`; the records whose ``quantity`` is
        ``"force"`` are the forces, the others the responses, paired in file order.
    response_quantity : str, optional
        Keep only responses of this quantity (e.g. ``"acceleration"``).

    Returns
    -------
    force, response : numpy.ndarray, shape (n_impacts, n_samples)
    fs : float
        Common sampling rate in Hz.

    Examples
    --------
    >>> import numpy as np
    >>> from gearshot.transfer import UffRecord, impact_arrays
    >>> records = [UffRecord(np.r_[1.0, np.zeros(7)], 1000.0, quantity="force"),
    ...            UffRecord(np.linspace(0.0, 1.0, 8), 1000.0, quantity="acceleration")]
    >>> force, response, fs = impact_arrays(records)
    >>> force.shape, response.shape, fs
    ((1, 8), (1, 8), 1000.0)
    """
    recs = list(records)
    if not recs or not all(isinstance(r, UffRecord) for r in recs):
        raise GearshotError("records must be a non-empty sequence of UffRecord")
    forces = [r for r in recs if r.quantity == "force"]
    resp = [r for r in recs if r.quantity != "force"
            and (response_quantity is None or r.quantity == response_quantity)]
    if not forces or len(forces) != len(resp):
        raise GearshotError(f"records must pair force and response records one to one; got "
                            f"{len(forces)} force and {len(resp)} response record(s)")
    fss = {r.fs for r in recs}
    lens = {r.data.size for r in forces + resp}
    if len(fss) != 1 or len(lens) != 1:
        raise GearshotError(f"records must share one sampling rate and length; got rates "
                            f"{sorted(fss)} Hz and lengths {sorted(lens)}")
    return (np.stack([r.data for r in forces]), np.stack([r.data for r in resp]),
            float(fss.pop()))
