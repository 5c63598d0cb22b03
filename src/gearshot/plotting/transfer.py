"""Plotting of transfer functions (matplotlib imported lazily; to move to gearshot.plotting)."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np

from .._errors import GearshotError
from ..transfer.function import TransferFunction

__all__ = ["plot_transfer_function", "plot_transfer_functions"]


def plot_transfer_function(tf: TransferFunction, ax: Sequence | None = None, *,
                           db: bool = True, wrap_phase: bool = True, phase_center: float = 0.0,
                           label: str | None = None, **line_kw):
    """Magnitude and phase of one TF against frequency in Hz.

    Parameters
    ----------
    tf : TransferFunction
    ax : (Axes, Axes), optional
        Magnitude and phase axes. If omitted, a new figure with two stacked axes (shared x)
        is created.
    db : bool
        Magnitude in dB (20·log10|H|) rather than linear.
    wrap_phase : bool
        Phase wrapped into a 360° window (default) or unwrapped.
    phase_center : float
        Centre of the wrapping window in degrees: the phase is shown in
        [phase_center − 180°, phase_center + 180°). Use 90 for nearly real FRFs (phase
        close to 0° or 180°), which otherwise flicker between ±180°.
    label : str, optional
        Legend label (default: ``tf.name``).
    **line_kw
        Passed to both ``Axes.plot`` calls.

    Returns
    -------
    (Line2D, Line2D)
        The magnitude and phase lines.
    """
    if not isinstance(tf, TransferFunction):
        raise GearshotError(f"tf must be a TransferFunction; got {type(tf).__name__}")
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(2, 1, sharex=True, figsize=(8, 5))
    try:
        ax_mag, ax_ph = ax
    except (TypeError, ValueError):
        raise GearshotError("ax must be a pair of Axes (magnitude, phase)") from None
    mag = tf.magnitude
    if db:
        mag = 20 * np.log10(np.maximum(mag, np.finfo(float).tiny))
    if wrap_phase:
        ph = np.mod(np.degrees(np.angle(tf.values)) - phase_center + 180.0, 360.0) \
            - 180.0 + phase_center
    else:
        ph = np.degrees(tf.phase)
    label = tf.name if label is None else label
    (l_mag,) = ax_mag.plot(tf.freqs, mag, label=label, **line_kw)
    (l_ph,) = ax_ph.plot(tf.freqs, ph, label=label, **line_kw)
    unit = f" [{tf.units}]" if tf.units else ""
    ax_mag.set_ylabel(("|H| [dB]" if db else "|H|") + unit)
    ax_ph.set_ylabel("phase [deg]")
    ax_ph.set_xlabel("frequency [Hz]")
    return l_mag, l_ph


def plot_transfer_functions(tfs: Iterable[TransferFunction], axes: Sequence | None = None, *,
                            db: bool = True, offset_db: float = 0.0, **line_kw):
    """Overlay several TFs (e.g. a :class:`TransferFunctionBank`).

    ``offset_db`` shifts each successive magnitude curve down by that many dB (readability).
    Returns the list of ``(magnitude line, phase line)`` pairs.
    """
    tfs = list(tfs)
    if axes is None:
        import matplotlib.pyplot as plt

        _, axes = plt.subplots(2, 1, sharex=True, figsize=(9, 6))
    out = []
    for i, tf in enumerate(tfs):
        scaled = tf
        if offset_db and db:
            import dataclasses

            scaled = dataclasses.replace(tf, values=tf.values * 10 ** (-offset_db * i / 20))
        out.append(plot_transfer_function(scaled, axes, db=db, **line_kw))
    return out
